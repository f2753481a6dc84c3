/* blocks._native: runs the compiled parts of event programs, and calls single kernels.
 *
 * A Runner holds one piece of an event program in which every step belongs to a block
 * with a kernel (blocks_kernel.h): its outputs, updates, advances and the copies of
 * delayed connections, for one event or for a stretch of consecutive events. The
 * executor (blocks/simulate.py) builds it from flat int64 tables and calls
 * ``run(k, next_k)``: the event at tick k and those at k + offset before next_k, each
 * one's advances stepping to the following event (or next_k). Kernels read their inputs through
 * pointers into the output buffers of the blocks that feed them, so passing a value on
 * costs nothing; logged outputs are copied into the loggers' buffers here, honouring
 * their decimation.
 *
 * An update that returns BLK_END_RUN asks to end the run: the Runner calls
 * ``on_end(op, which, tick)``, which records the request and returns the tick the run now
 * ends at, finishes the event and runs no event from that tick on. A kernel that returns
 * BLK_RAISED has set a Python exception; the failure carries it.
 *
 * The GIL: a call releases it over the ops whose kernels say they may run without it
 * (Kernel.nogil, a slot's S_NOGIL; blocks_kernel.h), so that threads running diagrams run
 * in parallel, and holds it for the others (the FMU kernel calls back into Python) and for
 * whatever touches Python objects: a failure's tuple, on_end, the Ctrl-C checks. Copies
 * leave it as it is. PyErr_CheckSignals does nothing on a thread that does not handle
 * signals, so there the checks are skipped and a stretch of such ops runs released from
 * its first op to the end of the call; on the thread that handles them (the main one) the
 * GIL is taken back for each check, between events and between the chunks of an advance,
 * as before. That thread releases it only while another thread exists (one that has a
 * Python thread state) that could take it.
 *
 * Time is k * num / den in double, as the Python executor computes it: both are exact
 * integers below 2^53 (the executor checks), so the division rounds the same way.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <string.h>

#include "blocks_kernel.h"
#include "fmu.h"
#include "library.h"

/* -- the tables a Runner is built from (int64 rows; pointers stored as integers) -------- */
enum { OP_OUTPUT = 0, OP_UPDATE = 1, OP_ADVANCE = 2, OP_COPY = 3 };
/* op row: [op, slot, a, b]: output/advance log the entries a..b-1 of the log table;
   copy: [OP_COPY, width, destination, source] */
enum { OP_CODE, OP_SLOT, OP_A, OP_B, OP_N };
/* slot row: one per block with a kernel; S_NOGIL: its functions may run without the GIL */
enum { S_OUTPUT, S_UPDATE, S_ADVANCE, S_CTX, S_STATE, S_INPUTS, S_OUT, S_WIDTH, S_ROWS, S_ROWS_CAP, S_PERIOD, S_NOGIL,
       S_N };
/* event row: [tick offset from the first event, first op, end of ops] */
enum { E_OFFSET, E_START, E_END, E_N };
/* log row: [buffer, width, first column in the block's outputs, capacity (rows), decimate];
   counter row: [rows written, hits seen] */
enum { L_BUF, L_WIDTH, L_COLUMN, L_CAPACITY, L_DECIMATE, L_N };
enum { C_POS, C_HITS, C_N };

typedef struct {
    PyObject_HEAD
    const int64_t *slots;
    const int64_t *ops;
    const int64_t *events;
    const int64_t *logs;
    int64_t *counters;
    Py_ssize_t n_events;
    int64_t num, den;
    int64_t reached; /* the tick the last call completed to (its advances reach it) */
    int64_t stop;    /* the call runs no event from this tick on (an update asked to end the run) */
    PyObject *on_end; /* on_end(op, which, tick) -> the tick the run ends at; None: a failure */
    PyObject *owners; /* the arrays the tables and pointers live in */
} RunnerObject;

static double tick_time(const RunnerObject *r, int64_t k)
{
    return (double)(k * r->num) / (double)r->den;
}

