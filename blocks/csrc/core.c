/* core.c: the interpreter of op tables (core.h), C99 and libc only. */
#include "core.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* -- checking and unpacking a table ---------------------------------------------------- */

static int in_range(int64_t first, int64_t count, int64_t size)
{
    return first >= 0 && count >= 0 && first <= size && count <= size - first;
}

static const char *check_block(const blk_table *t, const int64_t *b, int64_t arena)
{
    if (!in_range(b[BLK_B_OUT], b[BLK_B_WIDTH], arena))
        return "a block's outputs lie outside the arena";
    if (!in_range(b[BLK_B_FIRST_INPUT], b[BLK_B_N_INPUTS], t->n_inputs))
        return "a block's inputs lie outside the inputs table";
    if (!in_range(b[BLK_B_FIRST_PORT], b[BLK_B_N_PORTS], t->n_ports))
        return "a block's ports lie outside the ports table";
    if (b[BLK_B_PERIOD] < 0 || b[BLK_B_ROWS_CAPACITY] < 0 ||
        !in_range(b[BLK_B_ROWS], b[BLK_B_ROWS_CAPACITY] * b[BLK_B_WIDTH], arena))
        return "a block's advance rows lie outside the arena";
    return NULL;
}

static const char *check_op(const blk_table *t, const int64_t *op)
{
    int64_t code = op[BLK_OP_CODE], a = op[BLK_OP_A];
    if (code == BLK_COPY)
        return a >= 0 && a < t->n_copies ? NULL : "a copy op names no copy";
    if (code < BLK_OUTPUT || code > BLK_COPY || a < 0 || a >= t->n_blocks)
        return "an op names no block";
    const int64_t *b = t->blocks + a * BLK_B_N;
    if (code == BLK_OUTPUT || code == BLK_ADVANCE) {
        if (op[BLK_OP_B] > op[BLK_OP_C] || !in_range(op[BLK_OP_B], op[BLK_OP_C] - op[BLK_OP_B], t->n_logs))
            return "an op's log entries lie outside the logs table";
        for (int64_t e = op[BLK_OP_B]; e < op[BLK_OP_C]; e++)
            if (t->logs[e * BLK_L_N + BLK_L_BLOCK] != a)
                return "an op logs another block's signal";
    }
    if (code == BLK_OUTPUT && op[BLK_OP_D] != -1) {
        int64_t s = op[BLK_OP_D];
        if (s < 0 || s >= t->n_selections || !in_range(s + 1, t->selections[s], t->n_selections))
            return "an output op's selection lies outside the selections";
        for (int64_t i = 0; i < t->selections[s]; i++)
            if (t->selections[s + 1 + i] < 0 || t->selections[s + 1 + i] >= b[BLK_B_N_PORTS])
                return "an output op selects a port its block does not have";
    }
    if (code == BLK_ADVANCE && (b[BLK_B_PERIOD] <= 0 || b[BLK_B_ROWS_CAPACITY] <= 0))
        return "an advanced block has no period or no rows";
    return NULL;
}

static int updates_in(const blk_table *t, int64_t program)
{
    const int64_t *p = t->programs + program * BLK_PR_N;
    for (int64_t i = p[BLK_PR_FIRST]; i < p[BLK_PR_END]; i++)
        if (t->ops[i * BLK_OP_N + BLK_OP_CODE] == BLK_UPDATE)
            return 1;
    return 0;
}

