/* The suppresser's law (Suppresser): voluntary motion turns the grasping torque down.
 *
 * Per joint tau_g_eff = tau_g * sigmoid(S_a (S_b - g(tau_m))), with the logistic function
 * evaluated as suppression.sigmoid does, without overflow for large |x|:
 * 1 / (1 + e) for x >= 0, e / (1 + e) otherwise, e = exp(-|x|). The command adds the
 * manipulation torque and, unsuppressed, the feedforward: (tau_g_eff + tau_m) + tau_ff.
 *
 * The share output tells the grasping reflex which fingers voluntary motion has taken
 * over. Without it the reflex winds up: a finger pulled off the object still carries load,
 * its |f_t| / f_n climbs, and the reflex's one integrator raises the squeeze of every
 * finger, so the grasp torque of the withdrawing finger grows instead of falling.
 */
#include <math.h>

#include "control.h"

void hh_suppress(const double *params, const double *tau_g, const double *tau_m, const double *tau_ff, double *out)
{
    double mode = params[HH_SUPPRESS_P_MODE];
    for (int j = 0; j < HH_JOINTS; j++) {
        double m = tau_m[j];
        double factor = 1.0;
        if (mode != HH_SUPPRESS_PASS) {
            double g = mode == HH_SUPPRESS_MAGNITUDE ? fabs(m) : m;
            double x = params[HH_SUPPRESS_P_S_A + j] * (params[HH_SUPPRESS_P_S_B + j] - g);
            double e = exp(-fabs(x));
            factor = x >= 0.0 ? 1.0 / (1.0 + e) : e / (1.0 + e);
        }
        double eff = tau_g[j] * factor;
        out[HH_SUPPRESS_O_TAU_G_EFF + j] = eff;
        out[HH_SUPPRESS_O_TAU + j] = (eff + m) + tau_ff[j];
    }
    for (int i = 0; i < HH_FINGERS; i++) {
        double along = 0.0;
        double squared = 0.0;
        for (int j = 3 * i; j < 3 * i + 3; j++) {
            along += (out[HH_SUPPRESS_O_TAU_G_EFF + j] + tau_m[j]) * tau_g[j];
            squared += tau_g[j] * tau_g[j];
        }
        out[HH_SUPPRESS_O_SHARE + i] = mode == HH_SUPPRESS_PASS || !(squared > 0.0) ? 1.0 : along / squared;
    }
}
