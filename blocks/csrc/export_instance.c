/* One instance of an exported diagram FMU: its resources, parameters, initialization,
 * stepping and FMU states. See export_instance.h. Plain C99 and libc: the binary of an
 * exported FMU is this, the core, the FMI wrapper and the kernels. */
#include "export_instance.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STEP_TOLERANCE 1e-6 /* a communication step may miss a whole number of ticks by this many */
#define EXACT_TICKS 9007199254740992.0 /* 2^53: tick times are exact while tick * num stays below */

static const char *PHASE_NAMES[] = {"instantiated", "initialization mode", "step mode", "terminated", "failed"};

/* -- the diagram, as the resources describe it ------------------------------------------- */

typedef struct {
    char *name, *kind;
    const blk_kernel_type *type;
    const double *record;
    int64_t n_record;
    const double *state; /* the state Python gave the block, n_state values */
    int64_t n_state;
    int built_state; /* the kind builds the state */
} ex_block;

typedef struct {
    double start;
    int64_t n;
    const int64_t *offsets;
} ex_input;

typedef struct {
    int64_t block, slot, finite;
    char *name;
} ex_param;

typedef struct {
    int64_t block, slot, n_when, n_unless;
    const int64_t *when, *unless;
} ex_follow;

typedef struct {
    int64_t block, slot, source, source_slot, length;
} ex_link;

struct blk_export {
    int64_t *data;
    char *token, *model;
    int64_t grid, vr_input, vr_output, vr_param;
    int64_t initial_outputs, between, lazy;
    blk_table table;
    const double *arena0;
    int64_t n_blocks, n_inputs, n_outputs, n_params, n_follows, n_links;
    ex_block *blocks;
    ex_input *inputs;
    const int64_t *outputs;
    ex_param *params;
    ex_follow *follows;
    const ex_link *links;
};

/* The kernels of one initialized instance. */
typedef struct {
    double **records;
    blk_built *built;
    blk_kernel *kernels;
    double **states;
    int64_t *state_sizes;
    double *arena;
    blk_run run;
} ex_build;

struct blk_instance {
    char *name;
    blk_logger log;
    void *environment;
    int log_events;
    blk_export x;
    double *params;
    unsigned char *set;
    double *inputs;
    ex_build *build; /* NULL until the kernels are built */
    int outputs_fresh;
    int stop_defined;
    int64_t stop_tick;
    double stop_time;
    blk_phase phase;
};

void blk_instance_log(const blk_instance *inst, blk_status status, const char *category, const char *format, ...)
{
    if (inst == NULL || inst->log == NULL)
        return;
    if (status == BLK_STATUS_OK && !inst->log_events)
        return;
    char message[1024];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    inst->log(inst->environment, inst->name, status, category, message);
}

#define LOG_ERROR(inst, ...) blk_instance_log((inst), BLK_STATUS_ERROR, BLK_LOG_ERROR, __VA_ARGS__)
#define LOG_EVENT(inst, ...) blk_instance_log((inst), BLK_STATUS_OK, BLK_LOG_EVENTS, __VA_ARGS__)

blk_phase blk_instance_phase(const blk_instance *inst)
{
    return inst->phase;
}

blk_status blk_instance_set_logging(blk_instance *inst, int on, size_t n, const char *const categories[])
{
    int events = n == 0;
    for (size_t i = 0; i < n; i++) {
        if (categories == NULL || categories[i] == NULL)
            continue;
        if (strcmp(categories[i], BLK_LOG_EVENTS) == 0)
            events = 1;
        else if (strcmp(categories[i], BLK_LOG_WARNING) != 0 && strcmp(categories[i], BLK_LOG_ERROR) != 0) {
            LOG_ERROR(inst, "unknown log category '%s' (this FMU has %s, %s, %s)", categories[i], BLK_LOG_EVENTS,
                      BLK_LOG_WARNING, BLK_LOG_ERROR);
            return BLK_STATUS_ERROR;
        }
    }
    inst->log_events = on && events;
    return BLK_STATUS_OK;
}

int blk_path_from_uri(const char *uri, char *out, size_t size)
{
    const char *p = uri;
    if (strncmp(p, "file:", 5) == 0) {
        p += 5;
        if (strncmp(p, "///", 3) == 0)
            p += 2; /* file:///path */
        else if (strncmp(p, "//localhost/", 12) == 0)
            p += 11; /* file://localhost/path */
        else if (strncmp(p, "//", 2) == 0)
            return -1; /* a remote host */
    }
    size_t n = 0;
    while (*p != '\0') {
        char c = *p++;
        if (c == '%' && isxdigit((unsigned char)p[0]) && isxdigit((unsigned char)p[1])) {
            char hex[3] = {p[0], p[1], '\0'};
            c = (char)strtol(hex, NULL, 16);
            p += 2;
        }
        if (n + 1 >= size)
            return -1;
        out[n++] = c;
    }
    out[n] = '\0';
    return n > 0 ? 0 : -1;
}

/* -- reading the resources ---------------------------------------------------------------- */

typedef struct {
    const int64_t *w;
    int64_t n, at;
    int ok;
} reader;

