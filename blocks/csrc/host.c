/* blocks._native: the CPython host of the op-table core (core.h), and single kernel calls.
 *
 * A Run holds one run of an op table (blocks/engine/optable.py) bound by blocks/engine/native_run.py: the
 * tables, the run's arena, log buffers and counters (numpy arrays it keeps alive), one
 * kernel row per block, and for each block without a kernel its Python methods. run()
 * hands all of it to blk_run_table, which interprets the whole run in one call, and
 * returns how it went. What is Python's is here, in the hooks the core calls:
 *
 * - call: a Python block's op. Inputs whose values in the arena changed since the block
 *   last saw them get a new array in its input mapping (or the old one overwritten when
 *   nobody else holds it); its output() result is checked and the ports of the step
 *   copied into the arena; update() sets its state or raises EndRun (the request to end
 *   the run, state and all); advance() goes through blocks/engine/python_blocks.py. An
 *   exception is kept for the outcome (BLK_RAISED). The rules are python_blocks.py's;
 *   an output that fails the fast check goes there for its message.
 * - end: a kernel's request to end the run is its error factory's EndRun (another
 *   exception fails the update); a Python block's is the EndRun it raised.
 * - gil: the GIL is released over the ops whose kernels say they may run without it
 *   (Kernel.nogil), so that threads running diagrams run in parallel, and held for the
 *   others (the FMU kernel calls back into Python), for Python blocks and for the checks.
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
#include <string.h>

#include "blocks_kernel.h"
#include "core.h"
#include "export_instance.h"
#include "fmu_block_step.h"
#include "fmu_channel.h"
#include "fmu_me_integration.h"
#include "library.h"

/* -- a Python block ------------------------------------------------------------------- */

typedef struct {
    PyObject *key, *value; /* the port's name, the array its mapping holds */
    double *arena, *seen, *data; /* where it reads, what the block last saw, value's data if ours */
    Py_ssize_t width;
} py_input;

typedef struct {
    PyObject *key;
    double *arena;
    Py_ssize_t width;
} py_port;

typedef struct {
    PyObject *output, *update, *inputs, *ended; /* ended: the EndRun of its last update */
    Py_ssize_t state; /* its index in the states list */
    py_input *in;
    py_port *out;
    Py_ssize_t n_in, n_out;
} py_block;

/* The GIL over one run: saved non-NULL while released; signals: this thread handles
   signals; release: the GIL may be released at all. */
typedef struct {
    PyThreadState *saved;
    int signals, release;
} gil;

typedef struct {
    PyObject_HEAD
    blk_table table;
    blk_run run;
    blk_kernel *kernels;
    double **logs;
    py_block *python; /* per block; output NULL: the block has a kernel */
    PyObject *owners, *states, *side, *progress, *width_cache;
    PyObject *raised; /* the exception a hook or Python block stopped the run with */
    PyObject *end_reason; /* the EndRun of the first accepted request to end the run */
    PyTypeObject *ndarray;
    PyObject *empty, *end_run;
    gil g;
    int64_t polls;
    int ran;
} RunObject;

static void gil_hold(gil *g)
{
    if (g->saved != NULL) {
        PyEval_RestoreThread(g->saved);
        g->saved = NULL;
    }
}

/* Another thread with a Python thread state exists: one that could take a released GIL.
   Read with the GIL held: Python threads start and end under it; a C thread whose first
   PyGILState_Ensure is under way may be missed until the next check. */
static int other_threads(void)
{
    PyThreadState *self = PyThreadState_Get();
    PyThreadState *first = PyInterpreterState_ThreadHead(PyThreadState_GetInterpreter(self));
    return first != self || PyThreadState_Next(first) != NULL;
}

/* Keep the exception now set as the run's (the first one kept wins); BLK_RAISED. */
static int keep_raised(RunObject *r)
{
    PyObject *type, *value, *traceback;
    PyErr_Fetch(&type, &value, &traceback);
    if (type == NULL)
        return BLK_RAISED;
    PyErr_NormalizeException(&type, &value, &traceback);
    if (traceback != NULL && value != NULL)
        PyException_SetTraceback(value, traceback);
    Py_XDECREF(type);
    Py_XDECREF(traceback);
    if (r->raised == NULL)
        r->raised = value;
    else
        Py_XDECREF(value);
    return BLK_RAISED;
}

