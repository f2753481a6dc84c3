/* Tables of names that describe a C context's layout to Python: {name: slot index or
 * offset}. The FMU block's step (fmu_block_step.c), the model-exchange loops
 * (fmu_me_integration.c) and the channel to an isolated FMU (fmu_channel.c) each hand
 * Python the layout of the int64 tables and structs they read, so that the Python side
 * names slots instead of repeating numbers. Kept apart so that those files depend on it
 * and not on each other. */
#ifndef BLOCKS_LAYOUT_NAMES_H
#define BLOCKS_LAYOUT_NAMES_H

#include <Python.h>

/* A name and its value, in a table that ends with a NULL name. */
typedef struct {
    const char *name;
    int value;
} named;

/* {name: value} of a table of names ending with a NULL name, or NULL with an exception. */
PyObject *blk_names(const named *table);

#endif
