/* Kernels of the library's memoryless blocks: arithmetic, functions, comparisons, logic,
 * lookup tables and signal routing (blocks/library/arithmetic.py, logic.py, lookup.py,
 * routing.py, nonlinear.py). Contexts as lib_common.h says: [W, T, ...] then the block's
 * numbers, listed above each kernel from LIB_H on. */
#include <stdlib.h>
#include <string.h>

#include "lib_common.h"

/* -- elementwise arithmetic ------------------------------------------------------------ */

/* abs: [] */
LIB_OUTPUT(abs)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *u = inputs[0];
    for (int i = 0; i < LIB_W(c); i++)
        out[i] = fabs(u[i]);
    return 0;
}

/* sign: [] -1, 0 or 1; NaN stays NaN */
LIB_OUTPUT(sign)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *u = inputs[0];
    for (int i = 0; i < LIB_W(c); i++) {
        double v = u[i];
        out[i] = v > 0.0 ? 1.0 : v < 0.0 ? -1.0 : v == 0.0 ? 0.0 : v;
    }
    return 0;
}

/* bias: [bias(W)] */
LIB_OUTPUT(bias)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *u = inputs[0], *b = c + LIB_H;
    for (int i = 0; i < LIB_W(c); i++)
        out[i] = u[i] + b[i];
    return 0;
}

/* The smaller (is_max: larger) of r and v; a NaN wins, as numpy's minimum lets it. */
static double pick(int is_max, double r, double v)
{
    if (isnan(r) || isnan(v))
        return isnan(r) ? r : v;
    return (is_max ? v > r : v < r) ? v : r;
}

/* minmax: [is_max, count, in_width]: one input: over its in_width elements (W = 1);
   several: elementwise over W. */
LIB_OUTPUT(minmax)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int is_max = c[LIB_H] != 0.0, count = (int)c[LIB_H + 1], in_w = (int)c[LIB_H + 2];
    if (count == 1) {
        double r = inputs[0][0];
        for (int i = 1; i < in_w; i++)
            r = pick(is_max, r, inputs[0][i]);
        out[0] = r;
        return 0;
    }
    for (int i = 0; i < LIB_W(c); i++) {
        double r = inputs[0][i];
        for (int j = 1; j < count; j++)
            r = pick(is_max, r, inputs[j][i]);
        out[i] = r;
    }
    return 0;
}

/* Function codes of the Math block (arithmetic.MATH_FUNCTIONS). */
enum { F_EXP, F_LOG, F_LOG10, F_SQRT, F_SQUARE, F_RECIPROCAL, F_SIN, F_COS, F_TAN, F_ASIN, F_ACOS, F_ATAN,
       F_SINH, F_COSH, F_TANH, F_ATAN2 = 20, F_POW, F_HYPOT, F_MOD, F_REM };

/* MATLAB's mod: the sign of the divisor; mod(u, 0) = u. */
static double floor_mod(double u, double v)
{
    if (v == 0.0)
        return u;
    double r = fmod(u, v);
    if (r != 0.0 && ((r < 0.0) != (v < 0.0)))
        r += v;
    return r;
}

static double unary(int fn, double u)
{
    switch (fn) {
    case F_EXP: return exp(u);
    case F_LOG: return log(u);
    case F_LOG10: return log10(u);
    case F_SQRT: return sqrt(u);
    case F_SQUARE: return u * u;
    case F_RECIPROCAL: return 1.0 / u;
    case F_SIN: return sin(u);
    case F_COS: return cos(u);
    case F_TAN: return tan(u);
    case F_ASIN: return asin(u);
    case F_ACOS: return acos(u);
    case F_ATAN: return atan(u);
    case F_SINH: return sinh(u);
    case F_COSH: return cosh(u);
    default: return tanh(u);
    }
}

static double binary(int fn, double a, double b)
{
    switch (fn) {
    case F_ATAN2: return atan2(a, b);
    case F_POW: return pow(a, b);
    case F_HYPOT: return hypot(a, b);
    case F_MOD: return floor_mod(a, b);
    default: return fmod(a, b); /* rem: the sign of the dividend, rem(u, 0) = NaN */
    }
}

/* math: [function]: unary functions of u, binary ones of u0 and u1 (atan2(u0, u1)) */
LIB_OUTPUT(math)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int fn = (int)c[LIB_H], w = LIB_W(c);
    if (fn >= F_ATAN2) {
        for (int i = 0; i < w; i++)
            out[i] = binary(fn, inputs[0][i], inputs[1][i]);
    } else {
        for (int i = 0; i < w; i++)
            out[i] = unary(fn, inputs[0][i]);
    }
    return 0;
}