/* A new float64 array of width w for an input mapping, its data in *data. */
static PyObject *new_input(RunObject *r, Py_ssize_t w, double **data)
{
    PyObject *width = PyLong_FromSsize_t(w);
    if (width == NULL)
        return NULL;
    PyObject *fresh = PyObject_CallOneArg(r->empty, width);
    Py_DECREF(width);
    if (fresh == NULL)
        return NULL;
    Py_buffer view;
    if (PyObject_GetBuffer(fresh, &view, PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) != 0) {
        Py_DECREF(fresh);
        return NULL;
    }
    *data = view.buf;
    PyBuffer_Release(&view);
    return fresh;
}

/* The inputs of a Python block whose values changed since it last saw them. */
static int refresh(RunObject *r, py_block *b)
{
    for (Py_ssize_t i = 0; i < b->n_in; i++) {
        py_input *in = b->in + i;
        size_t bytes = (size_t)in->width * sizeof(double);
        if (memcmp(in->arena, in->seen, bytes) == 0)
            continue;
        memcpy(in->seen, in->arena, bytes);
        if (in->data != NULL && Py_REFCNT(in->value) <= 2) { /* held by the mapping and here only */
            memcpy(in->data, in->arena, bytes);
            continue;
        }
        double *data;
        PyObject *fresh = new_input(r, in->width, &data);
        if (fresh == NULL)
            return -1;
        memcpy(data, in->arena, bytes);
        if (PyDict_SetItem(b->inputs, in->key, fresh) != 0) {
            Py_DECREF(fresh);
            return -1;
        }
        Py_SETREF(in->value, fresh);
        in->data = data;
    }
    return 0;
}

/* Copy a float64 array of shape (width,) into dst; 0 if v is no such array. */
static int store(RunObject *r, PyObject *v, double *dst, Py_ssize_t width)
{
    if (v == NULL || !PyObject_TypeCheck(v, r->ndarray))
        return 0;
    Py_buffer view;
    if (PyObject_GetBuffer(v, &view, PyBUF_STRIDES | PyBUF_FORMAT) != 0) {
        PyErr_Clear();
        return 0;
    }
    int ok = view.ndim == 1 && view.shape[0] == width && view.itemsize == 8 && view.format != NULL &&
             strcmp(view.format, "d") == 0;
    if (ok && view.strides[0] == 8) {
        memcpy(dst, view.buf, (size_t)width * sizeof(double));
    } else if (ok) {
        for (Py_ssize_t i = 0; i < width; i++)
            memcpy(dst + i, (const char *)view.buf + i * view.strides[0], sizeof(double));
    }
    PyBuffer_Release(&view);
    return ok;
}

static PyObject *call_with_time(PyObject *method, double t, PyObject *state, PyObject *inputs)
{
    PyObject *time = PyFloat_FromDouble(t);
    if (time == NULL)
        return NULL;
    PyObject *args[4] = {NULL, time, state, inputs};
    PyObject *result = PyObject_Vectorcall(method, args + 1, 3 | PY_VECTORCALL_ARGUMENTS_OFFSET, NULL);
    Py_DECREF(time);
    return result;
}

/* The output values of a step that failed the fast check, checked by python_blocks.py:
   its message, or the selected ports' values side by side. */
static int store_checked(RunObject *r, py_block *b, int64_t block, PyObject *out, int64_t selection)
{
    PyObject *values = PyObject_CallMethod(r->side, "outputs_checked", "nOL", (Py_ssize_t)block, out,
                                           (long long)selection);
    if (values == NULL)
        return -1;
    Py_buffer view;
    int failed = PyObject_GetBuffer(values, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT);
    Py_DECREF(values);
    if (failed)
        return -1;
    const double *from = view.buf;
    int64_t count = selection < 0 ? b->n_out : r->table.selections[selection];
    for (int64_t i = 0; i < count; i++) {
        const py_port *o = b->out + (selection < 0 ? i : r->table.selections[selection + 1 + i]);
        memcpy(o->arena, from, (size_t)o->width * sizeof(double));
        from += o->width;
    }
    PyBuffer_Release(&view);
    return 0;
}

