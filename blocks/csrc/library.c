/* Compiled kernels of the framework's library blocks (blocks/library).
 *
 * These are the blocks' only definition: their Python methods call these same functions
 * (blocks/library/kernel_block.py). Every kernel reads a flat float64 context as
 * lib_common.h says: [W, T] then the block's numbers from LIB_H on, sizes stored as
 * doubles. Compiled with -ffp-contract=off: no fused multiply-add anywhere, every product
 * and sum is rounded on its own (the tests' numpy oracles, tests/blocks/library/oracles.py,
 * agree to the last bit where they do the same operations in the same order).
 *
 * Matrix-vector products (matvec) have one definition of their own, independent of any
 * BLAS: each row is summed in column order starting from its first product,
 *     y_i = ((M_i0 v_0 + M_i1 v_1) + M_i2 v_2) + ... + M_i,L-1 v_L-1.
 * A row of a single term is that one product, as numpy's is; longer rows equal numpy's
 * ndarray.dot to round-off, not bit for bit (BLAS sums in its own order).
 *
 * The table of kernel types at the end (blocks_kernel.h) also lists the kernels of the
 * library's other blocks (lib_math.c, lib_dynamic.c, lib_sources.c). Every library context
 * is a flat array of doubles, so a type's constructor copies its record.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib_common.h"
#include "library.h"

/* y (r) = M (r x L, row-major, L >= 1) . v (L), each row summed in order (see above).
   y must not overlap M or v. */
static void matvec(const double *M, int r, int L, const double *v, double *y)
{
    for (int i = 0; i < r; i++) {
        const double *a = M + (size_t)i * L;
        double s = a[0] * v[0];
        for (int j = 1; j < L; j++)
            s += a[j] * v[j];
        y[i] = s;
    }
}

/* -- sources ------------------------------------------------------------------------ */

/* constant: [value(W)] */
static int constant_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                           int *which)
{
    (void)t, (void)state, (void)inputs, (void)which;
    const double *c = ctx;
    memcpy(out, c + LIB_H, (size_t)LIB_W(c) * sizeof(double));
    return 0;
}

/* step: [time, before(W), after(W)]: before while t < time, after from time on */
static int step_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                       int *which)
{
    (void)state, (void)inputs, (void)which;
    const double *c = ctx;
    int w = LIB_W(c);
    const double *before = c + LIB_H + 1, *after = before + w;
    memcpy(out, t < c[LIB_H] ? before : after, (size_t)w * sizeof(double));
    return 0;
}

/* ramp: [start, slope(W), initial(W)]: initial + slope (t - start) once t > start */
static int ramp_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                       int *which)
{
    (void)state, (void)inputs, (void)which;
    const double *c = ctx;
    int w = LIB_W(c);
    const double *slope = c + LIB_H + 1, *initial = slope + w;
    double elapsed = t - c[LIB_H];
    if (elapsed <= 0.0) {
        memcpy(out, initial, (size_t)w * sizeof(double));
        return 0;
    }
    for (int i = 0; i < w; i++)
        out[i] = initial[i] + slope[i] * elapsed;
    return 0;
}

/* -- arithmetic --------------------------------------------------------------------- */

/* gain: [mode, rows, cols, k...]: mode 0 elementwise (k has `rows` entries, or 1 for a
   scalar applying to width cols), 1 matrix (rows x cols): y = u k, or K u by matvec. */
static int gain_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                       int *which)
{
    (void)t, (void)state, (void)which;
    const double *c = (const double *)ctx + LIB_H;
    int mode = (int)c[0], rows = (int)c[1], cols = (int)c[2];
    const double *k = c + 3, *u = inputs[0];
    if (mode == 1) {
        matvec(k, rows, cols, u, out);
    } else if (rows == 1) {
        for (int i = 0; i < cols; i++)
            out[i] = u[i] * k[0];
    } else {
        for (int i = 0; i < rows; i++)
            out[i] = u[i] * k[i];
    }
    return 0;
}