const char *blk_table_check(const blk_table *t)
{
    if (t->n_blocks < 0 || t->n_inputs < 0 || t->n_ports < 0 || t->n_ops < 0 || t->n_copies < 0 ||
        t->n_programs < 0 || t->n_events < 0 || t->n_logs < 0 || t->n_selections < 0)
        return "a negative row count";
    const int64_t *h = t->header;
    int64_t arena = h[BLK_H_ARENA];
    if (h[BLK_H_TICK_NUM] <= 0 || h[BLK_H_TICK_DEN] <= 0 || h[BLK_H_HYPERPERIOD] <= 0 || h[BLK_H_N_TICKS] < 0 ||
        arena < 0)
        return "the header's base tick, hyperperiod, length or arena is not positive";
    if (h[BLK_H_INITIAL] < 0 || h[BLK_H_INITIAL] >= t->n_programs || h[BLK_H_FINAL] < 0 ||
        h[BLK_H_FINAL] >= t->n_programs)
        return "the header names no initial or final program";
    for (int64_t i = 0; i < t->n_blocks; i++) {
        const char *bad = check_block(t, t->blocks + i * BLK_B_N, arena);
        if (bad)
            return bad;
    }
    for (int64_t i = 0; i < t->n_inputs; i++)
        if (!in_range(t->inputs[i * BLK_I_N + BLK_I_OFFSET], t->inputs[i * BLK_I_N + BLK_I_WIDTH], arena))
            return "an input reads outside the arena";
    for (int64_t i = 0; i < t->n_ports; i++) {
        const int64_t *p = t->ports + i * BLK_P_N;
        if (p[BLK_P_BLOCK] < 0 || p[BLK_P_BLOCK] >= t->n_blocks || !in_range(p[BLK_P_OFFSET], p[BLK_P_WIDTH], arena))
            return "a port lies outside the arena or names no block";
    }
    for (int64_t i = 0; i < t->n_copies; i++) {
        const int64_t *c = t->copies + i * BLK_C_N;
        if (!in_range(c[BLK_C_DST], c[BLK_C_WIDTH], arena) || !in_range(c[BLK_C_SRC], c[BLK_C_WIDTH], arena))
            return "a copy lies outside the arena";
    }
    for (int64_t i = 0; i < t->n_logs; i++) {
        const int64_t *lg = t->logs + i * BLK_L_N;
        if (lg[BLK_L_BLOCK] < 0 || lg[BLK_L_BLOCK] >= t->n_blocks || lg[BLK_L_DECIMATE] <= 0 ||
            lg[BLK_L_CAPACITY] < 0 ||
            !in_range(lg[BLK_L_COLUMN], lg[BLK_L_WIDTH], t->blocks[lg[BLK_L_BLOCK] * BLK_B_N + BLK_B_WIDTH]))
            return "a log entry lies outside its block's outputs";
    }
    for (int64_t i = 0; i < t->n_ops; i++) {
        const char *bad = check_op(t, t->ops + i * BLK_OP_N);
        if (bad)
            return bad;
    }
    for (int64_t i = 0; i < t->n_programs; i++) {
        const int64_t *p = t->programs + i * BLK_PR_N;
        if (p[BLK_PR_FIRST] > p[BLK_PR_END] || !in_range(p[BLK_PR_FIRST], p[BLK_PR_END] - p[BLK_PR_FIRST], t->n_ops))
            return "a program's ops lie outside the ops table";
        if (p[BLK_PR_FINAL] < -1 || p[BLK_PR_FINAL] >= t->n_programs)
            return "a program names no final program";
    }
    for (int64_t i = 0; i < t->n_events; i++) {
        const int64_t *e = t->events + i * BLK_E_N;
        if (e[BLK_E_TICK] < 0 || e[BLK_E_TICK] >= h[BLK_H_HYPERPERIOD] || (i > 0 && e[BLK_E_TICK] <= e[BLK_E_TICK - BLK_E_N]))
            return "the events are not in order within one hyperperiod";
        if (e[BLK_E_PROGRAM] < 0 || e[BLK_E_PROGRAM] >= t->n_programs)
            return "an event names no program";
        if (updates_in(t, e[BLK_E_PROGRAM]) && t->programs[e[BLK_E_PROGRAM] * BLK_PR_N + BLK_PR_FINAL] < 0)
            return "an event whose program updates blocks has no final program to end a run with";
    }
    return NULL;
}

