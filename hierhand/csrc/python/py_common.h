/* Shared pieces of the Python binding (the extension module hierhand._native).
 *
 * The binding uses only the stable ABI of Python 3.11 (Py_LIMITED_API, set by setup.py): its
 * types are heap types made from specs, objects are reached through functions, never their
 * structs, and arrays through the buffer protocol. One build serves every Python >= 3.11. */
#ifndef HIERHAND_PY_COMMON_H
#define HIERHAND_PY_COMMON_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "../hand.h"

/* A packed hand (hh_model) with the scratch its steps from Python use. The scratch makes
 * a Model unsafe to step from two threads at once; those functions hold the GIL
 * throughout, and the compiled kernel steps with a context of its run instead (its own
 * model and scratch, py_kernel_types.c). */
typedef struct {
    PyObject_HEAD
    hh_model model;
    hh_work work;
} ModelObject;

extern PyType_Spec hh_py_model_spec;
extern PyTypeObject *hh_py_model_type; /* made from hh_py_model_spec when the module loads */

/* A kernel's context built by its type's constructor from a record (py_kernel_types.c). */
extern PyType_Spec hh_py_context_spec;

/* A new object of the heap type ``type`` (zeroed); NULL with an exception. */
PyObject *hh_py_alloc(PyTypeObject *type);

/* Free ``self``, an object of a heap type, and the reference it held to its type. */
void hh_py_free(PyObject *self);

/* The name of ``obj``'s type as Python writes it ("numpy.ndarray", "list"): a new reference. */
PyObject *hh_py_type_name(PyObject *obj);

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

/* a (n values, named a_name) and out (as many, writable) held in h: the elementwise functions' arguments. */
int hh_py_elementwise(held_buffers *h, PyObject *a, const char *a_name, PyObject *out, const double **values,
                      double **result, Py_ssize_t *n);

/* fn of every value of args[0] (named what) into args[1], for the function ``name``. */
PyObject *hh_py_map_values(PyObject *const *args, Py_ssize_t nargs, const char *name, const char *what,
                          double (*fn)(double));

/* A METH_FASTCALL entry of a method table. */
#define HH_PY_FASTCALL(function) (PyCFunction)(void (*)(void))(function), METH_FASTCALL

/* The module's functions, one table per concept (module.c joins them). */
extern PyMethodDef hh_py_model_methods[]; /* py_model.c: the hand vector, queries */
extern PyMethodDef hh_py_plant_methods[]; /* py_plant.c: stepping */
extern PyMethodDef hh_py_reflex_methods[]; /* py_reflex.c: the grasping reflex, internal forces */
extern PyMethodDef hh_py_manipulation_methods[]; /* py_manipulation.c: the PD, trajectories, kinematics */
extern PyMethodDef hh_py_suppresser_methods[]; /* py_suppresser.c: the suppresser */
extern PyMethodDef hh_py_param_methods[]; /* py_params.c: the blocks' parameters checked and packed */
extern PyMethodDef hh_py_kernel_methods[]; /* py_kernel_types.c: the blocks' compiled kernels */

/* LAYOUTS, RECORD_LAYOUTS, INPUT_PORTS and DIMENSIONS, layouts.h's tables, into the module
 * (py_layouts.c); -1 on error. */
int hh_py_add_layouts(PyObject *module);

#endif
