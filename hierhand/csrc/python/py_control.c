/* The controllers' laws (control.h) for Python: the blocks' calls (one per output or
 * update) and the pieces the Python API of hierhand.control is made of.
 *
 * Arguments are packed parameters, inputs and output arrays, all float64 buffers the
 * caller allocates; a Model (Hand.native) or a finger geometry gives the finger geometry.
 * A buffer that is not C-contiguous float64 is a TypeError (the Python side then
 * converts it), one of the wrong length a ValueError naming the argument. The laws'
 * status codes become ValueErrors with the messages the blocks have always raised,
 * except reachability, which is returned (the Python side then raises UnreachableError
 * naming the finger and the distance).
 */
#include "py_common.h"

#include <limits.h>
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

/* One trajectory: waypoints (n x 4, n >= 1) and its interpolation (MANIP_INTERP_*). */
static int one_trajectory(held_buffers *h, PyObject *waypoints, PyObject *interpolation, hh_trajectory *tr)
{
    if ((tr->waypoints = hh_py_hold(h, waypoints, -1, 0, "waypoints")) == NULL)
        return -1;
    Py_ssize_t values = hh_py_last_count(h);
    if (values == 0 || values % HH_MANIP_W_COLS != 0) {
        PyErr_Format(PyExc_ValueError, "waypoints must hold n x 4 values (n >= 1), got %zd values", values);
        return -1;
    }
    long interp = PyLong_AsLong(interpolation);
    if (interp == -1 && PyErr_Occurred())
        return -1;
    if (interp != HH_MANIP_INTERP_LINEAR && interp != HH_MANIP_INTERP_MINJERK) {
        PyErr_Format(PyExc_ValueError, "interpolation must be %d (linear) or %d (minjerk), got %ld",
                     HH_MANIP_INTERP_LINEAR, HH_MANIP_INTERP_MINJERK, interp);
        return -1;
    }
    tr->count = (long)(values / HH_MANIP_W_COLS);
    tr->minimum_jerk = interp == HH_MANIP_INTERP_MINJERK;
    return 0;
}

/* waypoints, interpolation, t, out (3) of trajectory_sample and trajectory_velocity. */
static PyObject *trajectory_query(PyObject *const *args, Py_ssize_t nargs, const char *name,
                                  void (*query)(const hh_trajectory *, double, double[3]))
{
    held_buffers h = {.held = 0};
    hh_trajectory tr;
    double t, *out;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 4, name) != 0 || hh_py_double(args[2], &t, "t") != 0)
        return NULL;
    if (one_trajectory(&h, args[0], args[1], &tr) == 0 && (out = hh_py_hold(&h, args[3], 3, 1, "out")) != NULL) {
        query(&tr, t, out);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_trajectory_sample(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return trajectory_query(args, nargs, "trajectory_sample", hh_trajectory_sample);
}

static PyObject *py_trajectory_velocity(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return trajectory_query(args, nargs, "trajectory_velocity", hh_trajectory_velocity);
}

/* A finger parameter row (hh_model.fingers[f]'s layout) from ``geometry``: 6 values,
 * base x, base y, base angle and the three link lengths; what the kinematics do not read
 * is zero. */
static int finger_row(held_buffers *h, PyObject *geometry, double row[HH_N_FINGER_PARAMS])
{
    const double *g = hh_py_hold(h, geometry, 6, 0, "geometry");
    if (g == NULL)
        return -1;
    for (int i = 0; i < HH_N_FINGER_PARAMS; i++)
        row[i] = 0.0;
    row[HH_F_BASE_X] = g[0];
    row[HH_F_BASE_Y] = g[1];
    row[HH_F_BASE_ANGLE] = g[2];
    for (int i = 0; i < 3; i++)
        row[HH_F_LINK0 + HH_F_LINK_STRIDE * i + HH_L_LENGTH] = g[3 + i];
    return 0;
}

static PyObject *py_finger_fk(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    double row[HH_N_FINGER_PARAMS], *pose;
    const double *q;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 3, "finger_fk") != 0)
        return NULL;
    if (finger_row(&h, args[0], row) == 0 && (q = hh_py_hold(&h, args[1], 3, 0, "q")) != NULL &&
        (pose = hh_py_hold(&h, args[2], 3, 1, "pose")) != NULL) {
        hh_finger_fk(row, q, pose);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

/* x, y, phi at args[0..2] of the inverse kinematics. */
static int tip_target(PyObject *const *args, double *x, double *y, double *phi)
{
    return hh_py_double(args[0], x, "x") != 0 || hh_py_double(args[1], y, "y") != 0 ||
                   hh_py_double(args[2], phi, "phi") != 0
               ? -1
               : 0;
}

static PyObject *py_finger_ik(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    double row[HH_N_FINGER_PARAMS], reach_rtol, x, y, phi, *q, *reach;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 8, "finger_ik") != 0 || hh_py_double(args[1], &reach_rtol, "reach_rtol") != 0 ||
        tip_target(args + 2, &x, &y, &phi) != 0)
        return NULL;
    long elbow = PyLong_AsLong(args[5]);
    if (elbow == -1 && PyErr_Occurred())
        return NULL;
    if (elbow != 1 && elbow != -1) {
        PyErr_Format(PyExc_ValueError, "elbow must be +1 or -1, got %ld", elbow);
        return NULL;
    }
    if (finger_row(&h, args[0], row) == 0 && (q = hh_py_hold(&h, args[6], 3, 1, "q")) != NULL &&
        (reach = hh_py_hold(&h, args[7], 3, 1, "reach")) != NULL)
        result = PyBool_FromLong(hh_finger_ik(row, reach_rtol, x, y, phi, (int)elbow, q, reach));
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_ik_near(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    ModelObject *model;
    int f;
    double reach_rtol, x, y, phi, *q, *reach;
    const double *ref;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 9, "ik_near") != 0 || (model = hh_py_model(args[0], "model")) == NULL ||
        hh_py_finger(args[1], &f) != 0 || hh_py_double(args[2], &reach_rtol, "reach_rtol") != 0 ||
        tip_target(args + 3, &x, &y, &phi) != 0)
        return NULL;
    if ((ref = hh_py_hold(&h, args[6], 3, 0, "ref")) != NULL && (q = hh_py_hold(&h, args[7], 3, 1, "q")) != NULL &&
        (reach = hh_py_hold(&h, args[8], 3, 1, "reach")) != NULL)
        result = PyBool_FromLong(hh_ik_near(model->model.fingers[f], reach_rtol, x, y, phi, ref, q, reach));
    hh_py_release_all(&h);
    return result;
}