/* dead_zone: [start(W), end(W)]: 0 inside [start, end], else the distance past the edge */
LIB_OUTPUT(dead_zone)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *u = inputs[0];
    int w = LIB_W(c);
    const double *lo = c + LIB_H, *hi = lo + w;
    for (int i = 0; i < w; i++) {
        double v = u[i];
        out[i] = v > hi[i] ? v - hi[i] : v < lo[i] ? v - lo[i] : isnan(v) ? v : 0.0;
    }
    return 0;
}

/* quantizer: [interval(W)]: q * round(u / q), halves away from zero */
LIB_OUTPUT(quantizer)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *u = inputs[0], *q = c + LIB_H;
    for (int i = 0; i < LIB_W(c); i++)
        out[i] = q[i] * round(u[i] / q[i]);
    return 0;
}

/* -- products ---------------------------------------------------------------------------- */

#define LIB_STACK 512

/* inv (n x n) = A^-1 by Gauss-Jordan elimination with partial pivoting over work (2 n^2);
   nonzero when a pivot is exactly zero (A singular). */
static int invert(const double *A, int n, double *inv, double *work)
{
    int m = 2 * n;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < m; j++)
            work[(size_t)i * m + j] = j < n ? A[(size_t)i * n + j] : (j - n == i ? 1.0 : 0.0);
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(work[(size_t)i * m + k]) > fabs(work[(size_t)p * m + k]))
                p = i;
        double pivot = work[(size_t)p * m + k];
        if (pivot == 0.0 || isnan(pivot))
            return 1;
        if (p != k)
            for (int j = 0; j < m; j++) {
                double s = work[(size_t)k * m + j];
                work[(size_t)k * m + j] = work[(size_t)p * m + j];
                work[(size_t)p * m + j] = s;
            }
        for (int j = 0; j < m; j++)
            work[(size_t)k * m + j] /= pivot;
        for (int i = 0; i < n; i++) {
            double f = work[(size_t)i * m + k];
            if (i == k || f == 0.0)
                continue;
            for (int j = 0; j < m; j++)
                work[(size_t)i * m + j] -= f * work[(size_t)k * m + j];
        }
    }
    for (int i = 0; i < n; i++)
        memcpy(inv + (size_t)i * n, work + (size_t)i * m + n, (size_t)n * sizeof(double));
    return 0;
}

/* y (r x q) = A (r x k) B (k x q), each sum in order from its first product */
static void matmul(const double *A, const double *B, int r, int k, int q, double *y)
{
    for (int i = 0; i < r; i++)
        for (int j = 0; j < q; j++) {
            double s = A[(size_t)i * k] * B[j];
            for (int l = 1; l < k; l++)
                s += A[(size_t)i * k + l] * B[(size_t)l * q + j];
            y[(size_t)i * q + j] = s;
        }
}

/* The matrix product of the inputs, left to right, each one or its inverse. */
static int matrix_product(const double *c, const double *const *inputs, double *out, int *which)
{
    int count = (int)c[LIB_H + 1];
    const double *div = c + LIB_H + 3, *rows = div + count, *cols = rows + count;
    size_t need = (size_t)c[LIB_H + 2];
    double local[LIB_STACK], *scratch = need <= LIB_STACK ? local : malloc(need * sizeof(double));
    if (scratch == NULL)
        return LIB_NOMEM;
    int biggest = 0;
    for (int j = 0; j < count; j++) {
        int size = (int)rows[j] > (int)cols[j] ? (int)rows[j] : (int)cols[j];
        biggest = size > biggest ? size : biggest;
    }
    size_t square = (size_t)biggest * biggest;
    double *cur = scratch, *next = cur + square, *inv = next + square, *work = inv + square;
    int r = (int)rows[0], q = (int)cols[0], code = 0;
    if (div[0] != 0.0) {
        if (invert(inputs[0], r, cur, work) != 0) {
            *which = 0;
            code = LIB_SINGULAR;
        }
    } else {
        memcpy(cur, inputs[0], (size_t)r * q * sizeof(double));
    }
    for (int j = 1; j < count && code == 0; j++) {
        int k = (int)rows[j], n = (int)cols[j];
        const double *B = inputs[j];
        if (div[j] != 0.0) {
            if (invert(B, k, inv, work) != 0) {
                *which = j;
                code = LIB_SINGULAR;
                break;
            }
            B = inv;
        }
        matmul(cur, B, r, k, n, next);
        double *swap = cur;
        cur = next;
        next = swap;
        q = n;
    }
    if (code == 0)
        memcpy(out, cur, (size_t)r * q * sizeof(double));
    if (scratch != local)
        free(scratch);
    return code;
}

/* product: [matrix, count, in_width or scratch size, divide(count), (matrix: rows(count),
   cols(count))]. Elementwise: u0 (or 1 / u0), then each further input multiplied or
   divided in order; one input: its elements so, left to right (W = 1). Matrix: row-major
   matrices multiplied left to right, a '/' input inverted. */