const char *blk_table_unpack(const void *data, size_t size, blk_table *t, const double **initial)
{
    const int64_t *w = data;
    size_t words = size / sizeof(int64_t), at = 12;
    if ((uintptr_t)data % sizeof(int64_t) != 0 || words < at)
        return "too short or misaligned to be a packed op table";
    if (w[0] != BLK_PACK_MAGIC || w[1] != BLK_PACK_VERSION)
        return "not a packed op table of this version";
    const int64_t **tables[] = {&t->header, &t->blocks, &t->inputs, &t->ports, &t->ops,
                                &t->copies, &t->programs, &t->events, &t->logs, &t->selections};
    int64_t *counts[] = {NULL, &t->n_blocks, &t->n_inputs, &t->n_ports, &t->n_ops,
                         &t->n_copies, &t->n_programs, &t->n_events, &t->n_logs, &t->n_selections};
    static const int64_t widths[] = {BLK_H_N, BLK_B_N, BLK_I_N, BLK_P_N, BLK_OP_N, BLK_C_N, BLK_PR_N, BLK_E_N, BLK_L_N, 1};
    for (int i = 0; i < 10; i++) {
        int64_t rows = w[2 + i];
        if (rows < 0 || (i == 0 && rows != 1) || (uint64_t)rows > (words - at) / (uint64_t)widths[i])
            return "a table of the packed op table has a wrong size";
        *tables[i] = w + at;
        if (counts[i])
            *counts[i] = rows;
        at += (size_t)(rows * widths[i]);
    }
    int64_t arena = t->header[BLK_H_ARENA];
    if (arena < 0 || (uint64_t)arena != words - at)
        return "the packed op table's arena values do not fill its end";
    *initial = (const double *)(w + at);
    return blk_table_check(t);
}

/* -- running --------------------------------------------------------------------------- */

static double tick_time(const blk_table *t, int64_t k)
{
    return (double)(k * t->header[BLK_H_TICK_NUM]) / (double)t->header[BLK_H_TICK_DEN];
}

static int64_t event_tick(const blk_table *t, const blk_position *c)
{
    return c->cycle * t->header[BLK_H_HYPERPERIOD] + t->events[c->row * BLK_E_N + BLK_E_TICK];
}

static void following(const blk_table *t, blk_position *c)
{
    if (++c->row == t->n_events) {
        c->row = 0;
        c->cycle++;
    }
}

static void log_row(blk_run *r, int64_t e, const double *outputs)
{
    const int64_t *lg = r->table->logs + e * BLK_L_N;
    int64_t *c = r->counters + e * BLK_LC_N;
    if ((lg[BLK_L_DECIMATE] == 1 || c[BLK_LC_HITS] % lg[BLK_L_DECIMATE] == 0) && c[BLK_LC_ROWS] < lg[BLK_L_CAPACITY]) {
        memcpy(r->logs[e] + c[BLK_LC_ROWS] * lg[BLK_L_WIDTH], outputs + lg[BLK_L_COLUMN],
               (size_t)lg[BLK_L_WIDTH] * sizeof(double));
        c[BLK_LC_ROWS]++;
    }
    c[BLK_LC_HITS]++;
}

/* log_row for each of n rows of width values (an advance's): every row of a log entry
   that keeps every hit copied in one go when it takes whole rows, as log_row would. */
static void log_rows(blk_run *r, int64_t e, const double *rows, int64_t n, int64_t width)
{
    const int64_t *lg = r->table->logs + e * BLK_L_N;
    int64_t *c = r->counters + e * BLK_LC_N;
    if (lg[BLK_L_DECIMATE] != 1) {
        for (int64_t i = 0; i < n; i++)
            log_row(r, e, rows + i * width);
        return;
    }
    int64_t room = lg[BLK_L_CAPACITY] - c[BLK_LC_ROWS], kept = n < room ? n : room, w = lg[BLK_L_WIDTH];
    double *to = r->logs[e] + c[BLK_LC_ROWS] * w;
    if (kept > 0 && w == width)
        memcpy(to, rows, (size_t)(kept * w) * sizeof(double));
    else
        for (int64_t i = 0; i < kept; i++)
            memcpy(to + i * w, rows + i * width + lg[BLK_L_COLUMN], (size_t)w * sizeof(double));
    if (kept > 0)
        c[BLK_LC_ROWS] += kept;
    c[BLK_LC_HITS] += n;
}

