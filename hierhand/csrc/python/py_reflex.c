/* The grasping reflex's law (control.h, reflex.c) for Python: GraspReflex's calls (one per
 * output or update) and the internal forces of hierhand.control.internal_forces.
 *
 * Arguments are packed parameters, inputs and output arrays, all float64 buffers the
 * caller allocates (the conventions of py_common.h). The law's status codes become
 * ValueErrors with the messages the block has always raised.
 */
#include "py_common.h"

#include <limits.h>

#include "../control.h"

static PyObject *reflex_error(int code)
{
    if (code == HH_REFLEX_COINCIDENT)
        PyErr_SetString(PyExc_ValueError, "internal forces are undefined: all contact points coincide");
    else if (code == HH_REFLEX_NO_PERIOD)
        PyErr_SetString(PyExc_ValueError, "GraspReflex needs an explicit period (the paper's is 1 ms)");
    else
        PyErr_Format(PyExc_SystemError, "GraspReflex: unknown status %d", code);
    return NULL;
}

/* reflex_failure(code): the exception the reflex functions raise for a status code (for
 * the error factory of GraspReflex's kernel, so that each message has one definition). */
static PyObject *py_reflex_failure(PyObject *module, PyObject *arg)
{
    (void)module;
    int overflow;
    long code = PyLong_AsLongAndOverflow(arg, &overflow);
    if (code == -1 && PyErr_Occurred())
        return NULL;
    if (overflow || code < INT_MIN || code > INT_MAX || code == HH_REFLEX_OK) {
        PyErr_Format(PyExc_ValueError, "reflex_failure: %R is not a failure code", arg);
        return NULL;
    }
    PyObject *type, *value, *traceback;
    reflex_error((int)code);
    PyErr_Fetch(&type, &value, &traceback);
    PyErr_NormalizeException(&type, &value, &traceback);
    Py_XDECREF(type);
    Py_XDECREF(traceback);
    return value;
}

/* An input port of the reflex, of ``width`` values. */
static const double *reflex_input(held_buffers *h, PyObject *obj, Py_ssize_t width, const char *port)
{
    const double *values = hh_py_hold(h, obj, -1, 0, port);
    if (values != NULL && hh_py_last_count(h) != width) {
        PyErr_Format(PyExc_ValueError, "GraspReflex: input '%s' must have %zd entries", port, width);
        return NULL;
    }
    return values;
}

/* params, state, tip, normal, fn: the arguments every reflex function starts with. */
static int reflex_arguments(held_buffers *h, PyObject *const *args, const double **params, const double **state,
                            hh_reflex_inputs *in)
{
    if ((*params = hh_py_hold(h, args[0], HH_REFLEX_N_PARAMS, 0, "params")) == NULL)
        return -1;
    if ((*state = hh_py_hold(h, args[1], -1, 0, "state")) == NULL)
        return -1;
    if (hh_py_last_count(h) != HH_REFLEX_N_STATE) {
        PyErr_SetString(PyExc_ValueError, "GraspReflex: state must have 7 entries [scale, handed(3), hold(3)]");
        return -1;
    }
    if ((in->tip = reflex_input(h, args[2], 9, "tip")) == NULL ||
        (in->normal = reflex_input(h, args[3], 6, "normal")) == NULL ||
        (in->fn = reflex_input(h, args[4], 3, "fn")) == NULL)
        return -1;
    in->share = NULL;
    return 0;
}