/* a (n values) and out (as many): the elementwise functions. */
static int elementwise(held_buffers *h, PyObject *a, const char *a_name, PyObject *out, const double **values,
                       double **result, Py_ssize_t *n)
{
    if ((*values = hh_py_hold(h, a, -1, 0, a_name)) == NULL)
        return -1;
    *n = hh_py_last_count(h);
    return (*result = hh_py_hold(h, out, *n, 1, "out")) == NULL ? -1 : 0;
}

/* fn of every value of args[0] (named what) into args[1]: the elementwise functions. */
static PyObject *map_values(PyObject *const *args, Py_ssize_t nargs, const char *name, const char *what,
                            double (*fn)(double))
{
    held_buffers h = {.held = 0};
    const double *values;
    double *out;
    Py_ssize_t n;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 2, name) != 0)
        return NULL;
    if (elementwise(&h, args[0], what, args[1], &values, &out, &n) == 0) {
        for (Py_ssize_t i = 0; i < n; i++)
            out[i] = fn(values[i]);
        result = Py_NewRef(Py_None);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_wrap_angles(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return map_values(args, nargs, "wrap_angles", "a", hh_wrap_angle);
}

static PyObject *py_manipulation_output(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    held_buffers h = {.held = 0};
    ModelObject *model;
    hh_trajectories tr;
    double t;
    const double *params;
    hh_manip_inputs in;
    double *out;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 12, "manipulation_output") != 0 || (model = hh_py_model(args[0], "model")) == NULL ||
        hh_py_double(args[4], &t, "t") != 0)
        return NULL;
    if ((params = hh_py_hold(&h, args[1], HH_MANIP_N_PARAMS, 0, "params")) != NULL &&
        manip_trajectories(&h, args[2], args[3], &tr) == 0 &&
        (in.q = hh_py_hold(&h, args[5], HH_JOINTS, 0, "q")) != NULL &&
        (in.qd = hh_py_hold(&h, args[6], HH_JOINTS, 0, "qd")) != NULL &&
        (in.fn = hh_py_hold(&h, args[7], HH_FINGERS, 0, "fn")) != NULL &&
        (in.support = hh_py_hold(&h, args[8], 3, 0, "support")) != NULL &&
        (in.normal = hh_py_hold(&h, args[9], 2 * HH_FINGERS, 0, "normal")) != NULL &&
        (in.obj = hh_py_hold(&h, args[10], 3, 0, "obj")) != NULL &&
        (out = hh_py_hold(&h, args[11], HH_MANIP_N_OUT, 1, "out")) != NULL)
        result = PyLong_FromLong(hh_manipulation_output(&model->model, params, &tr, t, &in, out));
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_matched_gains(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    double inertia, kp, kd, period, kp_t, kd_t;
    if (hh_py_nargs(nargs, 4, "matched_gains") != 0 || hh_py_double(args[0], &inertia, "inertia") != 0 ||
        hh_py_double(args[1], &kp, "kp") != 0 || hh_py_double(args[2], &kd, "kd") != 0 ||
        hh_py_double(args[3], &period, "period") != 0)
        return NULL;
    hh_matched_gains(inertia, kp, kd, period, &kp_t, &kd_t);
    return Py_BuildValue("(dd)", kp_t, kd_t);
}

