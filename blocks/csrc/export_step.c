/* Stepping an exported FMU's instance: the outputs at the run's tick from the inputs set
 * there, and a communication step, a whole number of grid ticks counted in integers from
 * t = 0 (export_instance.h says why), run by the core up to the target tick. */
#include <math.h>

#include "export_internal.h"

/* The outputs at the run's tick from the inputs now: the outputs-only program of that tick
   (at t = 0 before the first step, between events, or an event's), then the lazy outputs.
   0; -1 after logging the failure (the instance then failed); 1 in initialization mode,
   where a failure is a warning (the outputs wait for the inputs). */
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
               the outputs wait for them, and are computed again when they change */
            const blk_outcome *o = &run->outcome;
            blk_instance_log(inst, BLK_STATUS_WARNING, BLK_LOG_WARNING,
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
    return inst->build != NULL ? ex_tick_time(inst, inst->build->run.at.tick) : 0.0;
}

blk_status blk_instance_do_step(blk_instance *inst, double current_time, double step, int *terminated)
{
    *terminated = 0;
    if (inst->phase != BLK_STEPPING)
        return ex_wrong_phase(inst, "a step");
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
        LOG_ERROR(inst, "a step to t=%.10g s passes the stop time %.10g s", ex_tick_time(inst, target),
                  inst->stop_time);
        return BLK_STATUS_ERROR;
    }
    if ((double)target * (double)h[BLK_H_TICK_NUM] >= EXACT_TICKS) {
        LOG_ERROR(inst, "a step to t=%.10g s is past the times the FMU counts exactly", ex_tick_time(inst, target));
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
        ex_describe_failure(inst);
        inst->phase = BLK_FAILED;
        return BLK_STATUS_ERROR;
    }
    if (ex_refresh_outputs(inst) != 0)
        return BLK_STATUS_ERROR;
    if (run->at.tick == run->at.end && run->at.end_program >= 0) {
        *terminated = 1;
        LOG_EVENT(inst, "a block ended the run at t=%.10g s", blk_instance_time(inst));
    }
    return BLK_STATUS_OK;
}
