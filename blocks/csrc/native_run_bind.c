/* A Run's arguments (native_run.h) checked and bound into the core's structs (core.h): the
 * ten tables, the kernel rows, the log buffers and counters, the arena, and the Python
 * blocks' specs (their methods, input mappings and the arena slices of their ports). The
 * arrays stay Python's: the Run keeps them alive and the core reads and writes their data
 * in place. A wrong argument is a TypeError or ValueError that says which and why. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <string.h>

#include "native_run.h"

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
        if (k[4] == RUN_STATE_OF_LIST) { /* the block's state in the states list: a flat float64 array */
            Py_ssize_t size;
            if (b >= PyList_GET_SIZE(r->states)) {
                PyErr_SetString(PyExc_ValueError, "Run: a kernel row names a state the states list lacks");
                return -1;
            }
            kb->state = array_data(PyList_GET_ITEM(r->states, b), 1, 'd', &size, "a kernel's state");
            if (kb->state == NULL)
                return -1;
        } else {
            kb->state = (double *)(intptr_t)k[4];
        }
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

int run_bind(RunObject *r, PyObject *tables, PyObject *arena, PyObject *logs, PyObject *counters, PyObject *kernels,
             PyObject *python)
{
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
    return 0;
}
