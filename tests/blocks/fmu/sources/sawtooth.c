/* A sawtooth, the model-exchange test model of a state event whose handler reads the
 * state's sign (me_model.h), as generated code does:
 *     x' = -rate,   x(0) = x0;
 * the event indicator is x, and the event handler acts only where x < 0 (not where the
 * indicator crossed): x = x + 1, teeth + 1, t_tooth = the time of the event. Handed the
 * state at the crossing itself (x exactly 0) instead of past it, it sees no event, and x
 * falls on without bound.
 *
 * Value references: rate 0, x0 1, x 2, der(x) 3, t_tooth 4; Int32 teeth 100.
 */
#include "me_model.h"

const char MODEL_TOKEN[] = "{7d3e2a10-1c4b-4f5e-9a72-sawtooth0002}";
const int MODEL_NX = 1, MODEL_NZ = 1;
const unsigned MODEL_STATES[] = {2}, MODEL_DERIVATIVES[] = {3};

void model_defaults(Values *v) {
    *v = (Values){0};
    v->r[0] = 1.0; v->r[1] = 0.75;
}
void model_start(Values *v) { v->r[2] = v->r[1]; }
void model_derivatives(const Values *v, double dx[]) { dx[0] = -v->r[0]; }
void model_indicators(const Values *v, double z[]) { z[0] = v->r[2]; }
void model_event(Values *v, Event *e) {
    if (v->r[2] < 0.0) {
        v->r[2] += 1.0;
        v->r[4] = v->time;
        v->i[0] += 1;
        e->states_changed = true;
    }
}
bool model_step_event(const Values *v) { (void)v; return false; }
