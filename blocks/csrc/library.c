/* Compiled kernels of the framework's library blocks (blocks/library). */
#include <stddef.h>

#include "library.h"

const blk_library_entry blk_library[] = {
    {NULL, NULL},
};
