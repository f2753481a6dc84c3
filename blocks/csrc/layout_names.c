/* {name: value} dictionaries of the layout tables of layout_names.h. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "layout_names.h"

PyObject *blk_names(const named *table)
{
    PyObject *found = PyDict_New();
    for (const named *e = table; found != NULL && e->name != NULL; e++) {
        PyObject *value = PyLong_FromLong(e->value);
        if (value == NULL || PyDict_SetItemString(found, e->name, value) != 0)
            Py_CLEAR(found);
        Py_XDECREF(value);
    }
    return found;
}
