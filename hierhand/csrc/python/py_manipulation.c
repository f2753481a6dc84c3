/* The manipulation PD's law (control.h, manipulation.c) for Python: ManipulationPD's call
 * per output, and the trajectories, inverse kinematics and matched gains of
 * hierhand.control.
 *
 * Arguments are float64 buffers the caller allocates (the conventions of py_common.h); a
 * Model (Hand.native) or a finger geometry gives the finger geometry. Reachability is
 * returned, not raised (the Python side then raises UnreachableError naming the finger
 * and the distance).
 */
#include "py_common.h"

#include <math.h>

#include "../control.h"

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

static PyObject *py_wrap_angles(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    return hh_py_map_values(args, nargs, "wrap_angles", "a", hh_wrap_angle);
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

PyMethodDef hh_py_manipulation_methods[] = {
    {"wrap_angles", HH_PY_FASTCALL(py_wrap_angles), "wrap_angles(a, out): every angle of a wrapped to (-pi, pi] into out."},
    {"finger_fk", HH_PY_FASTCALL(py_finger_fk),
     "finger_fk(geometry, q, pose): tip centre x, y and link-3 angle (pose, 3) of a finger (geometry: base x, "
     "base y, base angle, link lengths 1-3) at joint angles q (3)."},
    {"finger_ik", HH_PY_FASTCALL(py_finger_ik),
     "finger_ik(geometry, reach_rtol, x, y, phi, elbow, q, reach) -> reachable: joint angles (q, 3) of the elbow "
     "branch (+1 or -1) for a tip target; reach (3) gets the wrist distance and the reachable range."},
    {"ik_near", HH_PY_FASTCALL(py_ik_near),
     "ik_near(model, finger, reach_rtol, x, y, phi, ref, q, reach) -> reachable: the finger's joint angles (q, 3) "
     "for a tip target, on the elbow branch nearest ref (3), each angle nearest it; reach as finger_ik."},
    {"trajectory_sample", HH_PY_FASTCALL(py_trajectory_sample),
     "trajectory_sample(waypoints, interpolation, t, pose): the pose (x, y, phi) at time t of the trajectory "
     "through waypoints (n x 4: t, x, y, phi)."},
    {"trajectory_velocity", HH_PY_FASTCALL(py_trajectory_velocity),
     "trajectory_velocity(waypoints, interpolation, t, velocity): its time derivative at t."},
    {"manipulation_output", HH_PY_FASTCALL(py_manipulation_output),
     "manipulation_output(model, params, waypoints, meta, t, q, qd, fn, support, normal, obj, out) -> status: "
     "rows tau_m, tau_ff, "
     "q_ref into out (3x9); MANIP_OK, or MANIP_UNREACHABLE + f when a target of finger f is out of reach."},
    {"matched_gains", HH_PY_FASTCALL(py_matched_gains),
     "matched_gains(inertia, kp, kd, period) -> (kp_T, kd_T): the gains a torque held for each period needs "
     "to give a joint of that inertia the closed-loop poles of the continuous PD loop."},
    {NULL, NULL, 0, NULL},
};
