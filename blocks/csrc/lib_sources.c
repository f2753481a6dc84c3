/* Kernels of the library's sources of time: sine, pulse, chirp, data from a file, and
 * seeded random numbers (blocks/library/waveforms.py, from_file.py, noise.py). Contexts as
 * lib_common.h says: [W, T, ...] then the block's numbers from LIB_H on. */
#include <stdint.h>

#include "lib_common.h"

/* sine: [amplitude(W), omega = 2 pi f (W), phase(W), bias(W)]: A sin(omega t + phase) + bias */
LIB_OUTPUT(sine)
{
    (void)state, (void)inputs, (void)which;
    const double *c = ctx;
    int w = LIB_W(c);
    const double *A = c + LIB_H, *omega = A + w, *phase = omega + w, *bias = phase + w;
    for (int i = 0; i < w; i++)
        out[i] = A[i] * sin(omega[i] * t + phase[i]) + bias[i];
    return 0;
}

#define PULSE_EDGE 1e-9
/* A time within this fraction of a period of a pulse's edge is on the edge: tick times are
   floats (k * tick rounded), so 0.3 s is not exactly three periods of 0.1 s. */

/* pulse: [amplitude(W), period(W), duty(W), delay(W)]: amplitude from delay + j period for
   duty periods, 0 otherwise (and before delay) */
LIB_OUTPUT(pulse)
{
    (void)state, (void)inputs, (void)which;
    const double *c = ctx;
    int w = LIB_W(c);
    const double *A = c + LIB_H, *P = A + w, *duty = P + w, *delay = duty + w;
    for (int i = 0; i < w; i++) {
        double phase = (t - delay[i]) / P[i];
        double cycles = floor(phase + PULSE_EDGE);
        out[i] = cycles >= 0.0 && phase - cycles < duty[i] - PULSE_EDGE ? A[i] : 0.0;
    }
    return 0;
}

/* chirp: [logarithmic, amplitude(W), a(W), b(W), phase(W)]: A sin(a t + b t^2 + phase)
   (linear: a = 2 pi f0, b = pi (f1 - f0) / T1) or A sin(a expm1(b t) + phase)
   (logarithmic: a = 2 pi f0 T1 / ln(f1 / f0), b = ln(f1 / f0) / T1) */
LIB_OUTPUT(chirp)
{
    (void)state, (void)inputs, (void)which;
    const double *c = ctx;
    int w = LIB_W(c), logarithmic = c[LIB_H] != 0.0;
    const double *A = c + LIB_H + 1, *a = A + w, *b = a + w, *phase = b + w;
    for (int i = 0; i < w; i++) {
        double angle = logarithmic ? a[i] * expm1(b[i] * t) : a[i] * t + b[i] * (t * t);
        out[i] = A[i] * sin(angle + phase[i]);
    }
    return 0;
}

/* from_file: [n, linear, times(n), values(n x W)]: the last row at or before t (of equal
   times the last), or between it and the next one linearly; before the first time the
   first row, from the last time on the last row */
LIB_OUTPUT(from_file)
{
    (void)state, (void)inputs, (void)which;
    const double *c = ctx;
    int w = LIB_W(c), n = (int)c[LIB_H], linear = c[LIB_H + 1] != 0.0;
    const double *times = c + LIB_H + 2, *values = times + n;
    int lo = 0;
    if (t >= times[n - 1]) {
        lo = n - 1;
    } else if (t > times[0]) {
        int hi = n - 1; /* times[lo] <= t < times[hi] */
        while (hi - lo > 1) {
            int mid = lo + (hi - lo) / 2;
            if (t < times[mid])
                hi = mid;
            else
                lo = mid;
        }
    }
    const double *row = values + (size_t)lo * w;
    if (!linear || lo == n - 1 || t <= times[0]) {
        for (int i = 0; i < w; i++)
            out[i] = row[i];
        return 0;
    }
    double f = (t - times[lo]) / (times[lo + 1] - times[lo]);
    for (int i = 0; i < w; i++)
        out[i] = row[i] + (row[w + i] - row[i]) * f;
    return 0;
}

