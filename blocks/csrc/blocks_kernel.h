/* blocks_kernel.h: the C calling convention of a block's compiled kernel.
 *
 * A block that can compute its outputs, its update and its advance in C offers them to
 * the executor as a blocks.Kernel: the addresses of functions of the types below and a
 * context pointer (its constants: parameters, a model). The executor then runs every hit
 * of that block in C, and runs whole stretches of events whose blocks all have kernels
 * in one C call, with no Python in between (blocks/csrc/runner.c).
 *
 * Conventions, the same for every kernel:
 * - ctx is Kernel.context, passed back unchanged; the kernel only reads through it.
 * - state is the block's state, the flat float64 array initial_state() returned (NULL
 *   for a stateless block); update and advance change it in place.
 * - inputs[i] points at input port i, in the order of Block.inputs, of its declared
 *   width; the kernel only reads them, and they stay put during the call.
 * - out receives all output ports one after the other, in the order of Block.outputs.
 * - advance does n updates with held inputs, the first at time t, spaced by the block's
 *   period; row i of rows (n rows of the summed output width) is the outputs after
 *   update i + 1, as Block.advance returns them.
 * - A return of 0 is success. Anything else is a failure code; *which may name a detail
 *   (a joint, a finger) and advance sets *done to the number of rows it completed before
 *   the failing update. Kernel.error(code, which, t, phase) in Python turns these into
 *   the block's exception, so messages have one definition.
 * - A kernel computes what the block's Python methods compute. Within a run the executor
 *   uses a block's kernel for all of its hits or for none, so the two need not round
 *   alike; a block whose Python methods call the same C code (the hand's blocks) matches
 *   to the last bit, and one whose Python side uses numpy's matrix products matches to
 *   round-off.
 */
#ifndef BLOCKS_KERNEL_H
#define BLOCKS_KERNEL_H

#define BLK_KERNEL_ABI 1

typedef int (*blk_output_fn)(const void *ctx, double t, const double *state, const double *const *inputs,
                             double *out, int *which);
typedef int (*blk_update_fn)(const void *ctx, double t, double *state, const double *const *inputs, int *which);
typedef int (*blk_advance_fn)(const void *ctx, double t, double *state, const double *const *inputs, int n,
                              double *rows, int *done, int *which);

#endif
