/* The FMU block's compiled step (blocks/fmu), a kernel of the op table: the steady step of
 * a co-simulation FMU whose ports are all Float64 -- set the inputs, doStep, get the
 * outputs -- through the FMU's own C functions, with no Python in between.
 *
 * Its context is one run's int64 table (FMU_* slots of fmu_step_table.h, then the ports),
 * made and filled by blocks/fmu/compiled_step.py, which binds it to the run's FMU
 * instance. The kernel keeps the FMU's time and outputs there (the values array), so it
 * writes through its context. Everything but the steady step goes to the Python side,
 * slow(kind, t, status), which does what the block's Python methods do from that point
 * on, with the same messages: the first call (taking an instance, initialising it), a step
 * at the wrong time or of a broken or ended instance, a call that returned worse than a
 * warning, a doStep that asks to terminate or returned early, and arming the interrupt
 * hook when other code replaced it. slow returns 0, or 1 when the update ended the run
 * (BLK_END_RUN); a failure is a Python exception (BLK_RAISED).
 *
 * As the Python side does around each step: before it, the interrupt hook is looked at
 * and FMI 2's log proxy re-armed; after doStep, interrupt.check() raises a Ctrl-C that an
 * FMU callback noted (blocks/fmu/interrupt.py).
 *
 * An instance hosted in a process of its own (FMU_CHANNEL, blocks/fmu/isolation/client.py)
 * steps the same way through its channel instead (hosted_step): the inputs into the
 * channel's values, one round trip (fmu_channel.c), the outputs out of them; the FMU's
 * process makes the FMI calls (fmi_step_calls.h, shared with this file). Anything but a
 * plain success goes to slow as FMU_SLOW_HOSTED, with how waiting ended.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "blocks_kernel.h"
#include "fmi_step_calls.h"
#include "fmu_block_step.h"
#include "fmu_channel.h"
#include "fmu_step_table.h"
#include "layout_names.h"

typedef void (*log_arm_fn)(void *);

#define SLOT FMU_SLOT

/* The Python side for what is not the steady step; also where the inputs are for it. */
static int slow(int64_t *c, long kind, double t, int status, const double *const *inputs)
{
    c[FMU_INPUTS] = (int64_t)(intptr_t)inputs;
    PyObject *result = PyObject_CallFunction(SLOT(c, FMU_SLOW, PyObject *), "ldi", kind, t, status);
    if (result == NULL)
        return BLK_RAISED;
    long ended = PyLong_AsLong(result);
    Py_DECREF(result);
    if (ended == -1 && PyErr_Occurred())
        return BLK_RAISED;
    return ended ? BLK_END_RUN : 0;
}

static int fmu_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                      int *which)
{
    (void)state, (void)which;
    int64_t *c = (int64_t *)(intptr_t)ctx;
    if (!c[FMU_STARTED]) {
        int code = slow(c, FMU_SLOW_OUTPUT, t, 0, inputs);
        if (code)
            return code;
    }
    memcpy(out, SLOT(c, FMU_VALUES, double *) + FMU_V_HELD, (size_t)c[FMU_WIDTH] * sizeof(double));
    return 0;
}

/* Before a step, as Instance.arm: our unraisablehook in place, FMI 2's logger re-armed. */
static int arm(int64_t *c, double t, const double *const *inputs)
{
    if (PySys_GetObject("unraisablehook") != SLOT(c, FMU_HOOK, PyObject *)) {
        int code = slow(c, FMU_SLOW_ARM, t, 0, inputs);
        if (code)
            return code;
    }
    if (c[FMU_LOG_ARM])
        SLOT(c, FMU_LOG_ARM, log_arm_fn)(SLOT(c, FMU_LOG_ARG, void *));
    return 0;
}

/* The steady step of an instance hosted in a process of its own (FMU_CHANNEL): the inputs
   into the channel, one round trip, the outputs out of it. Anything but a plain success
   (the host's answer is a message, its process ended, the call took too long, a signal
   handler raised) goes to the Python side, which says what it was. */
static int hosted_step(int64_t *c, double t, const double *const *inputs)
{
    host_channel *ch = SLOT(c, FMU_CHANNEL, host_channel *);
    double *v = SLOT(c, FMU_VALUES, double *);
    double *buf = SLOT(c, FMU_SET_BUF, double *);
    const int64_t *port = c + FMU_PORTS;
    for (int64_t i = 0; i < c[FMU_N_IN]; i++, port += 2)
        memcpy(buf + port[0], inputs[i], (size_t)port[1] * sizeof(double));
    ch->command = HOST_STEP;
    ch->t = t;
    ch->h = v[FMU_V_STEP];
    blk_host_post(ch);
    int waited = blk_host_wait(ch, (int)c[FMU_SOCKET], v[FMU_V_TIMEOUT]);
    if (waited == HOST_RAISED)
        return BLK_RAISED;
    if (waited != HOST_ANSWERED || ch->answer != HOST_DONE)
        return slow(c, FMU_SLOW_HOSTED, t, waited, inputs);
    v[FMU_V_TIME] = t + v[FMU_V_STEP];
    const double *got = SLOT(c, FMU_GET_BUF, const double *);
    double *held = v + FMU_V_HELD;
    for (int64_t i = 0; i < c[FMU_N_OUT]; i++, port += 2) {
        memcpy(held, got + port[0], (size_t)port[1] * sizeof(double));
        held += port[1];
    }
    return 0;
}