static int64_t word(reader *r)
{
    if (!r->ok || r->at >= r->n) {
        r->ok = 0;
        return 0;
    }
    return r->w[r->at++];
}

/* The next count words (count >= 0, within the file); NULL otherwise. */
static const int64_t *words(reader *r, int64_t count)
{
    if (!r->ok || count < 0 || count > r->n - r->at) {
        r->ok = 0;
        return NULL;
    }
    const int64_t *p = r->w + r->at;
    r->at += count;
    return p;
}

/* A count, then that many words; a count of at most limit. */
static const int64_t *counted(reader *r, int64_t *count, int64_t limit)
{
    *count = word(r);
    if (*count < 0 || *count > limit)
        r->ok = 0;
    return words(r, *count);
}

static char *string(reader *r)
{
    int64_t length = word(r);
    if (length < 0 || length > 1 << 20) {
        r->ok = 0;
        return NULL;
    }
    const int64_t *p = words(r, (length + 7) / 8);
    char *s = p != NULL ? malloc((size_t)length + 1) : NULL;
    if (s == NULL) {
        r->ok = 0;
        return NULL;
    }
    memcpy(s, p, (size_t)length);
    s[length] = '\0';
    return s;
}

static int64_t index_in(reader *r, int64_t limit)
{
    int64_t i = word(r);
    if (i < 0 || i >= limit)
        r->ok = 0;
    return i;
}

static void free_export(blk_export *x)
{
    for (int64_t b = 0; x->blocks != NULL && b < x->n_blocks; b++) {
        free(x->blocks[b].name);
        free(x->blocks[b].kind);
    }
    for (int64_t p = 0; x->params != NULL && p < x->n_params; p++)
        free(x->params[p].name);
    free(x->blocks);
    free(x->inputs);
    free(x->params);
    free(x->follows);
    free(x->token);
    free(x->model);
    free(x->data);
    memset(x, 0, sizeof *x);
}

static const blk_kernel_type *kernel_type(const char *kind)
{
    for (const blk_kernel_type *const *set = blk_export_kernel_sets; *set != NULL; set++)
        for (const blk_kernel_type *k = *set; k->name != NULL; k++)
            if (strcmp(k->name, kind) == 0)
                return k;
    return NULL;
}

static void *read_file(blk_instance *inst, const char *path, int64_t *words_read)
{
    FILE *file = fopen(path, "rb");
    if (file == NULL) {
        LOG_ERROR(inst, "cannot open %s: the FMU's resources are missing or unreadable", path);
        return NULL;
    }
    int64_t *data = NULL;
    long size = fseek(file, 0, SEEK_END) == 0 ? ftell(file) : -1;
    if (size > 0 && size % 8 == 0 && fseek(file, 0, SEEK_SET) == 0 && (data = malloc((size_t)size)) != NULL &&
        fread(data, 1, (size_t)size, file) != (size_t)size) {
        free(data);
        data = NULL;
    }
    fclose(file);
    if (data == NULL)
        LOG_ERROR(inst, "cannot read %s (%ld bytes)", path, size);
    *words_read = size / 8;
    return data;
}

/* The blocks: names, kinds (looked up in this binary), records and states. */
static void read_blocks(reader *r, blk_export *x)
{
    x->n_blocks = word(r);
    if (!r->ok || x->n_blocks != x->table.n_blocks || (x->blocks = calloc((size_t)x->n_blocks + 1, sizeof *x->blocks)) == NULL) {
        r->ok = 0;
        return;
    }
    for (int64_t b = 0; r->ok && b < x->n_blocks; b++) {
        ex_block *k = x->blocks + b;
        k->name = string(r);
        k->kind = string(r);
        k->record = (const double *)counted(r, &k->n_record, r->n);
        k->built_state = (int)word(r);
        k->state = (const double *)counted(r, &k->n_state, r->n);
    }
}

