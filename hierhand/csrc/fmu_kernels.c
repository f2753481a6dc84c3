/* The kernel types of the binary of a diagram FMU exported by hierhand: the framework's
 * library and the hand's blocks (kernels.h), so any diagram of them leaves as an FMU. */
#include "export_instance.h"
#include "kernels.h"
#include "library.h"

const blk_kernel_type *const blk_export_kernel_sets[] = {blk_library_types, hh_kernel_types, NULL};
