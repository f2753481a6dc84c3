/* The life of an exported FMU's instance: instantiation from its resources, the phases
 * (setting up the experiment, entering and leaving initialization, termination, reset) and
 * its end. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "export_internal.h"

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
    if (resource_dir == NULL || ex_read_resources(inst, token, resource_dir) != 0) {
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

void blk_instance_free(blk_instance *inst)
{
    if (inst == NULL)
        return;
    ex_release_build(inst);
    ex_free_export(&inst->x);
    free(inst->scheduled);
    free(inst->params);
    free(inst->set);
    free(inst->inputs);
    free(inst->name);
    free(inst);
}

blk_status blk_instance_setup(blk_instance *inst, double start_time, int stop_defined, double stop_time)
{
    if (inst->phase != BLK_INSTANTIATED)
        return ex_wrong_phase(inst, "setting up the experiment");
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
        return ex_wrong_phase(inst, "entering initialization mode");
    ex_release_build(inst);
    inst->phase = BLK_INITIALIZATION;
    return BLK_STATUS_OK;
}

blk_status blk_instance_exit_initialization(blk_instance *inst)
{
    if (inst->phase != BLK_INITIALIZATION)
        return ex_wrong_phase(inst, "exiting initialization mode");
    /* scheduled execution: the outputs are the partitions' (clocked ones have no value before their clock ticks) */
    int outputs = !inst->outputs_fresh && inst->scheduled == NULL;
    if (ex_build_kernels(inst) != 0 || (outputs && (inst->phase = BLK_STEPPING, ex_refresh_outputs(inst) != 0))) {
        inst->phase = BLK_FAILED;
        return BLK_STATUS_ERROR;
    }
    inst->phase = BLK_STEPPING;
    LOG_EVENT(inst, "initialized: %lld block%s, arena of %lld values", (long long)inst->x.n_blocks,
              inst->x.n_blocks == 1 ? "" : "s", (long long)inst->x.table.header[BLK_H_ARENA]);
    return BLK_STATUS_OK;
}

blk_status blk_instance_terminate(blk_instance *inst)
{
    if (inst->phase != BLK_STEPPING && inst->phase != BLK_FAILED && inst->phase != BLK_INITIALIZATION)
        return ex_wrong_phase(inst, "terminate");
    inst->phase = BLK_TERMINATED;
    return BLK_STATUS_OK;
}

blk_status blk_instance_reset(blk_instance *inst)
{
    ex_release_build(inst);
    start_values(inst);
    inst->stop_defined = 0;
    inst->phase = BLK_INSTANTIATED;
    return BLK_STATUS_OK;
}

blk_phase blk_instance_phase(const blk_instance *inst)
{
    return inst->phase;
}