static void read_variables(reader *r, blk_export *x)
{
    int64_t arena = x->table.header[BLK_H_ARENA];
    x->n_inputs = word(r);
    if (r->ok && (x->n_inputs < 0 || x->n_inputs > r->n || (x->inputs = calloc((size_t)x->n_inputs + 1, sizeof *x->inputs)) == NULL))
        r->ok = 0;
    for (int64_t i = 0; r->ok && i < x->n_inputs; i++) {
        int64_t bits = word(r);
        memcpy(&x->inputs[i].start, &bits, sizeof bits);
        x->inputs[i].offsets = counted(r, &x->inputs[i].n, arena);
        for (int64_t j = 0; r->ok && j < x->inputs[i].n; j++)
            if (x->inputs[i].offsets[j] < 0 || x->inputs[i].offsets[j] >= arena)
                r->ok = 0;
    }
    x->outputs = counted(r, &x->n_outputs, r->n);
    for (int64_t i = 0; r->ok && i < x->n_outputs; i++)
        if (x->outputs[i] < 0 || x->outputs[i] >= arena)
            r->ok = 0;
    x->n_params = word(r);
    if (r->ok && (x->n_params < 0 || x->n_params > r->n || (x->params = calloc((size_t)x->n_params + 1, sizeof *x->params)) == NULL))
        r->ok = 0;
    for (int64_t p = 0; r->ok && p < x->n_params; p++) {
        ex_param *q = x->params + p;
        q->block = index_in(r, x->n_blocks);
        q->slot = word(r);
        q->finite = word(r);
        q->name = string(r);
        if (r->ok && (q->slot < 0 || q->slot >= x->blocks[q->block].n_record))
            r->ok = 0;
    }
    x->n_follows = word(r);
    if (r->ok && (x->n_follows < 0 || x->n_follows > r->n || (x->follows = calloc((size_t)x->n_follows + 1, sizeof *x->follows)) == NULL))
        r->ok = 0;
    for (int64_t f = 0; r->ok && f < x->n_follows; f++) {
        ex_follow *g = x->follows + f;
        g->block = index_in(r, x->n_blocks);
        g->slot = word(r);
        g->when = counted(r, &g->n_when, x->n_params);
        g->unless = counted(r, &g->n_unless, x->n_params);
        if (r->ok && (g->slot < 0 || g->slot >= x->blocks[g->block].n_record))
            r->ok = 0;
        for (int64_t j = 0; r->ok && j < g->n_when + g->n_unless; j++) {
            int64_t p = j < g->n_when ? g->when[j] : g->unless[j - g->n_when];
            if (p < 0 || p >= x->n_params)
                r->ok = 0;
        }
    }
    x->n_links = word(r);
    x->links = (const ex_link *)words(r, x->n_links * 5);
    for (int64_t l = 0; r->ok && l < x->n_links; l++) {
        const ex_link *k = x->links + l;
        if (k->block < 0 || k->block >= x->n_blocks || k->source < 0 || k->source >= x->n_blocks || k->length < 0 ||
            k->slot < 0 || k->length > x->blocks[k->block].n_record - k->slot || k->source_slot < 0 ||
            k->length > x->blocks[k->source].n_record - k->source_slot)
            r->ok = 0;
    }
}

/* Read BLK_EXPORT_RESOURCE: 0, or -1 after logging why. */
static int read_resources(blk_instance *inst, const char *token, const char *folder)
{
    char path[4096];
    size_t len = strlen(folder);
    const char *sep = len > 0 && folder[len - 1] == '/' ? "" : "/";
    if ((size_t)snprintf(path, sizeof path, "%s%s%s", folder, sep, BLK_EXPORT_RESOURCE) >= sizeof path) {
        LOG_ERROR(inst, "the resource folder path is too long: %s", folder);
        return -1;
    }
    blk_export *x = &inst->x;
    int64_t n;
    x->data = read_file(inst, path, &n);
    if (x->data == NULL)
        return -1;
    reader r = {x->data, n, 0, 1};
    if (word(&r) != BLK_EXPORT_MAGIC || word(&r) != BLK_EXPORT_VERSION) {
        LOG_ERROR(inst, "%s is not the resource of a diagram FMU of this version", path);
        return -1;
    }
    x->token = string(&r);
    x->model = string(&r);
    if (r.ok && token != NULL && strcmp(token, x->token) != 0) {
        LOG_ERROR(inst, "instantiation token '%s' does not match this FMU's '%s' (%s)", token, x->token, path);
        return -1;
    }
    x->grid = word(&r);
    x->vr_input = word(&r);
    x->vr_output = word(&r);
    x->vr_param = word(&r);
    x->initial_outputs = word(&r);
    x->between = word(&r);
    x->lazy = word(&r);
    int64_t table_words;
    const int64_t *table = counted(&r, &table_words, r.n);
    const char *bad = NULL;
    if (r.ok)
        bad = blk_table_unpack(table, (size_t)table_words * 8, &x->table, &x->arena0);
    if (bad != NULL) {
        LOG_ERROR(inst, "%s: its op table is wrong: %s", path, bad);
        return -1;
    }
    int64_t programs = x->table.n_programs;
    if (r.ok && (x->grid <= 0 || x->initial_outputs < 0 || x->initial_outputs >= programs || x->between < -1 ||
                 x->between >= programs || x->lazy < -1 || x->lazy >= programs))
        r.ok = 0;
    for (int64_t e = 0; r.ok && e < x->table.n_events; e++)
        if (x->table.programs[x->table.events[e * BLK_E_N + BLK_E_PROGRAM] * BLK_PR_N + BLK_PR_FINAL] < 0)
            r.ok = 0;
    read_blocks(&r, x);
    read_variables(&r, x);
    if (!r.ok || word(&r) != BLK_EXPORT_MAGIC || r.at != r.n) {
        LOG_ERROR(inst, "%s is damaged or incomplete (at word %lld of %lld)", path, (long long)r.at, (long long)n);
        return -1;
    }
    for (int64_t b = 0; b < x->n_blocks; b++) {
        ex_block *k = x->blocks + b;
        k->type = kernel_type(k->kind);
        if (k->type == NULL) {
            LOG_ERROR(inst, "block '%s': this FMU's binary has no kernel type '%s' (rebuild it with the sources of "
                            "the kind)", k->name, k->kind);
            return -1;
        }
    }
    return 0;
}

/* -- lifecycle ------------------------------------------------------------------------------ */