/* sum: [count, negate_sum, sign(count)] (sign +1 / -1 per input): the first '+' input,
   then the other '+' ones added in order, then the '-' ones subtracted (minus the first
   '-' to start when there is no '+'); negate_sum: "--", which is -(u0 + u1). */
static int sum_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                      int *which)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int w = LIB_W(c), count = (int)c[LIB_H];
    const double *sign = c + LIB_H + 2;
    if (c[LIB_H + 1] != 0.0) {
        const double *a = inputs[0], *b = inputs[1];
        for (int i = 0; i < w; i++)
            out[i] = -(a[i] + b[i]);
        return 0;
    }
    int first = -1;
    for (int j = 0; j < count; j++)
        if (sign[j] > 0) {
            first = j;
            break;
        }
    int skip = first;
    if (first >= 0) {
        memcpy(out, inputs[first], (size_t)w * sizeof(double));
    } else {
        skip = 0;
        for (int i = 0; i < w; i++)
            out[i] = -inputs[0][i];
    }
    for (int j = 0; j < count; j++)
        if (sign[j] > 0 && j != skip)
            for (int i = 0; i < w; i++)
                out[i] += inputs[j][i];
    for (int j = 0; j < count; j++)
        if (sign[j] < 0 && j != skip)
            for (int i = 0; i < w; i++)
                out[i] -= inputs[j][i];
    return 0;
}

/* saturation: [lower(W), upper(W)]: u clipped to [lower, upper], NaN passing through. */
static int saturation_output(const void *ctx, double t, const double *state, const double *const *inputs,
                             double *out, int *which)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int w = LIB_W(c);
    const double *lo = c + LIB_H, *hi = lo + w, *u = inputs[0];
    for (int i = 0; i < w; i++)
        out[i] = lib_clip(u[i], lo[i], hi[i]);
    return 0;
}

/* -- discrete ----------------------------------------------------------------------- */

/* unit delay (state: the last input) and zero-order hold: the header alone */
static int unit_delay_output(const void *ctx, double t, const double *state, const double *const *inputs,
                             double *out, int *which)
{
    (void)t, (void)inputs, (void)which;
    memcpy(out, state, (size_t)LIB_W((const double *)ctx) * sizeof(double));
    return 0;
}

static int unit_delay_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t, (void)which;
    memcpy(state, inputs[0], (size_t)LIB_W((const double *)ctx) * sizeof(double));
    return 0;
}

static int unit_delay_advance(const void *ctx, double t, double *state, const double *const *inputs, int n,
                              double *rows, int *done, int *which)
{
    (void)t, (void)which;
    size_t w = (size_t)LIB_W((const double *)ctx);
    if (n > 0) {
        memcpy(state, inputs[0], w * sizeof(double));
        for (int i = 0; i < n; i++)
            memcpy(rows + (size_t)i * w, inputs[0], w * sizeof(double));
    }
    *done = n > 0 ? n : 0;
    return 0;
}

static int zero_order_hold_output(const void *ctx, double t, const double *state, const double *const *inputs,
                                  double *out, int *which)
{
    (void)t, (void)state, (void)which;
    memcpy(out, inputs[0], (size_t)LIB_W((const double *)ctx) * sizeof(double));
    return 0;
}

/* -- linear time-invariant ---------------------------------------------------------- */

/* lti context, from LIB_H on: its own header, then the matrices at the offsets the header
   gives (counted from LIB_H).
   [n, m, p, scalar, ft_path, a, b, c, d, off_CD, off_C, off_D, off_AB, chunk_max,
    off_Y[1..chunk_max], off_X[1..chunk_max]]
   scalar (n = m = p = 1): output and update on the four numbers, c x + d u and a x + b u;
   chunk c's maps, as _LinearBlock._all_chunks builds them: Y (c p x (n + m)) at off_Y[c], X (n x (n + m))
   at off_X[c] (the Y's all start at one offset: each is the first c p rows of the last).
   Any sizes: the vectors z = [x; u] of the products live on the stack up to LTI_STACK
   doubles, in memory from malloc beyond (LTI_NOMEM when there is none). */
