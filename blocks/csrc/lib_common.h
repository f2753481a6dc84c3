/* lib_common.h: what the kernels of the library's blocks share (library.c, lib_*.c).
 *
 * Every one of these kernels reads a flat float64 context that its block's Python side
 * builds (blocks/library/kernel_block.py): the same two-number header first,
 *     [W, T, ...]   W the summed width of the block's outputs, T its period (0 if none),
 * then the block's own numbers at LIB_H, sizes stored as doubles. The header lets one
 * definition of advance serve every stateful block (LIB_ADVANCE). The Python methods of
 * these blocks call the same functions, so a block computes the same bits either way.
 */
#ifndef BLOCKS_LIB_COMMON_H
#define BLOCKS_LIB_COMMON_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "blocks_kernel.h"

#define LIB_W(c) ((int)(c)[0])
#define LIB_T(c) ((c)[1])
#define LIB_H 2

/* Failure codes (blocks/library/kernel_block.py words them; 1 is _kernels.NOMEM). */
enum { LIB_NOMEM = 1, LIB_SINGULAR = 2, LIB_OUT_OF_RANGE = 3 };

/* Edge kinds of a reset input (kernel_block.RESETS). */
enum { LIB_RESET_NONE, LIB_RESET_RISING, LIB_RESET_FALLING, LIB_RESET_EITHER, LIB_RESET_LEVEL };

/* v clipped to [lo, hi]; NaN passes through, as numpy's minimum(maximum(...)) lets it. */
static inline double lib_clip(double v, double lo, double hi)
{
    if (isnan(v))
        return v;
    v = v >= lo ? v : lo;
    return v <= hi ? v : hi;
}

/* Whether a reset input that was prev and is now cur resets, for an edge kind: rising
   from negative to zero or positive, or from zero to positive (falling the mirror
   image), as Simulink's triggers; level: while it is non-zero. */
static inline int lib_reset(int kind, double prev, double cur)
{
    int rising = (prev < 0.0 && cur >= 0.0) || (prev == 0.0 && cur > 0.0);
    int falling = (prev > 0.0 && cur <= 0.0) || (prev == 0.0 && cur < 0.0);
    switch (kind) {
    case LIB_RESET_RISING:
        return rising;
    case LIB_RESET_FALLING:
        return falling;
    case LIB_RESET_EITHER:
        return rising || falling;
    case LIB_RESET_LEVEL:
        return cur != 0.0;
    default:
        return 0;
    }
}

/* name_advance: n updates with held inputs, each followed by the output at the next hit,
   from name_update and name_output (every stateful library block's advance). */
#define LIB_ADVANCE(name)                                                                                   \
    int name##_advance(const void *ctx, double t, double *state, const double *const *inputs, int n,       \
                       double *rows, int *done, int *which)                                                \
    {                                                                                                       \
        const double *c_ = ctx;                                                                             \
        size_t w_ = (size_t)LIB_W(c_);                                                                      \
        double dt_ = LIB_T(c_);                                                                             \
        *done = 0;                                                                                          \
        for (int i = 0; i < n; i++) {                                                                       \
            int code = name##_update(ctx, t + i * dt_, state, inputs, which);                               \
            if (code != 0)                                                                                  \
                return code;                                                                                \
            code = name##_output(ctx, t + (i + 1) * dt_, state, inputs, rows + (size_t)i * w_, which);      \
            if (code != 0)                                                                                  \
                return code;                                                                                \
            *done = i + 1;                                                                                  \
        }                                                                                                   \
        return 0;                                                                                           \
    }

#define LIB_OUTPUT(name) \
    int name##_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out, \
                      int *which)
#define LIB_UPDATE(name) \
    int name##_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
#define LIB_ADVANCE_DECL(name) \
    int name##_advance(const void *ctx, double t, double *state, const double *const *inputs, int n, double *rows, \
                       int *done, int *which)

/* lib_math.c: memoryless arithmetic, comparisons, logic, tables, routing */
LIB_OUTPUT(abs);
LIB_OUTPUT(sign);
LIB_OUTPUT(bias);
LIB_OUTPUT(minmax);
LIB_OUTPUT(math);
LIB_OUTPUT(relational);
LIB_OUTPUT(compare);
LIB_OUTPUT(logic);
LIB_OUTPUT(dead_zone);
LIB_OUTPUT(quantizer);
LIB_OUTPUT(product);
LIB_OUTPUT(threshold_switch);
LIB_OUTPUT(multiport_switch);
LIB_OUTPUT(lookup1d);
LIB_OUTPUT(lookup2d);
LIB_OUTPUT(concatenate);
LIB_OUTPUT(selector);

/* lib_dynamic.c: blocks with state */
LIB_OUTPUT(integrator);
LIB_UPDATE(integrator);
LIB_ADVANCE_DECL(integrator);
LIB_OUTPUT(derivative);
LIB_UPDATE(derivative);
LIB_OUTPUT(moving_average);
LIB_UPDATE(moving_average);
LIB_OUTPUT(pid);
LIB_UPDATE(pid);
LIB_ADVANCE_DECL(pid);
LIB_OUTPUT(rate_limiter);
LIB_UPDATE(rate_limiter);
LIB_OUTPUT(backlash);
LIB_UPDATE(backlash);
LIB_OUTPUT(stop);
LIB_UPDATE(stop);

/* lib_sources.c: signals of time */
LIB_OUTPUT(sine);
LIB_OUTPUT(pulse);
LIB_OUTPUT(chirp);
LIB_OUTPUT(from_file);
LIB_OUTPUT(random_number);
LIB_UPDATE(random_number);
LIB_ADVANCE_DECL(random_number);

#endif
