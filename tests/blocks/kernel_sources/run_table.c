/* A plain C host of the op-table core (blocks/csrc/core.h), with no Python: it reads a
 * packed table (OpTable.pack), binds the test kernels of leak.c as a spec file says, runs
 * the table once and writes what the run logged.
 *
 *     run_table TABLE SPEC OUT
 *
 * SPEC has one line per block, in the table's order: "leak A B LIMIT WIDTH X0",
 * "scale K WIDTH" or "stopper STOP" (the contexts of leak.c's kernels; a leak's state is
 * WIDTH values of X0, a stopper's one zero). OUT receives, per log entry, its rows
 * written (int64) and those rows (doubles). stdout: "status end reached op tick code
 * end_op end_asked". Exit 0 when the run could be made, 1 otherwise.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "blocks_kernel.h"
#include "core.h"

int leak_output(const void *, double, const double *, const double *const *, double *, int *);
int leak_update(const void *, double, double *, const double *const *, int *);
int leak_advance(const void *, double, double *, const double *const *, int, double *, int *, int *);
int scale_output(const void *, double, const double *, const double *const *, double *, int *);
int stopper_output(const void *, double, const double *, const double *const *, double *, int *);
int stopper_update(const void *, double, double *, const double *const *, int *);

static void *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    void *data = malloc(n > 0 ? (size_t)n : 1);
    if (data != NULL && fread(data, 1, (size_t)n, f) != (size_t)n) {
        free(data);
        data = NULL;
    }
    fclose(f);
    *size = (size_t)n;
    return data;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: run_table TABLE SPEC OUT\n");
        return 1;
    }
    size_t size;
    void *packed = read_file(argv[1], &size);
    blk_table table;
    const double *initial;
    const char *bad = packed ? blk_table_unpack(packed, size, &table, &initial) : "cannot read the table";
    if (bad) {
        fprintf(stderr, "run_table: %s\n", bad);
        return 1;
    }
    FILE *spec = fopen(argv[2], "r");
    if (spec == NULL)
        return 1;
    int64_t n = table.n_blocks;
    blk_kernel *kernels = calloc((size_t)(n ? n : 1), sizeof *kernels);
    double **contexts = calloc((size_t)(n ? n : 1), sizeof *contexts);
    for (int64_t b = 0; b < n; b++) {
        char kind[16];
        double *ctx = contexts[b] = calloc(5, sizeof(double)), x0 = 0.0;
        if (fscanf(spec, "%15s", kind) != 1)
            return 1;
        kernels[b].ctx = ctx;
        kernels[b].nogil = 1;
        if (strcmp(kind, "leak") == 0) {
            if (fscanf(spec, "%lf %lf %lf %lf %lf", &ctx[0], &ctx[1], &ctx[2], &ctx[3], &x0) != 5)
                return 1;
            kernels[b].output = leak_output;
            kernels[b].update = leak_update;
            kernels[b].advance = leak_advance;
            kernels[b].state = malloc((size_t)ctx[3] * sizeof(double));
            for (int i = 0; i < (int)ctx[3]; i++)
                kernels[b].state[i] = x0;
        } else if (strcmp(kind, "scale") == 0) {
            if (fscanf(spec, "%lf %lf", &ctx[0], &ctx[1]) != 2)
                return 1;
            kernels[b].output = scale_output;
        } else if (strcmp(kind, "stopper") == 0) {
            if (fscanf(spec, "%lf", &ctx[0]) != 1)
                return 1;
            kernels[b].output = stopper_output;
            kernels[b].update = stopper_update;
            kernels[b].state = calloc(1, sizeof(double));
        } else {
            return 1;
        }
    }
    fclose(spec);
    int64_t values = table.header[BLK_H_ARENA];
    double *arena = malloc((size_t)(values ? values : 1) * sizeof(double));
    memcpy(arena, initial, (size_t)values * sizeof(double));
    double **logs = calloc((size_t)(table.n_logs ? table.n_logs : 1), sizeof *logs);
    for (int64_t e = 0; e < table.n_logs; e++) {
        const int64_t *lg = table.logs + e * BLK_L_N;
        logs[e] = malloc((size_t)(lg[BLK_L_CAPACITY] * lg[BLK_L_WIDTH] + 1) * sizeof(double));
    }
    int64_t *counters = calloc((size_t)(table.n_logs * BLK_LC_N + 1), sizeof(int64_t));
    blk_run run = {&table, arena, kernels, logs, counters, {NULL, NULL, NULL, NULL, NULL}, 0, {0}, 0, {0}, NULL};
    int status = blk_run_table(&run);
    const blk_outcome *o = &run.outcome;
    printf("%d %lld %lld %lld %lld %d %lld %lld\n", status, (long long)o->end, (long long)o->reached,
           (long long)o->op, (long long)o->tick, o->code, (long long)o->end_op, (long long)o->end_asked);
    FILE *out = fopen(argv[3], "wb");
    if (out == NULL)
        return 1;
    for (int64_t e = 0; e < table.n_logs; e++) {
        int64_t rows = counters[e * BLK_LC_N + BLK_LC_ROWS];
        fwrite(&rows, sizeof rows, 1, out);
        fwrite(logs[e], sizeof(double), (size_t)(rows * table.logs[e * BLK_L_N + BLK_L_WIDTH]), out);
    }
    fclose(out);
    return status == BLK_RUN_BAD;
}
