/* A scheduled-execution FMU with the clock kinds of the Modelica Association's Reference
 * FMU 'Clocks' (Reference-FMUs/Clocks/model.c), whose partitions do what that one's do:
 *
 *     inClock1  input, constant, every 1 s, priority 0: inClock1Ticks++, totalInClockTicks++;
 *               at t = 4 s it sets the countdown clock inClock3's interval to 0 (activate it now)
 *     inClock2  input, triggered, priority 1: inClock2Ticks++, totalInClockTicks++,
 *               result2 += input2, input2 = 0
 *     inClock3  input, countdown, priority 2: inClock3Ticks++, totalInClockTicks++, output3 = 1000
 *     outClock  output, triggered by every input clock: it ticks when totalInClockTicks is a
 *               multiple of 5 (and did not tick at the activation before)
 *
 * A partition that sets outClock or inClock3's interval calls clockUpdate, and partitions 2
 * and 3 lock preemption around the counters they share, as the Reference FMU does. Value
 * references: inClock1 1001, inClock2 1002, inClock3 1003, outClock 1005, inClock1Ticks
 * 2001, inClock2Ticks 2002, inClock3Ticks 2003, totalInClockTicks 2004, result2 2005,
 * input2 2006, output3 2007 (Int32), time 0. Built with SCHEDULED_EXECUTION and
 * NO_CO_SIMULATION beside fmi3_unsupported.c.
 */
#include <stdlib.h>
#include <string.h>
#include "fmi3Functions.h"

#define TOKEN "{c10c4500-5e1e-4d2a-9c3a-000000003003}"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3ClockUpdateCallback clock_update;
    fmi3LockPreemptionCallback lock;
    fmi3UnlockPreemptionCallback unlock;
    double time, in3_interval;
    int in3_qualifier, out_clock;
    fmi3Int32 ticks1, ticks2, ticks3, total, result2, input2, output3;
} Model;

static void reset(Model *m) {
    m->time = 0.0; m->in3_interval = 0.0; m->in3_qualifier = fmi3IntervalNotYetKnown; m->out_clock = 0;
    m->ticks1 = m->ticks2 = m->ticks3 = m->total = m->result2 = m->input2 = m->output3 = 0;
}

static fmi3Status error(Model *m, const char *text) {
    if (m->log) m->log(m->env, fmi3Error, "logStatusError", text);
    return fmi3Error;
}

const char *fmi3GetVersion(void) { return fmi3Version; }
fmi3Status fmi3SetDebugLogging(fmi3Instance i, fmi3Boolean on, size_t n, const fmi3String c[]) {
    (void)i; (void)on; (void)n; (void)c; return fmi3OK;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
        fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
        fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    (void)name; (void)resources; (void)visible; (void)loggingOn;
    if (strcmp(token, TOKEN) != 0) {
        if (log) log(env, fmi3Error, "logStatusError", "wrong instantiation token");
        return NULL;
    }
    Model *m = calloc(1, sizeof(Model));
    m->env = env; m->log = log; m->clock_update = clockUpdate; m->lock = lock; m->unlock = unlock;
    reset(m);
    return m;
}

void fmi3FreeInstance(fmi3Instance i) { free(i); }
fmi3Status fmi3EnterInitializationMode(fmi3Instance i, fmi3Boolean td, fmi3Float64 tol, fmi3Float64 start,
        fmi3Boolean sd, fmi3Float64 stop) {
    (void)td; (void)tol; (void)sd; (void)stop; ((Model *)i)->time = start; return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance i) { reset((Model *)i); return fmi3OK; }

/* outClock after an activation, and clockUpdate when it ticks or inClock3 has an interval */
static void settle(Model *m) {
    m->out_clock = !m->out_clock && m->total % 5 == 0;
    if ((m->out_clock || m->in3_qualifier == fmi3IntervalChanged) && m->clock_update)
        m->clock_update(m->env);
}

static void locked(Model *m, int on) {
    if (on && m->lock) m->lock();
    if (!on && m->unlock) m->unlock();
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance i, fmi3ValueReference clock, fmi3Float64 t) {
    Model *m = i;
    m->time = t;
    switch (clock) {
    case 1001:
        m->ticks1++; m->total++;
        if ((int)t == 4) { m->in3_qualifier = fmi3IntervalChanged; m->in3_interval = 0.0; }
        break;
    case 1002:
        locked(m, 1);
        m->ticks2++; m->total++; m->result2 += m->input2; m->input2 = 0;
        locked(m, 0);
        break;
    case 1003:
        m->ticks3++; m->output3 = 1000;
        locked(m, 1);
        m->total++;
        locked(m, 0);
        break;
    default:
        return error(m, "not an input clock");
    }
    settle(m);
    return fmi3OK;
}

fmi3Status fmi3GetClock(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3Clock values[]) {
    Model *m = i;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] != 1005) return error(m, "only outClock can be read");
        values[k] = m->out_clock;
        m->out_clock = 0; /* reported once */
    }
    return fmi3OK;
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3Float64 intervals[],
        fmi3IntervalQualifier qualifiers[]) {
    Model *m = i;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] != 1003) return error(m, "only inClock3 has an interval to get");
        qualifiers[k] = (fmi3IntervalQualifier)m->in3_qualifier;
        intervals[k] = m->in3_interval;
        if (m->in3_qualifier == fmi3IntervalChanged) m->in3_qualifier = fmi3IntervalUnchanged;
    }
    return fmi3OK;
}

static fmi3Int32 *int32_of(Model *m, fmi3ValueReference vr) {
    switch (vr) {
    case 2001: return &m->ticks1;
    case 2002: return &m->ticks2;
    case 2003: return &m->ticks3;
    case 2004: return &m->total;
    case 2005: return &m->result2;
    case 2006: return &m->input2;
    case 2007: return &m->output3;
    default: return NULL;
    }
}

fmi3Status fmi3GetInt32(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3Int32 v[], size_t nv) {
    (void)nv;
    for (size_t k = 0; k < n; k++) {
        fmi3Int32 *p = int32_of(i, vr[k]);
        if (p == NULL) return error(i, "no such Int32 variable");
        v[k] = *p;
    }
    return fmi3OK;
}

fmi3Status fmi3SetInt32(fmi3Instance i, const fmi3ValueReference vr[], size_t n, const fmi3Int32 v[], size_t nv) {
    (void)nv;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] != 2006) return error(i, "only input2 can be set");
        ((Model *)i)->input2 = v[k];
    }
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t n, fmi3Float64 v[], size_t nv) {
    (void)nv;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] != 0) return error(i, "no such Float64 variable");
        v[k] = ((Model *)i)->time;
    }
    return fmi3OK;
}

#define NONE_OF(TYPE, NAME, CONST)                                                                             \
    fmi3Status NAME(fmi3Instance i, const fmi3ValueReference vr[], size_t n, CONST TYPE v[], size_t nv) {   \
        (void)vr; (void)v; (void)nv;                                                                          \
        return n == 0 ? fmi3OK : error(i, "no such variable");                                                 \
    }
NONE_OF(fmi3Float64, fmi3SetFloat64, const)
NONE_OF(fmi3Float32, fmi3GetFloat32, )
NONE_OF(fmi3Boolean, fmi3GetBoolean, )
NONE_OF(fmi3Boolean, fmi3SetBoolean, const)
