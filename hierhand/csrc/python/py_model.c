/* Model objects, the hand vector's table and checks, and the kinematics/dynamics queries. */
#include "py_common.h"

#include <math.h>
#include <string.h>

/* -- problems of a hand vector ------------------------------------------------------------ */

static void collect_problem(void *context, int param, const char *text)
{
    PyObject *list = (PyObject *)context;
    if (PyErr_Occurred())
        return;
    PyObject *item = Py_BuildValue("(is)", param, text);
    if (item != NULL) {
        PyList_Append(list, item);
        Py_DECREF(item);
    }
}

/* ``hand`` checked and packed into ``m``; NULL-free problems list on success (empty). */
static PyObject *pack_hand(PyObject *hand, double dt, hh_model *m)
{
    Py_buffer view;
    if (hh_py_doubles(hand, &view, HH_HAND_PARAMS, 0, "hand") != 0)
        return NULL;
    PyObject *problems = PyList_New(0);
    if (problems != NULL) {
        hh_model_from_hand(m, (const double *)view.buf, dt, collect_problem, problems);
        if (PyErr_Occurred())
            Py_CLEAR(problems);
    }
    PyBuffer_Release(&view);
    return problems;
}

/* -- Model ---------------------------------------------------------------------------------- */

static PyObject *model_new(PyTypeObject *type, PyObject *args, PyObject *kwargs)
{
    static char *keywords[] = {"hand", "dt", NULL};
    PyObject *hand;
    double dt = 0.0;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "O|d:Model", keywords, &hand, &dt))
        return NULL;
    ModelObject *self = (ModelObject *)hh_py_alloc(type);
    if (self == NULL)
        return NULL;
    PyObject *problems = pack_hand(hand, dt, &self->model);
    if (problems == NULL) {
        Py_DECREF(self);
        return NULL;
    }
    Py_ssize_t count = PyList_Size(problems);
    if (count != 0) {
        PyObject *first = PyList_GetItem(problems, 0);
        int param = (int)PyLong_AsLong(PyTuple_GetItem(first, 0));
        PyErr_Format(PyExc_ValueError, "invalid hand: %s %U (%zd problem%s; check_hand lists them)",
                     hh_hand_param_name(param), PyTuple_GetItem(first, 1), count, count == 1 ? "" : "s");
        Py_DECREF(problems);
        Py_DECREF(self);
        return NULL;
    }
    Py_DECREF(problems);
    if (hh_work_init(&self->work, self->model.npts) != 0) {
        Py_DECREF(self);
        return PyErr_NoMemory();
    }
    return (PyObject *)self;
}

static void model_dealloc(ModelObject *self)
{
    hh_work_free(&self->work);
    hh_py_free((PyObject *)self);
}

static PyObject *model_with_dt(ModelObject *self, PyObject *arg)
{
    double dt;
    if (hh_py_double(arg, &dt, "dt") != 0)
        return NULL;
    if (!(dt > 0.0) || !isfinite(dt)) {
        PyErr_Format(PyExc_ValueError, "dt must be a positive finite number of seconds, got %g", dt);
        return NULL;
    }
    ModelObject *copy = (ModelObject *)hh_py_alloc(Py_TYPE((PyObject *)self));
    if (copy == NULL)
        return NULL;
    copy->model = self->model;
    copy->model.body[HH_B_DT] = dt;
    if (hh_work_init(&copy->work, copy->model.npts) != 0) {
        Py_DECREF(copy);
        return PyErr_NoMemory();
    }
    return (PyObject *)copy;
}

/* Copy ``n`` values into the float64 buffer ``target`` (held in ``h``); -1 on error. */
static int copy_out(held_buffers *h, PyObject *target, const double *source, Py_ssize_t n, const char *what)
{
    double *out = hh_py_hold(h, target, n, 1, what);
    if (out == NULL)
        return -1;
    memcpy(out, source, (size_t)n * sizeof(double));
    return 0;
}