enum { LTI_N, LTI_M, LTI_P, LTI_SCALAR, LTI_FT, LTI_A, LTI_B, LTI_C, LTI_D, LTI_OFF_CD, LTI_OFF_C, LTI_OFF_D,
       LTI_OFF_AB, LTI_CHUNK, LTI_HEADER };

#define LTI_STACK 256

enum { LTI_NOMEM = 1 }; /* failure code: no memory for the scratch (_kernels.NOMEM) */

/* count doubles of scratch: local (LTI_STACK of them) or malloc's; NULL when out of memory. */
static double *lti_scratch(double *local, size_t count)
{
    return count <= LTI_STACK ? local : malloc(count * sizeof(double));
}

static void lti_release(double *scratch, const double *local)
{
    if (scratch != local)
        free(scratch);
}

/* z = [x; u] */
static void lti_stack(double *z, const double *x, int n, const double *u, int m)
{
    memcpy(z, x, (size_t)n * sizeof(double));
    memcpy(z + n, u, (size_t)m * sizeof(double));
}

static int lti_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                      int *which)
{
    (void)t, (void)which;
    const double *c = (const double *)ctx + LIB_H;
    int n = (int)c[LTI_N], m = (int)c[LTI_M], p = (int)c[LTI_P];
    const double *u = inputs[0];
    if (c[LTI_SCALAR] != 0.0) {
        out[0] = c[LTI_FT] != 0.0 ? c[LTI_C] * state[0] + c[LTI_D] * u[0] : c[LTI_C] * state[0];
        return 0;
    }
    if (c[LTI_FT] == 0.0) {
        matvec(c + (size_t)c[LTI_OFF_C], p, n, state, out);
        return 0;
    }
    if (n == 0) {
        matvec(c + (size_t)c[LTI_OFF_D], p, m, u, out);
        return 0;
    }
    double local[LTI_STACK], *z = lti_scratch(local, (size_t)n + m);
    if (z == NULL)
        return LTI_NOMEM;
    lti_stack(z, state, n, u, m);
    matvec(c + (size_t)c[LTI_OFF_CD], p, n + m, z, out);
    lti_release(z, local);
    return 0;
}

static int lti_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t, (void)which;
    const double *c = (const double *)ctx + LIB_H;
    int n = (int)c[LTI_N], m = (int)c[LTI_M];
    const double *u = inputs[0];
    if (c[LTI_SCALAR] != 0.0) {
        state[0] = c[LTI_A] * state[0] + c[LTI_B] * u[0];
        return 0;
    }
    double local[LTI_STACK], *z = lti_scratch(local, (size_t)n + m);
    if (z == NULL)
        return LTI_NOMEM;
    lti_stack(z, state, n, u, m);
    matvec(c + (size_t)c[LTI_OFF_AB], n, n + m, z, state);
    lti_release(z, local);
    return 0;
}

/* The closed form for a held input, x_{k+i} = A^i x + (sum_{j<i} A^j) B u: per chunk of at
   most chunk_max steps, the rows Y z and the new state X z. */
static int lti_advance(const void *ctx, double t, double *state, const double *const *inputs, int count,
                       double *rows, int *done, int *which)
{
    (void)t, (void)which;
    const double *c = (const double *)ctx + LIB_H;
    int n = (int)c[LTI_N], m = (int)c[LTI_M], p = (int)c[LTI_P], chunk = (int)c[LTI_CHUNK];
    const double *u = inputs[0];
    const double *off_y = c + LTI_HEADER - 1, *off_x = c + LTI_HEADER + chunk - 1; /* indexed by c = 1..chunk */
    *done = 0;
    if (count <= 0)
        return 0;
    if (n == 0) { /* a stateless gain: D u on every row */
        matvec(c + (size_t)c[LTI_OFF_D], p, m, u, rows);
        for (int i = 1; i < count; i++)
            memcpy(rows + (size_t)i * p, rows, (size_t)p * sizeof(double));
        *done = count;
        return 0;
    }
    int L = n + m;
    double local[LTI_STACK], *z = lti_scratch(local, 2 * (size_t)L);
    if (z == NULL)
        return LTI_NOMEM;
    double *x = z + L;
    lti_stack(z, state, n, u, m);
    for (int k = 0; k < count;) {
        int step = count - k < chunk ? count - k : chunk;
        matvec(c + (size_t)off_y[step], step * p, L, z, rows + (size_t)k * p);
        matvec(c + (size_t)off_x[step], n, L, z, x);
        memcpy(z, x, (size_t)n * sizeof(double));
        k += step;
    }
    memcpy(state, z, (size_t)n * sizeof(double));
    lti_release(z, local);
    *done = count;
    return 0;
}

