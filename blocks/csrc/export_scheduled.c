/* Scheduled execution of an exported diagram FMU: its clocks read from the resources, the
 * activation of a partition at an instant of the tick grid (checked to come in the order
 * the diagram's semantics need, export_scheduled.h), and the clocks' intervals and shifts.
 *
 * Where the scheduled run is lives in the run's position (blk_position, which FMU states
 * save): started, an instant has begun; tick, that instant's tick; tail, how many of its
 * clocks (in priority order) have run their partitions. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "export_internal.h"
#include "export_scheduled.h"

typedef struct {
    int64_t vr, period, offset, priority, initial;
    const int64_t *hits; /* per hit in one hyperperiod, its program (-1: none) */
} ex_clock;

struct ex_scheduled {
    int64_t hyperperiod, n_clocks;
    blk_preemption lock, unlock;
    ex_clock *clocks;
    int64_t *words; /* the resource; clocks and words lie in this allocation */
};

enum { CLOCK_HEAD = 5 }; /* a clock's words before its hits: vr, period, offset, priority, initial */

/* A program index of the table that a partition may run: -1 (none) or one without advances. */
static int partition_program(const blk_table *t, int64_t p)
{
    if (p == -1)
        return 1;
    if (p < 0 || p >= t->n_programs)
        return 0;
    const int64_t *row = t->programs + p * BLK_PR_N;
    for (int64_t i = row[BLK_PR_FIRST]; i < row[BLK_PR_END]; i++)
        if (t->ops[i * BLK_OP_N + BLK_OP_CODE] == BLK_ADVANCE)
            return 0;
    return 1;
}

/* The clocks of words w (n of them) checked against the op table; NULL if they are wrong. */
static struct ex_scheduled *parse(const blk_table *t, const int64_t *w, int64_t n)
{
    if (n < 5 || w[0] != BLK_SCHEDULED_MAGIC || w[1] != BLK_SCHEDULED_VERSION || w[2] <= 0 || w[3] <= 0 ||
        w[3] > 4096)
        return NULL;
    int64_t hyper = w[2], count = w[3];
    struct ex_scheduled *s = malloc(sizeof *s + (size_t)count * sizeof(ex_clock) + (size_t)n * sizeof(int64_t));
    if (s == NULL)
        return NULL;
    s->hyperperiod = hyper;
    s->n_clocks = count;
    s->lock = s->unlock = NULL;
    s->clocks = (ex_clock *)(s + 1);
    s->words = (int64_t *)(s->clocks + count);
    memcpy(s->words, w, (size_t)n * sizeof(int64_t));
    int64_t at = 4;
    int ok = 1;
    for (int64_t c = 0; ok && c < count; c++) {
        ex_clock *k = s->clocks + c;
        ok = at + CLOCK_HEAD <= n;
        if (!ok)
            break;
        const int64_t *h = s->words + at;
        k->vr = h[0];
        k->period = h[1];
        k->offset = h[2];
        k->priority = h[3];
        k->initial = h[4];
        at += CLOCK_HEAD;
        ok = k->vr >= 0 && k->period > 0 && hyper % k->period == 0 && k->offset >= 0 && k->offset < k->period &&
             partition_program(t, k->initial) && at + hyper / k->period <= n;
        k->hits = s->words + at;
        for (int64_t j = 0; ok && j < hyper / k->period; j++)
            ok = partition_program(t, k->hits[j]);
        at += ok ? hyper / k->period : 0;
    }
    if (!ok || at + 1 != n || s->words[at] != BLK_SCHEDULED_MAGIC) {
        free(s);
        return NULL;
    }
    return s;
}

blk_instance *blk_instance_new_scheduled(const char *name, const char *token, const char *resource_dir,
                                         blk_logger log, void *environment, int logging_on, blk_preemption lock,
                                         blk_preemption unlock)
{
    blk_instance *inst = blk_instance_new(name, token, resource_dir, log, environment, logging_on);
    if (inst == NULL)
        return NULL;
    int64_t n = 0;
    int64_t *words = ex_read_resource_words(inst, resource_dir, BLK_SCHEDULED_RESOURCE, &n);
    if (words == NULL) {
        LOG_ERROR(inst, "this FMU has no clocks: it was exported for co-simulation (export it with scheduled "
                        "execution for its partitions)");
        blk_instance_free(inst);
        return NULL;
    }
    inst->scheduled = parse(&inst->x.table, words, n);
    free(words);
    if (inst->scheduled == NULL) {
        LOG_ERROR(inst, "%s is damaged or does not fit the FMU's op table", BLK_SCHEDULED_RESOURCE);
        blk_instance_free(inst);
        return NULL;
    }
    inst->scheduled->lock = lock;
    inst->scheduled->unlock = unlock;
    LOG_EVENT(inst, "scheduled execution: %lld clocks", (long long)inst->scheduled->n_clocks);
    return inst;
}

