/* An FMI 3.0 FMU with a port of every numeric FMI 3 type, for the conformance tests, for
 * co-simulation and model exchange (built with fmi3_unsupported.c, -DTYPED_ACCESSORS and
 * -DMODEL_EXCHANGE).
 *
 * Each output copies its input of the same type: at initialisation (so initial outputs
 * follow inputs set in initialization mode) and in every doStep (the inputs of the step's
 * start), or in model exchange at every event (the importer's, when it sets new inputs).
 * f_out has the alias f_alias; m_out (2x2) is f_in * [[1, 2], [3, 4]]. The step that
 * reaches the parameter stop_at sets terminateSimulation, lastSuccessfulTime stop_at; in
 * model exchange stop_at is a time event, at which the FMU asks to terminate. No
 * continuous states, no event indicators.
 *
 * Value references: Float64 f_in 0, f_out 1, stop_at 2, m_out 3 (4 values), time_out 4;
 * UInt64 u64_offset 5;
 * then input/output pairs Float32 10/11, Int8 12/13, UInt8 14/15, Int16 16/17,
 * UInt16 18/19, Int32 20/21, UInt32 22/23, Int64 24/25, UInt64 26/27, Boolean 28/29,
 * Enumeration 30/31 (through the Int64 functions); Binary bin_in 40; Clock tick 50.
 */
#include <stdlib.h>
#include <string.h>
#include "fmi3Functions.h"

#define TOKEN "{9a3e5c1d-2b7f-4e1a-8c6d-4f0b2a9e3003}"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3Float64 f[2], stop_at, time;
    fmi3Float32 f32[2];
    fmi3Int8 i8[2];
    fmi3UInt8 u8[2];
    fmi3Int16 i16[2];
    fmi3UInt16 u16[2];
    fmi3Int32 i32[2];
    fmi3UInt32 u32[2];
    fmi3Int64 i64[2], e[2];
    fmi3UInt64 u64[2], u64_offset;
    fmi3Boolean b[2];
} Model;

static void set_defaults(Model *m) {
    memset(m->f, 0, sizeof m->f);
    m->stop_at = 1e300; m->time = 0.0;
    m->f32[0] = m->f32[1] = 0; m->i8[0] = m->i8[1] = 0; m->u8[0] = m->u8[1] = 0;
    m->i16[0] = m->i16[1] = 0; m->u16[0] = m->u16[1] = 0; m->i32[0] = m->i32[1] = 0;
    m->u32[0] = m->u32[1] = 0; m->i64[0] = m->i64[1] = 0; m->u64[0] = m->u64[1] = 0;
    m->u64_offset = 0;
    m->b[0] = m->b[1] = fmi3False; m->e[0] = m->e[1] = 1;
}

static void follow_inputs(Model *m) {
    m->f[1] = m->f[0]; m->f32[1] = m->f32[0]; m->i8[1] = m->i8[0]; m->u8[1] = m->u8[0];
    m->i16[1] = m->i16[0]; m->u16[1] = m->u16[0]; m->i32[1] = m->i32[0]; m->u32[1] = m->u32[0];
    m->i64[1] = m->i64[0]; m->u64[1] = m->u64[0] + m->u64_offset; m->b[1] = m->b[0]; m->e[1] = m->e[0];
}

static fmi3Status refuse(Model *m, fmi3ValueReference vr) {
    if (m->log) m->log(m->env, fmi3Error, "logStatusError", "no such value reference for this type");
    (void)vr;
    return fmi3Error;
}

/* Get and set for a type with one input/output pair at value references IN and IN + 1. */
#define PAIR(NAME, CTYPE, FIELD, IN) \
fmi3Status fmi3Get##NAME(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, CTYPE v[], size_t nv) { \
    Model *m = i; \
    if (nvr != nv) return fmi3Error; \
    for (size_t k = 0; k < nvr; k++) { \
        if (vr[k] == IN || vr[k] == IN + 1) v[k] = m->FIELD[vr[k] - IN]; else return refuse(m, vr[k]); \
    } \
    return fmi3OK; \
} \
fmi3Status fmi3Set##NAME(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const CTYPE v[], size_t nv) { \
    Model *m = i; \
    if (nvr != nv) return fmi3Error; \
    for (size_t k = 0; k < nvr; k++) { if (vr[k] == IN) m->FIELD[0] = v[k]; else return refuse(m, vr[k]); } \
    return fmi3OK; \
}

