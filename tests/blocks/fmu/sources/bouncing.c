/* A bouncing ball, the model-exchange test model of a state event (me_model.h):
 *     h' = v,   v' = -g,   h(0) = h0, v(0) = v0;
 * the event indicator is h, and where it falls to 0 the ball bounces: h = 0, v = -e v,
 * bounces + 1, t_bounce = the time of the bounce.
 *
 * Built with STRICT_SIGN, the ball bounces only where h < 0, as generated code reads the
 * state's sign: handed the state at the crossing itself (h exactly 0), it would fall on.
 *
 * Value references: g 0, e 1, h0 2, v0 3, h 4, v 5, der(h) 6, der(v) 7, t_bounce 8;
 * Int32 bounces 100.
 */
#include <math.h>
#include "me_model.h"

const char MODEL_TOKEN[] = "{1f0c9a7e-5b2d-4c3e-8a61-bouncing0002}";
const int MODEL_NX = 2, MODEL_NZ = 1;
const unsigned MODEL_STATES[] = {4, 5}, MODEL_DERIVATIVES[] = {6, 7};

void model_defaults(Values *v) {
    *v = (Values){0};
    v->r[0] = 9.81; v->r[1] = 0.8; v->r[2] = 1.0; v->r[3] = 0.0;
}
void model_start(Values *v) { v->r[4] = v->r[2]; v->r[5] = v->r[3]; }
void model_derivatives(const Values *v, double dx[]) { dx[0] = v->r[5]; dx[1] = -v->r[0]; }
void model_indicators(const Values *v, double z[]) { z[0] = v->r[4]; }
void model_event(Values *v, Event *e) {
#ifdef STRICT_SIGN
    if (v->r[4] < 0.0 && v->r[5] < 0.0) {
#else
    if (v->r[4] <= 0.0 && v->r[5] < 0.0) {
#endif
        v->r[4] = 0.0;
        v->r[5] = -v->r[1] * v->r[5];
        v->r[8] = v->time;
        v->i[0] += 1;
        e->states_changed = true;
    }
}
bool model_step_event(const Values *v) { (void)v; return false; }
