/* The controllers' laws (control.h) for Python: one native call per output or update.
 *
 * Arguments are the block's packed parameters, its inputs and an output array, all
 * float64 buffers the caller allocates; a Model (Hand.native) gives the finger geometry.
 * A buffer that is not C-contiguous float64 is a TypeError (the Python side then
 * converts it), one of the wrong length a ValueError. The laws' status codes become
 * ValueErrors with the messages the blocks have always raised, except the manipulation
 * output's, which it returns (the block then names the finger and the target).
 */
#include "py_common.h"

#include <math.h>

#include "../control.h"

/* -- grasping reflex ------------------------------------------------------------------------ */

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
        PyErr_SetString(PyExc_ValueError, "GraspReflex: state must have 4 entries [scale, handed(3)]");
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

/* -- manipulation PD ------------------------------------------------------------------------ */

/* waypoints (3 x capacity x 4) and meta (3 x 2), checked: counts whole numbers within the
 * capacity, interpolations known. */
static int manip_trajectories(held_buffers *h, PyObject *waypoints, PyObject *meta, hh_trajectories *tr)
{
    if ((tr->waypoints = hh_py_hold(h, waypoints, -1, 0, "waypoints")) == NULL)
        return -1;
    Py_ssize_t values = hh_py_last_count(h);
    Py_ssize_t row = HH_FINGERS * HH_MANIP_W_COLS;
    if (values == 0 || values % row != 0) {
        PyErr_Format(PyExc_ValueError, "waypoints must hold 3 x n x 4 values (n >= 1), got %zd values", values);
        return -1;
    }
    tr->capacity = (long)(values / row);
    if ((tr->meta = hh_py_hold(h, meta, HH_FINGERS * HH_MANIP_N_META, 0, "meta")) == NULL)
        return -1;
    for (int f = 0; f < HH_FINGERS; f++) {
        double count = tr->meta[f * HH_MANIP_N_META + HH_MANIP_M_COUNT];
        double interp = tr->meta[f * HH_MANIP_N_META + HH_MANIP_M_INTERP];
        if (!(count >= 0.0 && count <= (double)tr->capacity && count == floor(count))) {
            PyErr_Format(PyExc_ValueError, "meta: finger %d's waypoint count must be a whole number in [0, %ld]", f,
                         tr->capacity);
            return -1;
        }
        if (interp != HH_MANIP_INTERP_LINEAR && interp != HH_MANIP_INTERP_MINJERK) {
            PyErr_Format(PyExc_ValueError, "meta: finger %d's interpolation must be %d (linear) or %d (minjerk)", f,
                         HH_MANIP_INTERP_LINEAR, HH_MANIP_INTERP_MINJERK);
            return -1;
        }
    }
    return 0;
}

/* waypoints, meta, finger, t of the trajectory queries; the finger must have waypoints. */
static int trajectory_query(held_buffers *h, PyObject *const *args, hh_trajectories *tr, int *finger, double *t)
{
    if (hh_py_finger(args[2], finger) != 0 || hh_py_double(args[3], t, "t") != 0 ||
        manip_trajectories(h, args[0], args[1], tr) != 0)
        return -1;
    if (tr->meta[*finger * HH_MANIP_N_META + HH_MANIP_M_COUNT] == 0.0) {
        PyErr_Format(PyExc_ValueError, "finger %d has no trajectory", *finger);
        return -1;
    }
    return 0;
}

static PyObject *py_trajectory_sample(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    hh_trajectories tr;
    int f;
    double t;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 4, "trajectory_sample") != 0)
        return NULL;
    if (trajectory_query(&h, args, &tr, &f, &t) == 0) {
        double pose[3];
        hh_trajectory_sample(&tr, f, t, pose);
        result = Py_BuildValue("(ddd)", pose[0], pose[1], pose[2]);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_trajectory_moving(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    hh_trajectories tr;
    int f;
    double t;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 4, "trajectory_moving") != 0)
        return NULL;
    if (trajectory_query(&h, args, &tr, &f, &t) == 0)
        result = PyBool_FromLong(hh_trajectory_moving(&tr, f, t));
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_ik_near(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *model;
    int f;
    double reach_rtol, x, y, phi, ref[3], q[3];
    if (hh_py_nargs(nargs, 9, "ik_near") != 0 || (model = hh_py_model(args[0], "model")) == NULL ||
        hh_py_finger(args[1], &f) != 0 || hh_py_double(args[2], &reach_rtol, "reach_rtol") != 0 ||
        hh_py_double(args[3], &x, "x") != 0 || hh_py_double(args[4], &y, "y") != 0 ||
        hh_py_double(args[5], &phi, "phi") != 0 || hh_py_double(args[6], &ref[0], "r0") != 0 ||
        hh_py_double(args[7], &ref[1], "r1") != 0 || hh_py_double(args[8], &ref[2], "r2") != 0)
        return NULL;
    if (!hh_ik_near(model->model.fingers[f], reach_rtol, x, y, phi, ref, q))
        return Py_BuildValue("(Oddd)", Py_False, 0.0, 0.0, 0.0);
    return Py_BuildValue("(Oddd)", Py_True, q[0], q[1], q[2]);
}