PAIR(Float32, fmi3Float32, f32, 10)
PAIR(Int8, fmi3Int8, i8, 12)
PAIR(UInt8, fmi3UInt8, u8, 14)
PAIR(Int16, fmi3Int16, i16, 16)
PAIR(UInt16, fmi3UInt16, u16, 18)
PAIR(Int32, fmi3Int32, i32, 20)
PAIR(UInt32, fmi3UInt32, u32, 22)
PAIR(Boolean, fmi3Boolean, b, 28)

fmi3Status fmi3GetInt64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Int64 v[], size_t nv) {
    Model *m = i;
    if (nvr != nv) return fmi3Error;
    for (size_t k = 0; k < nvr; k++) {
        if (vr[k] == 24 || vr[k] == 25) v[k] = m->i64[vr[k] - 24];
        else if (vr[k] == 30 || vr[k] == 31) v[k] = m->e[vr[k] - 30];
        else return refuse(m, vr[k]);
    }
    return fmi3OK;
}
fmi3Status fmi3SetInt64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Int64 v[], size_t nv) {
    Model *m = i;
    if (nvr != nv) return fmi3Error;
    for (size_t k = 0; k < nvr; k++) {
        if (vr[k] == 24) m->i64[0] = v[k];
        else if (vr[k] == 30) m->e[0] = v[k];
        else return refuse(m, vr[k]);
    }
    return fmi3OK;
}

fmi3Status fmi3GetUInt64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 v[], size_t nv) {
    Model *m = i;
    if (nvr != nv) return fmi3Error;
    for (size_t k = 0; k < nvr; k++) {
        if (vr[k] == 26 || vr[k] == 27) v[k] = m->u64[vr[k] - 26];
        else if (vr[k] == 5) v[k] = m->u64_offset;
        else return refuse(m, vr[k]);
    }
    return fmi3OK;
}
fmi3Status fmi3SetUInt64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3UInt64 v[], size_t nv) {
    Model *m = i;
    if (nvr != nv) return fmi3Error;
    for (size_t k = 0; k < nvr; k++) {
        if (vr[k] == 26) m->u64[0] = v[k];
        else if (vr[k] == 5) m->u64_offset = v[k];
        else return refuse(m, vr[k]);
    }
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 v[], size_t nv) {
    Model *m = i;
    size_t k = 0;
    for (size_t j = 0; j < nvr; j++) {
        switch (vr[j]) {
        case 0: case 1: if (k < nv) v[k++] = m->f[vr[j]]; break;
        case 2: if (k < nv) v[k++] = m->stop_at; break;
        case 3: if (k + 3 < nv) { for (int e = 1; e <= 4; e++) v[k++] = e * m->f[1]; } else return fmi3Error; break;
        case 4: if (k < nv) v[k++] = m->time; break;
        default: return refuse(m, vr[j]);
        }
    }
    return k == nv ? fmi3OK : fmi3Error;
}
fmi3Status fmi3SetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 v[], size_t nv) {
    Model *m = i;
    if (nvr != nv) return fmi3Error;
    for (size_t k = 0; k < nvr; k++) {
        if (vr[k] == 0) m->f[0] = v[k];
        else if (vr[k] == 2) m->stop_at = v[k];
        else return refuse(m, vr[k]);
    }
    return fmi3OK;
}
fmi3Status fmi3GetBinary(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, size_t sizes[],
                         fmi3Binary v[], size_t nv) {
    static const fmi3Byte data[1] = {0};
    (void)i;
    if (nvr != nv) return fmi3Error;
    for (size_t k = 0; k < nvr; k++) { if (vr[k] != 40) return fmi3Error; sizes[k] = 1; v[k] = data; }
    return fmi3OK;
}
fmi3Status fmi3SetBinary(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const size_t sizes[],
                         const fmi3Binary v[], size_t nv) {
    (void)i; (void)sizes; (void)v;
    if (nvr != nv) return fmi3Error;
    for (size_t k = 0; k < nvr; k++) if (vr[k] != 40) return fmi3Error;
    return fmi3OK;
}