static void start_values(blk_instance *inst)
{
    const blk_export *x = &inst->x;
    for (int64_t p = 0; p < x->n_params; p++) {
        inst->params[p] = x->blocks[x->params[p].block].record[x->params[p].slot];
        inst->set[p] = 0;
    }
    for (int64_t i = 0; i < x->n_inputs; i++)
        inst->inputs[i] = x->inputs[i].start;
}

blk_instance *blk_instance_new(const char *name, const char *token, const char *resource_dir, blk_logger log,
                               void *environment, int logging_on)
{
    blk_instance *inst = calloc(1, sizeof *inst);
    if (inst == NULL) {
        if (log != NULL)
            log(environment, name, BLK_STATUS_ERROR, BLK_LOG_ERROR, "out of memory");
        return NULL;
    }
    inst->name = malloc(strlen(name != NULL ? name : "") + 1);
    if (inst->name == NULL) {
        free(inst);
        return NULL;
    }
    strcpy(inst->name, name != NULL ? name : "");
    inst->log = log;
    inst->environment = environment;
    inst->log_events = logging_on != 0;
    if (resource_dir == NULL || read_resources(inst, token, resource_dir) != 0) {
        if (resource_dir == NULL)
            LOG_ERROR(inst, "no resource location was given: the FMU needs its resources folder");
        blk_instance_free(inst);
        return NULL;
    }
    const blk_export *x = &inst->x;
    inst->params = calloc((size_t)x->n_params + 1, sizeof *inst->params);
    inst->set = calloc((size_t)x->n_params + 1, 1);
    inst->inputs = calloc((size_t)x->n_inputs + 1, sizeof *inst->inputs);
    if (inst->params == NULL || inst->set == NULL || inst->inputs == NULL) {
        LOG_ERROR(inst, "out of memory for %lld parameters", (long long)x->n_params);
        blk_instance_free(inst);
        return NULL;
    }
    start_values(inst);
    inst->phase = BLK_INSTANTIATED;
    LOG_EVENT(inst, "instantiated: %s, %lld blocks, base tick %lld/%lld s", x->model, (long long)x->n_blocks,
              (long long)x->table.header[BLK_H_TICK_NUM], (long long)x->table.header[BLK_H_TICK_DEN]);
    return inst;
}

static void release_build(blk_instance *inst)
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
    free(b);
    inst->build = NULL;
    inst->outputs_fresh = 0;
}

void blk_instance_free(blk_instance *inst)
{
    if (inst == NULL)
        return;
    release_build(inst);
    free_export(&inst->x);
    free(inst->params);
    free(inst->set);
    free(inst->inputs);
    free(inst->name);
    free(inst);
}

/* -- building the kernels ------------------------------------------------------------------ */

static const char *block_name(const blk_instance *inst, int64_t b)
{
    return inst->x.blocks[b].name;
}

/* "block 'name' (Kind): " before a block's message, or nothing in a one-block diagram. */
static void block_prefix(const blk_instance *inst, int64_t b, char *out, size_t size)
{
    if (inst->x.n_blocks == 1)
        out[0] = '\0';
    else
        snprintf(out, size, "block '%s' (%s): ", block_name(inst, b), inst->x.blocks[b].kind);
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
    block_prefix(inst, k, prefix, sizeof prefix);
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

static int refresh_outputs(blk_instance *inst);

/* Build every kernel from the current parameters and the run at t = 0 with its outputs;
   0, or -1 after logging why. */
static int build(blk_instance *inst)
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
    int written = b->records == NULL || b->built == NULL || b->kernels == NULL || b->states == NULL ||
                          b->state_sizes == NULL || b->arena == NULL
                      ? -1
                      : write_records(inst, b);
    if (written != 0) {
        if (written == -1)
            LOG_ERROR(inst, "out of memory for %lld blocks", (long long)x->n_blocks);
        release_build(inst);
        return -1;
    }
    for (int64_t k = 0; k < x->n_blocks; k++)
        if (build_block(inst, b, k) != 0) {
            release_build(inst);
            return -1;
        }
    memcpy(b->arena, x->arena0, (size_t)x->table.header[BLK_H_ARENA] * sizeof(double));
    write_inputs(inst);
    b->run.table = &x->table;
    b->run.arena = b->arena;
    b->run.kernels = b->kernels;
    if (blk_run_begin(&b->run) != 0) {
        LOG_ERROR(inst, "the diagram cannot run: %s", b->run.outcome.message);
        release_build(inst);
        return -1;
    }
    if (inst->stop_defined && inst->stop_tick < b->run.at.end)
        b->run.at.end = inst->stop_tick;
    return refresh_outputs(inst) < 0 ? -1 : 0;
}

/* -- failures ---------------------------------------------------------------------------------- */

static double tick_time(const blk_instance *inst, int64_t tick)
{
    const int64_t *h = inst->x.table.header;
    return (double)(tick * h[BLK_H_TICK_NUM]) / (double)h[BLK_H_TICK_DEN];
}

