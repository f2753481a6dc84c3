/* A staircase, the model-exchange test model of time events, step events and event
 * iteration (me_model.h):
 *     x' = count,   x(0) = 0,
 * where count steps up by one at the time events T, 2 T, 3 T, ... and level follows
 * count in the second pass of each event's discrete update (so level equals count only
 * if the importer iterates). When an integrator step ends with x >= limit, the model asks
 * for an event (a step event), at which above becomes true and t_above that time.
 *
 * Value references: T 0, limit 1, x 2, der(x) 3, t_above 4; Int32 count 100, level 101;
 * Boolean above 200.
 */
#include <math.h>
#include "me_model.h"

const char MODEL_TOKEN[] = "{8e4a2c6b-7d19-4f0a-b3c5-stair0000003}";
const int MODEL_NX = 1, MODEL_NZ = 0;
const unsigned MODEL_STATES[] = {2}, MODEL_DERIVATIVES[] = {3};

void model_defaults(Values *v) {
    *v = (Values){0};
    v->r[0] = 0.25; v->r[1] = 0.5;
}
void model_start(Values *v) { v->r[2] = 0.0; }
void model_derivatives(const Values *v, double dx[]) { dx[0] = v->i[0]; }
void model_indicators(const Values *v, double z[]) { (void)v; (void)z; }
void model_event(Values *v, Event *e) {
    double period = v->r[0];
    if (v->i[1] != v->i[0]) {
        v->i[1] = v->i[0];
    } else if (v->time >= (v->i[0] + 1) * period * (1 - 1e-12)) {
        v->i[0] += 1;
        e->again = true;
    }
    if (!v->b[0] && v->r[2] >= v->r[1]) {
        v->b[0] = true;
        v->r[4] = v->time;
    }
    e->next_time = (v->i[0] + 1) * period;
}
bool model_step_event(const Values *v) { return !v->b[0] && v->r[2] >= v->r[1]; }
