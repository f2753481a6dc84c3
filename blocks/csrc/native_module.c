/* The extension module blocks._native: the Run type (native_run.h), single kernel calls
 * (native_kernel_call.h), the FMU block's compiled functions and their layouts
 * (fmu_block_step.h, fmu_me_integration.h, fmu_channel.h), and the constants Python shares
 * with the core and the exported FMUs (the kernel ABI, the export's resource format). Only
 * this file knows all of them: each part is written without the others. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "blocks_kernel.h"
#include "export_instance.h"
#include "export_scheduled.h"
#include "fmu_block_step.h"
#include "fmu_channel.h"
#include "fmu_me_integration.h"
#include "native_kernel_call.h"
#include "native_run.h"

/* fmu_kernel(): the FMU block's step (its kernel functions and context layout), with
   "model_exchange": the model-exchange loops', "host": the channel's to an isolated FMU. */
static PyObject *fmu_kernel(PyObject *module, PyObject *unused)
{
    (void)module;
    (void)unused;
    PyObject *found = blk_fmu_block_step();
    PyObject *parts[] = {blk_fmu_me_functions(), blk_fmu_channel_functions()};
    const char *names[] = {"model_exchange", "host"};
    for (int i = 0; i < 2; i++) {
        if (parts[i] == NULL || (found != NULL && PyDict_SetItemString(found, names[i], parts[i]) != 0))
            Py_CLEAR(found);
        Py_XDECREF(parts[i]);
    }
    return found;
}

static PyMethodDef module_methods[] = {
    {"call", blk_call_kernel, METH_VARARGS,
     "call(kind, function, context, t, state, inputs, out, n=0): one kernel call ('output', 'update', 'advance')."},
    {"library", blk_library_addresses, METH_NOARGS, "library(): {name: address} of the library blocks' kernels."},
    {"fmu_kernel", fmu_kernel, METH_NOARGS, "fmu_kernel(): the FMU block's kernel functions and context layout."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "_native",
    "The op-table core's runs, single kernel calls and the FMU block's compiled functions (see blocks/csrc).", -1,
    module_methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__native(void)
{
    if (PyType_Ready(&blk_run_type) < 0)
        return NULL;
    PyObject *module = PyModule_Create(&module_def);
    if (module == NULL)
        return NULL;
    Py_INCREF(&blk_run_type);
    if (PyModule_AddObject(module, "Run", (PyObject *)&blk_run_type) != 0 ||
        PyModule_AddIntConstant(module, "ABI", BLK_KERNEL_ABI) != 0 ||
        PyModule_AddStringConstant(module, "EXPORT_RESOURCE", BLK_EXPORT_RESOURCE) != 0 ||
        PyModule_AddObject(module, "EXPORT_FORMAT", Py_BuildValue("(LL)", (long long)BLK_EXPORT_MAGIC,
                                                                  (long long)BLK_EXPORT_VERSION)) != 0 ||
        PyModule_AddStringConstant(module, "SCHEDULED_RESOURCE", BLK_SCHEDULED_RESOURCE) != 0 ||
        PyModule_AddObject(module, "SCHEDULED_FORMAT", Py_BuildValue("(LL)", (long long)BLK_SCHEDULED_MAGIC,
                                                                     (long long)BLK_SCHEDULED_VERSION)) != 0 ||
        PyModule_AddObject(module, "EXPORT_LOG_CATEGORIES",
                           Py_BuildValue("(sss)", BLK_LOG_EVENTS, BLK_LOG_WARNING, BLK_LOG_ERROR)) != 0) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