static PyObject *model_pack_into(ModelObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (hh_py_nargs(nargs, 5, "pack_into") != 0)
        return NULL;
    const hh_model *m = &self->model;
    held_buffers h = {.held = 0};
    int failed = copy_out(&h, args[0], &m->fingers[0][0], HH_FINGERS * HH_N_FINGER_PARAMS, "fingers") != 0 ||
                 copy_out(&h, args[1], m->body, HH_N_BODY_PARAMS, "body") != 0 ||
                 copy_out(&h, args[2], &m->edges[0][0], HH_EDGES * HH_N_EDGE_COLS, "edges") != 0 ||
                 copy_out(&h, args[3], m->q0, HH_JOINTS, "q0") != 0 || copy_out(&h, args[4], m->pose0, 3, "pose0") != 0;
    hh_py_release_all(&h);
    return failed ? NULL : Py_NewRef(Py_None);
}

static PyObject *model_get_npts(ModelObject *self, void *closure)
{
    (void)closure;
    return PyLong_FromLong(self->model.npts);
}

static PyObject *model_get_state_size(ModelObject *self, void *closure)
{
    (void)closure;
    return PyLong_FromSize_t(hh_state_size(&self->model));
}

static PyObject *model_get_dt(ModelObject *self, void *closure)
{
    (void)closure;
    return PyFloat_FromDouble(self->model.body[HH_B_DT]);
}