static int fmu_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)state, (void)which;
    int64_t *c = (int64_t *)(intptr_t)ctx;
    double *v = SLOT(c, FMU_VALUES, double *);
    double h = v[FMU_V_STEP];
    if (!c[FMU_READY] || fabs(t - v[FMU_V_TIME]) > 1e-9 * fmax(h, fabs(t)))
        return slow(c, FMU_SLOW_UPDATE, t, 0, inputs);
    if (c[FMU_CHANNEL])
        return hosted_step(c, t, inputs);
    int code = arm(c, t, inputs);
    if (code)
        return code;
    const int64_t *port = c + FMU_PORTS;
    int status;
    if (c[FMU_SET]) {
        double *buf = SLOT(c, FMU_SET_BUF, double *);
        for (int64_t i = 0; i < c[FMU_N_IN]; i++, port += 2)
            memcpy(buf + port[0], inputs[i], (size_t)port[1] * sizeof(double));
        status = fmu_transfer(c, FMU_SET, true);
        if (status > 1)
            return slow(c, FMU_SLOW_SET, t, status, inputs);
    }
    bool plain;
    status = fmu_do_step(c, t, h, &plain);
    if (!plain)
        return slow(c, FMU_SLOW_STEP, t, status, inputs);
    PyObject *checked = PyObject_CallNoArgs(SLOT(c, FMU_CHECK, PyObject *));
    if (checked == NULL)
        return BLK_RAISED;
    Py_DECREF(checked);
    v[FMU_V_TIME] = t + h;
    if (c[FMU_GET]) {
        status = fmu_transfer(c, FMU_GET, false);
        if (status > 1)
            return slow(c, FMU_SLOW_GET, t, status, inputs);
        const double *buf = SLOT(c, FMU_GET_BUF, const double *);
        double *held = v + FMU_V_HELD;
        port = c + FMU_PORTS + 2 * c[FMU_N_IN];
        for (int64_t i = 0; i < c[FMU_N_OUT]; i++, port += 2) {
            memcpy(held, buf + port[0], (size_t)port[1] * sizeof(double));
            held += port[1];
        }
    }
    return 0;
}

static const named slots[] = {
    {"slow", FMU_SLOW}, {"check", FMU_CHECK}, {"hook", FMU_HOOK}, {"log_arm", FMU_LOG_ARM}, {"log_arg", FMU_LOG_ARG},
    {"values", FMU_VALUES}, {"inputs", FMU_INPUTS}, {"width", FMU_WIDTH}, {"started", FMU_STARTED},
    {"ready", FMU_READY}, {"version", FMU_VERSION}, {"component", FMU_COMPONENT}, {"set", FMU_SET},
    {"set_vrs", FMU_SET_VRS}, {"set_nvr", FMU_SET_NVR}, {"set_buf", FMU_SET_BUF}, {"set_count", FMU_SET_COUNT},
    {"do_step", FMU_DO_STEP}, {"get", FMU_GET}, {"get_vrs", FMU_GET_VRS}, {"get_nvr", FMU_GET_NVR},
    {"get_buf", FMU_GET_BUF}, {"get_count", FMU_GET_COUNT}, {"flags", FMU_FLAGS}, {"n_in", FMU_N_IN},
    {"n_out", FMU_N_OUT}, {"channel", FMU_CHANNEL}, {"socket", FMU_SOCKET}, {"trace", FMU_TRACE},
    {"trace_set", FMU_TRACE_SET}, {"trace_step", FMU_TRACE_STEP}, {"trace_get", FMU_TRACE_GET},
    {"ports", FMU_PORTS}, {NULL, 0}};
static const named values[] = {
    {"time", FMU_V_TIME}, {"step", FMU_V_STEP}, {"timeout", FMU_V_TIMEOUT}, {"held", FMU_V_HELD}, {NULL, 0}};
static const named kinds[] = {{"output", FMU_SLOW_OUTPUT}, {"update", FMU_SLOW_UPDATE}, {"arm", FMU_SLOW_ARM},
                              {"set", FMU_SLOW_SET}, {"step", FMU_SLOW_STEP}, {"get", FMU_SLOW_GET},
                              {"hosted", FMU_SLOW_HOSTED}, {NULL, 0}};

PyObject *blk_fmu_block_step(void)
{
    return Py_BuildValue("{s:N,s:N,s:N,s:N,s:N}", "output", PyLong_FromVoidPtr((void *)fmu_output), "update",
                         PyLong_FromVoidPtr((void *)fmu_update), "slots", blk_names(slots), "values", blk_names(values),
                         "kinds", blk_names(kinds));
}
