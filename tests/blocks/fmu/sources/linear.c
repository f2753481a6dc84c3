/* A linear model-exchange test model with a closed-form solution (me_model.h): a damped
 * oscillator driven by its input,
 *     x' = v,   v' = -k x - c v + u,   x(0) = x0, v(0) = v0,
 * whose outputs are its states x and v. No events.
 *
 * Value references: k 0, c 1, x0 2, v0 3, u 4, x 5, v 6, der(x) 7, der(v) 8.
 */
#include <math.h>
#include "me_model.h"

const char MODEL_TOKEN[] = "{6d2b8f4e-0c1a-4e57-9b3d-linear000001}";
const int MODEL_NX = 2, MODEL_NZ = 0;
const unsigned MODEL_STATES[] = {5, 6}, MODEL_DERIVATIVES[] = {7, 8};

void model_defaults(Values *v) {
    *v = (Values){0};
    v->r[0] = 4.0; v->r[1] = 0.4; v->r[2] = 1.0; v->r[3] = 0.0;
}
void model_start(Values *v) { v->r[5] = v->r[2]; v->r[6] = v->r[3]; }
void model_derivatives(const Values *v, double dx[]) {
    dx[0] = v->r[6];
    dx[1] = -v->r[0] * v->r[5] - v->r[1] * v->r[6] + v->r[4];
}
void model_indicators(const Values *v, double z[]) { (void)v; (void)z; }
void model_event(Values *v, Event *e) { (void)v; (void)e; }
bool model_step_event(const Values *v) { (void)v; return false; }
