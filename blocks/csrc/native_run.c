/* The type blocks._native.Run (native_run.h): Run(...) binds one run of an op table, run()
 * interprets it once through the core (blk_run_table) and says how it went, and the
 * object's end releases what it held. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>

#include "native_run.h"

static int run_init(RunObject *r, PyObject *args, PyObject *kwds)
{
    PyObject *tables, *arena, *logs, *counters, *kernels, *python, *states, *side, *progress = Py_None;
    int allow_nonfinite = 0;
    static char *names[] = {"tables", "arena", "logs", "counters", "kernels", "python", "states", "side", "progress",
                            "allow_nonfinite", NULL};
    if (r->owners != NULL) {
        PyErr_SetString(PyExc_TypeError, "Run: already initialised");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "OOOOOOO!O|Op", names, &tables, &arena, &logs, &counters, &kernels,
                                     &python, &PyList_Type, &states, &side, &progress, &allow_nonfinite))
        return -1;
    r->run.allow_nonfinite = allow_nonfinite;
    r->owners = Py_BuildValue("(OOOOOO)", tables, arena, logs, counters, kernels, python);
    if (r->owners == NULL)
        return -1;
    Py_INCREF(states);
    r->states = states;
    Py_INCREF(side);
    r->side = side;
    Py_INCREF(progress);
    r->progress = progress;
    PyObject *ndarray = PyObject_GetAttrString(side, "ndarray");
    r->empty = PyObject_GetAttrString(side, "empty");
    r->end_run = PyObject_GetAttrString(side, "end_run");
    if (ndarray == NULL || r->empty == NULL || r->end_run == NULL)
        return -1;
    if (!PyType_Check(ndarray)) {
        Py_DECREF(ndarray);
        PyErr_SetString(PyExc_TypeError, "Run: side.ndarray must be a type");
        return -1;
    }
    r->ndarray = (PyTypeObject *)ndarray;
    if (run_bind(r, tables, arena, logs, counters, kernels, python) != 0)
        return -1;
    r->run.hooks = run_hooks(r);
    return 0;
}

static PyObject *object_or_none(PyObject *obj)
{
    return obj != NULL ? obj : Py_None;
}

/* run(): (status, end, reached, code, which, op, tick, exception, end_op, end_asked,
   end_reason, message) of blk_outcome; exception: what a Python block, a kernel
   (BLK_RAISED) or a hook stopped the run with, else None; end_reason: the EndRun of the
   first accepted request to end the run. */
static PyObject *run_run(RunObject *r, PyObject *unused)
{
    (void)unused;
    if (r->owners == NULL || r->ran) {
        PyErr_SetString(PyExc_RuntimeError, r->ran ? "a Run runs once" : "Run: not initialised");
        return NULL;
    }
    r->ran = 1;
    int signals = _PyOS_IsMainThread(); /* intrcheck.h: PyErr_CheckSignals' own test of the thread */
    r->g = (gil){NULL, signals, !signals || run_other_threads()};
    int status = blk_run_table(&r->run);
    run_gil_hold(&r->g);
    const blk_outcome *o = &r->run.outcome;
    if (status == BLK_RUN_FAILED && o->code == BLK_RAISED && r->raised == NULL) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_SystemError, "a kernel returned BLK_RAISED without setting an exception");
        run_keep_raised(r);
    }
    return Py_BuildValue("(iLLiiLLOLLOz)", status, (long long)o->end, (long long)o->reached, o->code, o->which,
                         (long long)o->op, (long long)o->tick, object_or_none(r->raised), (long long)o->end_op,
                         (long long)o->end_asked, object_or_none(r->end_reason), o->message);
}

static void run_dealloc(RunObject *r)
{
    if (r->python != NULL) {
        for (int64_t b = 0; b < r->table.n_blocks; b++) {
            py_block *p = r->python + b;
            for (Py_ssize_t i = 0; p->in != NULL && i < p->n_in; i++) {
                Py_XDECREF(p->in[i].key);
                Py_XDECREF(p->in[i].value);
                PyMem_Free(p->in[i].seen);
            }
            for (Py_ssize_t i = 0; p->out != NULL && i < p->n_out; i++)
                Py_XDECREF(p->out[i].key);
            PyMem_Free(p->in);
            PyMem_Free(p->out);
            Py_XDECREF(p->output);
            Py_XDECREF(p->update);
            Py_XDECREF(p->inputs);
            Py_XDECREF(p->ended);
        }
        PyMem_Free(r->python);
    }
    PyMem_Free(r->kernels);
    PyMem_Free(r->logs);
    Py_XDECREF(r->owners);
    Py_XDECREF(r->states);
    Py_XDECREF(r->side);
    Py_XDECREF(r->progress);
    Py_XDECREF(r->raised);
    Py_XDECREF(r->end_reason);
    Py_XDECREF((PyObject *)r->ndarray);
    Py_XDECREF(r->empty);
    Py_XDECREF(r->end_run);
    Py_TYPE(r)->tp_free((PyObject *)r);
}

static PyMethodDef run_methods[] = {
    {"run", (PyCFunction)run_run, METH_NOARGS,
     "run(): interpret the table once; (status, end, reached, code, which, op, tick, exception, end_op, "
     "end_asked, end_reason, message)."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject blk_run_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "blocks._native.Run",
    .tp_basicsize = sizeof(RunObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Run(tables, arena, logs, counters, kernels, python, states, side, progress=None, "
              "allow_nonfinite=False): one run of an op table (blocks/csrc/core.h) through the C core; outputs that "
              "are not finite fail it (BLK_NONFINITE) unless allowed.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)run_init,
    .tp_dealloc = (destructor)run_dealloc,
    .tp_methods = run_methods,
};