static int py_output(RunObject *r, py_block *b, int64_t block, int64_t selection, double t)
{
    if (refresh(r, b) != 0)
        return keep_raised(r);
    PyObject *out = call_with_time(b->output, t, PyList_GET_ITEM(r->states, b->state), b->inputs);
    if (out == NULL)
        return keep_raised(r);
    int ok = PyDict_Check(out);
    int64_t count = selection < 0 ? b->n_out : r->table.selections[selection];
    for (int64_t i = 0; ok && i < count; i++) {
        const py_port *o = b->out + (selection < 0 ? i : r->table.selections[selection + 1 + i]);
        ok = store(r, PyDict_GetItemWithError(out, o->key), o->arena, o->width);
    }
    if (!ok) {
        PyErr_Clear();
        ok = store_checked(r, b, block, out, selection) == 0;
    }
    Py_DECREF(out);
    return ok ? 0 : keep_raised(r);
}

static int py_update(RunObject *r, py_block *b, double t)
{
    if (refresh(r, b) != 0)
        return keep_raised(r);
    PyObject *state = call_with_time(b->update, t, PyList_GET_ITEM(r->states, b->state), b->inputs);
    if (state != NULL) {
        PyList_SetItem(r->states, b->state, state);
        return 0;
    }
    if (!PyErr_ExceptionMatches(r->end_run))
        return keep_raised(r);
    PyObject *type, *end, *traceback;
    PyErr_Fetch(&type, &end, &traceback);
    PyErr_NormalizeException(&type, &end, &traceback);
    Py_XDECREF(type);
    Py_XDECREF(traceback);
    PyObject *has_state = PyObject_GetAttrString(end, "has_state");
    int given = has_state == NULL ? -1 : PyObject_IsTrue(has_state);
    Py_XDECREF(has_state);
    if (given == 1) {
        PyObject *new_state = PyObject_GetAttrString(end, "state");
        if (new_state == NULL)
            given = -1;
        else
            PyList_SetItem(r->states, b->state, new_state);
    }
    if (given < 0) {
        Py_DECREF(end);
        return keep_raised(r);
    }
    Py_XSETREF(b->ended, end);
    return BLK_END_RUN;
}

static int py_advance(RunObject *r, py_block *b, int64_t block, double t, int n, int *done)
{
    if (refresh(r, b) != 0)
        return keep_raised(r);
    PyObject *result = PyObject_CallMethod(r->side, "advance", "ndi", (Py_ssize_t)block, t, n);
    if (result == NULL)
        return keep_raised(r);
    PyObject *error = NULL;
    int parsed = PyArg_ParseTuple(result, "iO", done, &error);
    if (parsed && error != Py_None) {
        Py_INCREF(error);
        if (r->raised == NULL)
            r->raised = error;
        else
            Py_DECREF(error);
    }
    Py_DECREF(result);
    if (!parsed)
        return keep_raised(r);
    return error == Py_None ? 0 : BLK_RAISED;
}

/* -- the hooks --------------------------------------------------------------------------- */

static int host_call(void *host, int64_t op, int64_t tick, double t, int n, double *rows, int *done, int *which)
{
    (void)tick, (void)rows, (void)which;
    RunObject *r = host;
    const int64_t *row = r->table.ops + op * BLK_OP_N;
    int64_t block = row[BLK_OP_A];
    py_block *b = r->python + block;
    switch (row[BLK_OP_CODE]) {
    case BLK_OUTPUT:
        return py_output(r, b, block, row[BLK_OP_D], t);
    case BLK_UPDATE:
        return py_update(r, b, t);
    default:
        return py_advance(r, b, block, t, n, done);
    }
}

static void host_gil(void *host, int needed)
{
    gil *g = &((RunObject *)host)->g;
    if (needed)
        gil_hold(g);
    else if (g->saved == NULL && g->release)
        g->saved = PyEval_SaveThread();
}

