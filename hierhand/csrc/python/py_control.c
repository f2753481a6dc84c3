/* Scaffold while the controllers move to C (not to be committed). */
#include "py_common.h"

PyMethodDef hh_py_control_methods[] = {{NULL, NULL, 0, NULL}};

int hh_py_control_layout(PyObject *layout)
{
    (void)layout;
    return 0;
}
