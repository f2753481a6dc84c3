/* hierhand._native: the plant's C core and the controllers, for Python.
 *
 * Functions take a Model (a packed hand) and float64 arrays that the caller allocates;
 * they return status codes (HH_OK, HH_ERR_*) that the Python side turns into messages.
 * LAYOUTS gives every flat array's slots (layouts.h, py_layouts.c), so that Python reads
 * them from the one place they are declared. SOURCES_DIGEST is the hash of the C sources
 * it was built from.
 */
#include "py_common.h"

#ifndef HH_SOURCES_DIGEST
#define HH_SOURCES_DIGEST "unknown" /* setup.py stamps the hash of hierhand/csrc */
#endif

static PyMethodDef all_methods[64];

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "_native",
    "The hand plant's C core and the controllers' compiled laws (see hierhand/csrc).", -1, all_methods,
    NULL, NULL, NULL, NULL,
};

static int collect_methods(void)
{
    const PyMethodDef *tables[] = {hh_py_model_methods,        hh_py_plant_methods,      hh_py_reflex_methods,
                                   hh_py_manipulation_methods, hh_py_suppresser_methods, hh_py_param_methods,
                                   hh_py_kernel_methods};
    size_t n = 0;
    for (size_t t = 0; t < sizeof tables / sizeof tables[0]; t++)
        for (const PyMethodDef *d = tables[t]; d->ml_name != NULL; d++) {
            if (n + 1 >= sizeof all_methods / sizeof all_methods[0])
                return -1;
            all_methods[n++] = *d;
        }
    all_methods[n] = (PyMethodDef){NULL, NULL, 0, NULL};
    return 0;
}

PyMODINIT_FUNC PyInit__native(void)
{
    if (collect_methods() != 0) {
        PyErr_SetString(PyExc_SystemError, "hierhand._native: method table too small");
        return NULL;
    }
    PyObject *module = PyModule_Create(&module_def);
    if (module == NULL)
        return NULL;
    PyObject *model = PyType_FromSpec(&hh_py_model_spec);
    PyObject *context = PyType_FromSpec(&hh_py_context_spec);
    int added = model != NULL && context != NULL && PyModule_AddObjectRef(module, "Model", model) == 0 &&
                PyModule_AddObjectRef(module, "Context", context) == 0;
    Py_XDECREF(context);
    if (!added) {
        Py_XDECREF(model);
        Py_DECREF(module);
        return NULL;
    }
    hh_py_model_type = (PyTypeObject *)model; /* kept for the life of the process, as a static type would be */
    if (hh_py_add_layouts(module) != 0 ||
        PyModule_AddStringConstant(module, "SOURCES_DIGEST", HH_SOURCES_DIGEST) != 0) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