const char *fmi3GetVersion(void) { return fmi3Version; }
fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean on, size_t n, const fmi3String c[]) {
    (void)i; (void)on; (void)n; (void)c; return fmi3OK;
}

/* A new instance, for either interface (NULL for the wrong token). */
static Model *new_model(fmi3String token, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    if (strcmp(token, TOKEN) != 0) return NULL;
    Model *m = calloc(1, sizeof(Model));
    m->env = env;
    m->log = log;
    set_defaults(m);
    return m;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
        fmi3Boolean earlyReturnAllowed, const fmi3ValueReference required[], size_t nRequired,
        fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
        fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)name; (void)resources; (void)visible; (void)loggingOn; (void)eventModeUsed;
    (void)earlyReturnAllowed; (void)required; (void)nRequired; (void)intermediateUpdate;
    return new_model(token, env, log);
}

void fmi3FreeInstance(fmi3Instance i) { free(i); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance i, fmi3Boolean tolDef, fmi3Float64 tol,
        fmi3Float64 start, fmi3Boolean stopDef, fmi3Float64 stop) {
    (void)tolDef; (void)tol; (void)stopDef; (void)stop;
    ((Model *)i)->time = start;
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance i) { follow_inputs(i); return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance i) { set_defaults(i); return fmi3OK; }

fmi3Status fmi3DoStep(fmi3Instance i, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    Model *m = i;
    (void)noSetPrior;
    *eventHandlingNeeded = fmi3False;
    *earlyReturn = fmi3False;
    follow_inputs(m);
    *terminateSimulation = t + h >= m->stop_at - 1e-9 * h;
    m->time = *terminateSimulation && m->stop_at < t + h ? m->stop_at : t + h;
    *lastSuccessfulTime = m->time;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    (void)name; (void)resources; (void)visible; (void)loggingOn;
    return new_model(token, env, log);
}

fmi3Status fmi3EnterEventMode(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance i, fmi3Boolean *again, fmi3Boolean *terminate,
        fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined,
        fmi3Float64 *nextTime) {
    Model *m = i;
    follow_inputs(m);
    *again = *nominalsChanged = *valuesChanged = fmi3False;
    *terminate = m->time >= m->stop_at;
    *nextDefined = m->stop_at < 1e300 && m->time < m->stop_at;
    *nextTime = m->stop_at;
    return fmi3OK;
}
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance i, fmi3Boolean noSetPrior, fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation) {
    (void)i; (void)noSetPrior;
    *enterEventMode = *terminateSimulation = fmi3False;
    return fmi3OK;
}
fmi3Status fmi3SetTime(fmi3Instance i, fmi3Float64 time) { ((Model *)i)->time = time; return fmi3OK; }
/* No continuous states and no event indicators: the state functions take empty arrays. */
#define EMPTY(NAME, CONST) \
fmi3Status NAME(fmi3Instance i, CONST fmi3Float64 v[], size_t n) { (void)i; (void)v; return n ? fmi3Error : fmi3OK; }
EMPTY(fmi3SetContinuousStates, const)
EMPTY(fmi3GetContinuousStates, )
EMPTY(fmi3GetContinuousStateDerivatives, )
EMPTY(fmi3GetEventIndicators, )
EMPTY(fmi3GetNominalsOfContinuousStates, )
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance i, size_t *n) { (void)i; *n = 0; return fmi3OK; }
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance i, size_t *n) { (void)i; *n = 0; return fmi3OK; }