/* -- seeded random numbers ----------------------------------------------------------------- */

/* Counter-based: the number for (seed, stream, counter) is a hash of the three, so a
   block's output at its k-th hit depends on nothing else and is the same on every IEEE
   754 machine: integer mixing (SplitMix64's finaliser, a bijection of 64-bit words), and
   for the normal distribution only +, -, *, / and sqrt, which IEEE 754 rounds exactly,
   with a logarithm of their own (libm's differ in the last bit between systems). */

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

#define GOLDEN 0x9e3779b97f4a7c15ULL

static uint64_t draw(uint64_t seed, uint64_t stream, uint64_t counter, uint64_t attempt)
{
    uint64_t z = mix64(seed ^ 0x243f6a8885a308d3ULL);
    z = mix64(z + (stream + 1) * GOLDEN);
    z = mix64(z + (counter + 1) * GOLDEN);
    return mix64(z + (attempt + 1) * GOLDEN);
}

/* A uniform number in [0, 1): the top 53 bits of a draw */
static double unit(uint64_t bits)
{
    return (double)(bits >> 11) * (1.0 / 9007199254740992.0);
}

/* ln x for 0 < x <= 1 from frexp, +, -, *, / only: x = m 2^e with m in [sqrt(1/2),
   sqrt(2)), ln m = 2 atanh(s), s = (m - 1) / (m + 1), |s| < 0.172, by its series to the
   s^25 term (the next is below 2^-60 of the sum), and e ln 2 in two parts. */
static double portable_log(double x)
{
    int e;
    double m = frexp(x, &e);
    if (m < 0.70710678118654752440) {
        m *= 2.0;
        e -= 1;
    }
    double s = (m - 1.0) / (m + 1.0), s2 = s * s, series = 1.0 / 25.0;
    for (int k = 11; k >= 0; k--)
        series = series * s2 + 1.0 / (2 * k + 1);
    return e * 6.93147180369123816490e-01 + (e * 1.90821492927058770002e-10 + 2.0 * s * series);
}

#define MAX_ATTEMPTS 64
/* Marsaglia's polar method rejects about 21 % of its pairs; 64 rejections in a row have a
   probability below 1e-42. Should it happen, the number is 0. */

static double normal(uint64_t seed, uint64_t stream, uint64_t counter)
{
    for (uint64_t j = 0; j < MAX_ATTEMPTS; j++) {
        double a = 2.0 * unit(draw(seed, stream, counter, 2 * j)) - 1.0;
        double b = 2.0 * unit(draw(seed, stream, counter, 2 * j + 1)) - 1.0;
        double s = a * a + b * b;
        if (s > 0.0 && s < 1.0)
            return a * sqrt(-2.0 * portable_log(s) / s);
    }
    return 0.0;
}

/* random_number: [uniform, seed high 32 bits, seed low 32 bits, p(W), q(W)]; state [hits]:
   element i at hit k is p + q z with z the number of (seed, i, k): normal (p the mean, q the
   standard deviation) or uniform in [0, 1) (p the minimum, q the span). */
LIB_OUTPUT(random_number)
{
    (void)t, (void)inputs, (void)which;
    const double *c = ctx;
    int w = LIB_W(c), uniform = c[LIB_H] != 0.0;
    uint64_t seed = ((uint64_t)c[LIB_H + 1] << 32) | (uint64_t)c[LIB_H + 2], k = (uint64_t)state[0];
    const double *p = c + LIB_H + 3, *q = p + w;
    for (int i = 0; i < w; i++) {
        double z = uniform ? unit(draw(seed, (uint64_t)i, k, 0)) : normal(seed, (uint64_t)i, k);
        out[i] = p[i] + q[i] * z;
    }
    return 0;
}

LIB_UPDATE(random_number)
{
    (void)ctx, (void)t, (void)inputs, (void)which;
    state[0] += 1.0;
    return 0;
}

LIB_ADVANCE(random_number)
