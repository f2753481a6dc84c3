/* The kernel types of an exported FMU's binary that holds the framework's library only
 * (export_instance.h): an application with kernel types of its own links a file like this
 * one that lists its tables beside the library's. */
#include "export_instance.h"
#include "library.h"

const blk_kernel_type *const blk_export_kernel_sets[] = {blk_library_types, NULL};
