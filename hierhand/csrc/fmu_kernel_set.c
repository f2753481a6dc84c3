/* The kernel types of the binary of a diagram FMU exported by hierhand: the framework's
 * library and the hand's blocks (kernel_types.h), so any diagram of them leaves as an FMU. */
#include "export_instance.h"
#include "kernel_types.h"
#include "library.h"

const blk_kernel_type *const blk_export_kernel_sets[] = {blk_library_types, HH_KERNEL_TYPE_TABLES};
