/* Stepping an exported FMU's instance: the outputs at the run's tick from the inputs set
 * there, and a communication step of any length, run by the core up to the last grid tick
 * it reaches, counted in integers from t = 0 (export_instance.h says why); a step that
 * ends between grid ticks holds the outputs of the last one until the next. */
#include <math.h>

#include "export_internal.h"

/* The outputs at the run's tick from the inputs now: the outputs-only program of that tick
   (at t = 0 before the first step, between events, or an event's), then the lazy outputs.
   0; -1 after logging the failure (the instance then failed); 1 in initialization mode,
   where a failure is logged as an event (the outputs wait for the inputs). */
int ex_refresh_outputs(blk_instance *inst)
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
               the outputs wait for them, and are computed again when they change (not a
               warning: an importer may read outputs before setting inputs, and some treat
               a warning as an error) */
            const blk_outcome *o = &run->outcome;
            blk_instance_log(inst, BLK_STATUS_OK, BLK_LOG_EVENTS,
                             "the outputs at t=0 cannot be computed from the inputs set so far (block '%s' "
                             "fails with code %d); they are computed again when the inputs change",
                             ex_block_name(inst, x->table.ops[o->op * BLK_OP_N + BLK_OP_A]), o->code);
            run->outcome.status = BLK_RUN_COMPLETE;
            return 1;
        }
        ex_describe_failure(inst);
        inst->phase = BLK_FAILED;
        return -1;
    }
    inst->outputs_fresh = 1;
    return 0;
}

double blk_instance_time(const blk_instance *inst)
{
    const ex_build *b = inst->build;
    return b == NULL ? 0.0 : b->held ? b->held_time : ex_tick_time(inst, b->run.at.tick);
}

/* The grid point a step ends on or last passes: the number of grid steps from t = 0 to
   ``end``, rounded down unless ``end`` misses a grid point by STEP_TOLERANCE of a grid step
   (*on_grid: it falls on one); -1 for a time out of the range counted exactly. */
static int64_t grid_point(const blk_instance *inst, double end, int *on_grid)
{
    const int64_t *h = inst->x.table.header;
    double grid = (double)h[BLK_H_TICK_NUM] / (double)h[BLK_H_TICK_DEN] * (double)inst->x.grid;
    double count = end / grid, nearest = nearbyint(count);
    if (!(count >= 0.0) || !(count * (double)inst->x.grid * (double)h[BLK_H_TICK_NUM] < EXACT_TICKS))
        return -1;
    *on_grid = fabs(count - nearest) <= STEP_TOLERANCE;
    return (int64_t)(*on_grid ? nearest : floor(count)) * inst->x.grid;
}

/* Hold the outputs of the grid point the run is at, computed from the inputs set at the
   step's start (they hold until its end), and run that point's updates with them: the
   importer sets its next inputs at ``end``, after it. */
static blk_status hold(blk_instance *inst, double end)
{
    ex_build *b = inst->build;
    blk_run *run = &b->run;
    for (int64_t k = 0; k < inst->x.n_outputs; k++)
        b->held_outputs[k] = b->arena[inst->x.outputs[k]];
    b->held = 1;
    b->held_tick = run->at.tick;
    b->held_time = end;
    if (run->at.tick + inst->x.grid <= run->at.end && blk_run_until(run, run->at.tick + inst->x.grid) != 0) {
        ex_describe_failure(inst);
        inst->phase = BLK_FAILED;
        return BLK_STATUS_ERROR;
    }
    return BLK_STATUS_OK;
}

/* A communication step from current_time to current_time + step: every grid point in
   between runs with the inputs set at current_time (held over the step), the outputs are
   those of the last one (from the inputs set at the step's end when it ends on one). */
blk_status blk_instance_do_step(blk_instance *inst, double current_time, double step, int *terminated)
{
    *terminated = 0;
    if (inst->phase != BLK_STEPPING)
        return ex_wrong_phase(inst, "a step");
    ex_build *b = inst->build;
    blk_run *run = &b->run;
    double now = blk_instance_time(inst), end = current_time + step;
    double grid = ex_tick_time(inst, inst->x.grid);
    int on_grid = 0;
    int64_t target = grid_point(inst, end, &on_grid);
    if (!(step >= 0.0)) {
        LOG_ERROR(inst, "communication step %.10g s: a step must not be negative", step);
        return BLK_STATUS_ERROR;
    }
    if (fabs(current_time - now) > 1e-9 * (fabs(now) > grid ? fabs(now) : grid)) {
        LOG_ERROR(inst, "a step from t=%.10g s, but the FMU is at t=%.10g s", current_time, now);
        return BLK_STATUS_ERROR;
    }
    if (target < 0) {
        LOG_ERROR(inst, "a step to t=%.10g s is past the times the FMU counts exactly", end);
        return BLK_STATUS_ERROR;
    }
    if (inst->stop_defined && (target > inst->stop_tick || end > inst->stop_time + STEP_TOLERANCE * grid)) {
        LOG_ERROR(inst, "a step to t=%.10g s passes the stop time %.10g s", end, inst->stop_time);
        return BLK_STATUS_ERROR;
    }
    int64_t at = b->held ? b->held_tick : run->at.tick;
    if (run->at.tick == run->at.end && run->at.end_program >= 0 && target > run->at.tick) {
        *terminated = 1;
        LOG_ERROR(inst, "the diagram ended at t=%.10g s (a block asked to end the run): it cannot step further", now);
        return BLK_STATUS_DISCARD;
    }
    if (target == at && (b->held || step == 0.0)) {
        if (b->held)
            b->held_time = end; /* no grid point passed: the outputs hold */
        return BLK_STATUS_OK;
    }
    b->held = 0;
    if (target > run->at.tick && blk_run_until(run, target) != 0) {
        ex_describe_failure(inst);
        inst->phase = BLK_FAILED;
        return BLK_STATUS_ERROR;
    }
    if (ex_refresh_outputs(inst) != 0)
        return BLK_STATUS_ERROR;
    if (run->at.tick == run->at.end && run->at.end_program >= 0) {
        *terminated = 1;
        LOG_EVENT(inst, "a block ended the run at t=%.10g s", blk_instance_time(inst));
        return BLK_STATUS_OK;
    }
    return on_grid ? BLK_STATUS_OK : hold(inst, end);
}
