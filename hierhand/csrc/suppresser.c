/* The suppresser's law (Suppresser): voluntary motion turns the grasping torque down.
 *
 * Per joint tau_g_eff = tau_g * sigmoid(S_a (S_b - g(tau_m))), with the logistic function
 * evaluated without overflow for large |x|: 1 / (1 + e) for x >= 0, e / (1 + e)
 * otherwise, e = exp(-|x|). The command adds the manipulation torque and, unsuppressed,
 * the feedforward: (tau_g_eff + tau_m) + tau_ff.
 *
 * g(tau_m) is |tau_m| (magnitude) or, for the paper's literal formula (signed), tau_m
 * signed positive against the joint's grasping torque: -tau_m where tau_g >= 0, tau_m
 * where tau_g < 0, so that only voluntary motion that works against the grasp suppresses it.
 *
 * The sigmoid may read g as it is (the paper's static law) or low-passed by a first-order
 * filter, the block's state (hh_suppress_update): the sigmoid closes a loop from the
 * manipulation torque through the grasping torque and the finger back to the manipulation
 * torque whose gain is |tau_g| S_a / 4 at the sigmoid's middle, several times what the
 * 10 ms PD tolerates; the filter keeps it stable at the PD's rate.
 *
 * The share output is what the suppresser lets through of each finger's grasping torque,
 * and so what the reflex still commands there: a finger whose grasp the sigmoid has mostly
 * switched off is no longer the reflex's to squeeze (see reflex.c, hand_over).
 */
#include <math.h>

#include "control.h"

double hh_sigmoid(double x)
{
    double e = exp(-fabs(x));
    return x >= 0.0 ? 1.0 / (1.0 + e) : e / (1.0 + e);
}

double hh_suppression_input(double tau_g, double tau_m, double mode)
{
    return mode == HH_SUPPRESS_MAGNITUDE ? fabs(tau_m) : tau_g >= 0.0 ? -tau_m : tau_m;
}

double hh_suppressed(double tau_g, double g, double s_a, double s_b, double mode)
{
    return mode == HH_SUPPRESS_PASS ? tau_g : tau_g * hh_sigmoid(s_a * (s_b - g));
}

void hh_finger_shares(const double *tau_g, const double *tau_g_eff, double share[3])
{
    for (int i = 0; i < HH_FINGERS; i++) {
        double along = 0.0;
        double squared = 0.0;
        for (int j = 3 * i; j < 3 * i + 3; j++) {
            along += tau_g_eff[j] * tau_g[j];
            squared += tau_g[j] * tau_g[j];
        }
        share[i] = !(squared > 0.0) ? 1.0 : along / squared;
    }
}

void hh_suppress(const double *params, const double *tau_g, const double *g, const double *tau_m,
                 const double *tau_ff, double *out)
{
    double mode = params[HH_SUPPRESS_P_MODE];
    for (int j = 0; j < HH_JOINTS; j++) {
        double input = g != NULL ? g[j] : hh_suppression_input(tau_g[j], tau_m[j], mode);
        double eff = hh_suppressed(tau_g[j], input, params[HH_SUPPRESS_P_S_A + j], params[HH_SUPPRESS_P_S_B + j], mode);
        out[HH_SUPPRESS_O_TAU_G_EFF + j] = eff;
        out[HH_SUPPRESS_O_TAU + j] = (eff + tau_m[j]) + tau_ff[j];
    }
    if (mode == HH_SUPPRESS_PASS)
        for (int i = 0; i < HH_FINGERS; i++)
            out[HH_SUPPRESS_O_SHARE + i] = 1.0;
    else
        hh_finger_shares(tau_g, out + HH_SUPPRESS_O_TAU_G_EFF, out + HH_SUPPRESS_O_SHARE);
}

void hh_suppress_update(const double *params, const double *state, const double *tau_g, const double *tau_m,
                        double *next)
{
    double mode = params[HH_SUPPRESS_P_MODE];
    double alpha = params[HH_SUPPRESS_P_ALPHA];
    for (int j = 0; j < HH_JOINTS; j++)
        next[j] = mode == HH_SUPPRESS_PASS ? state[j]
                                           : state[j] + alpha * (hh_suppression_input(tau_g[j], tau_m[j], mode) - state[j]);
}
