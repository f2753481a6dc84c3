/* The FMI 3.0 twin of first_order_fmi2.c, with arrays.
 *
 *     x[k+1] = a x[k] + b u[k]   (x held when 'frozen'),   x[0] = x0
 *     y = x,   z = [scale * x, time] (an array output),   yf = (float32) x,
 *     wsum = w[1] + w[2] of the input array w used in the last step
 * doStep returns fmi3Error (and logs why) when u > threshold.
 *
 * Value references: a 0, b 1, x0 2, threshold 3, scale 4 (Int32), frozen 5 (Boolean),
 * u 6, y 7, z 8 (2 values), w 10 (2 values), wsum 11, yf 12 (Float32).
 * Built with MISBEHAVE (and misbehave.c), it misbehaves as its resources/misbehave.txt
 * says (misbehave.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fmi3Functions.h"
#include "misbehave.h"

#define TOKEN "{3f1c7d52-41a6-4f7e-9a55-0c3b3b6f0003}"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3Float64 a, b, x0, threshold, u, w[2], wsum, x, time;
    fmi3Int32 scale;
    fmi3Boolean frozen;
} Model;

static void set_defaults(Model *m) {
    m->a = 0.5; m->b = 1.0; m->x0 = 0.0; m->threshold = 100.0; m->u = 0.0;
    m->w[0] = m->w[1] = 0.0; m->wsum = 0.0; m->x = 0.0; m->time = 0.0;
    m->scale = 1; m->frozen = fmi3False;
}

static void say(Model *m, fmi3Status status, const char *category, const char *text) {
    if (m->log) m->log(m->env, status, category, text);
}

const char *fmi3GetVersion(void) { return fmi3Version; }
fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean on, size_t n, const fmi3String c[]) {
    (void)i; (void)on; (void)n; (void)c; return fmi3OK;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
        fmi3Boolean earlyReturnAllowed, const fmi3ValueReference required[], size_t nRequired,
        fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
        fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)name; (void)resources; (void)visible; (void)loggingOn; (void)eventModeUsed;
    (void)earlyReturnAllowed; (void)required; (void)nRequired; (void)intermediateUpdate;
    MISBEHAVE_SETUP(resources);
    MISBEHAVE_AT("fmi3InstantiateCoSimulation", 0.0);
    if (strcmp(token, TOKEN) != 0) {
        if (log) log(env, fmi3Error, "logStatusError", "wrong instantiation token");
        return NULL;
    }
    Model *m = calloc(1, sizeof(Model));
    m->env = env;
    m->log = log;
    set_defaults(m);
    return m;
}

void fmi3FreeInstance(fmi3Instance i) { MISBEHAVE_AT("fmi3FreeInstance", 0.0); free(i); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance i, fmi3Boolean tolDef, fmi3Float64 tol,
        fmi3Float64 start, fmi3Boolean stopDef, fmi3Float64 stop) {
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    MISBEHAVE_AT("fmi3EnterInitializationMode", start);
    ((Model *)i)->time = start;
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance i) {
    Model *m = i;
    MISBEHAVE_AT("fmi3ExitInitializationMode", m->time);
    m->x = m->x0;
    return fmi3OK;
}
fmi3Status fmi3Terminate(fmi3Instance i) { MISBEHAVE_AT("fmi3Terminate", ((Model *)i)->time); return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance i) { set_defaults((Model *)i); return fmi3OK; }

fmi3Status fmi3GetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Float64 v[], size_t nv) {
    Model *m = i;
    MISBEHAVE_AT("fmi3GetFloat64", m->time);
    size_t k = 0;
    for (size_t j = 0; j < nvr; j++) {
        switch (vr[j]) {
        case 0: if (k < nv) v[k++] = m->a; break;
        case 1: if (k < nv) v[k++] = m->b; break;
        case 2: if (k < nv) v[k++] = m->x0; break;
        case 3: if (k < nv) v[k++] = m->threshold; break;
        case 6: if (k < nv) v[k++] = m->u; break;
        case 7: if (k < nv) v[k++] = m->x; break;
        case 8: if (k + 1 < nv) { v[k++] = m->scale * m->x; v[k++] = m->time; } else return fmi3Error; break;
        case 10: if (k + 1 < nv) { v[k++] = m->w[0]; v[k++] = m->w[1]; } else return fmi3Error; break;
        case 11: if (k < nv) v[k++] = m->wsum; break;
        default: return fmi3Error;
        }
    }
    return k == nv ? fmi3OK : fmi3Error;
}

fmi3Status fmi3SetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Float64 v[], size_t nv) {
    Model *m = i;
    MISBEHAVE_AT("fmi3SetFloat64", m->time);
    size_t k = 0;
    for (size_t j = 0; j < nvr; j++) {
        switch (vr[j]) {
        case 0: m->a = v[k++]; break;
        case 1: m->b = v[k++]; break;
        case 2: m->x0 = v[k++]; break;
        case 3: m->threshold = v[k++]; break;
        case 6: m->u = v[k++]; break;
        case 10: if (k + 1 < nv) { m->w[0] = v[k++]; m->w[1] = v[k++]; } else return fmi3Error; break;
        default: say(m, fmi3Error, "logStatusError", "cannot set that variable"); return fmi3Error;
        }
    }
    return k == nv ? fmi3OK : fmi3Error;
}

fmi3Status fmi3GetFloat32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Float32 v[], size_t nv) {
    if (nvr != nv) return fmi3Error;
    for (size_t j = 0; j < nvr; j++) { if (vr[j] != 12) return fmi3Error; v[j] = (fmi3Float32)((Model *)i)->x; }
    return fmi3OK;
}
fmi3Status fmi3GetInt32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Int32 v[], size_t nv) {
    if (nvr != nv) return fmi3Error;
    for (size_t j = 0; j < nvr; j++) { if (vr[j] != 4) return fmi3Error; v[j] = ((Model *)i)->scale; }
    return fmi3OK;
}
fmi3Status fmi3SetInt32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 v[], size_t nv) {
    if (nvr != nv) return fmi3Error;
    for (size_t j = 0; j < nvr; j++) { if (vr[j] != 4) return fmi3Error; ((Model *)i)->scale = v[j]; }
    return fmi3OK;
}
fmi3Status fmi3GetBoolean(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Boolean v[], size_t nv) {
    if (nvr != nv) return fmi3Error;
    for (size_t j = 0; j < nvr; j++) { if (vr[j] != 5) return fmi3Error; v[j] = ((Model *)i)->frozen; }
    return fmi3OK;
}
fmi3Status fmi3SetBoolean(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Boolean v[], size_t nv) {
    if (nvr != nv) return fmi3Error;
    for (size_t j = 0; j < nvr; j++) { if (vr[j] != 5) return fmi3Error; ((Model *)i)->frozen = v[j]; }
    return fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance i, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    Model *m = i;
    (void)noSetPrior;
    MISBEHAVE_AT("fmi3DoStep", t);
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = t;
    if (m->u > m->threshold) {
        char text[200];
        snprintf(text, sizeof text, "input u = %g exceeds the threshold %g at t = %g", m->u, m->threshold, t);
        say(m, fmi3Error, "logStatusError", text);
        return fmi3Error;
    }
    if (!m->frozen) m->x = m->a * m->x + m->b * m->u;
    m->wsum = m->w[0] + m->w[1];
    m->time = t + h;
    *lastSuccessfulTime = t + h;
    return fmi3OK;
}