/* Log the failure of the run's outcome. */
static void describe_failure(blk_instance *inst)
{
    const blk_outcome *o = &inst->build->run.outcome;
    const blk_table *t = &inst->x.table;
    if (o->status == BLK_RUN_BAD) {
        LOG_ERROR(inst, "the diagram cannot run: %s", o->message);
        return;
    }
    static const char *phases[] = {"output", "update", "advance"};
    const int64_t *op = t->ops + o->op * BLK_OP_N;
    int64_t b = op[BLK_OP_A];
    const char *phase = phases[op[BLK_OP_CODE] <= BLK_ADVANCE ? op[BLK_OP_CODE] : 0];
    double when = tick_time(inst, o->tick);
    char prefix[256], message[512];
    block_prefix(inst, b, prefix, sizeof prefix);
    const blk_kernel_type *k = inst->x.blocks[b].type;
    if (o->code == BLK_END_RUN)
        snprintf(message, sizeof message, "asked to end the run in its %s at t=%.10g s", phase, when);
    else if (o->code == BLK_NONFINITE)
        snprintf(message, sizeof message,
                 "its output value %d (counting its outputs' elements from 0) is not finite at t=%.10g s (an "
                 "exported diagram stops at the first NaN or infinity a block outputs)",
                 o->which, when);
    else if (k->failure != NULL)
        k->failure(inst->build->built[b].ctx, o->code, o->which, phase, when, message, sizeof message);
    else
        snprintf(message, sizeof message, "its %s failed at t=%.10g s with code %d (detail %d)", phase, when, o->code,
                 o->which);
    LOG_ERROR(inst, "%s%s", prefix, message);
}

/* The outputs at the run's tick from the inputs now: the outputs-only program of that tick
   (at t = 0 before the first step, between events, or an event's), then the lazy outputs.
   0; -1 after logging the failure (the instance then failed); 1 in initialization mode,
   where a failure is a warning (the outputs wait for the inputs). */
static int refresh_outputs(blk_instance *inst)
{
    const blk_export *x = &inst->x;
    blk_run *run = &inst->build->run;
    const blk_position *at = &run->at;
    int64_t program;
    if (!at->started)
        program = x->initial_outputs;
    else if (at->pending >= 0)
        program = x->between;
    else if (at->tick == at->end && at->end_program >= 0)
        program = at->end_program;
    else if (x->table.n_events > 0)
        program = x->table.programs[x->table.events[at->row * BLK_E_N + BLK_E_PROGRAM] * BLK_PR_N + BLK_PR_FINAL];
    else
        program = -1;
    if ((program >= 0 && blk_run_outputs(run, program) != 0) || (x->lazy >= 0 && blk_run_outputs(run, x->lazy) != 0)) {
        if (inst->phase == BLK_INITIALIZATION) {
            /* the inputs an importer sets in initialization mode may not all be there yet:
               the outputs wait for them, and are computed again when they change */
            const blk_outcome *o = &run->outcome;
            blk_instance_log(inst, BLK_STATUS_WARNING, BLK_LOG_WARNING,
                             "the outputs at t=0 cannot be computed from the inputs set so far (block '%s' "
                             "fails with code %d); they are computed again when the inputs change",
                             block_name(inst, x->table.ops[o->op * BLK_OP_N + BLK_OP_A]), o->code);
            run->outcome.status = BLK_RUN_COMPLETE;
            return 1;
        }
        describe_failure(inst);
        inst->phase = BLK_FAILED;
        return -1;
    }
    inst->outputs_fresh = 1;
    return 0;
}

/* -- phases ------------------------------------------------------------------------------------ */

static blk_status wrong_phase(blk_instance *inst, const char *what)
{
    LOG_ERROR(inst, "%s is not allowed when the instance is %s", what, PHASE_NAMES[inst->phase]);
    return BLK_STATUS_ERROR;
}

blk_status blk_instance_setup(blk_instance *inst, double start_time, int stop_defined, double stop_time)
{
    if (inst->phase != BLK_INSTANTIATED)
        return wrong_phase(inst, "setting up the experiment");
    if (start_time != 0.0) {
        LOG_ERROR(inst, "the start time must be 0, got %g: the diagram's time starts at t = 0", start_time);
        return BLK_STATUS_ERROR;
    }
    inst->stop_defined = 0;
    if (stop_defined) {
        const int64_t *h = inst->x.table.header;
        double ticks = stop_time * (double)h[BLK_H_TICK_DEN] / (double)h[BLK_H_TICK_NUM];
        if (!(ticks >= 0 && ticks < EXACT_TICKS)) {
            LOG_ERROR(inst, "the stop time %g s is out of range", stop_time);
            return BLK_STATUS_ERROR;
        }
        inst->stop_defined = 1;
        inst->stop_time = stop_time;
        inst->stop_tick = (int64_t)floor(ticks + STEP_TOLERANCE);
    }
    return BLK_STATUS_OK;
}

blk_status blk_instance_enter_initialization(blk_instance *inst)
{
    if (inst->phase != BLK_INSTANTIATED)
        return wrong_phase(inst, "entering initialization mode");
    release_build(inst);
    inst->phase = BLK_INITIALIZATION;
    return BLK_STATUS_OK;
}

