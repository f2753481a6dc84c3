/* The hooks through which the core (core.h) calls back into a Run (native_run.h):
 *
 * - call: a Python block's op (native_python_blocks.c).
 * - end: a kernel's request to end the run is its error factory's EndRun (another
 *   exception fails the update); a Python block's is the EndRun it raised.
 * - gil: the GIL is released over the ops whose kernels say they may run without it
 *   (Kernel.nogil), so that threads running diagrams run in parallel, and held for the
 *   others (the FMU block's step calls back into Python), for Python blocks and for the
 *   checks.
 * - poll: between events and between the chunks of an advance, Ctrl-C is looked for on
 *   the thread that handles signals (PyErr_CheckSignals does nothing elsewhere, so there
 *   the checks are skipped and a stretch of nogil ops runs released throughout), taking
 *   the GIL back for it; every 256 polls, the progress callback. That thread releases the
 *   GIL only while another thread exists (one with a Python thread state) that could
 *   take it, looked at again at each check.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>

#include "native_run.h"

static int hook_call(void *host, int64_t op, int64_t tick, double t, int n, double *rows, int *done, int *which)
{
    (void)tick, (void)rows, (void)which;
    return run_python_op(host, op, t, n, done);
}

static void hook_gil(void *host, int needed)
{
    gil *g = &((RunObject *)host)->g;
    if (needed)
        run_gil_hold(g);
    else if (g->saved == NULL && g->release)
        g->saved = PyEval_SaveThread();
}

static int hook_poll(void *host, int64_t reached)
{
    RunObject *r = host;
    r->polls++;
    if (r->g.signals) {
        run_gil_hold(&r->g);
        if (PyErr_CheckSignals() != 0) {
            run_keep_raised(r);
            return 1;
        }
        r->g.release = run_other_threads();
    }
    if (r->progress != Py_None && (r->polls & 255) == 0) {
        run_gil_hold(&r->g);
        PyObject *done = PyObject_CallFunction(r->progress, "L", (long long)reached);
        if (done == NULL) {
            run_keep_raised(r);
            return 1;
        }
        Py_DECREF(done);
    }
    return 0;
}

static int hook_end(void *host, int64_t op, int which, int64_t tick)
{
    RunObject *r = host;
    run_gil_hold(&r->g);
    int64_t block = r->table.ops[op * BLK_OP_N + BLK_OP_A];
    PyObject *end;
    if (r->python[block].output != NULL) {
        end = r->python[block].ended;
        r->python[block].ended = NULL;
        if (end == NULL) {
            PyErr_SetString(PyExc_SystemError, "a Python block asked to end the run without an EndRun");
            run_keep_raised(r);
            return 1;
        }
    } else {
        end = PyObject_CallMethod(r->side, "kernel_end", "niL", (Py_ssize_t)block, which, (long long)tick);
        if (end == NULL) {
            run_keep_raised(r);
            return 1;
        }
    }
    int is_end = end != NULL ? PyObject_IsInstance(end, r->end_run) : 0;
    if (is_end == 1) {
        if (r->end_reason == NULL)
            r->end_reason = end;
        else
            Py_DECREF(end);
        return 0;
    }
    if (is_end < 0) {
        Py_XDECREF(end);
        run_keep_raised(r);
        return 1;
    }
    if (r->raised == NULL)
        r->raised = end;
    else
        Py_XDECREF(end);
    return 1;
}

blk_hooks run_hooks(RunObject *r)
{
    return (blk_hooks){r, hook_call, hook_gil, hook_poll, hook_end};
}
