/* The hierhand blocks' compiled kernels (blocks/csrc/blocks_kernel.h): adapters from the
 * framework's calling convention to the plant core and the controllers' laws, so that the
 * executor runs HandPlant, GraspReflex, ManipulationPD, Suppresser and ObjectSupport in C.
 *
 * Each adapter calls the very C function the block's Python method calls (through the
 * functions of py_plant.c and py_control.c), with the same arguments, so results are equal
 * to the last bit. The blocks' kernel() methods (Python) build the contexts:
 *
 * - HandPlant: a Scratch object of the run (its Kernel's bind makes one per run): the
 *   stepping Model, read only, and the hh_work the steps write.
 *
 * None calls Python's C API or writes anything but the state, the outputs and a Scratch,
 * so the blocks' Kernels say nogil and the executor runs them with the GIL released.
 * - GraspReflex: uintptr_t[2] = {Model object, params};
 * - ManipulationPD: uintptr_t[5] = {Model object, params, waypoints, meta, capacity};
 * - Suppresser: the params (HH_SUPPRESS_N_PARAMS doubles); its state, the low-passed
 *   suppression inputs (9), or none for the static law (the kernel's output gets NULL);
 * - ObjectSupport: double[4] = {fx, fy, torque, until}.
 *
 * Inputs arrive in the order of the block's ``inputs`` and outputs leave in the order of
 * its ``outputs`` (the plant's output row, the reflex's, the PD's and the suppresser's
 * vectors already are in that order). Adapters whose law may stop half way through
 * writing (reflex, manipulation) compute into a local buffer and copy it out on success,
 * as the Python methods return fresh arrays; the reflex update reads a copy of the state,
 * since it writes the new state in place.
 */
#include "py_common.h"

#include <stdint.h>
#include <string.h>

#include "../control.h"
#include "blocks_kernel.h"

/* -- Scratch: one run's hh_work for a Model ---------------------------------------------- */

static PyObject *scratch_new(PyTypeObject *type, PyObject *args, PyObject *kwargs)
{
    static char *keywords[] = {"model", NULL};
    PyObject *obj;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "O:Scratch", keywords, &obj))
        return NULL;
    ModelObject *model = hh_py_model(obj, "model");
    if (model == NULL)
        return NULL;
    if (!(model->model.body[HH_B_DT] > 0.0)) {
        PyErr_SetString(PyExc_ValueError, "Scratch: the model has no step; make one with Model.with_dt(dt)");
        return NULL;
    }
    ScratchObject *self = (ScratchObject *)type->tp_alloc(type, 0);
    if (self == NULL)
        return NULL;
    if (hh_work_init(&self->work, model->model.npts) != 0) {
        Py_DECREF(self);
        return PyErr_NoMemory();
    }
    self->model = (ModelObject *)Py_NewRef(model);
    return (PyObject *)self;
}

static void scratch_dealloc(ScratchObject *self)
{
    hh_work_free(&self->work);
    Py_XDECREF(self->model);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *scratch_address(ScratchObject *self, void *closure)
{
    (void)closure;
    return PyLong_FromVoidPtr(self);
}

static PyGetSetDef scratch_getset[] = {
    {"address", (getter)scratch_address, NULL,
     "the address of this object: the context of the plant's kernel (keep the Scratch alive while it runs)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject hh_py_scratch_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "hierhand._native.Scratch",
    .tp_basicsize = sizeof(ScratchObject),
    .tp_dealloc = (destructor)scratch_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Scratch(model): the scratch of one run of the plant's compiled kernel, stepping model (a stepping "
              "Model, kept alive); its address is that kernel's context.",
    .tp_getset = scratch_getset,
    .tp_new = scratch_new,
};

/* -- HandPlant: inputs tau (9), f_ext (3); out: the output row (HH_N_OUTPUTS) ---------------- */

static int plant_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                        int *which)
{
    (void)t;
    (void)inputs;
    ScratchObject *run = (ScratchObject *)(uintptr_t)ctx;
    return hh_output(&run->model->model, &run->work, state, out, which);
}

static int plant_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    ScratchObject *run = (ScratchObject *)(uintptr_t)ctx;
    int done;
    return hh_step(&run->model->model, &run->work, state, inputs[0], inputs[1], &done, which);
}

static int plant_advance(const void *ctx, double t, double *state, const double *const *inputs, int n, double *rows,
                         int *done, int *which)
{
    (void)t;
    ScratchObject *run = (ScratchObject *)(uintptr_t)ctx;
    long stepped = 0;
    int code = hh_advance(&run->model->model, &run->work, state, inputs[0], inputs[1], (long)n, rows, HH_N_OUTPUTS,
                          &stepped, which);
    /* hh_advance counts the failing update; the rows before it are complete (as
       HandPlant.advance: written = max(done - 1, 0)) */
    *done = code == HH_OK ? n : (stepped > 1 ? (int)(stepped - 1) : 0);
    return code;
}

/* -- GraspReflex: inputs q, tip, fn, ft, normal, share; out: tau_g, force, active ------------ */

enum { RI_Q = 0, RI_TIP = 1, RI_FN = 2, RI_FT = 3, RI_NORMAL = 4, RI_SHARE = 5 };

static int reflex_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                         int *which)
{
    (void)t;
    const uintptr_t *c = (const uintptr_t *)ctx;
    const ModelObject *model = (const ModelObject *)c[0];
    const double *params = (const double *)c[1];
    hh_reflex_inputs in = {.tip = inputs[RI_TIP], .normal = inputs[RI_NORMAL], .fn = inputs[RI_FN], .share = NULL};
    double buffer[HH_REFLEX_N_OUT];
    *which = 0;
    int code = hh_reflex_output(&model->model, params, state, &in, inputs[RI_Q], buffer);
    if (code == HH_REFLEX_OK)
        memcpy(out, buffer, sizeof buffer);
    return code;
}

