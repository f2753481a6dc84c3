/* Shared pieces of the Python binding (the extension module hierhand._native). */
#ifndef HIERHAND_PY_COMMON_H
#define HIERHAND_PY_COMMON_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "../hand.h"

/* A packed hand (hh_model) with the scratch its steps from Python use. The scratch makes
 * a Model unsafe to step from two threads at once; those functions hold the GIL
 * throughout, and the compiled kernel steps with a context of its run instead (its own
 * model and scratch, py_kernels.c). */
typedef struct {
    PyObject_HEAD
    hh_model model;
    hh_work work;
} ModelObject;

extern PyTypeObject hh_py_model_type;

/* A kernel's context built by its type's constructor from a record (py_kernels.c). */
extern PyTypeObject hh_py_context_type;

/* ``obj`` as a Model, or NULL with TypeError naming ``what``. */
ModelObject *hh_py_model(PyObject *obj, const char *what);

/* Acquire a C-contiguous float64 buffer of exactly ``n`` values (``n < 0``: any count);
 * 0 on success, -1 with TypeError/ValueError naming ``what``. Release with
 * PyBuffer_Release. */
int hh_py_doubles(PyObject *obj, Py_buffer *view, Py_ssize_t n, int writable, const char *what);

enum { HH_PY_MOST_BUFFERS = 12 };

/* The buffers one call holds, released together: start with {.held = 0}. */
typedef struct {
    Py_buffer view[HH_PY_MOST_BUFFERS];
    int held;
} held_buffers;

/* ``obj`` as ``n`` float64 values (n < 0: any count), held in ``h``; NULL on error. */
double *hh_py_hold(held_buffers *h, PyObject *obj, Py_ssize_t n, int writable, const char *what);

/* The count of float64 values of the buffer held last. */
Py_ssize_t hh_py_last_count(const held_buffers *h);

void hh_py_release_all(held_buffers *h);

/* A finger index argument (0, 1 or 2); -1 with ValueError or TypeError. */
int hh_py_finger(PyObject *obj, int *finger);

/* A float argument; -1 with TypeError on failure (check PyErr_Occurred). */
int hh_py_double(PyObject *obj, double *out, const char *what);

/* Check the argument count of a METH_FASTCALL function. */
int hh_py_nargs(Py_ssize_t nargs, Py_ssize_t expected, const char *function);

extern PyMethodDef hh_py_model_methods[]; /* py_model.c: the hand vector, queries */
extern PyMethodDef hh_py_plant_methods[]; /* py_plant.c: stepping */
extern PyMethodDef hh_py_control_methods[]; /* py_control.c: the controllers */
extern PyMethodDef hh_py_kernel_methods[]; /* py_kernels.c: the blocks' compiled kernels */

/* Add the controllers' layout constants to ``layout`` (py_control.c); -1 on error. */
int hh_py_control_layout(PyObject *layout);

#endif
