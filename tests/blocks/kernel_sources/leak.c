/* Test kernels of the calling convention in blocks/csrc/blocks_kernel.h.
 *
 * Leak: state x (width w), update x = a x + b u elementwise, outputs y = x and
 * sum = x[0] + ... + x[w-1]; an update whose new |x[i]| exceeds the limit fails with code 7
 * and which = i, leaving x as it was. Scale: y = k u (feedthrough, no state).
 * ctx: Leak [a, b, limit, w]; Scale [k, w].
 */
#include <math.h>

#include "blocks_kernel.h"

static int leak_step(const double *p, double *x, const double *u, int *which)
{
    int w = (int)p[3];
    for (int i = 0; i < w; i++)
        if (fabs(p[0] * x[i] + p[1] * u[i]) > p[2]) {
            *which = i;
            return 7;
        }
    for (int i = 0; i < w; i++)
        x[i] = p[0] * x[i] + p[1] * u[i];
    return 0;
}

static void leak_out(const double *p, const double *x, double *out)
{
    int w = (int)p[3];
    double sum = 0.0;
    for (int i = 0; i < w; i++) {
        out[i] = x[i];
        sum += x[i];
    }
    out[w] = sum;
}

int leak_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out, int *which)
{
    (void)t;
    (void)inputs;
    (void)which;
    leak_out(ctx, state, out);
    return 0;
}

int leak_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    return leak_step(ctx, state, inputs[0], which);
}

int leak_advance(const void *ctx, double t, double *state, const double *const *inputs, int n, double *rows,
                 int *done, int *which)
{
    (void)t;
    const double *p = ctx;
    int w = (int)p[3];
    for (int i = 0; i < n; i++) {
        int code = leak_step(p, state, inputs[0], which);
        if (code) {
            *done = i;
            return code;
        }
        leak_out(p, state, rows + i * (w + 1));
    }
    *done = n;
    return 0;
}

int scale_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out, int *which)
{
    (void)t;
    (void)state;
    (void)which;
    const double *p = ctx;
    for (int i = 0; i < (int)p[1]; i++)
        out[i] = p[0] * inputs[0][i];
    return 0;
}

/* Ticker: state [count]; each update adds one, and the update that brings the count to
   ctx[0] sends this process SIGINT (as Ctrl-C would, in the middle of a C call). */
#include <signal.h>

int ticker_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                  int *which)
{
    (void)ctx, (void)t, (void)inputs, (void)which;
    out[0] = state[0];
    return 0;
}

int ticker_advance(const void *ctx, double t, double *state, const double *const *inputs, int n, double *rows,
                   int *done, int *which)
{
    (void)t, (void)inputs, (void)which;
    for (int i = 0; i < n; i++) {
        state[0] += 1.0;
        if (state[0] == ((const double *)ctx)[0])
            raise(SIGINT);
        rows[i] = state[0];
    }
    *done = n;
    return 0;
}

/* Gate: stateless; its output waits until another thread opens the gate, which that thread
   can only do while the run has released the GIL. ctx: [open, waiting, patience (s)]: the
   output sets waiting (a test's handshake, the one write through a context here), then
   waits for open and gives 1; code 1 when patience runs out first. */
#include <time.h>

static double seconds(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

int gate_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                int *which)
{
    (void)t, (void)state, (void)inputs, (void)which;
    volatile double *gate = (volatile double *)ctx;
    double start = seconds();
    gate[1] = 1.0;
    while (gate[0] == 0.0)
        if (seconds() - start > gate[2])
            return 1;
    out[0] = 1.0;
    return 0;
}

/* Stopper: state [count]; y = [count, t]. Each update adds one, and the update that brings
   the count to ctx[0] asks to end the run (BLK_END_RUN), the new count kept. */
int stopper_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                   int *which)
{
    (void)ctx, (void)inputs, (void)which;
    out[0] = state[0];
    out[1] = t;
    return 0;
}

int stopper_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t, (void)inputs, (void)which;
    state[0] += 1.0;
    return state[0] == ((const double *)ctx)[0] ? BLK_END_RUN : 0;
}