static int host_poll(void *host, int64_t reached)
{
    RunObject *r = host;
    r->polls++;
    if (r->g.signals) {
        gil_hold(&r->g);
        if (PyErr_CheckSignals() != 0) {
            keep_raised(r);
            return 1;
        }
        r->g.release = other_threads();
    }
    if (r->progress != Py_None && (r->polls & 255) == 0) {
        gil_hold(&r->g);
        PyObject *done = PyObject_CallFunction(r->progress, "L", (long long)reached);
        if (done == NULL) {
            keep_raised(r);
            return 1;
        }
        Py_DECREF(done);
    }
    return 0;
}

static int host_end(void *host, int64_t op, int which, int64_t tick)
{
    RunObject *r = host;
    gil_hold(&r->g);
    int64_t block = r->table.ops[op * BLK_OP_N + BLK_OP_A];
    PyObject *end;
    if (r->python[block].output != NULL) {
        end = r->python[block].ended;
        r->python[block].ended = NULL;
        if (end == NULL) {
            PyErr_SetString(PyExc_SystemError, "a Python block asked to end the run without an EndRun");
            keep_raised(r);
            return 1;
        }
    } else {
        end = PyObject_CallMethod(r->side, "kernel_end", "niL", (Py_ssize_t)block, which, (long long)tick);
        if (end == NULL) {
            keep_raised(r);
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
        keep_raised(r);
        return 1;
    }
    if (r->raised == NULL)
        r->raised = end;
    else
        Py_XDECREF(end);
    return 1;
}

/* -- the Run type -------------------------------------------------------------------------- */

/* The data of a C-contiguous array argument of items of `itemsize` (format "q"/"l" or
   "d"), which the Run keeps alive; its number of items in *count. */
static void *array_data(PyObject *obj, int writable, char kind, Py_ssize_t *count, const char *what)
{
    Py_buffer view;
    if (PyObject_GetBuffer(obj, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0)) != 0)
        return NULL;
    const char *f = view.format;
    int ok = view.itemsize == 8 && f != NULL &&
             (kind == 'd' ? strcmp(f, "d") == 0 : (strcmp(f, "q") == 0 || strcmp(f, "l") == 0));
    void *data = view.buf;
    *count = view.len / 8;
    PyBuffer_Release(&view);
    if (!ok) {
        PyErr_Format(PyExc_TypeError, "Run: %s must be a%s C-contiguous %s array", what, writable ? " writable" : "",
                     kind == 'd' ? "float64" : "int64");
        return NULL;
    }
    return data;
}

/* count zeroed items of size (at least one), or NULL with MemoryError set. */
static void *zeroed(int64_t count, size_t size)
{
    void *items = PyMem_Calloc((size_t)(count > 0 ? count : 1), size);
    if (items == NULL)
        PyErr_NoMemory();
    return items;
}

/* obj is a list of count items, else ValueError saying what it must be. */
static int list_of(PyObject *obj, int64_t count, const char *what)
{
    if (PyList_Check(obj) && PyList_GET_SIZE(obj) == count)
        return 1;
    PyErr_Format(PyExc_ValueError, "Run: %s", what);
    return 0;
}

static int bind_tables(RunObject *r, PyObject *tables)
{
    static const char *names[] = {"header", "blocks", "inputs", "ports", "ops",
                                  "copies", "programs", "events", "logs", "selections"};
    static const Py_ssize_t widths[] = {BLK_H_N, BLK_B_N, BLK_I_N, BLK_P_N, BLK_OP_N, BLK_C_N, BLK_PR_N, BLK_E_N,
                                        BLK_L_N, 1};
    const int64_t **at[] = {&r->table.header, &r->table.blocks, &r->table.inputs, &r->table.ports, &r->table.ops,
                            &r->table.copies, &r->table.programs, &r->table.events, &r->table.logs,
                            &r->table.selections};
    int64_t *counts[] = {NULL, &r->table.n_blocks, &r->table.n_inputs, &r->table.n_ports, &r->table.n_ops,
                         &r->table.n_copies, &r->table.n_programs, &r->table.n_events, &r->table.n_logs,
                         &r->table.n_selections};
    if (!PyTuple_Check(tables) || PyTuple_GET_SIZE(tables) != 10) {
        PyErr_SetString(PyExc_TypeError, "Run: tables must be a tuple of the 10 tables of core.h");
        return -1;
    }
    for (int i = 0; i < 10; i++) {
        Py_ssize_t n;
        *at[i] = array_data(PyTuple_GET_ITEM(tables, i), 0, 'q', &n, names[i]);
        if (*at[i] == NULL)
            return -1;
        if (n % widths[i] != 0 || (i == 0 && n != BLK_H_N)) {
            PyErr_Format(PyExc_ValueError, "Run: table %s is not made of rows of %zd", names[i], widths[i]);
            return -1;
        }
        if (counts[i])
            *counts[i] = n / widths[i];
    }
    const char *bad = blk_table_check(&r->table);
    if (bad) {
        PyErr_Format(PyExc_ValueError, "Run: bad op table: %s", bad);
        return -1;
    }
    return 0;
}

