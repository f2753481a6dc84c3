/* The suppresser's law (Suppresser): voluntary motion turns the grasping torque down.
 *
 * Per joint tau_g_eff = tau_g * sigmoid(S_a (S_b - g(tau_m))), with the logistic function
 * evaluated without overflow for large |x|: 1 / (1 + e) for x >= 0, e / (1 + e)
 * otherwise, e = exp(-|x|). The command adds the manipulation torque and, unsuppressed,
 * the feedforward: (tau_g_eff + tau_m) + tau_ff.
 *
 * The share output tells the grasping reflex which fingers voluntary motion has taken
 * over. Without it the reflex winds up: a finger pulled off the object still carries load,
 * its |f_t| / f_n climbs, and the reflex's one integrator raises the squeeze of every
 * finger, so the grasp torque of the withdrawing finger grows instead of falling.
 */
#include <math.h>

#include "control.h"

double hh_sigmoid(double x)
{
    double e = exp(-fabs(x));
    return x >= 0.0 ? 1.0 / (1.0 + e) : e / (1.0 + e);
}

double hh_suppressed(double tau_g, double tau_m, double s_a, double s_b, double mode)
{
    double factor = 1.0;
    if (mode != HH_SUPPRESS_PASS) {
        double g = mode == HH_SUPPRESS_MAGNITUDE ? fabs(tau_m) : tau_m;
        factor = hh_sigmoid(s_a * (s_b - g));
    }
    return tau_g * factor;
}

void hh_finger_shares(const double *tau_g, const double *tau_g_eff, const double *tau_m, double share[3])
{
    for (int i = 0; i < HH_FINGERS; i++) {
        double along = 0.0;
        double squared = 0.0;
        for (int j = 3 * i; j < 3 * i + 3; j++) {
            along += (tau_g_eff[j] + tau_m[j]) * tau_g[j];
            squared += tau_g[j] * tau_g[j];
        }
        share[i] = !(squared > 0.0) ? 1.0 : along / squared;
    }
}

void hh_suppress(const double *params, const double *tau_g, const double *tau_m, const double *tau_ff, double *out)
{
    double mode = params[HH_SUPPRESS_P_MODE];
    for (int j = 0; j < HH_JOINTS; j++) {
        double eff = hh_suppressed(tau_g[j], tau_m[j], params[HH_SUPPRESS_P_S_A + j], params[HH_SUPPRESS_P_S_B + j],
                                   mode);
        out[HH_SUPPRESS_O_TAU_G_EFF + j] = eff;
        out[HH_SUPPRESS_O_TAU + j] = (eff + tau_m[j]) + tau_ff[j];
    }
    if (mode == HH_SUPPRESS_PASS)
        for (int i = 0; i < HH_FINGERS; i++)
            out[HH_SUPPRESS_O_SHARE + i] = 1.0;
    else
        hh_finger_shares(tau_g, out + HH_SUPPRESS_O_TAU_G_EFF, tau_m, out + HH_SUPPRESS_O_SHARE);
}
