/* hierhand._native: the plant's C core and the controllers, for Python.
 *
 * Functions take a Model (a packed hand) and float64 arrays that the caller allocates;
 * they return status codes (HH_OK, HH_ERR_*) that the Python side turns into messages.
 * LAYOUT names every slot of the flat arrays (the enums of hand.h and control.h), so that
 * Python reads the layout from the one place it is defined. SOURCES_DIGEST
 * is the hash of the C sources it was built from.
 */
#include "py_common.h"

#include "../control.h"

#ifndef HH_SOURCES_DIGEST
#define HH_SOURCES_DIGEST "unknown" /* setup.py stamps the hash of hierhand/csrc */
#endif

#define LAYOUT_ENTRY(name) {#name, name}

typedef struct {
    const char *name;
    long value;
} layout_entry;

static const layout_entry PLANT_LAYOUT[] = {
    LAYOUT_ENTRY(HH_FINGERS), LAYOUT_ENTRY(HH_JOINTS), LAYOUT_ENTRY(HH_EDGES),
    LAYOUT_ENTRY(HH_F_BASE_X), LAYOUT_ENTRY(HH_F_BASE_Y), LAYOUT_ENTRY(HH_F_BASE_ANGLE), LAYOUT_ENTRY(HH_F_LINK0),
    LAYOUT_ENTRY(HH_F_LINK_STRIDE), LAYOUT_ENTRY(HH_F_DAMPING), LAYOUT_ENTRY(HH_F_ARMATURE),
    LAYOUT_ENTRY(HH_F_TIP_RADIUS), LAYOUT_ENTRY(HH_N_FINGER_PARAMS), LAYOUT_ENTRY(HH_L_LENGTH),
    LAYOUT_ENTRY(HH_L_MASS), LAYOUT_ENTRY(HH_L_COM_ALONG), LAYOUT_ENTRY(HH_L_COM_ACROSS), LAYOUT_ENTRY(HH_L_INERTIA),
    LAYOUT_ENTRY(HH_B_GX), LAYOUT_ENTRY(HH_B_GY), LAYOUT_ENTRY(HH_B_MASS), LAYOUT_ENTRY(HH_B_INERTIA),
    LAYOUT_ENTRY(HH_B_HALF_A), LAYOUT_ENTRY(HH_B_HALF_B), LAYOUT_ENTRY(HH_B_K_N), LAYOUT_ENTRY(HH_B_C_N),
    LAYOUT_ENTRY(HH_B_K_T), LAYOUT_ENTRY(HH_B_C_T), LAYOUT_ENTRY(HH_B_MU_S), LAYOUT_ENTRY(HH_B_MU_D),
    LAYOUT_ENTRY(HH_B_DT), LAYOUT_ENTRY(HH_N_BODY_PARAMS), LAYOUT_ENTRY(HH_E_OX), LAYOUT_ENTRY(HH_E_OY),
    LAYOUT_ENTRY(HH_E_DX), LAYOUT_ENTRY(HH_E_DY), LAYOUT_ENTRY(HH_E_NX), LAYOUT_ENTRY(HH_E_NY),
    LAYOUT_ENTRY(HH_E_SPACING), LAYOUT_ENTRY(HH_E_COUNT), LAYOUT_ENTRY(HH_E_START), LAYOUT_ENTRY(HH_N_EDGE_COLS),
    LAYOUT_ENTRY(HH_S_Q), LAYOUT_ENTRY(HH_S_QD), LAYOUT_ENTRY(HH_S_OBJ), LAYOUT_ENTRY(HH_S_OBJ_VEL),
    LAYOUT_ENTRY(HH_S_WINDOW), LAYOUT_ENTRY(HH_S_TOUCH), LAYOUT_ENTRY(HH_O_Q), LAYOUT_ENTRY(HH_O_QD),
    LAYOUT_ENTRY(HH_O_TIP), LAYOUT_ENTRY(HH_O_FN), LAYOUT_ENTRY(HH_O_FT), LAYOUT_ENTRY(HH_O_RATIO),
    LAYOUT_ENTRY(HH_O_CONTACT), LAYOUT_ENTRY(HH_O_OBJ), LAYOUT_ENTRY(HH_O_OBJ_VEL), LAYOUT_ENTRY(HH_O_NORMAL),
    LAYOUT_ENTRY(HH_N_OUTPUTS), LAYOUT_ENTRY(HH_W_OBJ_FX), LAYOUT_ENTRY(HH_W_OBJ_FY), LAYOUT_ENTRY(HH_W_OBJ_M),
    LAYOUT_ENTRY(HH_W_TIP_M), LAYOUT_ENTRY(HH_W_FN), LAYOUT_ENTRY(HH_W_FT), LAYOUT_ENTRY(HH_W_FN_PX),
    LAYOUT_ENTRY(HH_W_FN_PY), LAYOUT_ENTRY(HH_N_WRENCH), LAYOUT_ENTRY(HH_OK), LAYOUT_ENTRY(HH_ERR_Q),
    LAYOUT_ENTRY(HH_ERR_QD), LAYOUT_ENTRY(HH_ERR_OBJ), LAYOUT_ENTRY(HH_ERR_OBJ_VEL), LAYOUT_ENTRY(HH_ERR_PENETRATION),
    LAYOUT_ENTRY(HH_ERR_TAU), LAYOUT_ENTRY(HH_ERR_F_EXT), LAYOUT_ENTRY(HH_HAND_PARAMS),
    LAYOUT_ENTRY(HH_MAX_POINTS),
    {NULL, 0},
};

static int add_layout(PyObject *layout, const layout_entry *entries)
{
    for (const layout_entry *e = entries; e->name != NULL; e++) {
        PyObject *value = PyLong_FromLong(e->value);
        /* names without their "HH_" prefix: LAYOUT["S_Q"] */
        const char *name = e->name[0] == 'H' && e->name[1] == 'H' && e->name[2] == '_' ? e->name + 3 : e->name;
        if (value == NULL || PyDict_SetItemString(layout, name, value) != 0) {
            Py_XDECREF(value);
            return -1;
        }
        Py_DECREF(value);
    }
    return 0;
}

static PyMethodDef all_methods[64];

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "_native",
    "The hand plant's C core and the controllers' compiled laws (see hierhand/csrc).", -1, all_methods,
    NULL, NULL, NULL, NULL,
};

static int collect_methods(void)
{
    const PyMethodDef *tables[] = {hh_py_model_methods, hh_py_plant_methods, hh_py_control_methods,
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
    if (PyType_Ready(&hh_py_model_type) < 0 || PyType_Ready(&hh_py_context_type) < 0)
        return NULL;
    PyObject *module = PyModule_Create(&module_def);
    if (module == NULL)
        return NULL;
    PyObject *layout = PyDict_New();
    if (layout == NULL || add_layout(layout, PLANT_LAYOUT) != 0 || hh_py_control_layout(layout) != 0 ||
        PyModule_AddObject(module, "LAYOUT", layout) != 0) {
        Py_XDECREF(layout);
        Py_DECREF(module);
        return NULL;
    }
    if (PyModule_AddStringConstant(module, "SOURCES_DIGEST", HH_SOURCES_DIGEST) != 0) {
        Py_DECREF(module);
        return NULL;
    }
    if (PyModule_AddObjectRef(module, "Model", (PyObject *)&hh_py_model_type) != 0 ||
        PyModule_AddObjectRef(module, "Context", (PyObject *)&hh_py_context_type) != 0) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
