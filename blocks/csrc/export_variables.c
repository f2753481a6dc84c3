/* The variables of an exported FMU's instance by value reference: 0 the time, then the
 * inputs, the outputs and the parameters, each a range that starts where the resources say
 * (export_instance.h). Reading an output computes the outputs first when an input changed
 * (between grid points the outputs hold: export_step.c; in scheduled execution the
 * partitions compute them);
 * setting a parameter releases the kernels, which are built again with it. */

#include "export_internal.h"

static int in_range(unsigned int vr, int64_t first, int64_t n)
{
    return (int64_t)vr >= first && (int64_t)vr < first + n;
}

blk_status blk_instance_get(blk_instance *inst, const unsigned int *vr, size_t n, double *values)
{
    const blk_export *x = &inst->x;
    blk_status status = BLK_STATUS_OK;
    if (inst->phase == BLK_FAILED)
        return ex_wrong_phase(inst, "getting values");
    for (size_t i = 0; i < n; i++) {
        if (!in_range(vr[i], x->vr_output, x->n_outputs))
            continue;
        if (inst->phase == BLK_INSTANTIATED) {
            LOG_ERROR(inst, "output %u is calculated: read it after entering initialization mode", vr[i]);
            return BLK_STATUS_ERROR;
        }
        /* held between grid points (export_step.c); in scheduled execution the partitions
         * computed them: a get computes nothing */
        int refreshed = -1;
        if (ex_build_kernels(inst) == 0) {
            int fresh = inst->outputs_fresh || inst->build->held
                        || (inst->scheduled != NULL && inst->phase == BLK_STEPPING);
            refreshed = fresh ? 0 : ex_refresh_outputs(inst);
        }
        if (refreshed < 0)
            return BLK_STATUS_ERROR;
        break;
    }
    for (size_t i = 0; i < n; i++) {
        unsigned int r = vr[i];
        if (r == 0)
            values[i] = blk_instance_time(inst);
        else if (in_range(r, x->vr_input, x->n_inputs))
            values[i] = inst->inputs[r - x->vr_input];
        else if (in_range(r, x->vr_output, x->n_outputs))
            values[i] = inst->build->held ? inst->build->held_outputs[r - x->vr_output]
                                          : inst->build->arena[x->outputs[r - x->vr_output]];
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
        return ex_wrong_phase(inst, "setting values");
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
            ex_release_build(inst);
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