/* -- kernel types: a context rebuilt from its record ---------------------------------- */

/* The summed output width a library context makes its kernel write, from its first
   numbers (the record holds at least `header` of them). */
typedef long (*width_fn)(const double *c);

static long width_first(const double *c)
{
    return (long)c[0];
}

/* A library context is its record itself (the numbers blocks/library/_kernels.py packs):
   construct copies it, after checking that it holds the header its width is read from and
   that the width is one a kernel can write. */
static int flat_construct(const double *record, long n, long header, width_fn width, blk_built *built,
                          char *message, long size)
{
    if (n < header || n > 1L << 40) {
        snprintf(message, (size_t)size, "a record of %ld numbers is too short for its kernel (at least %ld)", n,
                 header);
        return 1;
    }
    long w = width(record);
    if (!(w >= 0 && w <= n * 64 + 64)) {
        snprintf(message, (size_t)size, "the record gives an output width of %ld", w);
        return 1;
    }
    double *copy = malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    if (copy == NULL) {
        snprintf(message, (size_t)size, "no memory for a context of %ld numbers", n);
        return 1;
    }
    memcpy(copy, record, (size_t)n * sizeof(double));
    built->ctx = copy;
    built->outputs = w;
    built->state_size = -1;
    return 0;
}

#define CONSTRUCT(kind, header, width)                                                                         \
    static int kind##_construct(const double *record, long n, blk_built *built, char *message, long size)     \
    {                                                                                                          \
        return flat_construct(record, n, header, width, built, message, size);                                \
    }

CONSTRUCT(first, 1, width_first)
CONSTRUCT(gain, LIB_H + 3, width_first)
CONSTRUCT(lti, LIB_H + LTI_HEADER, width_first)

#define TYPE(kind, construct, out, upd, adv) {#kind, construct##_construct, free, NULL, out, upd, adv, NULL}
#define SIGNAL(kind) TYPE(kind, first, kind##_output, NULL, NULL)
#define STATEFUL(kind) TYPE(kind, first, kind##_output, kind##_update, NULL)
#define ADVANCING(kind) TYPE(kind, first, kind##_output, kind##_update, kind##_advance)

const blk_kernel_type blk_library_types[] = {
    SIGNAL(constant),
    SIGNAL(step),
    SIGNAL(ramp),
    TYPE(gain, gain, gain_output, NULL, NULL),
    SIGNAL(sum),
    SIGNAL(saturation),
    ADVANCING(unit_delay),
    SIGNAL(zero_order_hold),
    TYPE(lti, lti, lti_output, lti_update, lti_advance),
    SIGNAL(abs),
    SIGNAL(sign),
    SIGNAL(bias),
    SIGNAL(minmax),
    SIGNAL(math),
    SIGNAL(relational),
    SIGNAL(compare),
    SIGNAL(logic),
    SIGNAL(dead_zone),
    SIGNAL(quantizer),
    SIGNAL(product),
    SIGNAL(threshold_switch),
    SIGNAL(multiport_switch),
    SIGNAL(lookup1d),
    SIGNAL(lookup2d),
    SIGNAL(concatenate),
    SIGNAL(selector),
    ADVANCING(integrator),
    STATEFUL(derivative),
    STATEFUL(moving_average),
    ADVANCING(pid),
    STATEFUL(rate_limiter),
    STATEFUL(backlash),
    STATEFUL(stop),
    SIGNAL(sine),
    SIGNAL(pulse),
    SIGNAL(chirp),
    SIGNAL(from_file),
    ADVANCING(random_number),
    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL},
};
