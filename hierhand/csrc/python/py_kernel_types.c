/* The hierhand blocks' compiled kernels for Python: their kernel types (kernel_types.h)
 * and Context, a context built by a type's constructor from a block's record.
 *
 * A block's kernel() writes its record (hierhand.records) and makes a Context of it: the
 * constructor checks the record's numbers and builds what the adapters read (the plant's
 * model and scratch, a law's packed parameters), exactly as an exported FMU rebuilds it.
 * The Context frees it when it goes away; its address is the Kernel's context. kernels()
 * gives the adapters' addresses by "Block.phase".
 */
#include "py_common.h"

#include <stdint.h>
#include <string.h>

#include "../kernel_types.h"
#include "blocks_kernel.h"

typedef struct {
    PyObject_HEAD
    const blk_kernel_type *type;
    blk_built built;
} ContextObject;

static const blk_kernel_type *const TABLES[] = {HH_KERNEL_TYPE_TABLES};

static const blk_kernel_type *type_named(const char *name)
{
    for (const blk_kernel_type *const *table = TABLES; *table != NULL; table++)
        for (const blk_kernel_type *k = *table; k->name != NULL; k++)
            if (strcmp(k->name, name) == 0)
                return k;
    return NULL;
}

static PyObject *context_new(PyTypeObject *type, PyObject *args, PyObject *kwargs)
{
    static char *keywords[] = {"kind", "record", NULL};
    const char *kind;
    PyObject *record;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "sO:Context", keywords, &kind, &record))
        return NULL;
    const blk_kernel_type *k = type_named(kind);
    if (k == NULL) {
        PyErr_Format(PyExc_ValueError, "Context: no kernel type '%s'", kind);
        return NULL;
    }
    Py_buffer view;
    if (hh_py_doubles(record, &view, -1, 0, "record") != 0)
        return NULL;
    ContextObject *self = (ContextObject *)hh_py_alloc(type);
    if (self == NULL) {
        PyBuffer_Release(&view);
        return NULL;
    }
    char message[512] = "";
    int code = k->construct((const double *)view.buf, (long)(view.len / (Py_ssize_t)sizeof(double)), &self->built,
                            message, sizeof message);
    PyBuffer_Release(&view);
    if (code != 0) {
        Py_DECREF(self);
        PyErr_SetString(PyExc_ValueError, message);
        return NULL;
    }
    self->type = k;
    return (PyObject *)self;
}

static void context_dealloc(ContextObject *self)
{
    if (self->type != NULL && self->built.ctx != NULL)
        self->type->destroy(self->built.ctx);
    hh_py_free((PyObject *)self);
}

static PyObject *context_address(ContextObject *self, void *closure)
{
    (void)closure;
    return PyLong_FromVoidPtr(self->built.ctx);
}

static PyObject *context_state_size(ContextObject *self, void *closure)
{
    (void)closure;
    return PyLong_FromLong(self->built.state_size);
}

/* initial_state(out): the constructed kernel's initial state into out (state_size values). */
static PyObject *context_initial_state(ContextObject *self, PyObject *out)
{
    if (self->type->initial == NULL || self->built.state_size <= 0) {
        PyErr_SetString(PyExc_ValueError, "this kernel has no state of its own");
        return NULL;
    }
    Py_buffer view;
    if (hh_py_doubles(out, &view, self->built.state_size, 1, "out") != 0)
        return NULL;
    self->type->initial(self->built.ctx, (double *)view.buf);
    PyBuffer_Release(&view);
    Py_RETURN_NONE;
}

static PyGetSetDef context_getset[] = {
    {"address", (getter)context_address, NULL, "the context's address: a Kernel's context (keep this object alive)",
     NULL},
    {"state_size", (getter)context_state_size, NULL,
     "the size of the kernel's state (0: none, -1: the block's own, not the kernel's)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMethodDef context_methods[] = {
    {"initial_state", (PyCFunction)context_initial_state, METH_O,
     "initial_state(out): the kernel's initial state into the float64 array out."},
    {NULL, NULL, 0, NULL},
};

static PyType_Slot context_slots[] = {
    {Py_tp_dealloc, (void *)context_dealloc},
    {Py_tp_doc, "Context(kind, record): the context the constructor of kernel type kind (kernel_types.h) builds from "
                "record (float64), ValueError with the constructor's message when it refuses the record; freed "
                "with the object."},
    {Py_tp_getset, context_getset},
    {Py_tp_methods, context_methods},
    {Py_tp_new, (void *)context_new},
    {0, NULL},
};

PyType_Spec hh_py_context_spec = {
    .name = "hierhand._native.Context",
    .basicsize = sizeof(ContextObject),
    .flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_IMMUTABLETYPE,
    .slots = context_slots,
};

/* -- the adapters' addresses ------------------------------------------------------------------ */

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
    for (const blk_kernel_type *const *table = TABLES; found != NULL && *table != NULL; table++)
        for (const blk_kernel_type *k = *table; found != NULL && k->name != NULL; k++)
            if (add_kernel(found, k->name, "output", (void *)(uintptr_t)k->output) != 0 ||
                add_kernel(found, k->name, "update", (void *)(uintptr_t)k->update) != 0 ||
                add_kernel(found, k->name, "advance", (void *)(uintptr_t)k->advance) != 0)
                Py_CLEAR(found);
    return found;
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
     "of blocks/csrc/blocks_kernel.h, from the kernel types of kernel_types.h."},
    {"kernel_abi", py_kernel_abi, METH_NOARGS, "kernel_abi(): BLK_KERNEL_ABI of blocks_kernel.h built against."},
    {NULL, NULL, 0, NULL},
};