static void log_row(const RunnerObject *r, Py_ssize_t entry, const double *outputs)
{
    const int64_t *lg = r->logs + entry * L_N;
    int64_t *c = r->counters + entry * C_N;
    if (c[C_HITS] % lg[L_DECIMATE] == 0 && c[C_POS] < lg[L_CAPACITY]) {
        double *dst = (double *)(intptr_t)lg[L_BUF] + c[C_POS] * lg[L_WIDTH];
        memcpy(dst, outputs + lg[L_COLUMN], (size_t)lg[L_WIDTH] * sizeof(double));
        c[C_POS]++;
    }
    c[C_HITS]++;
}

/* The GIL over one call: released (saved non-NULL) over ops whose kernels may run without
   it; signals: this thread handles signals, so Ctrl-C checks need the GIL; release: it may
   be released at all (off the signals thread, or while another thread could take it). */
typedef struct {
    PyThreadState *saved;
    int signals, release;
} gil;

static void gil_hold(gil *g)
{
    if (g->saved != NULL) {
        PyEval_RestoreThread(g->saved);
        g->saved = NULL;
    }
}

/* The GIL as the kernels of slot s need it: released for a nogil slot, held otherwise. */
static void gil_for(gil *g, const int64_t *s)
{
    if (!s[S_NOGIL])
        gil_hold(g);
    else if (g->saved == NULL && g->release)
        g->saved = PyEval_SaveThread();
}

/* Another thread with a Python thread state exists: one that could take a released GIL.
   Read with the GIL held, once per call: Python threads start and end under it; a C
   thread whose first PyGILState_Ensure is under way may be missed, and then this call
   holds the GIL throughout, as every call did before. */
static int other_threads(void)
{
    PyThreadState *self = PyThreadState_Get();
    PyThreadState *first = PyInterpreterState_ThreadHead(PyThreadState_GetInterpreter(self));
    return first != self || PyThreadState_Next(first) != NULL;
}

/* A Ctrl-C check: nonzero with KeyboardInterrupt (or the handler's exception) set, the GIL
   held. Skipped off the signals thread, where PyErr_CheckSignals does nothing. */
static int interrupted(gil *g)
{
    if (!g->signals)
        return 0;
    gil_hold(g);
    return PyErr_CheckSignals() != 0;
}

/* What an op ended with: done, a block's failure (a tuple to return), or an exception set
   (an interrupt between the chunks of an advance); the GIL is held unless done. */
typedef struct {
    PyObject *failure;
    int raised;
} op_end;

static op_end failure(gil *g, int code, int which, Py_ssize_t op, int64_t tick)
{
    gil_hold(g);
    PyObject *raised = Py_None;
    Py_INCREF(raised);
    if (code == BLK_RAISED) {
        PyObject *type, *value, *traceback;
        PyErr_Fetch(&type, &value, &traceback);
        if (type == NULL) {
            PyErr_SetString(PyExc_SystemError, "a kernel returned BLK_RAISED without setting an exception");
            PyErr_Fetch(&type, &value, &traceback);
        }
        PyErr_NormalizeException(&type, &value, &traceback);
        if (traceback != NULL && value != NULL)
            PyException_SetTraceback(value, traceback);
        Py_XDECREF(type);
        Py_XDECREF(traceback);
        if (value != NULL)
            Py_SETREF(raised, value);
    }
    PyObject *t = Py_BuildValue("(iinLN)", code, which, op, (long long)tick, raised);
    return (op_end){t, t == NULL};
}

/* An update at tick ke asked to end the run: on_end records it and says where the run
   ends; no event of this call runs from there on. */
static op_end end_request(RunnerObject *r, gil *g, int which, Py_ssize_t op, int64_t ke)
{
    if (r->on_end == NULL || r->on_end == Py_None)
        return failure(g, BLK_END_RUN, which, op, ke);
    gil_hold(g);
    PyObject *end = PyObject_CallFunction(r->on_end, "niL", op, which, (long long)ke);
    if (end == NULL)
        return (op_end){NULL, 1};
    long long tick = PyLong_AsLongLong(end);
    Py_DECREF(end);
    if (tick == -1 && PyErr_Occurred())
        return (op_end){NULL, 1};
    if (tick < r->stop)
        r->stop = tick;
    return (op_end){NULL, 0};
}