static void lock_for(blk_run *r, const blk_kernel *k)
{
    if (r->hooks.gil)
        r->hooks.gil(r->hooks.host, k->output == NULL || !k->nogil);
}

static int fail(blk_run *r, int64_t op, int64_t tick, int code, int which)
{
    blk_outcome *o = &r->outcome;
    o->status = BLK_RUN_FAILED;
    o->op = op;
    o->tick = tick;
    o->code = code;
    o->which = which;
    return 1;
}

static int stopped(blk_run *r)
{
    blk_outcome *o = &r->outcome;
    if ((r->hooks.poll && r->hooks.poll(r->hooks.host, o->reached)) || r->stop) {
        o->status = BLK_RUN_STOPPED;
        return 1;
    }
    return 0;
}

/* The next hit of block b after the program running now: the first event (within one
   hyperperiod) whose program updates it. An update that asks to end the run is a hit of a
   block the program updates, and that block is updated at every hit it has. */
static void end_at_next_hit(blk_run *r, int64_t block)
{
    const blk_table *t = r->table;
    blk_position c = r->at;
    for (int64_t n = 0; n < t->n_events; n++, following(t, &c)) {
        int64_t k = event_tick(t, &c);
        if (k >= r->at.end)
            return;
        int64_t program = t->events[c.row * BLK_E_N + BLK_E_PROGRAM];
        const int64_t *p = t->programs + program * BLK_PR_N;
        for (int64_t i = p[BLK_PR_FIRST]; i < p[BLK_PR_END]; i++) {
            const int64_t *op = t->ops + i * BLK_OP_N;
            if (op[BLK_OP_CODE] == BLK_UPDATE && op[BLK_OP_A] == block) {
                r->at.end = k;
                r->at.end_program = p[BLK_PR_FINAL];
                return;
            }
        }
    }
}

/* A block's output (into the arena) or update at tick ke (time t): its kernel, or the
   host's call hook. */
static int step(blk_run *r, int64_t index, const int64_t *op, int64_t ke, double t, int *which)
{
    const int64_t *b = r->table->blocks + op[BLK_OP_A] * BLK_B_N;
    const blk_kernel *k = r->kernels + op[BLK_OP_A];
    const double *const *inputs = r->pointers + b[BLK_B_FIRST_INPUT];
    int done = 0;
    lock_for(r, k);
    if (k->output == NULL)
        return r->hooks.call(r->hooks.host, index, ke, t, 0, NULL, &done, which);
    if (op[BLK_OP_CODE] == BLK_OUTPUT)
        return k->output(k->ctx, t, k->state, inputs, r->arena + b[BLK_B_OUT], which);
    return k->update(k->ctx, t, k->state, inputs, which);
}

/* The index of the first of n values that is not finite, or -1: blk_all_finite first (the
   hand plant's advance rows alone are some 500 000 values per simulated second), then the
   search. Inlined into the two scans below, each compiled for its own instruction set
   (GCC vectorises when asked, at -O2). */
#if defined(__GNUC__) && !defined(__clang__)
#define SCAN_INLINE static inline __attribute__((always_inline))
#else
#define SCAN_INLINE static inline
#endif
SCAN_INLINE int64_t scan_nonfinite(const double *v, int64_t n)
{
    if (blk_all_finite(v, n))
        return -1;
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return i;
    return -1;
}

/* The scan of a few values (an output op's ports). */
BLK_VECTORISED static int64_t first_nonfinite(const double *v, int64_t n)
{
    return scan_nonfinite(v, n);
}

