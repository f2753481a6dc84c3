/* Argument helpers of the Python binding. */
#include "py_common.h"

#include <string.h>

ModelObject *hh_py_model(PyObject *obj, const char *what)
{
    if (!PyObject_TypeCheck(obj, &hh_py_model_type)) {
        PyErr_Format(PyExc_TypeError, "%s must be a hierhand._native.Model, got %.100s", what, Py_TYPE(obj)->tp_name);
        return NULL;
    }
    return (ModelObject *)obj;
}

int hh_py_doubles(PyObject *obj, Py_buffer *view, Py_ssize_t n, int writable, const char *what)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) != 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s must be a C-contiguous%s float64 array, got %.100s", what,
                     writable ? " writable" : "", Py_TYPE(obj)->tp_name);
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
        PyErr_Format(PyExc_TypeError, "%s must be a number, got %.100s", what, Py_TYPE(obj)->tp_name);
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