static const op_end DONE = {NULL, 0};

/* Step a block from tick ke to tick next in chunks of at most its rows capacity; Ctrl-C
   is looked for between chunks (r->reached then says how far the block got). */
static op_end advance(RunnerObject *r, gil *g, const int64_t *op, Py_ssize_t index, int64_t ke, int64_t next)
{
    const int64_t *s = r->slots + op[OP_SLOT] * S_N;
    blk_advance_fn fn = (blk_advance_fn)(intptr_t)s[S_ADVANCE];
    double *state = (double *)(intptr_t)s[S_STATE];
    const double *const *inputs = (const double *const *)(intptr_t)s[S_INPUTS];
    double *rows = (double *)(intptr_t)s[S_ROWS];
    double *out = (double *)(intptr_t)s[S_OUT];
    int64_t width = s[S_WIDTH], period = s[S_PERIOD], cap = s[S_ROWS_CAP];
    int64_t n = (next - ke) / period, stepped = 0;
    while (n > 0) {
        int m = (int)(n < cap ? n : cap), done = 0, which = 0;
        gil_for(g, s);
        int code = fn((const void *)(intptr_t)s[S_CTX], tick_time(r, ke + stepped * period), state, inputs, m, rows,
                      &done, &which);
        int logged = code ? (done < 0 ? 0 : done > m ? m : done) : m;
        for (int i = 0; i < logged; i++)
            for (int64_t e = op[OP_A]; e < op[OP_B]; e++)
                log_row(r, (Py_ssize_t)e, rows + i * width);
        if (code)
            return failure(g, code, which, index, ke + (stepped + logged) * period);
        memcpy(out, rows + (m - 1) * width, (size_t)width * sizeof(double));
        n -= m;
        stepped += m;
        if (n > 0 && interrupted(g)) {
            r->reached = ke + stepped * period;
            return (op_end){NULL, 1};
        }
    }
    return DONE;
}

/* One op at event tick ke whose advances reach next. */
static op_end run_op(RunnerObject *r, gil *g, Py_ssize_t index, int64_t ke, int64_t next)
{
    const int64_t *op = r->ops + index * OP_N;
    if (op[OP_CODE] == OP_COPY) {
        memcpy((double *)(intptr_t)op[OP_A], (const double *)(intptr_t)op[OP_B], (size_t)op[OP_SLOT] * sizeof(double));
        return DONE;
    }
    if (op[OP_CODE] == OP_ADVANCE)
        return advance(r, g, op, index, ke, next);
    const int64_t *s = r->slots + op[OP_SLOT] * S_N;
    const void *ctx = (const void *)(intptr_t)s[S_CTX];
    double *state = (double *)(intptr_t)s[S_STATE];
    const double *const *inputs = (const double *const *)(intptr_t)s[S_INPUTS];
    int which = 0, code;
    gil_for(g, s);
    if (op[OP_CODE] == OP_OUTPUT) {
        double *out = (double *)(intptr_t)s[S_OUT];
        code = ((blk_output_fn)(intptr_t)s[S_OUTPUT])(ctx, tick_time(r, ke), state, inputs, out, &which);
        if (!code)
            for (int64_t e = op[OP_A]; e < op[OP_B]; e++)
                log_row(r, (Py_ssize_t)e, out);
    } else {
        code = ((blk_update_fn)(intptr_t)s[S_UPDATE])(ctx, tick_time(r, ke), state, inputs, &which);
        if (code == BLK_END_RUN)
            return end_request(r, g, which, index, ke);
    }
    return code ? failure(g, code, which, index, ke) : DONE;
}

