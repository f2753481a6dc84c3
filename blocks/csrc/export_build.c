/* The kernels of an exported FMU's instance, built when it leaves initialization (or a
 * value is read or a state set) from the blocks' records with the parameters written in,
 * the follow rules and links applied, each block's kernel type constructing its kernel
 * and its state; and released when a parameter changes or the instance ends. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "export_internal.h"

void ex_release_build(blk_instance *inst)
{
    ex_build *b = inst->build;
    if (b == NULL)
        return;
    const blk_export *x = &inst->x;
    blk_run_release(&b->run);
    for (int64_t k = 0; k < x->n_blocks; k++) {
        if (b->built != NULL && b->built[k].ctx != NULL)
            x->blocks[k].type->destroy(b->built[k].ctx);
        if (b->records != NULL)
            free(b->records[k]);
        if (b->states != NULL)
            free(b->states[k]);
    }
    free(b->records);
    free(b->built);
    free(b->kernels);
    free(b->states);
    free(b->state_sizes);
    free(b->arena);
    free(b->held_outputs);
    free(b);
    inst->build = NULL;
    inst->outputs_fresh = 0;
}

/* The records with the parameters written in, the follow rules and the links applied: 0;
   -1 out of memory; -2 a parameter that must be finite is not (logged). */
static int write_records(blk_instance *inst, ex_build *b)
{
    const blk_export *x = &inst->x;
    for (int64_t k = 0; k < x->n_blocks; k++) {
        const ex_block *e = x->blocks + k;
        b->records[k] = malloc((size_t)(e->n_record > 0 ? e->n_record : 1) * sizeof(double));
        if (b->records[k] == NULL)
            return -1;
        memcpy(b->records[k], e->record, (size_t)e->n_record * sizeof(double));
    }
    for (int64_t p = 0; p < x->n_params; p++) {
        if (x->params[p].finite && !isfinite(inst->params[p])) {
            LOG_ERROR(inst, "invalid parameter: %s must be finite, got %g", x->params[p].name, inst->params[p]);
            return -2;
        }
        b->records[x->params[p].block][x->params[p].slot] = inst->params[p];
    }
    for (int64_t f = 0; f < x->n_follows; f++) {
        const ex_follow *g = x->follows + f;
        int when = 0, unless = 0;
        for (int64_t j = 0; j < g->n_when; j++)
            when |= inst->set[g->when[j]];
        for (int64_t j = 0; j < g->n_unless; j++)
            unless |= inst->set[g->unless[j]];
        if (when && !unless)
            b->records[g->block][g->slot] = 1.0;
    }
    for (int64_t l = 0; l < x->n_links; l++) {
        const ex_link *k = x->links + l;
        memcpy(b->records[k->block] + k->slot, b->records[k->source] + k->source_slot,
               (size_t)k->length * sizeof(double));
    }
    return 0;
}

/* Construct block k's kernel and its state; 0, or -1 after logging why. */
static int build_block(blk_instance *inst, ex_build *b, int64_t k)
{
    const ex_block *e = inst->x.blocks + k;
    const blk_table *t = &inst->x.table;
    char message[512] = "", prefix[256];
    ex_block_prefix(inst, k, prefix, sizeof prefix);
    if (e->type->construct(b->records[k], (long)e->n_record, &b->built[k], message, sizeof message) != 0) {
        b->built[k].ctx = NULL;
        LOG_ERROR(inst, "invalid parameter: %s%s", prefix, message);
        return -1;
    }
    int64_t width = t->blocks[k * BLK_B_N + BLK_B_WIDTH];
    if (b->built[k].outputs != width) {
        LOG_ERROR(inst, "%sits kernel writes %ld outputs, the diagram's block has %lld", prefix, b->built[k].outputs,
                  (long long)width);
        return -1;
    }
    int64_t size = e->built_state ? b->built[k].state_size : e->n_state;
    if ((size > 0) != (e->n_state > 0)) {
        LOG_ERROR(inst, "invalid parameter: %sthe parameters would %s its state, which changes the diagram", prefix,
                  size > 0 ? "give it" : "take away");
        return -1;
    }
    b->state_sizes[k] = size;
    if (size > 0) {
        b->states[k] = malloc((size_t)size * sizeof(double));
        if (b->states[k] == NULL) {
            LOG_ERROR(inst, "%sno memory for a state of %lld values", prefix, (long long)size);
            return -1;
        }
        if (e->built_state)
            e->type->initial(b->built[k].ctx, b->states[k]);
        else
            memcpy(b->states[k], e->state, (size_t)size * sizeof(double));
    }
    b->kernels[k] = (blk_kernel){e->type->output, e->type->update, e->type->advance, b->built[k].ctx, b->states[k], 1};
    return 0;
}

static void write_inputs(blk_instance *inst)
{
    const blk_export *x = &inst->x;
    for (int64_t i = 0; i < x->n_inputs; i++)
        for (int64_t j = 0; j < x->inputs[i].n; j++)
            inst->build->arena[x->inputs[i].offsets[j]] = inst->inputs[i];
}

/* Build every kernel from the current parameters and the run at t = 0 with its outputs;
   0, or -1 after logging why. */
int ex_build_kernels(blk_instance *inst)
{
    if (inst->build != NULL)
        return 0;
    const blk_export *x = &inst->x;
    size_t n = (size_t)x->n_blocks + 1;
    ex_build *b = calloc(1, sizeof *b);
    if (b == NULL) {
        LOG_ERROR(inst, "out of memory");
        return -1;
    }
    inst->build = b;
    b->records = calloc(n, sizeof *b->records);
    b->built = calloc(n, sizeof *b->built);
    b->kernels = calloc(n, sizeof *b->kernels);
    b->states = calloc(n, sizeof *b->states);
    b->state_sizes = calloc(n, sizeof *b->state_sizes);
    b->arena = malloc((size_t)(x->table.header[BLK_H_ARENA] + 1) * sizeof(double));
    b->held_outputs = calloc((size_t)x->n_outputs + 1, sizeof *b->held_outputs);
    int written = b->records == NULL || b->built == NULL || b->kernels == NULL || b->states == NULL ||
                          b->state_sizes == NULL || b->arena == NULL || b->held_outputs == NULL
                      ? -1
                      : write_records(inst, b);
    if (written != 0) {
        if (written == -1)
            LOG_ERROR(inst, "out of memory for %lld blocks", (long long)x->n_blocks);
        ex_release_build(inst);
        return -1;
    }
    for (int64_t k = 0; k < x->n_blocks; k++)
        if (build_block(inst, b, k) != 0) {
            ex_release_build(inst);
            return -1;
        }
    memcpy(b->arena, x->arena0, (size_t)x->table.header[BLK_H_ARENA] * sizeof(double));
    write_inputs(inst);
    b->run.table = &x->table;
    b->run.arena = b->arena;
    b->run.kernels = b->kernels;
    if (blk_run_begin(&b->run) != 0) {
        LOG_ERROR(inst, "the diagram cannot run: %s", b->run.outcome.message);
        ex_release_build(inst);
        return -1;
    }
    if (inst->stop_defined && inst->stop_tick < b->run.at.end)
        b->run.at.end = inst->stop_tick;
    return ex_refresh_outputs(inst) < 0 ? -1 : 0;
}
