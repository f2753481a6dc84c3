/* JointLowPass: a first-order low-pass filter of the nine joint values, as a kernel type.
 *
 * Per joint y_k = x_k and x_{k+1} = x_k + (1 - a) (u_k - x_k), a = exp(-T / time_constant):
 * the exact discretisation of time_constant dx/dt = u - x with u held over each period T,
 * so a step of u from 0 to 1 gives y_k = 1 - a^k. The output is the state (no feedthrough),
 * which starts at zero. The record is [time_constant, period] (layouts.h,
 * HH_JOINT_LOW_PASS_R_*); the context is the step 1 - a.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "control.h"
#include "kernel_types.h"

static int low_pass_construct(const double *r, long n, blk_built *built, char *message, long size)
{
    char number[40];
    if (n != HH_JOINT_LOW_PASS_RECORD) {
        snprintf(message, (size_t)size, "a JointLowPass record holds %d numbers, not %ld", HH_JOINT_LOW_PASS_RECORD, n);
        return 1;
    }
    double time_constant = r[HH_JOINT_LOW_PASS_R_TIME_CONSTANT], period = r[HH_JOINT_LOW_PASS_R_PERIOD];
    if (!(time_constant > 0.0 && isfinite(time_constant))) {
        hh_number_text(time_constant, number, sizeof number);
        snprintf(message, (size_t)size, "parameter 'time_constant' must be a time > 0 in seconds, got %s", number);
        return 1;
    }
    if (!(period > 0.0 && isfinite(period)) && !isnan(period)) { /* NaN: no period yet, the block checks */
        hh_number_text(period, number, sizeof number);
        snprintf(message, (size_t)size, "JointLowPass needs a positive period, got %s s", number);
        return 1;
    }
    double *step = malloc(sizeof *step);
    if (step == NULL) {
        snprintf(message, (size_t)size, "no memory for the filter's step");
        return 1;
    }
    *step = -expm1(-period / time_constant);
    built->ctx = step;
    built->outputs = HH_JOINTS;
    built->state_size = HH_JOINTS;
    return 0;
}

static void low_pass_initial(const void *ctx, double *state)
{
    (void)ctx;
    for (int i = 0; i < HH_JOINTS; i++)
        state[i] = 0.0;
}

static int low_pass_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                           int *which)
{
    (void)ctx;
    (void)t;
    (void)inputs;
    for (int i = 0; i < HH_JOINTS; i++)
        out[i] = state[i];
    *which = 0;
    return 0;
}

static int low_pass_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    double step = *(const double *)ctx;
    const double *u = inputs[HH_JOINT_LOW_PASS_I_U];
    for (int i = 0; i < HH_JOINTS; i++)
        state[i] += step * (u[i] - state[i]);
    *which = 0;
    return 0;
}

const blk_kernel_type hh_joint_low_pass_kernel_type[] = {
    {"JointLowPass", low_pass_construct, free, low_pass_initial, low_pass_output, low_pass_update, NULL, NULL},
    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL},
};
