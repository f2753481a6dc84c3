/* The kernels of the framework's library blocks (library.c), by name, for blocks._native. */
#ifndef BLOCKS_LIBRARY_H
#define BLOCKS_LIBRARY_H

#include "blocks_kernel.h"

typedef struct blk_library_entry {
    const char *name; /* e.g. "gain_output" */
    void (*function)(void); /* one of the blk_*_fn types, cast */
} blk_library_entry;

extern const blk_library_entry blk_library[]; /* ends with {NULL, NULL} */

#endif