/* -- suppresser ------------------------------------------------------------------------------ */

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
    return map_values(args, nargs, "sigmoid", "x", hh_sigmoid);
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
    if (elementwise(&h, args[0], "tau_g", args[5], &tau_g, &out, &n) == 0 &&
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

/* -- the blocks' parameters (control_params.c) -------------------------------------------------- */

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
    {"reflex_failure", py_reflex_failure, METH_O,
     "reflex_failure(code): the exception (not raised) the reflex functions raise for a failure status."},
    {"reflex_update", FASTCALL(py_reflex_update),
     "reflex_update(params, state, tip, normal, fn, ft, share, next): the next state (4) into next."},
    {"project_internal", FASTCALL(py_project_internal),
     "project_internal(points, f, out): the internal part (I - G^+ G) f of the forces f (k x 2) at the points "
     "(k x 2) into out (k x 2)."},
    {"centroid_squeeze", FASTCALL(py_centroid_squeeze),
     "centroid_squeeze(points, coincident_rtol, g): the squeeze toward the centroid of the points (k x 2), "
     "longest row 1, into g (k x 2); ValueError when the points coincide."},
    {"wrap_angles", FASTCALL(py_wrap_angles), "wrap_angles(a, out): every angle of a wrapped to (-pi, pi] into out."},
    {"finger_fk", FASTCALL(py_finger_fk),
     "finger_fk(geometry, q, pose): tip centre x, y and link-3 angle (pose, 3) of a finger (geometry: base x, "
     "base y, base angle, link lengths 1-3) at joint angles q (3)."},
    {"finger_ik", FASTCALL(py_finger_ik),
     "finger_ik(geometry, reach_rtol, x, y, phi, elbow, q, reach) -> reachable: joint angles (q, 3) of the elbow "
     "branch (+1 or -1) for a tip target; reach (3) gets the wrist distance and the reachable range."},
    {"ik_near", FASTCALL(py_ik_near),
     "ik_near(model, finger, reach_rtol, x, y, phi, ref, q, reach) -> reachable: the finger's joint angles (q, 3) "
     "for a tip target, on the elbow branch nearest ref (3), each angle nearest it; reach as finger_ik."},
    {"trajectory_sample", FASTCALL(py_trajectory_sample),
     "trajectory_sample(waypoints, interpolation, t, pose): the pose (x, y, phi) at time t of the trajectory "
     "through waypoints (n x 4: t, x, y, phi)."},
    {"trajectory_velocity", FASTCALL(py_trajectory_velocity),
     "trajectory_velocity(waypoints, interpolation, t, velocity): its time derivative at t."},
    {"manipulation_output", FASTCALL(py_manipulation_output),
     "manipulation_output(model, params, waypoints, meta, t, q, qd, fn, support, normal, obj, out) -> status: "
     "rows tau_m, tau_ff, "
     "q_ref into out (3x9); MANIP_OK, or MANIP_UNREACHABLE + f when a target of finger f is out of reach."},
    {"matched_gains", FASTCALL(py_matched_gains),
     "matched_gains(inertia, kp, kd, period) -> (kp_T, kd_T): the gains a torque held for each period needs "
     "to give a joint of that inertia the closed-loop poles of the continuous PD loop."},
    {"suppress", FASTCALL(py_suppress),
     "suppress(params, tau_g, g, tau_m, tau_ff, out): tau (9), tau_g_eff (9) and share (3) into out (SUPPRESS_N_OUT); "
     "g: the low-passed suppression inputs (9), or None for the static law."},
    {"suppress_update", FASTCALL(py_suppress_update),
     "suppress_update(params, state, tau_g, tau_m, next): the low-passed suppression inputs (9) into next."},
    {"sigmoid", FASTCALL(py_sigmoid), "sigmoid(x, out): the logistic function of every value of x into out."},
    {"suppress_joints", FASTCALL(py_suppress_joints),
     "suppress_joints(tau_g, tau_m, S_a, S_b, mode, out): the suppressed grasping torque of n joints (n values "
     "each) into out, mode SUPPRESS_PASS, _MAGNITUDE or _SIGNED."},
    {"finger_shares", FASTCALL(py_finger_shares),
     "finger_shares(tau_g, tau_g_eff, share): per finger (3) the share of its grasping torque the suppresser "
     "lets through."},
    {"reflex_pack", FASTCALL(py_reflex_pack),
     "reflex_pack(given, hand, dt) -> params: GraspReflex's parameters (REFLEX_G_*) checked and packed "
     "(REFLEX_P_*) for the hand vector; ValueError naming a bad one."},
    {"manip_pack", FASTCALL(py_manip_pack),
     "manip_pack(given, hand, dt) -> params: ManipulationPD's parameters (MANIP_G_*) checked and packed."},
    {"suppress_pack", FASTCALL(py_suppress_pack),
     "suppress_pack(given, None, period) -> params: Suppresser's parameters (SUPPRESS_G_*) checked and packed."},
    {"support_pack", FASTCALL(py_support_pack),
     "support_pack(None, hand, until) -> [fx, fy, torque, until]: ObjectSupport's context."},
    {"plate_inertia", FASTCALL(py_plate_inertia),
     "plate_inertia(mass, a, b): m (a^2 + b^2) / 12, the inertia of an object whose hand file gives none."},
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
    LAYOUT_ENTRY(HH_REFLEX_P_RELEASE_SHARE), LAYOUT_ENTRY(HH_REFLEX_P_TIP_RADIUS), LAYOUT_ENTRY(HH_REFLEX_P_FOLLOW), LAYOUT_ENTRY(HH_REFLEX_P_HOLD_SHARE),
    LAYOUT_ENTRY(HH_REFLEX_N_PARAMS), LAYOUT_ENTRY(HH_REFLEX_S_SCALE), LAYOUT_ENTRY(HH_REFLEX_S_HANDED), LAYOUT_ENTRY(HH_REFLEX_S_HOLD),
    LAYOUT_ENTRY(HH_REFLEX_N_STATE), LAYOUT_ENTRY(HH_REFLEX_O_TAU), LAYOUT_ENTRY(HH_REFLEX_O_FORCE),
    LAYOUT_ENTRY(HH_REFLEX_O_ACTIVE), LAYOUT_ENTRY(HH_REFLEX_N_OUT), LAYOUT_ENTRY(HH_REFLEX_OK),
    LAYOUT_ENTRY(HH_REFLEX_COINCIDENT), LAYOUT_ENTRY(HH_REFLEX_NO_PERIOD),
    LAYOUT_ENTRY(HH_MANIP_P_Q0), LAYOUT_ENTRY(HH_MANIP_P_KP), LAYOUT_ENTRY(HH_MANIP_P_KD), LAYOUT_ENTRY(HH_MANIP_P_GX),
    LAYOUT_ENTRY(HH_MANIP_P_GY), LAYOUT_ENTRY(HH_MANIP_P_WX), LAYOUT_ENTRY(HH_MANIP_P_WY),
    LAYOUT_ENTRY(HH_MANIP_P_THRESHOLD), LAYOUT_ENTRY(HH_MANIP_P_GRAVITY_COMP), LAYOUT_ENTRY(HH_MANIP_P_LOAD_COMP),
    LAYOUT_ENTRY(HH_MANIP_P_STEP), LAYOUT_ENTRY(HH_MANIP_P_REACH_RTOL), LAYOUT_ENTRY(HH_MANIP_P_DT),
    LAYOUT_ENTRY(HH_MANIP_P_MATCHED), LAYOUT_ENTRY(HH_MANIP_P_CONTACT_COMP), LAYOUT_ENTRY(HH_MANIP_N_PARAMS),
    LAYOUT_ENTRY(HH_MANIP_W_T), LAYOUT_ENTRY(HH_MANIP_W_X), LAYOUT_ENTRY(HH_MANIP_W_Y), LAYOUT_ENTRY(HH_MANIP_W_PHI),
    LAYOUT_ENTRY(HH_MANIP_W_COLS), LAYOUT_ENTRY(HH_MANIP_M_COUNT), LAYOUT_ENTRY(HH_MANIP_M_INTERP),
    LAYOUT_ENTRY(HH_MANIP_N_META), LAYOUT_ENTRY(HH_MANIP_INTERP_LINEAR), LAYOUT_ENTRY(HH_MANIP_INTERP_MINJERK),
    LAYOUT_ENTRY(HH_MANIP_O_TAU_M), LAYOUT_ENTRY(HH_MANIP_O_TAU_FF), LAYOUT_ENTRY(HH_MANIP_O_Q_REF),
    LAYOUT_ENTRY(HH_MANIP_N_OUT), LAYOUT_ENTRY(HH_MANIP_OK), LAYOUT_ENTRY(HH_MANIP_UNREACHABLE), LAYOUT_ENTRY(HH_MANIP_NO_PERIOD),
    LAYOUT_ENTRY(HH_SUPPRESS_P_S_A), LAYOUT_ENTRY(HH_SUPPRESS_P_S_B), LAYOUT_ENTRY(HH_SUPPRESS_P_MODE), LAYOUT_ENTRY(HH_SUPPRESS_P_ALPHA),
    LAYOUT_ENTRY(HH_SUPPRESS_N_PARAMS), LAYOUT_ENTRY(HH_SUPPRESS_PASS), LAYOUT_ENTRY(HH_SUPPRESS_MAGNITUDE),
    LAYOUT_ENTRY(HH_SUPPRESS_SIGNED), LAYOUT_ENTRY(HH_SUPPRESS_O_TAU), LAYOUT_ENTRY(HH_SUPPRESS_O_TAU_G_EFF),
    LAYOUT_ENTRY(HH_SUPPRESS_O_SHARE), LAYOUT_ENTRY(HH_SUPPRESS_N_OUT),
    LAYOUT_ENTRY(HH_REFLEX_G_KI), LAYOUT_ENTRY(HH_REFLEX_G_SAFETY_RATIO), LAYOUT_ENTRY(HH_REFLEX_G_MARGIN),
    LAYOUT_ENTRY(HH_REFLEX_G_MIN_FORCE), LAYOUT_ENTRY(HH_REFLEX_G_MAX_FORCE), LAYOUT_ENTRY(HH_REFLEX_G_APPROACH),
    LAYOUT_ENTRY(HH_REFLEX_G_THRESHOLD), LAYOUT_ENTRY(HH_REFLEX_G_RELEASE_SHARE), LAYOUT_ENTRY(HH_REFLEX_G_HOLD_SHARE),
    LAYOUT_ENTRY(HH_REFLEX_G_FOLLOW), LAYOUT_ENTRY(HH_REFLEX_G_GRASP), LAYOUT_ENTRY(HH_REFLEX_G_COINCIDENT_RTOL),
    LAYOUT_ENTRY(HH_REFLEX_N_GIVEN),
    LAYOUT_ENTRY(HH_MANIP_G_KP), LAYOUT_ENTRY(HH_MANIP_G_KD), LAYOUT_ENTRY(HH_MANIP_G_THRESHOLD),
    LAYOUT_ENTRY(HH_MANIP_G_GRAVITY_COMP), LAYOUT_ENTRY(HH_MANIP_G_LOAD_COMP), LAYOUT_ENTRY(HH_MANIP_G_MATCHED),
    LAYOUT_ENTRY(HH_MANIP_G_CONTACT_COMP), LAYOUT_ENTRY(HH_MANIP_G_STEP), LAYOUT_ENTRY(HH_MANIP_G_REACH_RTOL),
    LAYOUT_ENTRY(HH_MANIP_N_GIVEN),
    LAYOUT_ENTRY(HH_SUPPRESS_G_S_A), LAYOUT_ENTRY(HH_SUPPRESS_G_S_B), LAYOUT_ENTRY(HH_SUPPRESS_G_MODE),
    LAYOUT_ENTRY(HH_SUPPRESS_G_ENABLED), LAYOUT_ENTRY(HH_SUPPRESS_G_TIME_CONSTANT), LAYOUT_ENTRY(HH_SUPPRESS_N_GIVEN),
    LAYOUT_ENTRY(HH_SEG_FOLLOWS), LAYOUT_ENTRY(HH_SEG_HAND), LAYOUT_ENTRY(HH_SEGMENT),
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