static PyMethodDef model_methods[] = {
    {"with_dt", (PyCFunction)model_with_dt, METH_O, "A copy of this model stepping at dt seconds."},
    {"pack_into", (PyCFunction)(void (*)(void))model_pack_into, METH_FASTCALL,
     "pack_into(fingers, body, edges, q0, pose0): copy the packed parameters into float64 arrays "
     "of 3*25, 13, 4*9, 9 and 3 values."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef model_getset[] = {
    {"npts", (getter)model_get_npts, NULL, "surface points of the object", NULL},
    {"state_size", (getter)model_get_state_size, NULL, "length of the plant's state vector", NULL},
    {"dt", (getter)model_get_dt, NULL, "integration step, s (0: none; such a model cannot step)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyType_Slot model_slots[] = {
    {Py_tp_dealloc, (void *)model_dealloc},
    {Py_tp_doc, "Model(hand, dt=0): a hand vector (HH_HAND_PARAMS float64 values) checked and packed "
                "for the plant's C core; raises ValueError for an invalid hand."},
    {Py_tp_methods, model_methods},
    {Py_tp_getset, model_getset},
    {Py_tp_new, (void *)model_new},
    {0, NULL},
};

PyType_Spec hh_py_model_spec = {
    .name = "hierhand._native.Model",
    .basicsize = sizeof(ModelObject),
    .flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_IMMUTABLETYPE,
    .slots = model_slots,
};

/* -- module functions ------------------------------------------------------------------------ */

static PyObject *py_check_hand(PyObject *module, PyObject *hand)
{
    (void)module;
    hh_model m;
    return pack_hand(hand, NAN, &m);
}

static PyObject *py_hand_parameters(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    PyObject *list = PyList_New(HH_HAND_PARAMS);
    if (list == NULL)
        return NULL;
    for (int i = 0; i < HH_HAND_PARAMS; i++) {
        PyObject *item = Py_BuildValue("(ssO)", hh_hand_param_name(i), hh_hand_param_doc(i),
                                       hh_hand_param_at_least_zero(i) ? Py_True : Py_False);
        if (item == NULL) {
            Py_DECREF(list);
            return NULL;
        }
        PyList_SetItem(list, i, item); /* steals item; cannot fail on a new list */
    }
    return list;
}

static PyObject *py_initial_state(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    double *state;
    if (hh_py_nargs(nargs, 2, "initial_state") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if ((state = hh_py_hold(&h, args[1], (Py_ssize_t)hh_state_size(&self->model), 1, "state")) != NULL)
        hh_initial_state(&self->model, state);
    hh_py_release_all(&h);
    return state != NULL ? Py_NewRef(Py_None) : NULL;
}

static PyObject *py_frames(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    const double *q;
    double *u, *pts, *phi = NULL;
    if (hh_py_nargs(nargs, 5, "frames") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if ((q = hh_py_hold(&h, args[1], HH_JOINTS, 0, "q")) != NULL && (u = hh_py_hold(&h, args[2], 18, 1, "u")) != NULL &&
        (pts = hh_py_hold(&h, args[3], 24, 1, "pts")) != NULL && (phi = hh_py_hold(&h, args[4], 3, 1, "phi")) != NULL)
        hh_frames(&self->model, q, u, pts, phi);
    hh_py_release_all(&h);
    return phi != NULL ? Py_NewRef(Py_None) : NULL;
}

static PyObject *py_point_jacobian(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    const double *q;
    double *jac = NULL, px, py;
    int f;
    if (hh_py_nargs(nargs, 6, "point_jacobian") != 0 || (self = hh_py_model(args[0], "model")) == NULL ||
        hh_py_finger(args[2], &f) != 0 || hh_py_double(args[3], &px, "px") != 0 ||
        hh_py_double(args[4], &py, "py") != 0)
        return NULL;
    if ((q = hh_py_hold(&h, args[1], HH_JOINTS, 0, "q")) != NULL &&
        (jac = hh_py_hold(&h, args[5], 6, 1, "jac")) != NULL)
        hh_point_jacobian(&self->model, q, f, px, py, jac);
    hh_py_release_all(&h);
    return jac != NULL ? Py_NewRef(Py_None) : NULL;
}

static PyObject *py_mass_matrix(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    const double *q;
    double *mass = NULL;
    if (hh_py_nargs(nargs, 3, "mass_matrix") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if ((q = hh_py_hold(&h, args[1], HH_JOINTS, 0, "q")) != NULL &&
        (mass = hh_py_hold(&h, args[2], HH_JOINTS * HH_JOINTS, 1, "mass")) != NULL)
        hh_mass_matrix(&self->model, q, mass);
    hh_py_release_all(&h);
    return mass != NULL ? Py_NewRef(Py_None) : NULL;
}

static PyObject *py_bias(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    const double *q, *qd;
    double *bias = NULL;
    if (hh_py_nargs(nargs, 4, "bias") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if ((q = hh_py_hold(&h, args[1], HH_JOINTS, 0, "q")) != NULL &&
        (qd = hh_py_hold(&h, args[2], HH_JOINTS, 0, "qd")) != NULL &&
        (bias = hh_py_hold(&h, args[3], HH_JOINTS, 1, "bias")) != NULL)
        hh_bias(&self->model, q, qd, bias);
    hh_py_release_all(&h);
    return bias != NULL ? Py_NewRef(Py_None) : NULL;
}

PyMethodDef hh_py_model_methods[] = {
    {"check_hand", (PyCFunction)py_check_hand, METH_O,
     "check_hand(hand) -> [(index, text), ...]: the problems of a hand vector (empty if valid)."},
    {"hand_parameters", (PyCFunction)py_hand_parameters, METH_NOARGS,
     "hand_parameters() -> [(name, doc, at_least_zero), ...]: the hand vector's numbers in order, and "
     "whether each must be >= 0."},
    {"initial_state", (PyCFunction)(void (*)(void))py_initial_state, METH_FASTCALL,
     "initial_state(model, state): write the model's initial state."},
    {"frames", (PyCFunction)(void (*)(void))py_frames, METH_FASTCALL,
     "frames(model, q, u, pts, phi): link directions (3x3x2), joint points and tip centres (3x4x2), "
     "link-3 angles (3)."},
    {"point_jacobian", (PyCFunction)(void (*)(void))py_point_jacobian, METH_FASTCALL,
     "point_jacobian(model, q, finger, px, py, jac): Jacobian (2x3) of the link-3 point at (px, py)."},
    {"mass_matrix", (PyCFunction)(void (*)(void))py_mass_matrix, METH_FASTCALL,
     "mass_matrix(model, q, out): the 9x9 joint-space mass matrix including armature."},
    {"bias", (PyCFunction)(void (*)(void))py_bias, METH_FASTCALL,
     "bias(model, q, qd, out): Coriolis/centrifugal + gravity + damping torques (9)."},
    {NULL, NULL, 0, NULL},
};