static PyObject *py_manipulation_output(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    ModelObject *model;
    hh_trajectories tr;
    double t;
    const double *params, *q, *qd, *fn, *support;
    double *out;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 10, "manipulation_output") != 0 || (model = hh_py_model(args[0], "model")) == NULL ||
        hh_py_double(args[4], &t, "t") != 0)
        return NULL;
    if ((params = hh_py_hold(&h, args[1], HH_MANIP_N_PARAMS, 0, "params")) != NULL &&
        manip_trajectories(&h, args[2], args[3], &tr) == 0 &&
        (q = hh_py_hold(&h, args[5], HH_JOINTS, 0, "q")) != NULL &&
        (qd = hh_py_hold(&h, args[6], HH_JOINTS, 0, "qd")) != NULL &&
        (fn = hh_py_hold(&h, args[7], HH_FINGERS, 0, "fn")) != NULL &&
        (support = hh_py_hold(&h, args[8], 3, 0, "support")) != NULL &&
        (out = hh_py_hold(&h, args[9], HH_MANIP_N_OUT, 1, "out")) != NULL)
        result = PyLong_FromLong(hh_manipulation_output(&model->model, params, &tr, t, q, qd, fn, support, out));
    hh_py_release_all(&h);
    return result;
}

/* -- suppresser ------------------------------------------------------------------------------ */

