/* The suppresser's law (Suppresser): voluntary motion turns the grasping torque down.
 *
 * Per joint tau_g_eff = tau_g * sigmoid(S_a (S_b - g(tau_m))), with the logistic function
 * evaluated as suppression.sigmoid does, without overflow for large |x|:
 * 1 / (1 + e) for x >= 0, e / (1 + e) otherwise, e = exp(-|x|). The command adds the
 * manipulation torque and, unsuppressed, the feedforward: (tau_g_eff + tau_m) + tau_ff.
 */
#include <math.h>

#include "control.h"

void hh_suppress(const double *params, const double *tau_g, const double *tau_m, const double *tau_ff, double *out)
{
    double mode = params[HH_SUPPRESS_P_MODE];
    for (int j = 0; j < HH_JOINTS; j++) {
        double m = tau_m[j];
        double eff;
        if (mode == HH_SUPPRESS_PASS) {
            eff = tau_g[j];
        } else {
            double g = mode == HH_SUPPRESS_MAGNITUDE ? fabs(m) : m;
            double x = params[HH_SUPPRESS_P_S_A + j] * (params[HH_SUPPRESS_P_S_B + j] - g);
            double e = exp(-fabs(x));
            eff = tau_g[j] * (x >= 0.0 ? 1.0 / (1.0 + e) : e / (1.0 + e));
        }
        out[HH_SUPPRESS_O_TAU_G_EFF + j] = eff;
        out[HH_SUPPRESS_O_TAU + j] = (eff + m) + tau_ff[j];
    }
}
