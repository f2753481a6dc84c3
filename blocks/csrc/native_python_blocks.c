/* A Python block's ops in a Run (native_run.h): what the core's call hook does for a block
 * without a kernel.
 *
 * Inputs whose values in the arena changed since the block last saw them get a new array
 * in its input mapping (or the old one overwritten when nobody else holds it); its
 * output() result is checked and the ports of the step copied into the arena; update()
 * sets its state or raises EndRun (the request to end the run, state and all); advance()
 * goes through blocks/engine/python_blocks.py. An exception is kept for the outcome
 * (BLK_RAISED). The rules are python_blocks.py's; an output that fails the fast check goes
 * there for its message.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <string.h>

#include "native_run.h"

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
        return run_keep_raised(r);
    PyObject *out = call_with_time(b->output, t, PyList_GET_ITEM(r->states, b->state), b->inputs);
    if (out == NULL)
        return run_keep_raised(r);
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
    return ok ? 0 : run_keep_raised(r);
}

static int py_update(RunObject *r, py_block *b, double t)
{
    if (refresh(r, b) != 0)
        return run_keep_raised(r);
    PyObject *state = call_with_time(b->update, t, PyList_GET_ITEM(r->states, b->state), b->inputs);
    if (state != NULL) {
        PyList_SetItem(r->states, b->state, state);
        return 0;
    }
    if (!PyErr_ExceptionMatches(r->end_run))
        return run_keep_raised(r);
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
        return run_keep_raised(r);
    }
    Py_XSETREF(b->ended, end);
    return BLK_END_RUN;
}

static int py_advance(RunObject *r, py_block *b, int64_t block, double t, int n, int *done)
{
    if (refresh(r, b) != 0)
        return run_keep_raised(r);
    PyObject *result = PyObject_CallMethod(r->side, "advance", "ndi", (Py_ssize_t)block, t, n);
    if (result == NULL)
        return run_keep_raised(r);
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
        return run_keep_raised(r);
    return error == Py_None ? 0 : BLK_RAISED;
}

int run_python_op(RunObject *r, int64_t op, double t, int n, int *done)
{
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