static int reflex_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    const uintptr_t *c = (const uintptr_t *)ctx;
    const double *params = (const double *)c[1];
    hh_reflex_inputs in = {
        .tip = inputs[RI_TIP], .normal = inputs[RI_NORMAL], .fn = inputs[RI_FN], .share = inputs[RI_SHARE]};
    double current[HH_REFLEX_N_STATE], next[HH_REFLEX_N_STATE];
    memcpy(current, state, sizeof current);
    *which = 0;
    int code = hh_reflex_update(params, current, &in, inputs[RI_FT], next);
    if (code == HH_REFLEX_OK)
        memcpy(state, next, sizeof next);
    return code;
}

/* -- ManipulationPD: inputs q, qd, fn, support, normal, obj; out: tau_m, tau_ff, q_ref ------- */

static int manipulation_output(const void *ctx, double t, const double *state, const double *const *inputs,
                               double *out, int *which)
{
    (void)state;
    const uintptr_t *c = (const uintptr_t *)ctx;
    const ModelObject *model = (const ModelObject *)c[0];
    hh_trajectories tr = {.waypoints = (const double *)c[2], .meta = (const double *)c[3], .capacity = (long)c[4]};
    double buffer[HH_MANIP_N_OUT];
    hh_manip_inputs in = {.q = inputs[0], .qd = inputs[1], .fn = inputs[2], .support = inputs[3],
                          .normal = inputs[4], .obj = inputs[5]};
    int status = hh_manipulation_output(&model->model, (const double *)c[1], &tr, t, &in, buffer);
    if (status == HH_MANIP_OK) {
        *which = 0;
        memcpy(out, buffer, sizeof buffer);
    } else {
        *which = status - HH_MANIP_UNREACHABLE; /* the finger out of reach */
    }
    return status;
}

/* -- Suppresser: inputs tau_g, tau_m, tau_ff; out: tau, tau_g_eff, share ---------------------- */

static int suppresser_output(const void *ctx, double t, const double *state, const double *const *inputs,
                             double *out, int *which)
{
    (void)t;
    *which = 0;
    hh_suppress((const double *)ctx, inputs[0], state, inputs[1], inputs[2], out); /* state NULL: static law */
    return 0;
}

static int suppresser_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    *which = 0;
    double next[HH_JOINTS];
    hh_suppress_update((const double *)ctx, state, inputs[0], inputs[1], next);
    memcpy(state, next, sizeof next);
    return 0;
}

/* -- ObjectSupport: no inputs; out: y (3) = the force while t < until, else zero -------------- */

static int support_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                          int *which)
{
    (void)state;
    (void)inputs;
    const double *c = (const double *)ctx;
    int on = t < c[3];
    for (int i = 0; i < 3; i++)
        out[i] = on ? c[i] : 0.0;
    *which = 0;
    return 0;
}

/* -- the table and the module functions ---------------------------------------------------- */

/* Typed fields, so that the compiler checks every adapter against blocks_kernel.h. */
typedef struct {
    const char *block;
    blk_output_fn output;
    blk_update_fn update;
    blk_advance_fn advance;
} block_kernels;

static const block_kernels KERNELS[] = {
    {"HandPlant", plant_output, plant_update, plant_advance},
    {"GraspReflex", reflex_output, reflex_update, NULL},
    {"ManipulationPD", manipulation_output, NULL, NULL},
    {"Suppresser", suppresser_output, suppresser_update, NULL},
    {"ObjectSupport", support_output, NULL, NULL},
};

static int add_kernel(PyObject *found, const char *block, const char *phase, void *function)
{
    if (function == NULL)
        return 0;
    PyObject *address = PyLong_FromVoidPtr(function);
    if (address == NULL)
        return -1;
    char name[64];
    PyOS_snprintf(name, sizeof name, "%s.%s", block, phase);
    int failed = PyDict_SetItemString(found, name, address);
    Py_DECREF(address);
    return failed;
}

static PyObject *py_kernels(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    PyObject *found = PyDict_New();
    for (size_t i = 0; found != NULL && i < sizeof KERNELS / sizeof KERNELS[0]; i++) {
        const block_kernels *k = &KERNELS[i];
        if (add_kernel(found, k->block, "output", (void *)(uintptr_t)k->output) != 0 ||
            add_kernel(found, k->block, "update", (void *)(uintptr_t)k->update) != 0 ||
            add_kernel(found, k->block, "advance", (void *)(uintptr_t)k->advance) != 0)
            Py_CLEAR(found);
    }
    return found;
}

static PyObject *py_model_address(PyObject *module, PyObject *obj)
{
    (void)module;
    ModelObject *self = hh_py_model(obj, "model");
    return self == NULL ? NULL : PyLong_FromVoidPtr(self);
}

static PyObject *py_kernel_abi(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    return PyLong_FromLong(BLK_KERNEL_ABI);
}

PyMethodDef hh_py_kernel_methods[] = {
    {"kernels", py_kernels, METH_NOARGS,
     "kernels() -> {name: address}: the blocks' compiled kernels ('HandPlant.output', ...), functions of the types "
     "of blocks/csrc/blocks_kernel.h."},
    {"model_address", py_model_address, METH_O,
     "model_address(model): the address of a Model object, the context of the kernels that read it (keep the "
     "Model alive while they run)."},
    {"kernel_abi", py_kernel_abi, METH_NOARGS, "kernel_abi(): BLK_KERNEL_ABI of blocks_kernel.h built against."},
    {NULL, NULL, 0, NULL},
};