static int bind_kernels(RunObject *r, PyObject *rows)
{
    Py_ssize_t n;
    const int64_t *k = array_data(rows, 0, 'q', &n, "kernels");
    if (k == NULL)
        return -1;
    if (n != r->table.n_blocks * 6) {
        PyErr_SetString(PyExc_ValueError, "Run: kernels must have one row of 6 per block");
        return -1;
    }
    r->kernels = zeroed(r->table.n_blocks, sizeof *r->kernels);
    if (r->kernels == NULL)
        return -1;
    for (int64_t b = 0; b < r->table.n_blocks; b++, k += 6) {
        blk_kernel *kb = r->kernels + b;
        kb->output = (blk_output_fn)(intptr_t)k[0];
        kb->update = (blk_update_fn)(intptr_t)k[1];
        kb->advance = (blk_advance_fn)(intptr_t)k[2];
        kb->ctx = (const void *)(intptr_t)k[3];
        kb->state = (double *)(intptr_t)k[4];
        kb->nogil = (int)k[5];
    }
    return 0;
}

static int bind_logs(RunObject *r, PyObject *logs, PyObject *counters)
{
    if (!list_of(logs, r->table.n_logs, "logs must be a list of one buffer per log entry"))
        return -1;
    r->logs = zeroed(r->table.n_logs, sizeof *r->logs);
    if (r->logs == NULL)
        return -1;
    for (int64_t e = 0; e < r->table.n_logs; e++) {
        Py_ssize_t n;
        const int64_t *lg = r->table.logs + e * BLK_L_N;
        r->logs[e] = array_data(PyList_GET_ITEM(logs, e), 1, 'd', &n, "a log buffer");
        if (r->logs[e] == NULL)
            return -1;
        if (n < lg[BLK_L_CAPACITY] * lg[BLK_L_WIDTH]) {
            PyErr_SetString(PyExc_ValueError, "Run: a log buffer is smaller than its entry's capacity");
            return -1;
        }
    }
    Py_ssize_t n;
    r->run.counters = array_data(counters, 1, 'q', &n, "counters");
    if (r->run.counters == NULL)
        return -1;
    if (n != r->table.n_logs * BLK_LC_N) {
        PyErr_SetString(PyExc_ValueError, "Run: counters must have one row of 2 per log entry");
        return -1;
    }
    return 0;
}

/* A Python block from its spec (output, update, inputs, state index,
   [(port, offset, width, value)] of its connected inputs, [(port, offset, width)] of its
   outputs). */