blk_status blk_instance_exit_initialization(blk_instance *inst)
{
    if (inst->phase != BLK_INITIALIZATION)
        return wrong_phase(inst, "exiting initialization mode");
    if (build(inst) != 0 || (!inst->outputs_fresh && (inst->phase = BLK_STEPPING, refresh_outputs(inst) != 0))) {
        inst->phase = BLK_FAILED;
        return BLK_STATUS_ERROR;
    }
    inst->phase = BLK_STEPPING;
    LOG_EVENT(inst, "initialized: %lld block%s, arena of %lld values", (long long)inst->x.n_blocks,
              inst->x.n_blocks == 1 ? "" : "s", (long long)inst->x.table.header[BLK_H_ARENA]);
    return BLK_STATUS_OK;
}

double blk_instance_time(const blk_instance *inst)
{
    return inst->build != NULL ? tick_time(inst, inst->build->run.at.tick) : 0.0;
}

blk_status blk_instance_terminate(blk_instance *inst)
{
    if (inst->phase != BLK_STEPPING && inst->phase != BLK_FAILED && inst->phase != BLK_INITIALIZATION)
        return wrong_phase(inst, "terminate");
    inst->phase = BLK_TERMINATED;
    return BLK_STATUS_OK;
}

blk_status blk_instance_reset(blk_instance *inst)
{
    release_build(inst);
    start_values(inst);
    inst->stop_defined = 0;
    inst->phase = BLK_INSTANTIATED;
    return BLK_STATUS_OK;
}

/* -- variables --------------------------------------------------------------------------------- */

static int in_range(unsigned int vr, int64_t first, int64_t n)
{
    return (int64_t)vr >= first && (int64_t)vr < first + n;
}

blk_status blk_instance_get(blk_instance *inst, const unsigned int *vr, size_t n, double *values)
{
    const blk_export *x = &inst->x;
    blk_status status = BLK_STATUS_OK;
    if (inst->phase == BLK_FAILED)
        return wrong_phase(inst, "getting values");
    for (size_t i = 0; i < n; i++) {
        if (!in_range(vr[i], x->vr_output, x->n_outputs))
            continue;
        if (inst->phase == BLK_INSTANTIATED) {
            LOG_ERROR(inst, "output %u is calculated: read it after entering initialization mode", vr[i]);
            return BLK_STATUS_ERROR;
        }
        int refreshed = build(inst) != 0 ? -1 : inst->outputs_fresh ? 0 : refresh_outputs(inst);
        if (refreshed < 0)
            return BLK_STATUS_ERROR;
        if (refreshed > 0)
            status = BLK_STATUS_WARNING;
        break;
    }
    for (size_t i = 0; i < n; i++) {
        unsigned int r = vr[i];
        if (r == 0)
            values[i] = blk_instance_time(inst);
        else if (in_range(r, x->vr_input, x->n_inputs))
            values[i] = inst->inputs[r - x->vr_input];
        else if (in_range(r, x->vr_output, x->n_outputs))
            values[i] = inst->build->arena[x->outputs[r - x->vr_output]];
        else if (in_range(r, x->vr_param, x->n_params))
            values[i] = inst->params[r - x->vr_param];
        else {
            LOG_ERROR(inst, "unknown value reference %u", r);
            return BLK_STATUS_ERROR;
        }
    }
    return status;
}

blk_status blk_instance_set(blk_instance *inst, const unsigned int *vr, size_t n, const double *values)
{
    const blk_export *x = &inst->x;
    if (inst->phase == BLK_FAILED || inst->phase == BLK_TERMINATED)
        return wrong_phase(inst, "setting values");
    for (size_t i = 0; i < n; i++) {
        unsigned int r = vr[i];
        if (in_range(r, x->vr_input, x->n_inputs)) {
            int64_t k = r - x->vr_input;
            inst->inputs[k] = values[i];
            if (inst->build != NULL)
                for (int64_t j = 0; j < x->inputs[k].n; j++)
                    inst->build->arena[x->inputs[k].offsets[j]] = values[i];
            inst->outputs_fresh = 0;
        } else if (in_range(r, x->vr_param, x->n_params)) {
            int64_t p = r - x->vr_param;
            if (inst->phase != BLK_INSTANTIATED && inst->phase != BLK_INITIALIZATION) {
                LOG_ERROR(inst, "parameter %s can only be set before initialization ends (variability fixed)",
                          x->params[p].name);
                return BLK_STATUS_ERROR;
            }
            inst->params[p] = values[i];
            inst->set[p] = 1;
            release_build(inst);
        } else if (r == 0 || in_range(r, x->vr_output, x->n_outputs)) {
            LOG_ERROR(inst, "value reference %u is not an input or a parameter: it cannot be set", r);
            return BLK_STATUS_ERROR;
        } else {
            LOG_ERROR(inst, "unknown value reference %u", r);
            return BLK_STATUS_ERROR;
        }
    }
    return BLK_STATUS_OK;
}

/* -- stepping ---------------------------------------------------------------------------------- */