/* The scan of an advance's rows: on x86-64 with glibc (GCC) also compiled for AVX2, four
   values an instruction to SSE2's two (the plant's 10 rows of 51 values in about half the
   time), the loader choosing by the processor; a few values keep the plain scan, which
   the AVX2 version's set-up and call would slow. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__)
enum { WIDE_SCAN = 64 };
__attribute__((optimize("tree-vectorize", "unroll-loops"), target_clones("avx2", "default"))) static int64_t
scan_wide(const double *v, int64_t n)
{
    return scan_nonfinite(v, n);
}
static int64_t first_nonfinite_row(const double *v, int64_t n)
{
    return n >= WIDE_SCAN ? scan_wide(v, n) : first_nonfinite(v, n);
}
#else
static int64_t first_nonfinite_row(const double *v, int64_t n)
{
    return first_nonfinite(v, n);
}
#endif

/* The index among its block's outputs of the first value an output op computed (the ports
   of its selection) that is not finite, or -1. */
static int64_t nonfinite_output(const blk_run *r, const int64_t *op)
{
    const blk_table *t = r->table;
    const int64_t *b = t->blocks + op[BLK_OP_A] * BLK_B_N, s = op[BLK_OP_D];
    const double *arena = r->arena;
    if (s < 0)
        return first_nonfinite(arena + b[BLK_B_OUT], b[BLK_B_WIDTH]);
    for (int64_t i = 0; i < t->selections[s]; i++) {
        const int64_t *p = t->ports + (b[BLK_B_FIRST_PORT] + t->selections[s + 1 + i]) * BLK_P_N;
        int64_t j = first_nonfinite(arena + p[BLK_P_OFFSET], p[BLK_P_WIDTH]);
        if (j >= 0)
            return p[BLK_P_OFFSET] - b[BLK_B_OUT] + j;
    }
    return -1;
}

static int output(blk_run *r, int64_t index, const int64_t *op, int64_t ke, double t)
{
    int which = 0, code = step(r, index, op, ke, t, &which);
    if (code)
        return fail(r, index, ke, code, which);
    int64_t bad = r->allow_nonfinite ? -1 : nonfinite_output(r, op);
    if (bad >= 0)
        return fail(r, index, ke, BLK_NONFINITE, (int)bad);
    const double *out = r->arena + r->table->blocks[op[BLK_OP_A] * BLK_B_N + BLK_B_OUT];
    for (int64_t e = op[BLK_OP_B]; e < op[BLK_OP_C]; e++)
        log_row(r, e, out);
    return 0;
}

static int update(blk_run *r, int64_t index, const int64_t *op, int64_t ke, double t)
{
    int which = 0, code = step(r, index, op, ke, t, &which);
    if (code == BLK_END_RUN) {
        if (r->hooks.end && r->hooks.end(r->hooks.host, index, which, ke))
            return fail(r, index, ke, code, which);
        if (r->outcome.end_op < 0) {
            r->outcome.end_op = index;
            r->outcome.end_asked = ke;
        }
        end_at_next_hit(r, op[BLK_OP_A]);
        return 0;
    }
    return code ? fail(r, index, ke, code, which) : 0;
}

/* Step a block from tick ke to tick next in chunks of at most its rows' capacity, each
   from the time of its first tick. */
