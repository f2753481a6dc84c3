/* Argument helpers of the Python binding. */
#include "py_common.h"

#include <string.h>

PyTypeObject *hh_py_model_type;

PyObject *hh_py_alloc(PyTypeObject *type)
{
    return PyType_GenericAlloc(type, 0);
}

void hh_py_free(PyObject *self)
{
    PyTypeObject *type = Py_TYPE(self);
    PyObject_Free(self);
    Py_DECREF(type);
}

PyObject *hh_py_type_name(PyObject *obj)
{
    PyObject *type = (PyObject *)Py_TYPE(obj);
    PyObject *module = PyObject_GetAttrString(type, "__module__");
    PyObject *name = PyObject_GetAttrString(type, "__qualname__");
    PyObject *full = NULL;
    if (module != NULL && name != NULL)
        full = PyUnicode_Check(module) && PyUnicode_CompareWithASCIIString(module, "builtins") != 0
                   ? PyUnicode_FromFormat("%U.%U", module, name)
                   : Py_NewRef(name);
    Py_XDECREF(module);
    Py_XDECREF(name);
    return full;
}

/* TypeError: "<what> <text>, got <obj's type>". */
static void type_error(const char *what, const char *text, PyObject *obj)
{
    PyObject *name = hh_py_type_name(obj);
    if (name != NULL) {
        PyErr_Format(PyExc_TypeError, "%s %s, got %.100U", what, text, name);
        Py_DECREF(name);
    }
}

ModelObject *hh_py_model(PyObject *obj, const char *what)
{
    if (!PyObject_TypeCheck(obj, hh_py_model_type)) {
        type_error(what, "must be a hierhand._native.Model", obj);
        return NULL;
    }
    return (ModelObject *)obj;
}

int hh_py_doubles(PyObject *obj, Py_buffer *view, Py_ssize_t n, int writable, const char *what)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) != 0) {
        PyErr_Clear();
        type_error(what, writable ? "must be a C-contiguous writable float64 array" : "must be a C-contiguous float64 array",
                   obj);
        return -1;
    }
    const char *format = view->format;
    if (format != NULL && (format[0] == '@' || format[0] == '=' || format[0] == '<'))
        format++;
    if (view->itemsize != 8 || format == NULL || strcmp(format, "d") != 0) {
        PyErr_Format(PyExc_TypeError, "%s must hold float64 values (format 'd'), got format '%s'", what,
                     view->format ? view->format : "?");
        PyBuffer_Release(view);
        return -1;
    }
    if (n >= 0 && view->len != n * 8) {
        PyErr_Format(PyExc_ValueError, "%s must hold %zd values, got %zd", what, n, view->len / 8);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

int hh_py_double(PyObject *obj, double *out, const char *what)
{
    double x = PyFloat_AsDouble(obj);
    if (x == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        type_error(what, "must be a number", obj);
        return -1;
    }
    *out = x;
    return 0;
}

int hh_py_nargs(Py_ssize_t nargs, Py_ssize_t expected, const char *function)
{
    if (nargs != expected) {
        PyErr_Format(PyExc_TypeError, "%s() takes %zd arguments, got %zd", function, expected, nargs);
        return -1;
    }
    return 0;
}

double *hh_py_hold(held_buffers *h, PyObject *obj, Py_ssize_t n, int writable, const char *what)
{
    if (h->held == HH_PY_MOST_BUFFERS) {
        PyErr_SetString(PyExc_SystemError, "hierhand._native: too many buffers in one call");
        return NULL;
    }
    Py_buffer *view = &h->view[h->held];
    if (hh_py_doubles(obj, view, n, writable, what) != 0)
        return NULL;
    h->held += 1;
    return view->buf;
}

Py_ssize_t hh_py_last_count(const held_buffers *h)
{
    return h->view[h->held - 1].len / (Py_ssize_t)sizeof(double);
}

void hh_py_release_all(held_buffers *h)
{
    while (h->held > 0)
        PyBuffer_Release(&h->view[--h->held]);
}

int hh_py_finger(PyObject *obj, int *finger)
{
    long f = PyLong_AsLong(obj);
    if (f == -1 && PyErr_Occurred())
        return -1;
    if (f < 0 || f >= HH_FINGERS) {
        PyErr_Format(PyExc_ValueError, "finger must be 0, 1 or 2, got %ld", f);
        return -1;
    }
    *finger = (int)f;
    return 0;
}

int hh_py_elementwise(held_buffers *h, PyObject *a, const char *a_name, PyObject *out, const double **values,
                      double **result, Py_ssize_t *n)
{
    if ((*values = hh_py_hold(h, a, -1, 0, a_name)) == NULL)
        return -1;
    *n = hh_py_last_count(h);
    return (*result = hh_py_hold(h, out, *n, 1, "out")) == NULL ? -1 : 0;
}

PyObject *hh_py_map_values(PyObject *const *args, Py_ssize_t nargs, const char *name, const char *what,
                          double (*fn)(double))
{
    held_buffers h = {.held = 0};
    const double *values;
    double *out;
    Py_ssize_t n;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 2, name) != 0)
        return NULL;
    if (hh_py_elementwise(&h, args[0], what, args[1], &values, &out, &n) == 0) {
        for (Py_ssize_t i = 0; i < n; i++)
            out[i] = fn(values[i]);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}