static int64_t clock_index(const struct ex_scheduled *s, unsigned int vr)
{
    for (int64_t c = 0; c < s->n_clocks; c++)
        if (s->clocks[c].vr == (int64_t)vr)
            return c;
    return -1;
}

static int ticks_at(const ex_clock *k, int64_t tick)
{
    return tick >= k->offset && (tick - k->offset) % k->period == 0;
}

/* The i-th clock (in priority order) that ticks at tick, or -1; *count: how many do. */
static int64_t nth_ticking(const struct ex_scheduled *s, int64_t tick, int64_t i, int64_t *count)
{
    int64_t found = -1, seen = 0;
    for (int64_t c = 0; c < s->n_clocks; c++)
        if (ticks_at(s->clocks + c, tick)) {
            if (seen == i)
                found = c;
            seen++;
        }
    *count = seen;
    return found;
}

/* The first tick after ``after`` (-1: from 0 on) at which a clock ticks. */
static int64_t next_instant(const struct ex_scheduled *s, int64_t after)
{
    int64_t next = INT64_MAX;
    for (int64_t c = 0; c < s->n_clocks; c++) {
        const ex_clock *k = s->clocks + c;
        int64_t hit = after < k->offset ? k->offset : k->offset + ((after - k->offset) / k->period + 1) * k->period;
        next = hit < next ? hit : next;
    }
    return next;
}

static double seconds(const blk_instance *inst, int64_t ticks)
{
    return ex_tick_time(inst, ticks);
}

/* Whether clock c at tick comes in order (export_scheduled.h); the position moves to its
   instant. BLK_STATUS_OK, or an error after logging what came out of order. */
static blk_status in_order(blk_instance *inst, int64_t c, int64_t tick)
{
    const struct ex_scheduled *s = inst->scheduled;
    blk_position *at = &inst->build->run.at;
    int64_t count, vr = s->clocks[c].vr;
    if (at->started && tick < at->tick) {
        LOG_ERROR(inst, "clock %lld activated at t=%.10g s after the instant t=%.10g s: activate the instants in time "
                        "order", (long long)vr, seconds(inst, tick), seconds(inst, at->tick));
        return BLK_STATUS_ERROR;
    }
    if (!at->started || tick > at->tick) {
        if (at->started) {
            int64_t missing = nth_ticking(s, at->tick, at->tail, &count);
            if (missing >= 0) {
                LOG_ERROR(inst, "clock %lld was not activated at t=%.10g s before clock %lld at t=%.10g s: activate "
                                "every clock at each of its ticks", (long long)s->clocks[missing].vr,
                          seconds(inst, at->tick), (long long)vr, seconds(inst, tick));
                return BLK_STATUS_ERROR;
            }
        }
        int64_t next = next_instant(s, at->started ? at->tick : -1);
        if (tick != next) {
            int64_t missing = nth_ticking(s, next, 0, &count);
            LOG_ERROR(inst, "clock %lld ticks at t=%.10g s, which came before this activation of clock %lld at "
                            "t=%.10g s: activate every clock at each of its ticks", (long long)s->clocks[missing].vr,
                      seconds(inst, next), (long long)vr, seconds(inst, tick));
            return BLK_STATUS_ERROR;
        }
        at->started = 1;
        at->tick = tick;
        at->tail = 0;
    }
    int64_t wanted = nth_ticking(s, tick, at->tail, &count);
    if (wanted != c) {
        if (wanted < 0)
            LOG_ERROR(inst, "clock %lld was activated twice at t=%.10g s", (long long)vr, seconds(inst, tick));
        else
            LOG_ERROR(inst, "at t=%.10g s clock %lld (priority %lld) comes before clock %lld (priority %lld): "
                            "activate the clocks of an instant in priority order", seconds(inst, tick),
                      (long long)s->clocks[wanted].vr, (long long)s->clocks[wanted].priority, (long long)vr,
                      (long long)s->clocks[c].priority);
        return BLK_STATUS_ERROR;
    }
    return BLK_STATUS_OK;
}

/* The tick of ``time`` (a whole number of base ticks, counted exactly): 0, or -1. */
static int tick_of(const blk_instance *inst, double time, int64_t *tick)
{
    const int64_t *h = inst->x.table.header;
    double ticks = time * (double)h[BLK_H_TICK_DEN] / (double)h[BLK_H_TICK_NUM], whole = nearbyint(ticks);
    if (!(whole >= 0.0 && whole * (double)h[BLK_H_TICK_NUM] < EXACT_TICKS) || fabs(ticks - whole) > STEP_TOLERANCE)
        return -1;
    *tick = (int64_t)whole;
    return 0;
}

