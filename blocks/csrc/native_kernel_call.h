/* Single kernel calls from Python (native_kernel_call.c), functions of blocks._native. */
#ifndef BLOCKS_NATIVE_KERNEL_CALL_H
#define BLOCKS_NATIVE_KERNEL_CALL_H

#include <Python.h>

/* call(kind, function, context, t, state, inputs, out, n=0): one kernel call. */
PyObject *blk_call_kernel(PyObject *module, PyObject *args);

/* library(): {name: address} of the library blocks' kernel functions ("gain_output", ...). */
PyObject *blk_library_addresses(PyObject *module, PyObject *unused);

#endif
