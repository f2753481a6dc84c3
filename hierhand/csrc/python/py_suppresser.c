/* The suppresser's law (control.h, suppresser.c) for Python: Suppresser's calls and the
 * functions of hierhand.control (sigmoid, suppress, finger_shares), for any number of joints.
 * Arguments are float64 buffers the caller allocates (the conventions of py_common.h).
 */
#include "py_common.h"

#include "../control.h"

static PyObject *py_suppress(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *params, *tau_g, *g = NULL, *tau_m, *tau_ff;
    double *out;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 6, "suppress") != 0)
        return NULL;
    if ((params = hh_py_hold(&h, args[0], HH_SUPPRESS_N_PARAMS, 0, "params")) != NULL &&
        (tau_g = hh_py_hold(&h, args[1], HH_JOINTS, 0, "tau_g")) != NULL &&
        (args[2] == Py_None || (g = hh_py_hold(&h, args[2], HH_JOINTS, 0, "g")) != NULL) &&
        (tau_m = hh_py_hold(&h, args[3], HH_JOINTS, 0, "tau_m")) != NULL &&
        (tau_ff = hh_py_hold(&h, args[4], HH_JOINTS, 0, "tau_ff")) != NULL &&
        (out = hh_py_hold(&h, args[5], HH_SUPPRESS_N_OUT, 1, "out")) != NULL) {
        hh_suppress(params, tau_g, g, tau_m, tau_ff, out);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_suppress_update(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *params, *state, *tau_g, *tau_m;
    double *next;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 5, "suppress_update") != 0)
        return NULL;
    if ((params = hh_py_hold(&h, args[0], HH_SUPPRESS_N_PARAMS, 0, "params")) != NULL &&
        (state = hh_py_hold(&h, args[1], HH_JOINTS, 0, "state")) != NULL &&
        (tau_g = hh_py_hold(&h, args[2], HH_JOINTS, 0, "tau_g")) != NULL &&
        (tau_m = hh_py_hold(&h, args[3], HH_JOINTS, 0, "tau_m")) != NULL &&
        (next = hh_py_hold(&h, args[4], HH_JOINTS, 1, "next")) != NULL) {
        hh_suppress_update(params, state, tau_g, tau_m, next);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_sigmoid(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return hh_py_map_values(args, nargs, "sigmoid", "x", hh_sigmoid);
}

static PyObject *py_suppress_joints(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *tau_g, *tau_m, *s_a, *s_b;
    double *out;
    Py_ssize_t n;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 6, "suppress_joints") != 0)
        return NULL;
    long mode = PyLong_AsLong(args[4]);
    if (mode == -1 && PyErr_Occurred())
        return NULL;
    if (mode != HH_SUPPRESS_PASS && mode != HH_SUPPRESS_MAGNITUDE && mode != HH_SUPPRESS_SIGNED) {
        PyErr_Format(PyExc_ValueError, "mode must be %d (pass), %d (magnitude) or %d (signed), got %ld",
                     HH_SUPPRESS_PASS, HH_SUPPRESS_MAGNITUDE, HH_SUPPRESS_SIGNED, mode);
        return NULL;
    }
    if (hh_py_elementwise(&h, args[0], "tau_g", args[5], &tau_g, &out, &n) == 0 &&
        (tau_m = hh_py_hold(&h, args[1], n, 0, "tau_m")) != NULL && (s_a = hh_py_hold(&h, args[2], n, 0, "S_a")) != NULL &&
        (s_b = hh_py_hold(&h, args[3], n, 0, "S_b")) != NULL) {
        for (Py_ssize_t i = 0; i < n; i++)
            out[i] = hh_suppressed(tau_g[i], hh_suppression_input(tau_g[i], tau_m[i], (double)mode), s_a[i], s_b[i],
                                   (double)mode);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_finger_shares(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *tau_g, *tau_g_eff;
    double *share;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 3, "finger_shares") != 0)
        return NULL;
    if ((tau_g = hh_py_hold(&h, args[0], HH_JOINTS, 0, "tau_g")) != NULL &&
        (tau_g_eff = hh_py_hold(&h, args[1], HH_JOINTS, 0, "tau_g_eff")) != NULL &&
        (share = hh_py_hold(&h, args[2], HH_FINGERS, 1, "share")) != NULL) {
        hh_finger_shares(tau_g, tau_g_eff, share);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

PyMethodDef hh_py_suppresser_methods[] = {
    {"suppress", HH_PY_FASTCALL(py_suppress),
     "suppress(params, tau_g, g, tau_m, tau_ff, out): tau (9), tau_g_eff (9) and share (3) into out (SUPPRESS_N_OUT); "
     "g: the low-passed suppression inputs (9), or None for the static law."},
    {"suppress_update", HH_PY_FASTCALL(py_suppress_update),
     "suppress_update(params, state, tau_g, tau_m, next): the low-passed suppression inputs (9) into next."},
    {"sigmoid", HH_PY_FASTCALL(py_sigmoid), "sigmoid(x, out): the logistic function of every value of x into out."},
    {"suppress_joints", HH_PY_FASTCALL(py_suppress_joints),
     "suppress_joints(tau_g, tau_m, S_a, S_b, mode, out): the suppressed grasping torque of n joints (n values "
     "each) into out, mode SUPPRESS_PASS, _MAGNITUDE or _SIGNED."},
    {"finger_shares", HH_PY_FASTCALL(py_finger_shares),
     "finger_shares(tau_g, tau_g_eff, share): per finger (3) the share of its grasping torque the suppresser "
     "lets through."},
    {NULL, NULL, 0, NULL},
};
