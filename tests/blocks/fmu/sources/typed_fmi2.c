/* An FMI 2.0 FMU with a port of every FMI 2 type, for the conformance tests, for
 * co-simulation and model exchange (built with fmi2_unsupported.c and -DSTEP_STATUS).
 *
 * Each output copies its input of the same type: at initialisation (so initial outputs
 * follow inputs set before exitInitializationMode) and in every doStep (the inputs of the
 * step's start), or in model exchange at every event (the importer's, when it sets new
 * inputs). The step that reaches the parameter stop_at ends at stop_at and asks to
 * terminate: fmi2Discard, with fmi2Terminated true and fmi2LastSuccessfulTime stop_at; in
 * model exchange stop_at is a time event, at which the FMU asks to terminate. No
 * continuous states, no event indicators.
 *
 * Value references: Real r_in 0, r_out 1, stop_at 2, time_out 3; Integer i_in 10, i_out 11;
 * Boolean b_in 20, b_out 21; Enumeration e_in 30, e_out 31; String s_in 40.
 */
#include <stdlib.h>
#include <string.h>
#include "fmi2Functions.h"

#define GUID "{5b0f1f6e-93a4-4c55-a1f2-1d7e2e0c2002}"

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    fmi2Real r[2], stop_at, time, last;
    fmi2Integer i[2], e[2];
    fmi2Boolean b[2], terminated;
} Model;

static void set_defaults(Model *m) {
    m->r[0] = m->r[1] = 0.0;
    m->i[0] = m->i[1] = 0;
    m->e[0] = m->e[1] = 1;
    m->b[0] = m->b[1] = fmi2False;
    m->stop_at = 1e300; m->time = 0.0; m->last = 0.0; m->terminated = fmi2False;
}

static void follow_inputs(Model *m) {
    m->r[1] = m->r[0]; m->i[1] = m->i[0]; m->e[1] = m->e[0]; m->b[1] = m->b[0];
}

static fmi2Status refuse(Model *m, const char *what, fmi2ValueReference vr) {
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
    (void)type;
    if (strcmp(guid, GUID) != 0) return NULL;
    Model *m = calloc(1, sizeof(Model));
    m->cb = *cb;
    m->name = strdup(name);
    set_defaults(m);
    return m;
}

void fmi2FreeInstance(fmi2Component c) {
    Model *m = c;
    if (!m) return;
    free(m->name);
    free(m);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDef, fmi2Real stop) {
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    ((Model *)c)->time = start;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { follow_inputs(c); return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { set_defaults(c); return fmi2OK; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    Model *m = c;
    for (size_t k = 0; k < n; k++) {
        switch (vr[k]) {
        case 0: case 1: v[k] = m->r[vr[k]]; break;
        case 2: v[k] = m->stop_at; break;
        case 3: v[k] = m->time; break;
        default: return refuse(m, "fmi2GetReal", vr[k]);
        }
    }
    return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    Model *m = c;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] == 0) m->r[0] = v[k];
        else if (vr[k] == 2) m->stop_at = v[k];
        else return refuse(m, "fmi2SetReal", vr[k]);
    }
    return fmi2OK;
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    Model *m = c;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] == 10 || vr[k] == 11) v[k] = m->i[vr[k] - 10];
        else if (vr[k] == 30 || vr[k] == 31) v[k] = m->e[vr[k] - 30];
        else return refuse(m, "fmi2GetInteger", vr[k]);
    }
    return fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    Model *m = c;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] == 10) m->i[0] = v[k];
        else if (vr[k] == 30) m->e[0] = v[k];
        else return refuse(m, "fmi2SetInteger", vr[k]);
    }
    return fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    Model *m = c;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] == 20 || vr[k] == 21) v[k] = m->b[vr[k] - 20];
        else return refuse(m, "fmi2GetBoolean", vr[k]);
    }
    return fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    Model *m = c;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] == 20) m->b[0] = v[k];
        else return refuse(m, "fmi2SetBoolean", vr[k]);
    }
    return fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    for (size_t k = 0; k < n; k++) { if (vr[k] != 40) return fmi2Error; v[k] = "text"; }
    (void)c; return fmi2OK;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)c; (void)v;
    for (size_t k = 0; k < n; k++) if (vr[k] != 40) return fmi2Error;
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    Model *m = c;
    (void)noSetPrior;
    follow_inputs(m);
    if (t + h >= m->stop_at - 1e-9 * h) {
        m->time = m->last = m->stop_at < t + h ? m->stop_at : t + h;
        m->terminated = fmi2True;
        m->cb.logger(m->cb.componentEnvironment, m->name, fmi2OK, "logEvents", "stop_at reached at t = %g", m->time);
        return fmi2Discard;
    }
    m->time = m->last = t + h;
    return fmi2OK;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v) {
    if (k != fmi2Terminated) return fmi2Error;
    *v = ((Model *)c)->terminated;
    return fmi2OK;
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v) {
    if (k != fmi2LastSuccessfulTime) return fmi2Error;
    *v = ((Model *)c)->last;
    return fmi2OK;
}

fmi2Status fmi2EnterEventMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    Model *m = c;
    follow_inputs(m);
    info->newDiscreteStatesNeeded = info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    info->terminateSimulation = m->time >= m->stop_at;
    info->nextEventTimeDefined = m->stop_at < 1e300 && m->time < m->stop_at;
    info->nextEventTime = m->stop_at;
    return fmi2OK;
}
fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetPrior, fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation) {
    (void)c; (void)noSetPrior;
    *enterEventMode = *terminateSimulation = fmi2False;
    return fmi2OK;
}
fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) { ((Model *)c)->time = time; return fmi2OK; }
/* No continuous states and no event indicators: the state functions take empty arrays. */
#define EMPTY(NAME, CONST) \
fmi2Status NAME(fmi2Component c, CONST fmi2Real v[], size_t n) { (void)c; (void)v; return n ? fmi2Error : fmi2OK; }
EMPTY(fmi2SetContinuousStates, const)
EMPTY(fmi2GetContinuousStates, )
EMPTY(fmi2GetDerivatives, )
EMPTY(fmi2GetEventIndicators, )
EMPTY(fmi2GetNominalsOfContinuousStates, )
