/* The FMI 3.0 model-exchange API over a test model of me_model.h (built with
 * fmi3_unsupported.c -DMODEL_EXCHANGE -DNO_CO_SIMULATION and one model source). Modes are
 * not checked; a value reference the model does not have is an error, logged. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fmi3Functions.h"
#include "me_model.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    Values v;
} Instance;

static fmi3Status refuse(Instance *m, const char *what, fmi3ValueReference vr) {
    char text[160];
    snprintf(text, sizeof text, "%s: no value reference %u", what, vr);
    if (m->log) m->log(m->env, fmi3Error, "logStatusError", text);
    return fmi3Error;
}

const char *fmi3GetVersion(void) { return fmi3Version; }
fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean on, size_t n, const fmi3String c[]) {
    (void)i; (void)on; (void)n; (void)c; return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    (void)name; (void)resources; (void)visible; (void)loggingOn;
    if (strcmp(token, MODEL_TOKEN) != 0) {
        if (log) log(env, fmi3Error, "logStatusError", "wrong instantiation token");
        return NULL;
    }
    Instance *m = calloc(1, sizeof(Instance));
    m->env = env;
    m->log = log;
    model_defaults(&m->v);
    return m;
}

void fmi3FreeInstance(fmi3Instance i) { free(i); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance i, fmi3Boolean tolDef, fmi3Float64 tol,
        fmi3Float64 start, fmi3Boolean stopDef, fmi3Float64 stop) {
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    ((Instance *)i)->v.time = start;
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance i) { model_start(&((Instance *)i)->v); return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance i) { model_defaults(&((Instance *)i)->v); return fmi3OK; }

/* The outputs that follow from the states: the derivatives, before any get. */
static void refresh(Instance *m) {
    double dx[MODEL_NX + 1];
    model_derivatives(&m->v, dx);
    for (int k = 0; k < MODEL_NX; k++) m->v.r[MODEL_DERIVATIVES[k]] = dx[k];
}

/* Get and set for the COUNT scalars FIELD[0 ..] at value references FIRST, FIRST + 1, ... */
#define ACCESSORS(NAME, CTYPE, FIELD, FIRST, COUNT) \
fmi3Status fmi3Get##NAME(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, CTYPE value[], size_t nv) { \
    Instance *m = i; \
    if (nvr != nv) return refuse(m, "fmi3Get" #NAME ": arrays", (unsigned)nv); \
    refresh(m); \
    for (size_t k = 0; k < nvr; k++) { \
        if (vr[k] - (unsigned)(FIRST) >= (unsigned)(COUNT)) return refuse(m, "fmi3Get" #NAME, vr[k]); \
        value[k] = m->v.FIELD[vr[k] - (FIRST)]; \
    } \
    return fmi3OK; \
} \
fmi3Status fmi3Set##NAME(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const CTYPE value[], \
                         size_t nv) { \
    Instance *m = i; \
    if (nvr != nv) return refuse(m, "fmi3Set" #NAME ": arrays", (unsigned)nv); \
    for (size_t k = 0; k < nvr; k++) { \
        if (vr[k] - (unsigned)(FIRST) >= (unsigned)(COUNT)) return refuse(m, "fmi3Set" #NAME, vr[k]); \
        m->v.FIELD[vr[k] - (FIRST)] = value[k]; \
    } \
    return fmi3OK; \
}

ACCESSORS(Float64, fmi3Float64, r, 0, N_REALS)
ACCESSORS(Int32, fmi3Int32, i, INT_VR, N_INTS)
ACCESSORS(Boolean, fmi3Boolean, b, BOOL_VR, N_BOOLS)

fmi3Status fmi3GetFloat32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Float32 value[],
                          size_t nv) {
    (void)value; (void)nv;
    return nvr ? refuse(i, "fmi3GetFloat32", vr[0]) : fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance i, fmi3Boolean *again, fmi3Boolean *terminate,
        fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined,
        fmi3Float64 *nextTime) {
    Event e = {false, false, false, INFINITY};
    model_event(&((Instance *)i)->v, &e);
    *again = e.again;
    *terminate = e.terminate;
    *nominalsChanged = fmi3False;
    *valuesChanged = e.states_changed;
    *nextDefined = isfinite(e.next_time);
    *nextTime = isfinite(e.next_time) ? e.next_time : 0.0;
    return fmi3OK;
}
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance i, fmi3Boolean noSetPrior, fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation) {
    (void)noSetPrior;
    *enterEventMode = model_step_event(&((Instance *)i)->v);
    *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance i, fmi3Float64 time) { ((Instance *)i)->v.time = time; return fmi3OK; }
fmi3Status fmi3SetContinuousStates(fmi3Instance i, const fmi3Float64 x[], size_t nx) {
    Instance *m = i;
    if (nx != (size_t)MODEL_NX) return refuse(m, "fmi3SetContinuousStates: wrong number of states", (unsigned)nx);
    for (size_t k = 0; k < nx; k++) m->v.r[MODEL_STATES[k]] = x[k];
    return fmi3OK;
}
fmi3Status fmi3GetContinuousStates(fmi3Instance i, fmi3Float64 x[], size_t nx) {
    Instance *m = i;
    if (nx != (size_t)MODEL_NX) return refuse(m, "fmi3GetContinuousStates: wrong number of states", (unsigned)nx);
    for (size_t k = 0; k < nx; k++) x[k] = m->v.r[MODEL_STATES[k]];
    return fmi3OK;
}
fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance i, fmi3Float64 nominals[], size_t nx) {
    (void)i;
    for (size_t k = 0; k < nx; k++) nominals[k] = 1.0;
    return fmi3OK;
}
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance i, fmi3Float64 dx[], size_t nx) {
    Instance *m = i;
    if (nx != (size_t)MODEL_NX) return refuse(m, "fmi3GetContinuousStateDerivatives: wrong number", (unsigned)nx);
#ifdef FAIL_DERIVATIVES_AT
    if (m->v.time >= FAIL_DERIVATIVES_AT) {
        char text[96];
        snprintf(text, sizeof text, "the derivatives cannot be computed at t = %g", m->v.time);
        if (m->log) m->log(m->env, fmi3Error, "logStatusError", text);
        return fmi3Error;
    }
#endif
    model_derivatives(&m->v, dx);
    return fmi3OK;
}
fmi3Status fmi3GetEventIndicators(fmi3Instance i, fmi3Float64 z[], size_t nz) {
    Instance *m = i;
    if (nz != (size_t)MODEL_NZ) return refuse(m, "fmi3GetEventIndicators: wrong number", (unsigned)nz);
    model_indicators(&m->v, z);
    return fmi3OK;
}
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance i, size_t *n) { (void)i; *n = (size_t)MODEL_NX; return fmi3OK; }
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance i, size_t *n) { (void)i; *n = (size_t)MODEL_NZ; return fmi3OK; }