static int bind_python_block(RunObject *r, py_block *b, PyObject *spec, double *arena, int64_t size)
{
    PyObject *inputs_list, *outputs_list;
    if (!PyArg_ParseTuple(spec, "OOO!nO!O!", &b->output, &b->update, &PyDict_Type, &b->inputs, &b->state,
                          &PyList_Type, &inputs_list, &PyList_Type, &outputs_list))
        return -1;
    Py_INCREF(b->output);
    Py_INCREF(b->update);
    Py_INCREF(b->inputs);
    if (b->state < 0 || b->state >= PyList_GET_SIZE(r->states)) {
        PyErr_SetString(PyExc_ValueError, "Run: a Python block's state index is out of range");
        return -1;
    }
    b->n_in = PyList_GET_SIZE(inputs_list);
    b->n_out = PyList_GET_SIZE(outputs_list);
    b->in = zeroed(b->n_in, sizeof *b->in);
    b->out = b->in == NULL ? NULL : zeroed(b->n_out, sizeof *b->out);
    if (b->out == NULL)
        return -1;
    for (Py_ssize_t i = 0; i < b->n_in; i++) {
        py_input *in = b->in + i;
        Py_ssize_t offset;
        if (!PyArg_ParseTuple(PyList_GET_ITEM(inputs_list, i), "UnnO", &in->key, &offset, &in->width, &in->value))
            return -1;
        Py_INCREF(in->key);
        Py_INCREF(in->value);
        if (offset < 0 || in->width < 0 || offset + in->width > size) {
            PyErr_SetString(PyExc_ValueError, "Run: a Python block's input lies outside the arena");
            return -1;
        }
        in->arena = arena + offset;
        in->seen = zeroed(in->width, sizeof(double));
        if (in->seen == NULL)
            return -1;
        memcpy(in->seen, in->arena, (size_t)in->width * sizeof(double));
        Py_buffer view; /* the value is ours to overwrite if it is a float64 array of the width */
        if (Py_IS_TYPE(in->value, r->ndarray) &&
            PyObject_GetBuffer(in->value, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) == 0) {
            if (view.len == in->width * 8 && view.format != NULL && strcmp(view.format, "d") == 0)
                in->data = view.buf;
            PyBuffer_Release(&view);
        }
        PyErr_Clear();
    }
    for (Py_ssize_t i = 0; i < b->n_out; i++) {
        py_port *o = b->out + i;
        Py_ssize_t offset;
        if (!PyArg_ParseTuple(PyList_GET_ITEM(outputs_list, i), "Unn", &o->key, &offset, &o->width))
            return -1;
        Py_INCREF(o->key);
        if (offset < 0 || o->width < 0 || offset + o->width > size) {
            PyErr_SetString(PyExc_ValueError, "Run: a Python block's output lies outside the arena");
            return -1;
        }
        o->arena = arena + offset;
    }
    return 0;
}

static int bind_python(RunObject *r, PyObject *python, double *arena, int64_t size)
{
    if (!list_of(python, r->table.n_blocks, "python must be a list of one entry (None or a spec) per block"))
        return -1;
    r->python = zeroed(r->table.n_blocks, sizeof *r->python);
    if (r->python == NULL)
        return -1;
    for (int64_t b = 0; b < r->table.n_blocks; b++) {
        PyObject *spec = PyList_GET_ITEM(python, b);
        if (spec == Py_None) {
            if (r->kernels[b].output == NULL) {
                PyErr_SetString(PyExc_ValueError, "Run: a block has neither a kernel nor Python methods");
                return -1;
            }
            continue;
        }
        if (bind_python_block(r, r->python + b, spec, arena, size) != 0)
            return -1;
        r->kernels[b].output = NULL; /* its ops go to the call hook */
    }
    return 0;
}

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
    if (bind_tables(r, tables) != 0 || bind_kernels(r, kernels) != 0 || bind_logs(r, logs, counters) != 0)
        return -1;
    Py_ssize_t size;
    double *values = array_data(arena, 1, 'd', &size, "arena");
    if (values == NULL)
        return -1;
    if (size != r->table.header[BLK_H_ARENA]) {
        PyErr_SetString(PyExc_ValueError, "Run: the arena is not of the table's size");
        return -1;
    }
    if (bind_python(r, python, values, size) != 0)
        return -1;
    r->run.table = &r->table;
    r->run.arena = values;
    r->run.kernels = r->kernels;
    r->run.logs = r->logs;
    r->run.hooks = (blk_hooks){r, host_call, host_gil, host_poll, host_end};
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
    r->g = (gil){NULL, signals, !signals || other_threads()};
    int status = blk_run_table(&r->run);
    gil_hold(&r->g);
    const blk_outcome *o = &r->run.outcome;
    if (status == BLK_RUN_FAILED && o->code == BLK_RAISED && r->raised == NULL) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_SystemError, "a kernel returned BLK_RAISED without setting an exception");
        keep_raised(r);
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

