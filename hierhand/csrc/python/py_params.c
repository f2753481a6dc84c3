/* The controller blocks' parameters (control.h, control_params.c) for Python: each block's
 * numbers as given checked and packed into its law's parameter vector, a bad one a
 * ValueError with the one message the C checks write (an exported FMU writes the same).
 */
#include "py_common.h"

#include "../control.h"

/* A packer's result: a new float64 array of n values filled by pack, or ValueError with its
   message. pack gets the array's data. */
static PyObject *packed(Py_ssize_t n, int (*pack)(void *args, double *out, char *message, size_t size), void *args)
{
    PyObject *np = PyImport_ImportModule("numpy");
    if (np == NULL)
        return NULL;
    PyObject *out = PyObject_CallMethod(np, "empty", "n", n);
    Py_DECREF(np);
    if (out == NULL)
        return NULL;
    Py_buffer view;
    if (hh_py_doubles(out, &view, n, 1, "out") != 0) {
        Py_DECREF(out);
        return NULL;
    }
    char message[512] = "";
    int code = pack(args, (double *)view.buf, message, sizeof message);
    PyBuffer_Release(&view);
    if (code != 0) {
        Py_DECREF(out);
        PyErr_SetString(PyExc_ValueError, message);
        return NULL;
    }
    return out;
}

typedef struct {
    const double *given, *hand;
    double dt;
} pack_args;

static int pack_reflex(void *a, double *out, char *message, size_t size)
{
    pack_args *p = a;
    return hh_reflex_pack(p->given, p->hand, p->dt, out, message, size);
}

static int pack_manip(void *a, double *out, char *message, size_t size)
{
    pack_args *p = a;
    return hh_manip_pack(p->given, p->hand, p->dt, out, message, size);
}

static int pack_suppress(void *a, double *out, char *message, size_t size)
{
    pack_args *p = a;
    return hh_suppress_pack(p->given, p->dt, out, message, size);
}

static int pack_support(void *a, double *out, char *message, size_t size)
{
    pack_args *p = a;
    return hh_support_pack(p->dt, p->hand, out, message, size);
}

/* name(given, hand, dt) -> params, for the packers that take a hand (hand None: none). */
static PyObject *pack_call(PyObject *const *args, Py_ssize_t nargs, const char *name, Py_ssize_t given_n,
                           int takes_hand, Py_ssize_t n_out, int (*pack)(void *, double *, char *, size_t))
{
    held_buffers h = {.held = 0};
    pack_args a = {NULL, NULL, 0.0};
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 3, name) != 0)
        return NULL;
    if ((given_n == 0 || (a.given = hh_py_hold(&h, args[0], given_n, 0, "given")) != NULL) &&
        (!takes_hand || (a.hand = hh_py_hold(&h, args[1], HH_HAND_PARAMS, 0, "hand")) != NULL) &&
        hh_py_double(args[2], &a.dt, "dt") == 0)
        result = packed(n_out, pack, &a);
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_reflex_pack(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return pack_call(args, nargs, "reflex_pack", HH_REFLEX_N_GIVEN, 1, HH_REFLEX_N_PARAMS, pack_reflex);
}

static PyObject *py_manip_pack(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return pack_call(args, nargs, "manip_pack", HH_MANIP_N_GIVEN, 1, HH_MANIP_N_PARAMS, pack_manip);
}

static PyObject *py_suppress_pack(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return pack_call(args, nargs, "suppress_pack", HH_SUPPRESS_N_GIVEN, 0, HH_SUPPRESS_N_PARAMS, pack_suppress);
}

static PyObject *py_support_pack(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return pack_call(args, nargs, "support_pack", 0, 1, 4, pack_support);
}

static PyObject *py_plate_inertia(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    double mass, a, b;
    if (hh_py_nargs(nargs, 3, "plate_inertia") != 0 || hh_py_double(args[0], &mass, "mass") != 0 ||
        hh_py_double(args[1], &a, "a") != 0 || hh_py_double(args[2], &b, "b") != 0)
        return NULL;
    return PyFloat_FromDouble(hh_plate_inertia(mass, a, b));
}

PyMethodDef hh_py_param_methods[] = {
    {"reflex_pack", HH_PY_FASTCALL(py_reflex_pack),
     "reflex_pack(given, hand, dt) -> params: GraspReflex's parameters (REFLEX_G_*) checked and packed "
     "(REFLEX_P_*) for the hand vector; ValueError naming a bad one."},
    {"manip_pack", HH_PY_FASTCALL(py_manip_pack),
     "manip_pack(given, hand, dt) -> params: ManipulationPD's parameters (MANIP_G_*) checked and packed."},
    {"suppress_pack", HH_PY_FASTCALL(py_suppress_pack),
     "suppress_pack(given, None, period) -> params: Suppresser's parameters (SUPPRESS_G_*) checked and packed."},
    {"support_pack", HH_PY_FASTCALL(py_support_pack),
     "support_pack(None, hand, until) -> [fx, fy, torque, until]: ObjectSupport's context."},
    {"plate_inertia", HH_PY_FASTCALL(py_plate_inertia),
     "plate_inertia(mass, a, b): m (a^2 + b^2) / 12, the inertia of an object whose hand file gives none."},
    {NULL, NULL, 0, NULL},
    {NULL, NULL, 0, NULL},
};
