/* One kernel function called from Python, outside a run, for tests and tools: call() with
 * numpy arrays for the state, inputs and outputs, and library(), the addresses of the
 * library's kernel functions (library.c) by name. A run calls kernels through the core
 * (native_run.h); this is the same call, one at a time. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <string.h>

#include "blocks_kernel.h"
#include "library.h"
#include "native_kernel_call.h"

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
PyObject *blk_call_kernel(PyObject *module, PyObject *args)
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
PyObject *blk_library_addresses(PyObject *module, PyObject *unused)
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
