/* Stepping the plant from Python: one native call per update, output or span. */
#include "py_common.h"

static PyObject *status(int code, long done, int which)
{
    return Py_BuildValue("(ili)", code, done, which);
}

/* The model of a step: it must have one (Model.with_dt). */
static ModelObject *stepping_model(PyObject *obj)
{
    ModelObject *self = hh_py_model(obj, "model");
    if (self != NULL && !(self->model.body[HH_B_DT] > 0.0)) {
        PyErr_SetString(PyExc_ValueError, "the model has no step; make one with Model.with_dt(dt)");
        return NULL;
    }
    return self;
}

static Py_ssize_t state_size(ModelObject *self)
{
    return (Py_ssize_t)hh_state_size(&self->model);
}

static PyObject *py_advance(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    double *state, *rows;
    const double *tau, *f_ext;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 5, "advance") != 0 || (self = stepping_model(args[0])) == NULL)
        return NULL;
    if ((state = hh_py_hold(&h, args[1], state_size(self), 1, "state")) != NULL &&
        (tau = hh_py_hold(&h, args[2], HH_JOINTS, 0, "tau")) != NULL &&
        (f_ext = hh_py_hold(&h, args[3], 3, 0, "f_ext")) != NULL &&
        (rows = hh_py_hold(&h, args[4], -1, 1, "rows")) != NULL) {
        Py_ssize_t values = hh_py_last_count(&h);
        if (values % HH_N_OUTPUTS != 0) {
            PyErr_Format(PyExc_ValueError, "rows must hold whole output rows of %d values, got %zd values",
                         HH_N_OUTPUTS, values);
        } else {
            long done;
            int which;
            int code = hh_advance(&self->model, &self->work, state, tau, f_ext, (long)(values / HH_N_OUTPUTS), rows,
                                  HH_N_OUTPUTS, &done, &which);
            result = status(code, done, which);
        }
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_step(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    double *state;
    const double *tau, *f_ext;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 4, "step") != 0 || (self = stepping_model(args[0])) == NULL)
        return NULL;
    if ((state = hh_py_hold(&h, args[1], state_size(self), 1, "state")) != NULL &&
        (tau = hh_py_hold(&h, args[2], HH_JOINTS, 0, "tau")) != NULL &&
        (f_ext = hh_py_hold(&h, args[3], 3, 0, "f_ext")) != NULL) {
        int done, which;
        int code = hh_step(&self->model, &self->work, state, tau, f_ext, &done, &which);
        result = status(code, done, which);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_output(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    const double *state;
    double *row;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 3, "output") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if ((state = hh_py_hold(&h, args[1], state_size(self), 0, "state")) != NULL &&
        (row = hh_py_hold(&h, args[2], HH_N_OUTPUTS, 1, "row")) != NULL) {
        int which;
        int code = hh_output(&self->model, &self->work, state, row, &which);
        result = status(code, 0, which);
    }
    hh_py_release_all(&h);
    return result;
}

static PyObject *py_contact(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    held_buffers h = {.held = 0};
    const double *state;
    double *tips, *wrench;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 4, "contact") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if ((state = hh_py_hold(&h, args[1], state_size(self), 0, "state")) != NULL &&
        (tips = hh_py_hold(&h, args[2], HH_FINGERS * 3, 1, "tips")) != NULL &&
        (wrench = hh_py_hold(&h, args[3], HH_FINGERS * HH_N_WRENCH, 1, "wrench")) != NULL) {
        int which;
        int code = hh_contact(&self->model, &self->work, state, &which);
        for (int f = 0; f < HH_FINGERS; f++) {
            for (int i = 0; i < 3; i++)
                tips[3 * f + i] = self->work.tip[f][i];
            for (int i = 0; i < HH_N_WRENCH; i++)
                wrench[HH_N_WRENCH * f + i] = self->work.wrench[f][i];
        }
        result = status(code, 0, which);
    }
    hh_py_release_all(&h);
    return result;
}

PyMethodDef hh_py_plant_methods[] = {
    {"advance", (PyCFunction)(void (*)(void))py_advance, METH_FASTCALL,
     "advance(model, state, tau, f_ext, rows) -> (code, done, which): len(rows) / 51 updates in place, "
     "each followed by its output row."},
    {"step", (PyCFunction)(void (*)(void))py_step, METH_FASTCALL,
     "step(model, state, tau, f_ext) -> (code, done, which): one update in place."},
    {"output", (PyCFunction)(void (*)(void))py_output, METH_FASTCALL,
     "output(model, state, row) -> (code, 0, which): the output row (51) of a state."},
    {"contact", (PyCFunction)(void (*)(void))py_contact, METH_FASTCALL,
     "contact(model, state, tips, wrench) -> (code, 0, which): tip poses (3x3) and contact summaries (3x8)."},
    {NULL, NULL, 0, NULL},
};