static PyTypeObject run_type = {
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
   'update': returns (code, which); 'advance': out receives n rows, returns (code, done, which).
   A kernel that returns BLK_RAISED raises the exception it set. */
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
            code = 0;
            PyErr_Format(PyExc_ValueError, "kind must be 'output', 'update' or 'advance', not '%s'", kind);
        }
        if (code == BLK_RAISED && result != NULL) { /* the exception the kernel set is the call's */
            if (!PyErr_Occurred())
                PyErr_SetString(PyExc_SystemError, "a kernel returned BLK_RAISED without setting an exception");
            Py_CLEAR(result);
        }
    }
    release_views(views, count);
    release_doubles(&state_view);
    release_doubles(&out_view);
    return result;
}

/* library(): {name: address} of the library blocks' kernel functions ("gain_output", ...), from
   the kernel types of library.c. */
static PyObject *library(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    PyObject *found = PyDict_New();
    static const char *phases[] = {"output", "update", "advance"};
    for (const blk_kernel_type *k = blk_library_types; found != NULL && k->name != NULL; k++) {
        void *functions[] = {(void *)(uintptr_t)k->output, (void *)(uintptr_t)k->update,
                             (void *)(uintptr_t)k->advance};
        for (int i = 0; found != NULL && i < 3; i++) {
            if (functions[i] == NULL)
                continue;
            PyObject *address = PyLong_FromVoidPtr(functions[i]);
            PyObject *name = PyUnicode_FromFormat("%s_%s", k->name, phases[i]);
            if (address == NULL || name == NULL || PyDict_SetItem(found, name, address) != 0)
                Py_CLEAR(found);
            Py_XDECREF(address);
            Py_XDECREF(name);
        }
    }
    return found;
}

/* fmu_kernel(): the FMU block's step (its kernel functions and context layout), with
   "model_exchange": the model-exchange loops', "host": the channel's to an isolated FMU. */
static PyObject *fmu_kernel(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    PyObject *found = blk_fmu_block_step();
    PyObject *parts[] = {blk_fmu_me_functions(), blk_fmu_channel_functions()};
    const char *names[] = {"model_exchange", "host"};
    for (int i = 0; i < 2; i++) {
        if (parts[i] == NULL || (found != NULL && PyDict_SetItemString(found, names[i], parts[i]) != 0))
            Py_CLEAR(found);
        Py_XDECREF(parts[i]);
    }
    return found;
}

static PyMethodDef module_methods[] = {
    {"call", call_kernel, METH_VARARGS,
     "call(kind, function, context, t, state, inputs, out, n=0): one kernel call ('output', 'update', 'advance')."},
    {"library", library, METH_NOARGS, "library(): {name: address} of the library blocks' kernels."},
    {"fmu_kernel", fmu_kernel, METH_NOARGS, "fmu_kernel(): the FMU block's kernel functions and context layout."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "_native", "The op-table core's host and single kernel calls (see blocks/csrc).", -1,
    module_methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__native(void)
{
    if (PyType_Ready(&run_type) < 0)
        return NULL;
    PyObject *module = PyModule_Create(&module_def);
    if (module == NULL)
        return NULL;
    Py_INCREF(&run_type);
    if (PyModule_AddObject(module, "Run", (PyObject *)&run_type) != 0 ||
        PyModule_AddIntConstant(module, "ABI", BLK_KERNEL_ABI) != 0 ||
        PyModule_AddStringConstant(module, "EXPORT_RESOURCE", BLK_EXPORT_RESOURCE) != 0 ||
        PyModule_AddObject(module, "EXPORT_FORMAT", Py_BuildValue("(LL)", (long long)BLK_EXPORT_MAGIC,
                                                                  (long long)BLK_EXPORT_VERSION)) != 0 ||
        PyModule_AddObject(module, "EXPORT_LOG_CATEGORIES",
                           Py_BuildValue("(sss)", BLK_LOG_EVENTS, BLK_LOG_WARNING, BLK_LOG_ERROR)) != 0) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