LIB_OUTPUT(product)
{
    (void)t, (void)state;
    const double *c = ctx;
    int count = (int)c[LIB_H + 1];
    const double *div = c + LIB_H + 3;
    if (c[LIB_H] != 0.0)
        return matrix_product(c, inputs, out, which);
    if (count == 1) {
        const double *u = inputs[0];
        int in_w = (int)c[LIB_H + 2];
        double p = div[0] != 0.0 ? 1.0 / u[0] : u[0];
        for (int i = 1; i < in_w; i++)
            p = div[0] != 0.0 ? p / u[i] : p * u[i];
        out[0] = p;
        return 0;
    }
    for (int i = 0; i < LIB_W(c); i++) {
        double p = div[0] != 0.0 ? 1.0 / inputs[0][i] : inputs[0][i];
        for (int j = 1; j < count; j++)
            p = div[j] != 0.0 ? p / inputs[j][i] : p * inputs[j][i];
        out[i] = p;
    }
    return 0;
}

/* -- comparisons and logic ------------------------------------------------------------ */

/* Relational operators (logic.RELATIONS): <, <=, ==, !=, >=, > */
static int relation(int op, double a, double b)
{
    switch (op) {
    case 0: return a < b;
    case 1: return a <= b;
    case 2: return a == b;
    case 3: return a != b;
    case 4: return a >= b;
    default: return a > b;
    }
}

/* relational: [op]: 1 where u0 op u1, else 0 */
LIB_OUTPUT(relational)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int op = (int)c[LIB_H];
    for (int i = 0; i < LIB_W(c); i++)
        out[i] = relation(op, inputs[0][i], inputs[1][i]) ? 1.0 : 0.0;
    return 0;
}

/* compare: [op, constant(W)]: 1 where u op constant, else 0 */
LIB_OUTPUT(compare)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *k = c + LIB_H + 1;
    int op = (int)c[LIB_H];
    for (int i = 0; i < LIB_W(c); i++)
        out[i] = relation(op, inputs[0][i], k[i]) ? 1.0 : 0.0;
    return 0;
}

/* Logic operators (logic.OPERATORS). */
enum { L_AND, L_OR, L_NAND, L_NOR, L_XOR, L_NXOR, L_NOT };

static double combine(int op, int trues, int count)
{
    int r;
    switch (op) {
    case L_AND: r = trues == count; break;
    case L_OR: r = trues > 0; break;
    case L_NAND: r = trues != count; break;
    case L_NOR: r = trues == 0; break;
    case L_XOR: r = trues % 2 == 1; break;
    default: r = trues % 2 == 0; break; /* nxor */
    }
    return r ? 1.0 : 0.0;
}

/* logic: [op, count, in_width]: non-zero (NaN too) is true; not: elementwise; one input
   of another operator: over its in_width elements (W = 1); several: elementwise. */
LIB_OUTPUT(logic)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int op = (int)c[LIB_H], count = (int)c[LIB_H + 1], in_w = (int)c[LIB_H + 2], w = LIB_W(c);
    if (op == L_NOT) {
        for (int i = 0; i < w; i++)
            out[i] = inputs[0][i] != 0.0 ? 0.0 : 1.0;
        return 0;
    }
    if (count == 1) {
        int trues = 0;
        for (int i = 0; i < in_w; i++)
            trues += inputs[0][i] != 0.0;
        out[0] = combine(op, trues, in_w);
        return 0;
    }
    for (int i = 0; i < w; i++) {
        int trues = 0;
        for (int j = 0; j < count; j++)
            trues += inputs[j][i] != 0.0;
        out[i] = combine(op, trues, count);
    }
    return 0;
}

/* -- switches ----------------------------------------------------------------------------- */

static int passes(int criterion, double control, double threshold)
{
    switch (criterion) {
    case 0: return control >= threshold;
    case 1: return control > threshold;
    default: return control != 0.0;
    }
}

/* threshold_switch: [criterion (>=, >, nonzero), threshold, elementwise]; inputs u0,
   control, u1: u0 where the control passes, else u1 (a scalar control for all elements,
   or one per element). */
LIB_OUTPUT(threshold_switch)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *a = inputs[0], *control = inputs[1], *b = inputs[2];
    int criterion = (int)c[LIB_H], each = c[LIB_H + 2] != 0.0, w = LIB_W(c);
    double threshold = c[LIB_H + 1];
    for (int i = 0; i < w; i++)
        out[i] = passes(criterion, control[each ? i : 0], threshold) ? a[i] : b[i];
    return 0;
}

/* multiport_switch: [count, base, last_default]; inputs control, u0 ... u(count-1): the
   data input numbered by the control truncated toward zero, counted from base; out of
   range: the last data input (last_default) or failure LIB_OUT_OF_RANGE. */