static PyObject *py_reflex_directions(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *params, *state;
    hh_reflex_inputs in;
    double *g, *flags;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 7, "reflex_directions") != 0)
        return NULL;
    if (reflex_arguments(&h, args, &params, &state, &in) == 0 &&
        (g = hh_py_hold(&h, args[5], 6, 1, "g")) != NULL &&
        (flags = hh_py_hold(&h, args[6], 6, 1, "flags")) != NULL) {
        int grasp[3], touching[3];
        int code = hh_reflex_directions(params, state, &in, (double(*)[2])g, grasp, touching);
        if (code == HH_REFLEX_OK) {
            for (int i = 0; i < 3; i++) {
                flags[i] = grasp[i];
                flags[3 + i] = touching[i];
            }
            result = Py_NewRef(Py_None);
        } else {
            reflex_error(code);
        }
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_reflex_forces(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *params, *state;
    hh_reflex_inputs in;
    double *f, *grasp_flags;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 7, "reflex_forces") != 0)
        return NULL;
    if (reflex_arguments(&h, args, &params, &state, &in) == 0 &&
        (f = hh_py_hold(&h, args[5], 6, 1, "f")) != NULL &&
        (grasp_flags = hh_py_hold(&h, args[6], 3, 1, "grasp")) != NULL) {
        double g[3][2];
        int grasp[3], touching[3];
        int code = hh_reflex_directions(params, state, &in, g, grasp, touching);
        if (code == HH_REFLEX_OK) {
            hh_reflex_forces(params, state, (const double(*)[2])g, touching, (double(*)[2])f);
            for (int i = 0; i < 3; i++)
                grasp_flags[i] = grasp[i];
            result = Py_NewRef(Py_None);
        } else {
            reflex_error(code);
        }
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_reflex_output(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    ModelObject *model;
    const double *params, *state, *q;
    hh_reflex_inputs in;
    double *out;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 8, "reflex_output") != 0 || (model = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if (reflex_arguments(&h, args + 1, &params, &state, &in) == 0 &&
        (q = reflex_input(&h, args[6], 9, "q")) != NULL &&
        (out = hh_py_hold(&h, args[7], HH_REFLEX_N_OUT, 1, "out")) != NULL) {
        int code = hh_reflex_output(&model->model, params, state, &in, q, out);
        result = code == HH_REFLEX_OK ? Py_NewRef(Py_None) : reflex_error(code);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_reflex_update(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *params, *state, *ft;
    hh_reflex_inputs in;
    double *next;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 8, "reflex_update") != 0)
        return NULL;
    if (reflex_arguments(&h, args, &params, &state, &in) == 0 &&
        (ft = reflex_input(&h, args[5], 3, "ft")) != NULL &&
        (in.share = reflex_input(&h, args[6], 3, "share")) != NULL &&
        (next = hh_py_hold(&h, args[7], HH_REFLEX_N_STATE, 1, "next")) != NULL) {
        int code = hh_reflex_update(params, state, &in, ft, next);
        result = code == HH_REFLEX_OK ? Py_NewRef(Py_None) : reflex_error(code);
    }
    hh_py_release_all(&h);
    return result;
}

/* points (k x 2, k >= 1) and a second buffer of as many values. */
static int points_and(held_buffers *h, PyObject *points, PyObject *other, int writable, const char *what,
                      const double **p, double **o, int *k)
{
    if ((*p = hh_py_hold(h, points, -1, 0, "points")) == NULL)
        return -1;
    Py_ssize_t n = hh_py_last_count(h);
    if (n == 0 || n % 2 != 0 || n / 2 > INT_MAX) {
        PyErr_Format(PyExc_ValueError, "points must hold k x 2 values (k >= 1), got %zd values", n);
        return -1;
    }
    *k = (int)(n / 2);
    return (*o = hh_py_hold(h, other, n, writable, what)) == NULL ? -1 : 0;
}

static PyObject *py_project_internal(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *points;
    double *f, *out;
    int k;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 3, "project_internal") != 0)
        return NULL;
    if (points_and(&h, args[0], args[1], 0, "f", &points, &f, &k) == 0 &&
        (out = hh_py_hold(&h, args[2], 2 * (Py_ssize_t)k, 1, "out")) != NULL) {
        hh_project_internal(k, points, f, out);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_centroid_squeeze(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *points;
    double *g, rtol;
    int k;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 3, "centroid_squeeze") != 0 || hh_py_double(args[1], &rtol, "coincident_rtol") != 0)
        return NULL;
    if (points_and(&h, args[0], args[2], 1, "g", &points, &g, &k) == 0) {
        int code = hh_centroid_squeeze(k, points, rtol, g);
        result = code == HH_REFLEX_OK ? Py_NewRef(Py_None) : reflex_error(code);
    }
    hh_py_release_all(&h);
    return result;
}

PyMethodDef hh_py_reflex_methods[] = {
    {"reflex_directions", HH_PY_FASTCALL(py_reflex_directions),
     "reflex_directions(params, state, tip, normal, fn, g, flags): the internal force per finger at unit scale "
     "into g (3x2) and the grasp and touching flags (0/1) into flags (6)."},
    {"reflex_forces", HH_PY_FASTCALL(py_reflex_forces),
     "reflex_forces(params, state, tip, normal, fn, f, grasp): fingertip force commands (3x2) and the grasp "
     "flags (3)."},
    {"reflex_output", HH_PY_FASTCALL(py_reflex_output),
     "reflex_output(model, params, state, tip, normal, fn, q, out): tau_g (9), |f_i| (3), grasp flags (3) "
     "into out (REFLEX_N_OUT)."},
    {"reflex_failure", py_reflex_failure, METH_O,
     "reflex_failure(code): the exception (not raised) the reflex functions raise for a failure status."},
    {"reflex_update", HH_PY_FASTCALL(py_reflex_update),
     "reflex_update(params, state, tip, normal, fn, ft, share, next): the next state (4) into next."},
    {"project_internal", HH_PY_FASTCALL(py_project_internal),
     "project_internal(points, f, out): the internal part (I - G^+ G) f of the forces f (k x 2) at the points "
     "(k x 2) into out (k x 2)."},
    {"centroid_squeeze", HH_PY_FASTCALL(py_centroid_squeeze),
     "centroid_squeeze(points, coincident_rtol, g): the squeeze toward the centroid of the points (k x 2), "
     "longest row 1, into g (k x 2); ValueError when the points coincide."},
    {NULL, NULL, 0, NULL},
};