/* The events from tick k before next_k (runner_run); NULL with an exception set, a
   failure tuple, or Py_None (a borrowed reference: the caller takes one). */
static PyObject *run_events(RunnerObject *r, gil *g, int64_t k, int64_t next_k)
{
    r->stop = next_k;
    for (Py_ssize_t e = 0; e < r->n_events; e++) {
        const int64_t *ev = r->events + e * E_N;
        int64_t ke = k + ev[E_OFFSET];
        if (e > 0 && ke >= next_k) /* the first event always runs: a final one has k == next_k */
            break;
        int64_t next = e + 1 < r->n_events ? k + ev[E_N + E_OFFSET] : next_k;
        if (next > next_k)
            next = next_k;
        for (int64_t i = ev[E_START]; i < ev[E_END]; i++) {
            op_end end = run_op(r, g, (Py_ssize_t)i, ke, next);
            if (end.raised)
                return NULL;
            if (end.failure != NULL) {
                r->reached = ke;
                return end.failure;
            }
        }
        r->reached = next;
        if (r->stop < next_k)
            next_k = r->stop;
        if (e + 1 < r->n_events && interrupted(g))
            return NULL;
    }
    return Py_None;
}

/* run(k, next_k): None, or (code, which, op index, tick, exception) of the first failure
   (the exception a kernel raised with BLK_RAISED, else None). Ctrl-C is looked for between
   events and between the chunks of long advances; it raises KeyboardInterrupt with
   ``reached`` saying how far the run got. */
static PyObject *runner_run(RunnerObject *r, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "run(k, next_k) takes 2 arguments");
        return NULL;
    }
    long long k = PyLong_AsLongLong(args[0]), next_k = PyLong_AsLongLong(args[1]);
    if ((k == -1 || next_k == -1) && PyErr_Occurred())
        return NULL;
    int signals = _PyOS_IsMainThread(); /* intrcheck.h: PyErr_CheckSignals' own test of the thread */
    gil g = {NULL, signals, !signals || other_threads()};
    PyObject *result = run_events(r, &g, k, next_k);
    gil_hold(&g);
    if (result == Py_None)
        Py_INCREF(result);
    return result;
}

static PyObject *runner_reached(RunnerObject *r, void *closure)
{
    (void)closure;
    return PyLong_FromLongLong(r->reached);
}

/* The data pointer of a C-contiguous int64 array argument, which the Runner keeps alive. */
static int64_t *int64_table(PyObject *obj, Py_ssize_t row, const char *what)
{
    Py_buffer view;
    if (PyObject_GetBuffer(obj, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) != 0)
        return NULL;
    int ok = view.itemsize == 8 && view.format != NULL && (strcmp(view.format, "q") == 0 || strcmp(view.format, "l") == 0) &&
             view.len % (row * 8) == 0;
    int64_t *data = view.buf;
    PyBuffer_Release(&view);
    if (!ok) {
        PyErr_Format(PyExc_TypeError, "Runner: %s must be a writable C-contiguous int64 array of rows of %zd", what, row);
        return NULL;
    }
    return data;
}

static int runner_init(RunnerObject *r, PyObject *args, PyObject *kwds)
{
    PyObject *slots, *ops, *events, *logs, *counters, *owners, *on_end = Py_None;
    long long num, den;
    static char *names[] = {"slots", "ops", "events", "logs", "counters", "num", "den", "owners", "on_end", NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "OOOOOLLO|O", names, &slots, &ops, &events, &logs, &counters, &num,
                                     &den, &owners, &on_end))
        return -1;
    if (on_end != Py_None && !PyCallable_Check(on_end)) {
        PyErr_SetString(PyExc_TypeError, "Runner: on_end must be callable or None");
        return -1;
    }
    if (num <= 0 || den <= 0) {
        PyErr_SetString(PyExc_ValueError, "Runner: num and den must be positive");
        return -1;
    }
    r->slots = int64_table(slots, S_N, "slots");
    r->ops = r->slots ? int64_table(ops, OP_N, "ops") : NULL;
    r->events = r->ops ? int64_table(events, E_N, "events") : NULL;
    r->logs = r->events ? int64_table(logs, L_N, "logs") : NULL;
    r->counters = r->logs ? int64_table(counters, C_N, "counters") : NULL;
    if (r->counters == NULL)
        return -1;
    r->n_events = PyObject_Length(events);
    if (r->n_events < 0)
        return -1;
    r->num = num;
    r->den = den;
    r->reached = -1;
    Py_INCREF(on_end);
    Py_XSETREF(r->on_end, on_end);
    Py_INCREF(owners);
    Py_XSETREF(r->owners, Py_BuildValue("(OOOOOO)", slots, ops, events, logs, counters, owners));
    Py_DECREF(owners);
    return r->owners == NULL ? -1 : 0;
}

