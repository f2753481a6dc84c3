/* blocks_kernel.h: the C calling convention of a block's compiled kernel.
 *
 * A block that can compute its outputs, its update and its advance in C offers them to
 * the executor as a blocks.Kernel: the addresses of functions of the types below and a
 * context pointer (its constants: parameters, a model). The executor then runs every hit
 * of that block in C: the op-table core (blocks/csrc/core.h) calls these functions
 * directly, with no Python between one kernel's step and the next.
 *
 * Conventions, the same for every kernel:
 * - ctx is Kernel.context, passed back unchanged; the kernel only reads through it
 *   (except a per-run context, below).
 * - state is the block's state, the flat float64 array initial_state() returned (NULL
 *   for a stateless block, or one whose state is not such an array); update and advance
 *   change it in place.
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
 * - Two codes are not failures of that kind. BLK_END_RUN from update: the update is done
 *   and the block asks to end the run (its Python update raises EndRun); the executor
 *   finishes the tick and ends the run at the block's next hit, taking the reason from
 *   Kernel.error(BLK_END_RUN, which, t, 'update'). BLK_RAISED: the kernel has set a
 *   Python exception (only a kernel that runs with the GIL, one without nogil, below),
 *   which becomes the step's error as it is, a KeyboardInterrupt the run's interrupt.
 * - A kernel that writes anything besides its state (an FMU instance's time and outputs,
 *   the plant's scratch) gives its Kernel a bind(state): the executor calls it once per run
 *   and uses the Kernel it returns, whose context belongs to that run and may be written.
 *   That kernel gets the state as above: the flat array (the plant's), else NULL (an FMU's
 *   live instance, whose changes it keeps in its context).
 * - The GIL: the executor (blocks/csrc/native_run_hooks.c) holds it around a kernel's calls unless
 *   the Kernel says nogil.
 *   A nogil kernel calls nothing of Python's C API (so never returns BLK_RAISED) and
 *   writes only its state, its outputs and a context no other run uses at the same time
 *   (no static buffers, no scratch shared through a constant context: give such scratch
 *   a bind, or keep it on the stack); the executor then runs it with the GIL released, so
 *   that threads that simulate diagrams run in parallel. The Ctrl-C checks between events
 *   take the GIL back, and a kernel that looks for Ctrl-C itself must hold it.
 * - A kernel computes what the block's Python methods compute. Within a run the executor
 *   uses a block's kernel for all of its hits or for none, so the two need not round
 *   alike; a block whose Python methods call the same C code (the hand's blocks) matches
 *   to the last bit, and one whose Python side uses numpy's matrix products matches to
 *   round-off.
 */
#ifndef BLOCKS_KERNEL_H
#define BLOCKS_KERNEL_H

#include <stdint.h>
#include <string.h>

#define BLK_KERNEL_ABI 1

/* Marks a function whose loops GCC should vectorise at -O2 (as it does at -O3): the scans
   of values below, once inlined. */
#if defined(__GNUC__) && !defined(__clang__)
#define BLK_VECTORISED __attribute__((optimize("tree-vectorize")))
#else
#define BLK_VECTORISED
#endif

/* Whether all of n values are finite (no NaN, no infinity), the test the core applies to
   every output: the values are looked over as bits, without a branch, which compilers
   vectorise. A NaN or an infinity has every exponent bit set, so adding one to its
   exponent carries into the sign. A kernel checking its own values uses it before it
   looks for which value failed (in a function marked BLK_VECTORISED, to vectorise it). */
static inline int blk_all_finite(const double *v, int64_t n)
{
    const uint64_t exponent = 0x7ff0000000000000u, one = 0x0010000000000000u;
    uint64_t carried = 0;
    for (int64_t i = 0; i < n; i++) {
        uint64_t bits;
        memcpy(&bits, v + i, sizeof bits);
        carried |= (bits & exponent) + one;
    }
    return !(carried >> 63);
}

#define BLK_END_RUN (-1)
#define BLK_RAISED (-2)

typedef int (*blk_output_fn)(const void *ctx, double t, const double *state, const double *const *inputs,
                             double *out, int *which);
typedef int (*blk_update_fn)(const void *ctx, double t, double *state, const double *const *inputs, int *which);
typedef int (*blk_advance_fn)(const void *ctx, double t, double *state, const double *const *inputs, int n,
                              double *rows, int *done, int *which);

/* Kernel types: a kernel that a program without Python (an exported FMU) rebuilds.
 *
 * Python describes a block's kernel by a record (blocks.engine.kernel.KernelRecord): the name of
 * its type and a flat array of doubles, the block's parameters in the type's own order,
 * which the type's construct turns into a context, checking them as the block does when it
 * is made (the checks are the type's, so one definition serves the block and the FMU). An
 * exported FMU keeps the records in its resources and rebuilds every context when it is
 * initialised, from the records with its tunable parameters written into them.
 *
 * construct: from the record (n doubles) fills built (its context, which it allocates;
 *            the summed width of the outputs its functions write; its state's size, or -1
 *            when the record's block keeps the state Python gave it) and returns 0; or a
 *            nonzero code with one line in message (size bytes) saying which parameter is
 *            wrong and why, named as in the record (its slots' names).
 * destroy:   frees a built context (NULL: nothing to free beyond construct's malloc, which
 *            free releases).
 * initial:   the initial state of a built context (state_size values), NULL when
 *            construct gives -1.
 * failure:   one line saying what a failure code of the kernel's functions means (NULL:
 *            the program says the code), for the phase ("output", "update", "advance")
 *            and the time of the hit that failed: the words the block's Python side uses. */
typedef struct {
    void *ctx;
    long outputs;
    long state_size;
} blk_built;

typedef int (*blk_construct_fn)(const double *record, long n, blk_built *built, char *message, long size);

typedef struct blk_kernel_type {
    const char *name; /* NULL ends a table of types */
    blk_construct_fn construct;
    void (*destroy)(void *ctx);
    void (*initial)(const void *ctx, double *state);
    blk_output_fn output;
    blk_update_fn update;
    blk_advance_fn advance;
    void (*failure)(const void *ctx, int code, int which, const char *phase, double t, char *message, long size);
} blk_kernel_type;

#endif
