/* A model-exchange test model as the FMI wrappers me_fmi2.c and me_fmi3.c see it.
 *
 * A model (linear.c, bouncing.c, stair.c) keeps its variables in one Values record by
 * value reference -- Float64 (FMI 2 Real) 0..N_REALS-1, Int32 (FMI 2 Integer) from INT_VR,
 * Boolean from BOOL_VR -- names its continuous states and their derivatives by value
 * reference, and gives its equations as the functions below. The wrappers do the rest of
 * the FMI API, FMI 2 or FMI 3, from one model source.
 *
 * Built with FAIL_DERIVATIVES_AT, the derivatives fail (an error status, logged) once the
 * model's time has reached that value: for the tests of a failing model. me_fmi2.c built
 * with SIGINT_AT and SIGINT_STATUS sends the process SIGINT (as Ctrl-C would) in the first
 * call for the derivatives from that time on, logs, and returns that status.
 */
#ifndef ME_MODEL_H
#define ME_MODEL_H

#include <stdbool.h>

#define N_REALS 16
#define N_INTS 4
#define N_BOOLS 4
#define INT_VR 100
#define BOOL_VR 200

typedef struct {
    double r[N_REALS];
    int i[N_INTS];
    bool b[N_BOOLS];
    double time;
} Values;

/* What one pass of the discrete update (an event) did. */
typedef struct {
    bool again;          /* the discrete states need another pass (event iteration) */
    bool terminate;      /* the model asks to end the simulation */
    bool states_changed; /* the continuous states changed */
    double next_time;    /* the next time event (INFINITY: none) */
} Event;

extern const char MODEL_TOKEN[]; /* the GUID / instantiation token */
extern const int MODEL_NX, MODEL_NZ;
extern const unsigned MODEL_STATES[], MODEL_DERIVATIVES[]; /* value references, MODEL_NX each */

void model_defaults(Values *v);                        /* at instantiation and reset */
void model_start(Values *v);                           /* leaving initialization: states from parameters */
void model_derivatives(const Values *v, double dx[]); /* at v->time, states in place */
void model_indicators(const Values *v, double z[]);
void model_event(Values *v, Event *e);                 /* one pass of the discrete update */
bool model_step_event(const Values *v);                /* after an integrator step: enter event mode? */

#endif