static blk_status activate(blk_instance *inst, int64_t c, int64_t tick)
{
    blk_status status = in_order(inst, c, tick);
    if (status != BLK_STATUS_OK)
        return status;
    const struct ex_scheduled *s = inst->scheduled;
    const ex_clock *k = s->clocks + c;
    int64_t program = tick == 0 ? k->initial : k->hits[(tick % s->hyperperiod - k->offset) / k->period];
    blk_run *run = &inst->build->run;
    if (program >= 0 && blk_run_outputs(run, program) != 0) {
        ex_describe_failure(inst);
        inst->phase = BLK_FAILED;
        return BLK_STATUS_ERROR;
    }
    run->at.tail++;
    inst->outputs_fresh = 1;
    return BLK_STATUS_OK;
}

blk_status blk_instance_activate(blk_instance *inst, unsigned int clock, double time)
{
    struct ex_scheduled *s = inst->scheduled;
    if (s == NULL) {
        LOG_ERROR(inst, "this instance was not instantiated for scheduled execution");
        return BLK_STATUS_ERROR;
    }
    if (inst->phase != BLK_STEPPING)
        return ex_wrong_phase(inst, "activating a model partition");
    int64_t c = clock_index(s, clock), tick = 0;
    if (c < 0) {
        LOG_ERROR(inst, "value reference %u is not an input clock of this FMU", clock);
        return BLK_STATUS_ERROR;
    }
    const ex_clock *k = s->clocks + c;
    if (tick_of(inst, time, &tick) != 0 || !ticks_at(k, tick)) {
        LOG_ERROR(inst, "t=%.17g s is not a tick of clock %u (every %.10g s from %.10g s on)", time, clock,
                  seconds(inst, k->period), seconds(inst, k->offset));
        return BLK_STATUS_ERROR;
    }
    if (inst->stop_defined && tick > inst->stop_tick) {
        LOG_ERROR(inst, "an activation at t=%.10g s passes the stop time %.10g s", time, inst->stop_time);
        return BLK_STATUS_ERROR;
    }
    if (s->lock != NULL)
        s->lock();
    blk_status status = activate(inst, c, tick);
    if (s->unlock != NULL)
        s->unlock();
    return status;
}

static uint64_t gcd(uint64_t a, uint64_t b)
{
    while (b != 0) {
        uint64_t r = a % b;
        a = b;
        b = r;
    }
    return a;
}

/* ticks as seconds: a double and counter / resolution in lowest terms. */
static void as_time(const blk_instance *inst, int64_t ticks, double *decimal, uint64_t *counter, uint64_t *resolution)
{
    const int64_t *h = inst->x.table.header;
    uint64_t num = (uint64_t)ticks * (uint64_t)h[BLK_H_TICK_NUM], den = (uint64_t)h[BLK_H_TICK_DEN];
    uint64_t g = num == 0 ? den : gcd(num, den);
    if (decimal != NULL)
        *decimal = seconds(inst, ticks);
    if (counter != NULL)
        *counter = num / g;
    if (resolution != NULL)
        *resolution = den / g;
}

/* Clock vr's index, or -1 after logging that it is none. */
static int64_t clock_or_error(blk_instance *inst, unsigned int vr)
{
    int64_t c = inst->scheduled != NULL ? clock_index(inst->scheduled, vr) : -1;
    if (c < 0)
        LOG_ERROR(inst, "value reference %u is not a clock of this %s", vr,
                  inst->scheduled != NULL ? "FMU" : "instance (instantiated for co-simulation, without clocks)");
    return c;
}

/* The periods (shift 0) or offsets (shift 1) of clocks vr as times; an error for one that is none. */
static blk_status clock_times(blk_instance *inst, const unsigned int *vr, size_t n, int shift, double *decimal,
                              uint64_t *counters, uint64_t *resolutions)
{
    for (size_t i = 0; i < n; i++) {
        int64_t c = clock_or_error(inst, vr[i]);
        if (c < 0)
            return BLK_STATUS_ERROR;
        const ex_clock *k = inst->scheduled->clocks + c;
        as_time(inst, shift ? k->offset : k->period, decimal ? decimal + i : NULL, counters ? counters + i : NULL,
                resolutions ? resolutions + i : NULL);
    }
    return BLK_STATUS_OK;
}

blk_status blk_instance_clock_intervals(blk_instance *inst, const unsigned int *vr, size_t n, double *decimal,
                                        uint64_t *counters, uint64_t *resolutions, int *qualifiers)
{
    blk_status status = clock_times(inst, vr, n, 0, decimal, counters, resolutions);
    for (size_t i = 0; status == BLK_STATUS_OK && qualifiers != NULL && i < n; i++)
        qualifiers[i] = 1; /* fmi3IntervalUnchanged: a constant clock */
    return status;
}

blk_status blk_instance_clock_shifts(blk_instance *inst, const unsigned int *vr, size_t n, double *decimal,
                                     uint64_t *counters, uint64_t *resolutions)
{
    return clock_times(inst, vr, n, 1, decimal, counters, resolutions);
}
