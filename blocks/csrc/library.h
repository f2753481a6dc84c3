/* The kernel types of the framework's library blocks (library.c), for blocks._native and
   for the binaries of exported FMUs. Plain C: no Python. */
#ifndef BLOCKS_LIBRARY_H
#define BLOCKS_LIBRARY_H

#include "blocks_kernel.h"

/* {"gain", ...}: each library kernel as a type (its functions gain_output, ...), the
   table ending with a NULL name. */
extern const blk_kernel_type blk_library_types[];

#endif
