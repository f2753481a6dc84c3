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

static int state_buffer(ModelObject *self, PyObject *obj, Py_buffer *view, int writable)
{
    return hh_py_doubles(obj, view, (Py_ssize_t)hh_state_size(&self->model), writable, "state");
}

static PyObject *py_advance(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    Py_buffer state, tau, f_ext, rows;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 5, "advance") != 0 || (self = stepping_model(args[0])) == NULL)
        return NULL;
    if (state_buffer(self, args[1], &state, 1) != 0)
        return NULL;
    if (hh_py_doubles(args[2], &tau, HH_JOINTS, 0, "tau") != 0)
        goto release_state;
    if (hh_py_doubles(args[3], &f_ext, 3, 0, "f_ext") != 0)
        goto release_tau;
    if (hh_py_doubles(args[4], &rows, -1, 1, "rows") != 0)
        goto release_f_ext;
    Py_ssize_t values = rows.len / 8;
    if (values % HH_N_OUTPUTS != 0) {
        PyErr_Format(PyExc_ValueError, "rows must hold whole output rows of %d values, got %zd values",
                     HH_N_OUTPUTS, values);
    } else {
        long done;
        int which;
        int code = hh_advance(&self->model, &self->work, state.buf, tau.buf, f_ext.buf,
                              (long)(values / HH_N_OUTPUTS), rows.buf, HH_N_OUTPUTS, &done, &which);
        result = status(code, done, which);
    }
    PyBuffer_Release(&rows);
release_f_ext:
    PyBuffer_Release(&f_ext);
release_tau:
    PyBuffer_Release(&tau);
release_state:
    PyBuffer_Release(&state);
    return result;
}

static PyObject *py_step(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    Py_buffer state, tau, f_ext;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 4, "step") != 0 || (self = stepping_model(args[0])) == NULL)
        return NULL;
    if (state_buffer(self, args[1], &state, 1) != 0)
        return NULL;
    if (hh_py_doubles(args[2], &tau, HH_JOINTS, 0, "tau") != 0)
        goto release_state;
    if (hh_py_doubles(args[3], &f_ext, 3, 0, "f_ext") == 0) {
        int done, which;
        int code = hh_step(&self->model, &self->work, state.buf, tau.buf, f_ext.buf, &done, &which);
        result = status(code, done, which);
        PyBuffer_Release(&f_ext);
    }
    PyBuffer_Release(&tau);
release_state:
    PyBuffer_Release(&state);
    return result;
}

static PyObject *py_output(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    Py_buffer state, row;
    if (hh_py_nargs(nargs, 3, "output") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if (state_buffer(self, args[1], &state, 0) != 0)
        return NULL;
    if (hh_py_doubles(args[2], &row, HH_N_OUTPUTS, 1, "row") != 0) {
        PyBuffer_Release(&state);
        return NULL;
    }
    int which;
    int code = hh_output(&self->model, &self->work, state.buf, row.buf, &which);
    PyBuffer_Release(&row);
    PyBuffer_Release(&state);
    return status(code, 0, which);
}

static PyObject *py_contact(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    (void)module;
    ModelObject *self;
    Py_buffer state, tips, wrench;
    PyObject *result = NULL;
    if (hh_py_nargs(nargs, 4, "contact") != 0 || (self = hh_py_model(args[0], "model")) == NULL)
        return NULL;
    if (state_buffer(self, args[1], &state, 0) != 0)
        return NULL;
    if (hh_py_doubles(args[2], &tips, HH_FINGERS * 3, 1, "tips") != 0)
        goto release_state;
    if (hh_py_doubles(args[3], &wrench, HH_FINGERS * HH_N_WRENCH, 1, "wrench") == 0) {
        int which;
        int code = hh_contact(&self->model, &self->work, state.buf, &which);
        double *t = tips.buf, *wr = wrench.buf;
        for (int f = 0; f < HH_FINGERS; f++) {
            for (int i = 0; i < 3; i++)
                t[3 * f + i] = self->work.tip[f][i];
            for (int i = 0; i < HH_N_WRENCH; i++)
                wr[HH_N_WRENCH * f + i] = self->work.wrench[f][i];
        }
        result = status(code, 0, which);
        PyBuffer_Release(&wrench);
    }
    PyBuffer_Release(&tips);
release_state:
    PyBuffer_Release(&state);
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