static int advance(blk_run *r, int64_t index, const int64_t *op, int64_t ke, int64_t next)
{
    int64_t block = op[BLK_OP_A];
    const int64_t *b = r->table->blocks + block * BLK_B_N;
    const blk_kernel *k = r->kernels + block;
    double *rows = r->arena + b[BLK_B_ROWS], *out = r->arena + b[BLK_B_OUT];
    int64_t width = b[BLK_B_WIDTH], period = b[BLK_B_PERIOD], capacity = b[BLK_B_ROWS_CAPACITY];
    int64_t n = period == 1 ? next - ke : (next - ke) / period, stepped = 0;
    while (n > 0) {
        int m = (int)(n < capacity ? n : capacity), done = 0, which = 0, code;
        int64_t first = ke + stepped * period;
        double t = tick_time(r->table, first);
        lock_for(r, k);
        if (k->output == NULL)
            code = r->hooks.call(r->hooks.host, index, first, t, m, rows, &done, &which);
        else
            code = k->advance(k->ctx, t, k->state, r->pointers + b[BLK_B_FIRST_INPUT], m, rows, &done, &which);
        int logged = code ? (done < 0 ? 0 : done > m ? m : done) : m;
        int64_t bad = r->allow_nonfinite || width == 0 ? -1 : first_nonfinite_row(rows, logged * width);
        if (bad >= 0) { /* the row that has it becomes the outputs, those before it are logged */
            logged = (int)(bad / width);
            bad -= logged * width;
            memcpy(out, rows + logged * width, (size_t)width * sizeof(double));
        }
        for (int64_t e = op[BLK_OP_B]; e < op[BLK_OP_C]; e++)
            log_rows(r, e, rows, logged, width);
        if (bad >= 0)
            return fail(r, index, first + (logged + 1) * period, BLK_NONFINITE, (int)bad);
        if (code)
            return fail(r, index, first + logged * period, code, which);
        memcpy(out, rows + (m - 1) * width, (size_t)width * sizeof(double));
        n -= m;
        stepped += m;
        if (op[BLK_OP_D])
            r->outcome.reached = ke + stepped * period;
        if (n > 0 && stopped(r))
            return 1;
    }
    return 0;
}

static void copy(blk_run *r, const int64_t *op)
{
    const int64_t *c = r->table->copies + op[BLK_OP_A] * BLK_C_N;
    memcpy(r->arena + c[BLK_C_DST], r->arena + c[BLK_C_SRC], (size_t)c[BLK_C_WIDTH] * sizeof(double));
}

/* A program's ops at tick ke up to its first advance (all of them for a final program);
   nonzero: the run stops. *tail: where its advances begin. */
static int head(blk_run *r, int64_t p, int64_t ke, int64_t *tail)
{
    const blk_table *t = r->table;
    const int64_t *row = t->programs + p * BLK_PR_N;
    r->outcome.reached = ke;
    double t_ke = tick_time(t, ke); /* one time for the event's ops */
    int64_t i = row[BLK_PR_FIRST];
    for (; i < row[BLK_PR_END]; i++) {
        const int64_t *op = t->ops + i * BLK_OP_N;
        int stop = 0;
        switch (op[BLK_OP_CODE]) {
        case BLK_OUTPUT:
            stop = output(r, i, op, ke, t_ke);
            break;
        case BLK_UPDATE:
            stop = update(r, i, op, ke, t_ke);
            break;
        case BLK_ADVANCE:
            *tail = i;
            return 0;
        default:
            copy(r, op);
        }
        if (stop)
            return 1;
    }
    *tail = i;
    return 0;
}

/* The advances of program p (its ops from tail on: advances and copies), stepping the
   advanced blocks from tick from to tick to; nonzero: the run stops. */
static int tail(blk_run *r, int64_t p, int64_t tail_at, int64_t from, int64_t to)
{
    const blk_table *t = r->table;
    const int64_t *row = t->programs + p * BLK_PR_N;
    for (int64_t i = tail_at; i < row[BLK_PR_END]; i++) {
        const int64_t *op = t->ops + i * BLK_OP_N;
        if (op[BLK_OP_CODE] == BLK_ADVANCE) {
            if (advance(r, i, op, from, to))
                return 1;
        } else {
            copy(r, op);
        }
    }
    r->outcome.reached = to;
    return 0;
}

static int64_t earlier(int64_t a, int64_t b)
{
    return a < b ? a : b;
}

static int bad(blk_run *r, const char *message)
{
    r->outcome.status = BLK_RUN_BAD;
    r->outcome.message = message;
    return BLK_RUN_BAD;
}

