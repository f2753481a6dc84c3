/* The log of an exported FMU's instance (export_internal.h): messages through the
 * importer's logger by category (logEvents only when asked for), and the messages that
 * name a block, describe a failed run or refuse a call in the wrong phase, written once
 * for every file of the instance. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "export_internal.h"

static const char *PHASE_NAMES[] = {"instantiated", "initialization mode", "step mode", "terminated", "failed"};

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

const char *ex_block_name(const blk_instance *inst, int64_t b)
{
    return inst->x.blocks[b].name;
}

/* "block 'name' (Kind): " before a block's message, or nothing in a one-block diagram. */
void ex_block_prefix(const blk_instance *inst, int64_t b, char *out, size_t size)
{
    if (inst->x.n_blocks == 1)
        out[0] = '\0';
    else
        snprintf(out, size, "block '%s' (%s): ", ex_block_name(inst, b), inst->x.blocks[b].kind);
}

/* Log the failure of the run's outcome. */
void ex_describe_failure(blk_instance *inst)
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
    double when = ex_tick_time(inst, o->tick);
    char prefix[256], message[512];
    ex_block_prefix(inst, b, prefix, sizeof prefix);
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

blk_status ex_wrong_phase(blk_instance *inst, const char *what)
{
    LOG_ERROR(inst, "%s is not allowed when the instance is %s", what, PHASE_NAMES[inst->phase]);
    return BLK_STATUS_ERROR;
}