blk_status blk_instance_do_step(blk_instance *inst, double current_time, double step, int *terminated)
{
    *terminated = 0;
    if (inst->phase != BLK_STEPPING)
        return wrong_phase(inst, "a step");
    const int64_t *h = inst->x.table.header;
    blk_run *run = &inst->build->run;
    double base = (double)h[BLK_H_TICK_NUM] / (double)h[BLK_H_TICK_DEN], grid = base * (double)inst->x.grid;
    double count = step / grid, whole = nearbyint(count), now = blk_instance_time(inst);
    if (!(step >= 0.0) || !(whole < EXACT_TICKS) || fabs(count - whole) > STEP_TOLERANCE) {
        LOG_ERROR(inst,
                  "communication step %.10g s is not a whole multiple of the internal step %g s (hint: use "
                  "multiples of %g s)",
                  step, grid, grid);
        return BLK_STATUS_ERROR;
    }
    if (fabs(current_time - now) > 1e-9 * (fabs(now) > grid ? fabs(now) : grid)) {
        LOG_ERROR(inst, "a step from t=%.10g s, but the FMU is at t=%.10g s", current_time, now);
        return BLK_STATUS_ERROR;
    }
    int64_t target = run->at.tick + (int64_t)whole * inst->x.grid;
    if (inst->stop_defined && target > inst->stop_tick) {
        LOG_ERROR(inst, "a step to t=%.10g s passes the stop time %.10g s", tick_time(inst, target), inst->stop_time);
        return BLK_STATUS_ERROR;
    }
    if ((double)target * (double)h[BLK_H_TICK_NUM] >= EXACT_TICKS) {
        LOG_ERROR(inst, "a step to t=%.10g s is past the times the FMU counts exactly", tick_time(inst, target));
        return BLK_STATUS_ERROR;
    }
    if (run->at.tick == run->at.end && run->at.end_program >= 0 && target > run->at.tick) {
        *terminated = 1;
        LOG_ERROR(inst, "the diagram ended at t=%.10g s (a block asked to end the run): it cannot step further", now);
        return BLK_STATUS_DISCARD;
    }
    if (target == run->at.tick)
        return BLK_STATUS_OK;
    if (blk_run_until(run, target) != 0) {
        describe_failure(inst);
        inst->phase = BLK_FAILED;
        return BLK_STATUS_ERROR;
    }
    if (refresh_outputs(inst) != 0)
        return BLK_STATUS_ERROR;
    if (run->at.tick == run->at.end && run->at.end_program >= 0) {
        *terminated = 1;
        LOG_EVENT(inst, "a block ended the run at t=%.10g s", blk_instance_time(inst));
    }
    return BLK_STATUS_OK;
}

/* -- FMU states -------------------------------------------------------------------------------- */

#define SNAPSHOT_MAGIC "BLKXST01"

/* A snapshot: this header, then the parameters, their set flags (as doubles), the inputs,
   and when built the arena, the state sizes (as doubles) and the states. */
struct blk_snapshot {
    char magic[8];
    int64_t words; /* the doubles after the header */
    int64_t phase, built, fresh, stop_defined, stop_tick, outcome_status, end_op, end_asked;
    double stop_time;
    blk_position at;
    double values[];
};

static int64_t snapshot_words(const blk_instance *inst)
{
    const blk_export *x = &inst->x;
    int64_t n = 2 * x->n_params + x->n_inputs;
    if (inst->build != NULL) {
        n += x->table.header[BLK_H_ARENA] + x->n_blocks;
        for (int64_t k = 0; k < x->n_blocks; k++)
            n += inst->build->state_sizes[k] > 0 ? inst->build->state_sizes[k] : 0;
    }
    return n;
}

static blk_status missing_argument(blk_instance *inst, const char *what)
{
    LOG_ERROR(inst, "%s is NULL", what);
    return BLK_STATUS_ERROR;
}

blk_status blk_instance_get_state(blk_instance *inst, blk_snapshot **snapshot)
{
    if (snapshot == NULL)
        return missing_argument(inst, "the pointer for the FMU state");
    const blk_export *x = &inst->x;
    int64_t words = snapshot_words(inst);
    blk_snapshot *s = *snapshot;
    if (s == NULL || s->words != words) {
        blk_snapshot_free(snapshot);
        s = malloc(sizeof *s + (size_t)words * sizeof(double));
        if (s == NULL) {
            LOG_ERROR(inst, "out of memory for an FMU state");
            return BLK_STATUS_ERROR;
        }
    }
    memset(s, 0, sizeof *s);
    memcpy(s->magic, SNAPSHOT_MAGIC, 8);
    s->words = words;
    s->phase = inst->phase;
    s->built = inst->build != NULL;
    s->fresh = inst->outputs_fresh;
    s->stop_defined = inst->stop_defined;
    s->stop_tick = inst->stop_tick;
    s->stop_time = inst->stop_time;
    double *v = s->values;
    for (int64_t p = 0; p < x->n_params; p++) {
        *v++ = inst->params[p];
        *v++ = inst->set[p];
    }
    memcpy(v, inst->inputs, (size_t)x->n_inputs * sizeof(double));
    v += x->n_inputs;
    if (inst->build != NULL) {
        ex_build *b = inst->build;
        s->at = b->run.at;
        s->outcome_status = b->run.outcome.status;
        s->end_op = b->run.outcome.end_op;
        s->end_asked = b->run.outcome.end_asked;
        memcpy(v, b->arena, (size_t)x->table.header[BLK_H_ARENA] * sizeof(double));
        v += x->table.header[BLK_H_ARENA];
        for (int64_t k = 0; k < x->n_blocks; k++)
            *v++ = (double)b->state_sizes[k];
        for (int64_t k = 0; k < x->n_blocks; k++)
            if (b->state_sizes[k] > 0) {
                memcpy(v, b->states[k], (size_t)b->state_sizes[k] * sizeof(double));
                v += b->state_sizes[k];
            }
    }
    *snapshot = s;
    return BLK_STATUS_OK;
}