int blk_run_begin(blk_run *r)
{
    const blk_table *t = r->table;
    blk_outcome *o = &r->outcome;
    memset(o, 0, sizeof *o);
    o->end_op = o->end_asked = o->op = -1;
    r->pointers = NULL;
    for (int64_t i = 0; i < t->n_ops; i++) {
        const int64_t *op = t->ops + i * BLK_OP_N;
        if (op[BLK_OP_CODE] == BLK_COPY)
            continue;
        const blk_kernel *k = r->kernels + op[BLK_OP_A];
        if (k->output == NULL ? r->hooks.call == NULL
                              : (op[BLK_OP_CODE] == BLK_UPDATE && k->update == NULL) ||
                                    (op[BLK_OP_CODE] == BLK_ADVANCE && k->advance == NULL))
            return bad(r, "a block's op has neither a kernel function nor the host's call hook");
    }
    r->pointers = malloc((size_t)(t->n_inputs > 0 ? t->n_inputs : 1) * sizeof(const double *));
    if (r->pointers == NULL)
        return bad(r, "no memory for the input pointers");
    for (int64_t i = 0; i < t->n_inputs; i++)
        r->pointers[i] = r->arena + t->inputs[i * BLK_I_N + BLK_I_OFFSET];
    blk_position *at = &r->at;
    memset(at, 0, sizeof *at);
    at->pending = -1;
    at->end = t->header[BLK_H_N_TICKS];
    at->end_program = -1;
    if (t->n_events > 0 && t->events[BLK_E_TICK] == 0)
        following(t, at); /* the event at tick 0 is the initial program's */
    return 0;
}

int blk_run_until(blk_run *r, int64_t stop)
{
    const blk_table *t = r->table;
    blk_position *at = &r->at;
    if (r->outcome.status != BLK_RUN_COMPLETE)
        return r->outcome.status; /* failed or stopped before: the run cannot go on */
    for (;;) {
        int64_t limit = earlier(stop, at->end);
        if (at->pending >= 0) {
            int64_t to = earlier(at->span_end, limit);
            if (to >= at->tick && tail(r, at->pending, at->tail, at->tick, to))
                return r->outcome.status;
            at->tick = to;
            if (to < at->span_end)
                return 0; /* stopped inside the span */
            at->pending = -1;
            if (stopped(r))
                return r->outcome.status;
            continue;
        }
        if (at->tick >= limit)
            return 0;
        int64_t p;
        if (!at->started) {
            p = t->header[BLK_H_INITIAL];
            at->started = 1;
        } else {
            p = t->events[at->row * BLK_E_N + BLK_E_PROGRAM];
            following(t, at);
        }
        int64_t next = t->n_events > 0 ? event_tick(t, at) : INT64_MAX;
        at->span_end = earlier(next, at->end);
        if (head(r, p, at->tick, &at->tail))
            return r->outcome.status;
        at->pending = p;
    }
}

int blk_run_outputs(blk_run *r, int64_t program)
{
    int64_t unused;
    if (head(r, program, r->at.tick, &unused))
        return r->outcome.status;
    return 0;
}

void blk_run_release(blk_run *r)
{
    free(r->pointers);
    r->pointers = NULL;
}

int blk_run_table(blk_run *r)
{
    if (blk_run_begin(r) != 0)
        return r->outcome.status;
    const blk_table *t = r->table;
    blk_outcome *o = &r->outcome;
    if (blk_run_until(r, t->header[BLK_H_N_TICKS]) == 0) {
        blk_position *at = &r->at;
        int64_t final = at->end == t->header[BLK_H_N_TICKS] ? t->header[BLK_H_FINAL] : at->end_program;
        if (blk_run_outputs(r, final) == 0) {
            o->status = BLK_RUN_COMPLETE;
            o->end = at->end;
        }
    }
    blk_run_release(r);
    return o->status;
}
