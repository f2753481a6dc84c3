/* A tiny FMI 2.0 co-simulation FMU for the tests of the FMU block.
 *
 * Discrete first-order system, one step per communication step:
 *     x[k+1] = a x[k] + b u[k]   (x held when 'frozen'),   x[0] = x0
 *     y = x,   z[1] = scale * x,   z[2] = the FMU's current time
 * doStep returns fmi2Error (and logs why) when u > threshold, fmi2Discard when u < -threshold.
 *
 * Value references: a 0, b 1, x0 2, threshold 3, scale 4 (Integer), frozen 5 (Boolean),
 * u 6, y 7, z[1] 8, z[2] 9.
 * Built with FAIL_SET_AT (FAIL_GET_AT), setting u (getting y) fails with fmi2Error, logged,
 * once the FMU's time has reached that value. Built with MISBEHAVE (and misbehave.c), it
 * misbehaves as its resources/misbehave.txt says (misbehave.h). Built with INTERNAL_STEP, doStep refuses
 * (fmi2Error, logged) a communication step that is not a whole multiple of it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fmi2Functions.h"
#include "misbehave.h"

#ifdef TRACE_RUNS
void trace_run(const char *event); /* marker.c: leaves a file saying the code ran */
#endif
#ifdef SIGINT_AT
#include <signal.h> /* Ctrl-C inside doStep at t >= SIGINT_AT, then a log message, then SIGINT_STATUS */
#endif

#define GUID "{8c4e810f-3df3-4a00-8276-176fa3c9f000}"
#define NREAL 10

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    fmi2Real r[NREAL];   /* reals by value reference (4 and 5 unused) */
    fmi2Integer scale;
    fmi2Boolean frozen;
    fmi2Real x, time;
} Model;

static void set_defaults(Model *m) {
    memset(m->r, 0, sizeof(m->r));
    m->r[0] = 0.5; m->r[1] = 1.0; m->r[2] = 0.0; m->r[3] = 100.0;
    m->scale = 1; m->frozen = fmi2False;
    m->x = 0.0; m->time = 0.0;
}

static void outputs(Model *m) {
    m->r[7] = m->x;
    m->r[8] = m->scale * m->x;
    m->r[9] = m->time;
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
#ifdef TRACE_RUNS
    trace_run("instantiated");
#endif
    if (type != fmi2CoSimulation || strcmp(guid, GUID) != 0) {
        if (cb && cb->logger) cb->logger(cb->componentEnvironment, name, fmi2Error, "logStatusError",
                                         "wrong FMU type or GUID %s", guid);
        return NULL;
    }
    Model *m = calloc(1, sizeof(Model));
    m->cb = *cb;
    m->name = strdup(name);
    set_defaults(m);
    outputs(m);
    return m;
}

void fmi2FreeInstance(fmi2Component c) {
    Model *m = c;
    MISBEHAVE_AT("fmi2FreeInstance", 0.0);
    if (!m) return;
    free(m->name);
    free(m);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDef, fmi2Real stop) {
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    MISBEHAVE_AT("fmi2SetupExperiment", start);
    ((Model *)c)->time = start;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    MISBEHAVE_AT("fmi2EnterInitializationMode", ((Model *)c)->time);
    return fmi2OK;
}
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Model *m = c;
    MISBEHAVE_AT("fmi2ExitInitializationMode", m->time);
    m->x = m->r[2];
    outputs(m);
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component c) {
    MISBEHAVE_AT("fmi2Terminate", ((Model *)c)->time);
    return fmi2OK;
}
fmi2Status fmi2Reset(fmi2Component c) { set_defaults((Model *)c); outputs((Model *)c); return fmi2OK; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    Model *m = c;
    MISBEHAVE_AT("fmi2GetReal", m->time);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= NREAL) return fmi2Error;
#ifdef FAIL_GET_AT
        if (vr[i] == 7 && m->time >= FAIL_GET_AT) {
            m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError", "cannot get y at t = %g",
                         m->time);
            return fmi2Error;
        }
#endif
        v[i] = m->r[vr[i]];
    }
    return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    Model *m = c;
    MISBEHAVE_AT("fmi2SetReal", m->time);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] > 6 || vr[i] == 4 || vr[i] == 5) {
            m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError",
                         "cannot set value reference %u", vr[i]);
            return fmi2Error;
        }
#ifdef FAIL_SET_AT
        if (vr[i] == 6 && m->time >= FAIL_SET_AT) {
            m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError", "cannot set u at t = %g",
                         m->time);
            return fmi2Error;
        }
#endif
        m->r[vr[i]] = v[i];
    }
    return fmi2OK;
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    for (size_t i = 0; i < n; i++) { if (vr[i] != 4) return fmi2Error; v[i] = ((Model *)c)->scale; }
    return fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    for (size_t i = 0; i < n; i++) { if (vr[i] != 4) return fmi2Error; ((Model *)c)->scale = v[i]; }
    return fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    for (size_t i = 0; i < n; i++) { if (vr[i] != 5) return fmi2Error; v[i] = ((Model *)c)->frozen; }
    return fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    for (size_t i = 0; i < n; i++) { if (vr[i] != 5) return fmi2Error; ((Model *)c)->frozen = v[i]; }
    return fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)c; (void)vr; (void)n; (void)v; return fmi2Error;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)c; (void)vr; (void)n; (void)v; return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    Model *m = c;
    (void)noSetPrior;
    MISBEHAVE_AT("fmi2DoStep", t);
    fmi2Real u = m->r[6], threshold = m->r[3];
#ifdef SIGINT_AT
    if (t >= SIGINT_AT) {
        raise(SIGINT);
        m->cb.logger(m->cb.componentEnvironment, m->name, fmi2OK, "logEvents", "interrupted at t = %g", t);
        if (SIGINT_STATUS != fmi2OK) return SIGINT_STATUS;
    }
#endif
#ifdef INTERNAL_STEP
    double steps = h / INTERNAL_STEP;
    if (steps < 0.5 || fabs(steps - floor(steps + 0.5)) > 1e-9 * steps) {
        m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError",
                     "the step %g s is not a whole multiple of the internal step %g s", h, INTERNAL_STEP);
        return fmi2Error;
    }
#endif
    if (u > threshold) {
        m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError",
                     "input u = %g exceeds the threshold %g at t = %g", u, threshold, t);
        return fmi2Error;
    }
    if (u < -threshold) {
        m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Discard, "logStatusDiscard",
                     "input u = %g is below -threshold at t = %g; step discarded", u, t);
        return fmi2Discard;
    }
    if (!m->frozen) m->x = m->r[0] * m->x + m->r[1] * u;
    m->time = t + h;
    outputs(m);
    return fmi2OK;
}
