/* The FMI 2.0 model-exchange API over a test model of me_model.h (built with
 * fmi2_unsupported.c and one model source). Modes are not checked; a value reference the
 * model does not have is an error, logged. Built with MISBEHAVE (and misbehave.c), it
 * misbehaves as its resources/misbehave.txt says (misbehave.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "fmi2Functions.h"
#include "me_model.h"
#include "misbehave.h"
#ifdef SIGINT_AT
#include <signal.h> /* Ctrl-C in fmi2GetDerivatives once t >= SIGINT_AT, then a log message, then SIGINT_STATUS */
#endif

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    Values v;
    int interrupted;
} Instance;

static fmi2Status refuse(Instance *m, const char *what, fmi2ValueReference vr) {
    m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError", "%s: no value reference %u",
                 what, vr);
    return fmi2Error;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    (void)c; (void)on; (void)n; (void)cat; return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)resources; (void)visible; (void)loggingOn;
    MISBEHAVE_SETUP(resources);
    MISBEHAVE_AT("fmi2Instantiate", 0.0);
    if (type != fmi2ModelExchange || strcmp(guid, MODEL_TOKEN) != 0) {
        if (cb && cb->logger) cb->logger(cb->componentEnvironment, name, fmi2Error, "logStatusError",
                                         "not a model-exchange instantiation of this FMU (GUID %s)", guid);
        return NULL;
    }
    Instance *m = calloc(1, sizeof(Instance));
    m->cb = *cb;
    m->name = strdup(name);
    model_defaults(&m->v);
    return m;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *m = c;
    if (!m) return;
    free(m->name);
    free(m);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDef, fmi2Real stop) {
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    ((Instance *)c)->v.time = start;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { model_start(&((Instance *)c)->v); return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) {
    model_defaults(&((Instance *)c)->v);
    ((Instance *)c)->interrupted = 0;
    return fmi2OK;
}

/* The outputs that follow from the states: the derivatives, before any get. */
static void refresh(Instance *m) {
    double dx[MODEL_NX + 1];
    model_derivatives(&m->v, dx);
    for (int k = 0; k < MODEL_NX; k++) m->v.r[MODEL_DERIVATIVES[k]] = dx[k];
}

/* Get and set for the COUNT variables FIELD[0 ..] at value references FIRST, FIRST + 1, ... */
#define ACCESSORS(NAME, CTYPE, FIELD, FIRST, COUNT) \
fmi2Status fmi2Get##NAME(fmi2Component c, const fmi2ValueReference vr[], size_t n, CTYPE value[]) { \
    Instance *m = c; \
    refresh(m); \
    for (size_t k = 0; k < n; k++) { \
        if (vr[k] - (unsigned)(FIRST) >= (unsigned)(COUNT)) return refuse(m, "fmi2Get" #NAME, vr[k]); \
        value[k] = m->v.FIELD[vr[k] - (FIRST)]; \
    } \
    return fmi2OK; \
} \
fmi2Status fmi2Set##NAME(fmi2Component c, const fmi2ValueReference vr[], size_t n, const CTYPE value[]) { \
    Instance *m = c; \
    for (size_t k = 0; k < n; k++) { \
        if (vr[k] - (unsigned)(FIRST) >= (unsigned)(COUNT)) return refuse(m, "fmi2Set" #NAME, vr[k]); \
        m->v.FIELD[vr[k] - (FIRST)] = value[k]; \
    } \
    return fmi2OK; \
}

ACCESSORS(Real, fmi2Real, r, 0, N_REALS)
ACCESSORS(Integer, fmi2Integer, i, INT_VR, N_INTS)
ACCESSORS(Boolean, fmi2Boolean, b, BOOL_VR, N_BOOLS)

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    (void)value;
    return n ? refuse(c, "fmi2GetString", vr[0]) : fmi2OK;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    (void)value;
    return n ? refuse(c, "fmi2SetString", vr[0]) : fmi2OK;
}

fmi2Status fmi2EnterEventMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    MISBEHAVE_AT("fmi2NewDiscreteStates", ((Instance *)c)->v.time);
    Event e = {false, false, false, INFINITY};
    model_event(&((Instance *)c)->v, &e);
    info->newDiscreteStatesNeeded = e.again;
    info->terminateSimulation = e.terminate;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = e.states_changed;
    info->nextEventTimeDefined = isfinite(e.next_time);
    info->nextEventTime = isfinite(e.next_time) ? e.next_time : 0.0;
    return fmi2OK;
}
fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetPrior, fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation) {
    (void)noSetPrior;
    MISBEHAVE_AT("fmi2CompletedIntegratorStep", ((Instance *)c)->v.time);
    *enterEventMode = model_step_event(&((Instance *)c)->v);
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    MISBEHAVE_AT("fmi2SetTime", time);
    ((Instance *)c)->v.time = time;
    return fmi2OK;
}
fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    Instance *m = c;
    if (nx != (size_t)MODEL_NX) return refuse(m, "fmi2SetContinuousStates: wrong number of states", (unsigned)nx);
    for (size_t k = 0; k < nx; k++) m->v.r[MODEL_STATES[k]] = x[k];
    return fmi2OK;
}
fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    Instance *m = c;
    if (nx != (size_t)MODEL_NX) return refuse(m, "fmi2GetContinuousStates: wrong number of states", (unsigned)nx);
    for (size_t k = 0; k < nx; k++) x[k] = m->v.r[MODEL_STATES[k]];
    return fmi2OK;
}
fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real nominals[], size_t nx) {
    (void)c;
    for (size_t k = 0; k < nx; k++) nominals[k] = 1.0;
    return fmi2OK;
}
fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t nx) {
    Instance *m = c;
    MISBEHAVE_AT("fmi2GetDerivatives", m->v.time);
    if (nx != (size_t)MODEL_NX) return refuse(m, "fmi2GetDerivatives: wrong number of states", (unsigned)nx);
#ifdef SIGINT_AT
    if (m->v.time >= SIGINT_AT && !m->interrupted) {
        m->interrupted = 1;
        raise(SIGINT);
        m->cb.logger(m->cb.componentEnvironment, m->name, fmi2OK, "logEvents", "interrupted at t = %g", m->v.time);
        if (SIGINT_STATUS != fmi2OK) return SIGINT_STATUS;
    }
#endif
#ifdef FAIL_DERIVATIVES_AT
    if (m->v.time >= FAIL_DERIVATIVES_AT) {
        m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError",
                     "the derivatives cannot be computed at t = %g", m->v.time);
        return fmi2Error;
    }
#endif
    model_derivatives(&m->v, dx);
    return fmi2OK;
}
fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t nz) {
    Instance *m = c;
    MISBEHAVE_AT("fmi2GetEventIndicators", m->v.time);
    if (nz != (size_t)MODEL_NZ) return refuse(m, "fmi2GetEventIndicators: wrong number of indicators", (unsigned)nz);
    model_indicators(&m->v, z);
    return fmi2OK;
}