LIB_OUTPUT(multiport_switch)
{
    (void)t, (void)state;
    const double *c = ctx;
    int count = (int)c[LIB_H];
    double k = trunc(inputs[0][0]) - c[LIB_H + 1];
    int port;
    if (k >= 0.0 && k < count) {
        port = (int)k;
    } else if (c[LIB_H + 2] != 0.0) {
        port = count - 1;
    } else {
        *which = 0;
        return LIB_OUT_OF_RANGE;
    }
    memcpy(out, inputs[1 + port], (size_t)LIB_W(c) * sizeof(double));
    return 0;
}

/* -- lookup tables ------------------------------------------------------------------------ */

/* The segment [x[i], x[i+1]] (0 <= i <= n - 2) for u: the one holding it, the first one
   below x[0], the last one from x[n-1] on. */
static int segment(const double *x, int n, double u)
{
    int lo = 0, hi = n - 1;
    if (u < x[1])
        return 0;
    if (u >= x[n - 2])
        return n - 2;
    while (hi - lo > 1) { /* x[lo] <= u < x[hi] */
        int mid = lo + (hi - lo) / 2;
        if (u < x[mid])
            hi = mid;
        else
            lo = mid;
    }
    return lo;
}

/* a + (b - a) f, exactly b at f = 1 (a breakpoint's value at the breakpoint) */
static double lerp(double a, double b, double f)
{
    return f == 1.0 ? b : a + (b - a) * f;
}

/* u clipped into [x[0], x[n-1]] unless extrapolating */
static double into_range(const double *x, int n, double u, int extrapolate)
{
    return extrapolate ? u : u < x[0] ? x[0] : u > x[n - 1] ? x[n - 1] : u;
}

/* lookup1d: [n, extrapolate, x(n), y(n)]: linear interpolation of the table, elementwise;
   outside [x[0], x[n-1]] the end values (clip) or the end segments' lines */
LIB_OUTPUT(lookup1d)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int n = (int)c[LIB_H], extrapolate = c[LIB_H + 1] != 0.0;
    const double *x = c + LIB_H + 2, *y = x + n;
    for (int i = 0; i < LIB_W(c); i++) {
        double u = inputs[0][i];
        if (isnan(u)) {
            out[i] = u;
            continue;
        }
        u = into_range(x, n, u, extrapolate);
        int s = segment(x, n, u);
        out[i] = lerp(y[s], y[s + 1], (u - x[s]) / (x[s + 1] - x[s]));
    }
    return 0;
}

/* lookup2d: [rows, cols, extrapolate, row breakpoints(rows), column breakpoints(cols),
   table(rows x cols, row-major)]: bilinear interpolation at (u0, u1), elementwise: along
   the columns in each of the two rows, then between the rows */
LIB_OUTPUT(lookup2d)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int nr = (int)c[LIB_H], nc = (int)c[LIB_H + 1], extrapolate = c[LIB_H + 2] != 0.0;
    const double *xr = c + LIB_H + 3, *xc = xr + nr, *table = xc + nc;
    for (int i = 0; i < LIB_W(c); i++) {
        double a = inputs[0][i], b = inputs[1][i];
        if (isnan(a) || isnan(b)) {
            out[i] = a + b;
            continue;
        }
        a = into_range(xr, nr, a, extrapolate);
        b = into_range(xc, nc, b, extrapolate);
        int r = segment(xr, nr, a), k = segment(xc, nc, b);
        double fa = (a - xr[r]) / (xr[r + 1] - xr[r]), fb = (b - xc[k]) / (xc[k + 1] - xc[k]);
        const double *row0 = table + (size_t)r * nc, *row1 = row0 + nc;
        out[i] = lerp(lerp(row0[k], row0[k + 1], fb), lerp(row1[k], row1[k + 1], fb), fa);
    }
    return 0;
}

/* -- routing ---------------------------------------------------------------------------- */

/* concatenate: [count, widths(count)]: the inputs one after another (Mux, Concatenate;
   Demux is one input of width W, whose outputs lie one after another in out). */
LIB_OUTPUT(concatenate)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx;
    int count = (int)c[LIB_H];
    const double *widths = c + LIB_H + 1;
    for (int j = 0; j < count; j++) {
        size_t w = (size_t)widths[j];
        memcpy(out, inputs[j], w * sizeof(double));
        out += w;
    }
    return 0;
}

/* selector: [count, index(count)]: the input's elements at the indices, in their order */
LIB_OUTPUT(selector)
{
    (void)t, (void)state, (void)which;
    const double *c = ctx, *index = c + LIB_H + 1;
    int count = (int)c[LIB_H];
    for (int i = 0; i < count; i++)
        out[i] = inputs[0][(size_t)index[i]];
    return 0;
}