blk_status blk_instance_set_state(blk_instance *inst, const blk_snapshot *s)
{
    const blk_export *x = &inst->x;
    if (s == NULL || memcmp(s->magic, SNAPSHOT_MAGIC, 8) != 0) {
        LOG_ERROR(inst, "not an FMU state of this FMU");
        return BLK_STATUS_ERROR;
    }
    release_build(inst);
    const double *v = s->values;
    for (int64_t p = 0; p < x->n_params; p++) {
        inst->params[p] = *v++;
        inst->set[p] = *v++ != 0.0;
    }
    memcpy(inst->inputs, v, (size_t)x->n_inputs * sizeof(double));
    v += x->n_inputs;
    inst->stop_defined = (int)s->stop_defined;
    inst->stop_tick = s->stop_tick;
    inst->stop_time = s->stop_time;
    if (s->built) {
        if (build(inst) != 0 || snapshot_words(inst) != s->words) {
            if (inst->build != NULL)
                LOG_ERROR(inst, "the FMU state holds %lld values, its parameters give %lld", (long long)s->words,
                          (long long)snapshot_words(inst));
            release_build(inst);
            inst->phase = BLK_FAILED;
            return BLK_STATUS_ERROR;
        }
        ex_build *b = inst->build;
        memcpy(b->arena, v, (size_t)x->table.header[BLK_H_ARENA] * sizeof(double));
        v += x->table.header[BLK_H_ARENA] + x->n_blocks;
        for (int64_t k = 0; k < x->n_blocks; k++)
            if (b->state_sizes[k] > 0) {
                memcpy(b->states[k], v, (size_t)b->state_sizes[k] * sizeof(double));
                v += b->state_sizes[k];
            }
        b->run.at = s->at;
        b->run.outcome.status = (int)s->outcome_status;
        b->run.outcome.end_op = s->end_op;
        b->run.outcome.end_asked = s->end_asked;
        inst->outputs_fresh = (int)s->fresh;
    }
    inst->phase = (blk_phase)s->phase;
    return BLK_STATUS_OK;
}

blk_status blk_snapshot_free(blk_snapshot **snapshot)
{
    if (snapshot != NULL) {
        free(*snapshot);
        *snapshot = NULL;
    }
    return BLK_STATUS_OK;
}

static size_t snapshot_bytes(const blk_snapshot *snapshot)
{
    return sizeof *snapshot + (size_t)snapshot->words * sizeof(double);
}

blk_status blk_snapshot_size(blk_instance *inst, const blk_snapshot *snapshot, size_t *size)
{
    if (snapshot == NULL || size == NULL)
        return missing_argument(inst, snapshot == NULL ? "the FMU state" : "the pointer for its size");
    *size = snapshot_bytes(snapshot);
    return BLK_STATUS_OK;
}

blk_status blk_snapshot_serialize(blk_instance *inst, const blk_snapshot *snapshot, unsigned char *bytes, size_t size)
{
    if (snapshot == NULL || bytes == NULL)
        return missing_argument(inst, snapshot == NULL ? "the FMU state" : "the buffer for the serialized state");
    size_t need = snapshot_bytes(snapshot);
    if (size < need) {
        LOG_ERROR(inst, "the buffer for the serialized FMU state holds %zu bytes, it needs %zu", size, need);
        return BLK_STATUS_ERROR;
    }
    memcpy(bytes, snapshot, need);
    return BLK_STATUS_OK;
}

blk_status blk_snapshot_deserialize(blk_instance *inst, const unsigned char *bytes, size_t size,
                                    blk_snapshot **snapshot)
{
    if (bytes == NULL || snapshot == NULL)
        return missing_argument(inst, bytes == NULL ? "the serialized state" : "the pointer for the FMU state");
    blk_snapshot head;
    if (size < sizeof head) {
        LOG_ERROR(inst, "a serialized FMU state of %zu bytes is too short", size);
        return BLK_STATUS_ERROR;
    }
    memcpy(&head, bytes, sizeof head);
    if (memcmp(head.magic, SNAPSHOT_MAGIC, 8) != 0 || head.words < 0 ||
        (uint64_t)head.words > (size - sizeof head) / sizeof(double) ||
        size != sizeof head + (size_t)head.words * sizeof(double) || head.phase < BLK_INSTANTIATED ||
        head.phase > BLK_FAILED) {
        LOG_ERROR(inst, "the bytes are not a serialized FMU state of this FMU");
        return BLK_STATUS_ERROR;
    }
    blk_snapshot *s = malloc(size);
    if (s == NULL) {
        LOG_ERROR(inst, "out of memory for an FMU state");
        return BLK_STATUS_ERROR;
    }
    memcpy(s, bytes, size);
    blk_snapshot_free(snapshot);
    *snapshot = s;
    return BLK_STATUS_OK;
}