static void runner_dealloc(RunnerObject *r)
{
    Py_XDECREF(r->on_end);
    Py_XDECREF(r->owners);
    Py_TYPE(r)->tp_free((PyObject *)r);
}

static PyMethodDef runner_methods[] = {
    {"run", (PyCFunction)(void (*)(void))runner_run, METH_FASTCALL,
     "run(k, next_k): the events from tick k before next_k; None, or (code, which, op, tick, exception) of a "
     "failure."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef runner_getset[] = {
    {"reached", (getter)runner_reached, NULL, "the tick the last run completed to (-1 before any)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject runner_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "blocks._native.Runner",
    .tp_basicsize = sizeof(RunnerObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Runner(slots, ops, events, logs, counters, num, den, owners, on_end=None): compiled steps of event "
              "programs.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)runner_init,
    .tp_dealloc = (destructor)runner_dealloc,
    .tp_methods = runner_methods,
    .tp_getset = runner_getset,
};

/* -- single kernel calls, for tests and tools ------------------------------------------ */

#define MAX_INPUTS 64

/* Pointers to the float64 arrays of the sequence ``inputs``; the buffers are held in
   ``views`` (released by release_views). -1 with an exception on error. */
static int hold_inputs(PyObject *inputs, Py_buffer *views, const double **pointers, Py_ssize_t *count)
{
    PyObject *seq = PySequence_Fast(inputs, "inputs must be a sequence of float64 arrays");
    if (seq == NULL)
        return -1;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    *count = 0;
    if (n > MAX_INPUTS) {
        Py_DECREF(seq);
        PyErr_Format(PyExc_ValueError, "at most %d inputs", MAX_INPUTS);
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        if (PyObject_GetBuffer(PySequence_Fast_GET_ITEM(seq, i), &views[i], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) != 0) {
            Py_DECREF(seq);
            return -1;
        }
        *count = i + 1;
        if (views[i].itemsize != 8 || views[i].format == NULL || strcmp(views[i].format, "d") != 0) {
            Py_DECREF(seq);
            PyErr_Format(PyExc_TypeError, "input %zd must be a float64 array", i);
            return -1;
        }
        pointers[i] = views[i].buf;
    }
    Py_DECREF(seq);
    return 0;
}

static void release_views(Py_buffer *views, Py_ssize_t count)
{
    for (Py_ssize_t i = 0; i < count; i++)
        PyBuffer_Release(&views[i]);
}

/* A writable float64 buffer, or None (NULL pointer) where allowed. */
static int hold_doubles(PyObject *obj, Py_buffer *view, double **data, int none_ok, const char *what)
{
    if (obj == Py_None && none_ok) {
        view->obj = NULL;
        *data = NULL;
        return 0;
    }
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) != 0)
        return -1;
    if (view->itemsize != 8 || view->format == NULL || strcmp(view->format, "d") != 0) {
        PyBuffer_Release(view);
        PyErr_Format(PyExc_TypeError, "%s must be a writable C-contiguous float64 array", what);
        return -1;
    }
    *data = view->buf;
    return 0;
}

static void release_doubles(Py_buffer *view)
{
    if (view->obj != NULL)
        PyBuffer_Release(view);
}

/* call(kind, function, context, t, state, inputs, out, n): one kernel call.
   kind 'output': out receives the outputs, returns (code, which);
   'update': returns (code, which); 'advance': out receives n rows, returns (code, done, which). */
static PyObject *call_kernel(PyObject *module, PyObject *args)
{
    (void)module;
    const char *kind;
    unsigned long long function, context;
    double t;
    PyObject *state_obj, *inputs_obj, *out_obj;
    int n = 0;
    if (!PyArg_ParseTuple(args, "sKKdOOO|i", &kind, &function, &context, &t, &state_obj, &inputs_obj, &out_obj, &n))
        return NULL;
    if (function == 0) {
        PyErr_SetString(PyExc_ValueError, "no function (address 0)");
        return NULL;
    }
    Py_buffer views[MAX_INPUTS], state_view, out_view;
    const double *pointers[MAX_INPUTS];
    Py_ssize_t count = 0;
    double *state, *out;
    if (hold_doubles(state_obj, &state_view, &state, 1, "state") != 0)
        return NULL;
    if (hold_doubles(out_obj, &out_view, &out, 1, "out") != 0) {
        release_doubles(&state_view);
        return NULL;
    }
    PyObject *result = NULL;
    if (hold_inputs(inputs_obj, views, pointers, &count) == 0) {
        const void *ctx = (const void *)(uintptr_t)context;
        int which = 0, done = 0, code;
        if (strcmp(kind, "output") == 0) {
            code = ((blk_output_fn)(uintptr_t)function)(ctx, t, state, pointers, out, &which);
            result = Py_BuildValue("(ii)", code, which);
        } else if (strcmp(kind, "update") == 0) {
            code = ((blk_update_fn)(uintptr_t)function)(ctx, t, state, pointers, &which);
            result = Py_BuildValue("(ii)", code, which);
        } else if (strcmp(kind, "advance") == 0) {
            code = ((blk_advance_fn)(uintptr_t)function)(ctx, t, state, pointers, n, out, &done, &which);
            result = Py_BuildValue("(iii)", code, done, which);
        } else {
            PyErr_Format(PyExc_ValueError, "kind must be 'output', 'update' or 'advance', not '%s'", kind);
        }
    }
    release_views(views, count);
    release_doubles(&state_view);
    release_doubles(&out_view);
    return result;
}

/* library(): {name: address} of the library blocks' kernels. */
static PyObject *library(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    PyObject *found = PyDict_New();
    for (const blk_library_entry *e = blk_library; found != NULL && e->name != NULL; e++) {
        PyObject *address = PyLong_FromVoidPtr((void *)e->function);
        if (address == NULL || PyDict_SetItemString(found, e->name, address) != 0)
            Py_CLEAR(found);
        Py_XDECREF(address);
    }
    return found;
}

/* fmu_kernel(): the FMU block's kernel functions and its context's layout (fmu.h). */
static PyObject *fmu_kernel(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    return blk_fmu_kernel();
}

static PyMethodDef module_methods[] = {
    {"call", call_kernel, METH_VARARGS,
     "call(kind, function, context, t, state, inputs, out, n=0): one kernel call ('output', 'update', 'advance')."},
    {"library", library, METH_NOARGS, "library(): {name: address} of the library blocks' kernels."},
    {"fmu_kernel", fmu_kernel, METH_NOARGS, "fmu_kernel(): the FMU block's kernel functions and context layout."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "_native", "Compiled event programs and kernel calls (see blocks/csrc).", -1,
    module_methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__native(void)
{
    if (PyType_Ready(&runner_type) < 0)
        return NULL;
    PyObject *module = PyModule_Create(&module_def);
    if (module == NULL)
        return NULL;
    Py_INCREF(&runner_type);
    if (PyModule_AddObject(module, "Runner", (PyObject *)&runner_type) != 0 ||
        PyModule_AddIntConstant(module, "ABI", BLK_KERNEL_ABI) != 0) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