static PyObject *py_suppress(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    const double *params, *tau_g, *tau_m, *tau_ff;
    double *out;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 5, "suppress") != 0)
        return NULL;
    if ((params = hh_py_hold(&h, args[0], HH_SUPPRESS_N_PARAMS, 0, "params")) != NULL &&
        (tau_g = hh_py_hold(&h, args[1], HH_JOINTS, 0, "tau_g")) != NULL &&
        (tau_m = hh_py_hold(&h, args[2], HH_JOINTS, 0, "tau_m")) != NULL &&
        (tau_ff = hh_py_hold(&h, args[3], HH_JOINTS, 0, "tau_ff")) != NULL &&
        (out = hh_py_hold(&h, args[4], HH_SUPPRESS_N_OUT, 1, "out")) != NULL) {
        hh_suppress(params, tau_g, tau_m, tau_ff, out);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

/* -- the module's table and layout ------------------------------------------------------------ */

#define FASTCALL(function) (PyCFunction)(void (*)(void))(function), METH_FASTCALL

PyMethodDef hh_py_control_methods[] = {
    {"reflex_directions", FASTCALL(py_reflex_directions),
     "reflex_directions(params, state, tip, normal, fn, g, flags): the internal force per finger at unit scale "
     "into g (3x2) and the grasp and touching flags (0/1) into flags (6)."},
    {"reflex_forces", FASTCALL(py_reflex_forces),
     "reflex_forces(params, state, tip, normal, fn, f, grasp): fingertip force commands (3x2) and the grasp "
     "flags (3)."},
    {"reflex_output", FASTCALL(py_reflex_output),
     "reflex_output(model, params, state, tip, normal, fn, q, out): tau_g (9), |f_i| (3), grasp flags (3) "
     "into out (REFLEX_N_OUT)."},
    {"reflex_update", FASTCALL(py_reflex_update),
     "reflex_update(params, state, tip, normal, fn, ft, share, next): the next state (4) into next."},
    {"ik_near", FASTCALL(py_ik_near),
     "ik_near(model, finger, reach_rtol, x, y, phi, r0, r1, r2) -> (reachable, q1, q2, q3): the finger's joint "
     "angles for a tip target, on the elbow branch nearest the reference, each angle nearest it."},
    {"trajectory_sample", FASTCALL(py_trajectory_sample),
     "trajectory_sample(waypoints, meta, finger, t) -> (x, y, phi): the finger's trajectory at time t."},
    {"trajectory_moving", FASTCALL(py_trajectory_moving),
     "trajectory_moving(waypoints, meta, finger, t) -> bool: whether its velocity at t is non-zero."},
    {"manipulation_output", FASTCALL(py_manipulation_output),
     "manipulation_output(model, params, waypoints, meta, t, q, qd, fn, support, out) -> status: rows tau_m, tau_ff, "
     "q_ref into out (3x9); MANIP_OK, or MANIP_UNREACHABLE + f when a target of finger f is out of reach."},
    {"suppress", FASTCALL(py_suppress),
     "suppress(params, tau_g, tau_m, tau_ff, out): tau (9) and tau_g_eff (9) into out (SUPPRESS_N_OUT)."},
    {NULL, NULL, 0, NULL},
};

#define LAYOUT_ENTRY(name) {#name, name}

static const struct {
    const char *name;
    long value;
} CONTROL_LAYOUT[] = {
    LAYOUT_ENTRY(HH_REFLEX_P_THRESHOLD), LAYOUT_ENTRY(HH_REFLEX_P_APPROACH), LAYOUT_ENTRY(HH_REFLEX_P_KI),
    LAYOUT_ENTRY(HH_REFLEX_P_DT), LAYOUT_ENTRY(HH_REFLEX_P_MIN_FORCE), LAYOUT_ENTRY(HH_REFLEX_P_RATIO),
    LAYOUT_ENTRY(HH_REFLEX_P_MAX_FORCE), LAYOUT_ENTRY(HH_REFLEX_P_INITIAL), LAYOUT_ENTRY(HH_REFLEX_P_COINCIDENT_RTOL),
    LAYOUT_ENTRY(HH_REFLEX_P_RELEASE_SHARE),
    LAYOUT_ENTRY(HH_REFLEX_N_PARAMS), LAYOUT_ENTRY(HH_REFLEX_S_SCALE), LAYOUT_ENTRY(HH_REFLEX_S_HANDED),
    LAYOUT_ENTRY(HH_REFLEX_N_STATE), LAYOUT_ENTRY(HH_REFLEX_O_TAU), LAYOUT_ENTRY(HH_REFLEX_O_FORCE),
    LAYOUT_ENTRY(HH_REFLEX_O_ACTIVE), LAYOUT_ENTRY(HH_REFLEX_N_OUT), LAYOUT_ENTRY(HH_REFLEX_OK),
    LAYOUT_ENTRY(HH_REFLEX_COINCIDENT), LAYOUT_ENTRY(HH_REFLEX_NO_PERIOD),
    LAYOUT_ENTRY(HH_MANIP_P_Q0), LAYOUT_ENTRY(HH_MANIP_P_KP), LAYOUT_ENTRY(HH_MANIP_P_KD), LAYOUT_ENTRY(HH_MANIP_P_GX),
    LAYOUT_ENTRY(HH_MANIP_P_GY), LAYOUT_ENTRY(HH_MANIP_P_WX), LAYOUT_ENTRY(HH_MANIP_P_WY),
    LAYOUT_ENTRY(HH_MANIP_P_THRESHOLD), LAYOUT_ENTRY(HH_MANIP_P_GRAVITY_COMP), LAYOUT_ENTRY(HH_MANIP_P_LOAD_COMP),
    LAYOUT_ENTRY(HH_MANIP_P_STEP), LAYOUT_ENTRY(HH_MANIP_P_REACH_RTOL), LAYOUT_ENTRY(HH_MANIP_N_PARAMS),
    LAYOUT_ENTRY(HH_MANIP_W_T), LAYOUT_ENTRY(HH_MANIP_W_X), LAYOUT_ENTRY(HH_MANIP_W_Y), LAYOUT_ENTRY(HH_MANIP_W_PHI),
    LAYOUT_ENTRY(HH_MANIP_W_COLS), LAYOUT_ENTRY(HH_MANIP_M_COUNT), LAYOUT_ENTRY(HH_MANIP_M_INTERP),
    LAYOUT_ENTRY(HH_MANIP_N_META), LAYOUT_ENTRY(HH_MANIP_INTERP_LINEAR), LAYOUT_ENTRY(HH_MANIP_INTERP_MINJERK),
    LAYOUT_ENTRY(HH_MANIP_O_TAU_M), LAYOUT_ENTRY(HH_MANIP_O_TAU_FF), LAYOUT_ENTRY(HH_MANIP_O_Q_REF),
    LAYOUT_ENTRY(HH_MANIP_N_OUT), LAYOUT_ENTRY(HH_MANIP_OK), LAYOUT_ENTRY(HH_MANIP_UNREACHABLE),
    LAYOUT_ENTRY(HH_SUPPRESS_P_S_A), LAYOUT_ENTRY(HH_SUPPRESS_P_S_B), LAYOUT_ENTRY(HH_SUPPRESS_P_MODE),
    LAYOUT_ENTRY(HH_SUPPRESS_N_PARAMS), LAYOUT_ENTRY(HH_SUPPRESS_PASS), LAYOUT_ENTRY(HH_SUPPRESS_MAGNITUDE),
    LAYOUT_ENTRY(HH_SUPPRESS_SIGNED), LAYOUT_ENTRY(HH_SUPPRESS_O_TAU), LAYOUT_ENTRY(HH_SUPPRESS_O_TAU_G_EFF),
    LAYOUT_ENTRY(HH_SUPPRESS_O_SHARE), LAYOUT_ENTRY(HH_SUPPRESS_N_OUT),
};

int hh_py_control_layout(PyObject *layout)
{
    for (size_t i = 0; i < sizeof CONTROL_LAYOUT / sizeof CONTROL_LAYOUT[0]; i++) {
        PyObject *value = PyLong_FromLong(CONTROL_LAYOUT[i].value);
        /* without the "HH_" prefix, as the plant's: LAYOUT["REFLEX_P_KI"] */
        if (value == NULL || PyDict_SetItemString(layout, CONTROL_LAYOUT[i].name + 3, value) != 0) {
            Py_XDECREF(value);
            return -1;
        }
        Py_DECREF(value);
    }
    return 0;
}
