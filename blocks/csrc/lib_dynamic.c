/* Kernels of the library's blocks with state: integrator, derivative, moving average, PID,
 * rate limiter, backlash and stop (blocks/library/integrator.py, pid.py, discrete.py,
 * nonlinear.py, stop.py). Contexts as lib_common.h says: [W, T, ...] then the block's
 * numbers from LIB_H on; each kernel's state layout is written above it.
 *
 * Output and update of a block compute the hit's values by the same function, so the
 * update's state follows from exactly the output the hit gave. */
#include <string.h>

#include "lib_common.h"

/* -- discrete-time integrator ----------------------------------------------------------- */

/* integrator: [c, after, state_form, reset kind, K(W), lower(W), upper(W), initial(W)];
   state [x(W), previous reset, started]; inputs u (and reset).
   The integral rule: y(n) = clip(x(n) + c K u(n)), x(n+1) = clip(y(n) + after K u(n)),
   c + after = T (forward Euler c = 0, backward c = T, trapezoidal c = T / 2). Without
   state_form the first hit, and a hit that resets, output clip(initial) (Simulink's
   initial output); with it the state starts at, and resets to, initial. y (or NULL) gets
   the outputs, next (or NULL; it may be state itself) the state after the hit. */
static void integrate(const double *c, const double *state, const double *const *inputs, double *y, double *next)
{
    int w = LIB_W(c), state_form = c[LIB_H + 2] != 0.0, kind = (int)c[LIB_H + 3];
    double cc = c[LIB_H], after = c[LIB_H + 1];
    const double *K = c + LIB_H + 4, *lo = K + w, *hi = lo + w, *ic = hi + w, *u = inputs[0];
    int reset = kind != LIB_RESET_NONE && lib_reset(kind, state[w], inputs[1][0]);
    int first = !state_form && (state[w + 1] == 0.0 || reset);
    for (int i = 0; i < w; i++) {
        double v = K[i] * u[i], out;
        if (first) {
            out = lib_clip(ic[i], lo[i], hi[i]);
        } else {
            double base = reset ? ic[i] : state[i];
            out = lib_clip(cc != 0.0 ? base + cc * v : base, lo[i], hi[i]);
        }
        if (y != NULL)
            y[i] = out;
        if (next != NULL)
            next[i] = after != 0.0 ? lib_clip(out + after * v, lo[i], hi[i]) : out;
    }
}

LIB_OUTPUT(integrator)
{
    (void)t, (void)which;
    integrate(ctx, state, inputs, out, NULL);
    return 0;
}

LIB_UPDATE(integrator)
{
    (void)t, (void)which;
    const double *c = ctx;
    int w = LIB_W(c);
    integrate(c, state, inputs, NULL, state);
    if ((int)c[LIB_H + 3] != LIB_RESET_NONE)
        state[w] = inputs[1][0];
    state[w + 1] = 1.0;
    return 0;
}

LIB_ADVANCE(integrator)

/* -- discrete derivative -------------------------------------------------------------- */

/* derivative: [K(W)]; state [previous input(W)]: y = K (u - previous) / T */
LIB_OUTPUT(derivative)
{
    (void)t, (void)which;
    const double *c = ctx, *K = c + LIB_H, *u = inputs[0];
    double T = LIB_T(c);
    for (int i = 0; i < LIB_W(c); i++)
        out[i] = K[i] * (u[i] - state[i]) / T;
    return 0;
}

LIB_UPDATE(derivative)
{
    (void)t, (void)which;
    memcpy(state, inputs[0], (size_t)LIB_W((const double *)ctx) * sizeof(double));
    return 0;
}

/* -- moving average ------------------------------------------------------------------- */

/* moving_average: [N]; state [oldest slot, the N - 1 previous inputs (slot-major, W each)]:
   y = (the previous N - 1 inputs from the oldest, then u, summed in that order) / N */
LIB_OUTPUT(moving_average)
{
    (void)t, (void)which;
    const double *c = ctx, *u = inputs[0], *buf = state + 1;
    int w = LIB_W(c), slots = (int)c[LIB_H] - 1, oldest = (int)state[0];
    for (int i = 0; i < w; i++) {
        double s = 0.0;
        for (int j = 0; j < slots; j++)
            s += buf[(size_t)((oldest + j) % slots) * w + i];
        out[i] = (s + u[i]) / c[LIB_H];
    }
    return 0;
}

LIB_UPDATE(moving_average)
{
    (void)t, (void)which;
    const double *c = ctx;
    int w = LIB_W(c), slots = (int)c[LIB_H] - 1;
    if (slots > 0) {
        int oldest = (int)state[0];
        memcpy(state + 1 + (size_t)oldest * w, inputs[0], (size_t)w * sizeof(double));
        state[0] = (double)((oldest + 1) % slots);
    }
    return 0;
}

/* -- PID ---------------------------------------------------------------------------------- */

enum { AW_NONE, AW_CLAMPING, AW_BACK_CALCULATION };

/* pid: [c, filtered, anti-windup, tracking, reset kind, P(W), I(W), D(W), Nf(W), lower(W),
   upper(W), Kb(W), Kt(W), initial integrator(W), initial filter(W)];
   state [integrator x(W), filter f(W), previous reset]; inputs u (error), then track and
   reset where the block has them. Gains are the parallel form's (pid.py converts the
   ideal one). At a hit, with e = u:
     integral    yI = x + c I e                     (c as the integrator's, above)
     derivative  d = Nf (D e - f),  Nf = N / (1 + N cf)   (cf: the filter's rule)
                 unfiltered: d = D (e - f) / T, f the previous error
     output      y = clip(P e + yI + d)
   and the state after it: x' = x + T v with v = I e, made 0 by clamping when the output
   saturates and I e pushes further, plus Kb (y - unsaturated) by back-calculation and
   Kt (track - y) when tracking; f' = f + T d (unfiltered: e). A reset restarts x and f
   from their initial values at that hit. */
typedef struct {
    int w, filtered, aw, tracking, kind;
    double T, c;
    const double *P, *I, *D, *Nf, *lo, *hi, *Kb, *Kt, *x0, *f0;
} pid_params;

static pid_params pid_unpack(const double *c)
{
    pid_params p;
    p.w = LIB_W(c);
    p.T = LIB_T(c);
    p.c = c[LIB_H];
    p.filtered = c[LIB_H + 1] != 0.0;
    p.aw = (int)c[LIB_H + 2];
    p.tracking = c[LIB_H + 3] != 0.0;
    p.kind = (int)c[LIB_H + 4];
    const double *v = c + LIB_H + 5;
    const double **fields[] = {&p.P, &p.I, &p.D, &p.Nf, &p.lo, &p.hi, &p.Kb, &p.Kt, &p.x0, &p.f0};
    for (size_t k = 0; k < sizeof fields / sizeof fields[0]; k++)
        *fields[k] = v + k * (size_t)p.w;
    return p;
}

static int pid_reset(const pid_params *p, const double *state, const double *const *inputs)
{
    return p->kind != LIB_RESET_NONE && lib_reset(p->kind, state[2 * p->w], inputs[1 + p->tracking][0]);
}

/* Element i's terms at this hit: its output, unsaturated output, integrator input I e,
   derivative term and the states it started from. */
typedef struct {
    double y, unsaturated, v, d, x, f;
} pid_terms;

static pid_terms pid_terms_of(const pid_params *p, const double *state, double e, int reset, int i)
{
    pid_terms r;
    r.x = reset ? p->x0[i] : state[i];
    r.f = reset ? p->f0[i] : state[p->w + i];
    r.v = p->I[i] * e;
    double integral = p->c != 0.0 ? r.x + p->c * r.v : r.x;
    r.d = p->filtered ? p->Nf[i] * (p->D[i] * e - r.f) : p->D[i] * (e - r.f) / p->T;
    r.unsaturated = p->P[i] * e + integral + r.d;
    r.y = lib_clip(r.unsaturated, p->lo[i], p->hi[i]);
    return r;
}

LIB_OUTPUT(pid)
{
    (void)t, (void)which;
    pid_params p = pid_unpack(ctx);
    int reset = pid_reset(&p, state, inputs);
    for (int i = 0; i < p.w; i++)
        out[i] = pid_terms_of(&p, state, inputs[0][i], reset, i).y;
    return 0;
}

LIB_UPDATE(pid)
{
    (void)t, (void)which;
    pid_params p = pid_unpack(ctx);
    int reset = pid_reset(&p, state, inputs);
    for (int i = 0; i < p.w; i++) {
        double e = inputs[0][i];
        pid_terms r = pid_terms_of(&p, state, e, reset, i);
        double v = r.v, excess = r.unsaturated - r.y;
        if (p.aw == AW_CLAMPING && excess != 0.0 && excess * v > 0.0)
            v = 0.0;
        else if (p.aw == AW_BACK_CALCULATION)
            v += p.Kb[i] * (r.y - r.unsaturated);
        if (p.tracking)
            v += p.Kt[i] * (inputs[1][i] - r.y);
        state[i] = r.x + p.T * v;
        state[p.w + i] = p.filtered ? r.f + p.T * r.d : e;
    }
    if (p.kind != LIB_RESET_NONE)
        state[2 * p.w] = inputs[1 + p.tracking][0];
    return 0;
}

LIB_ADVANCE(pid)

/* -- rate limiter and backlash ------------------------------------------------------------ */

/* name_output and name_update of a block whose state is its previous output and whose
   element i's output is next(c, state, u, i): the update stores what the output gave. */
#define LIB_FOLLOWS_PREVIOUS(name, next)                                                                    \
    LIB_OUTPUT(name)                                                                                        \
    {                                                                                                       \
        (void)t, (void)which;                                                                               \
        const double *c = ctx;                                                                              \
        for (int i = 0; i < LIB_W(c); i++)                                                                  \
            out[i] = next(c, state, inputs[0], i);                                                          \
        return 0;                                                                                           \
    }                                                                                                       \
    LIB_UPDATE(name)                                                                                        \
    {                                                                                                       \
        (void)t, (void)which;                                                                               \
        const double *c = ctx;                                                                              \
        for (int i = 0; i < LIB_W(c); i++)                                                                  \
            state[i] = next(c, state, inputs[0], i);                                                        \
        return 0;                                                                                           \
    }

/* rate_limiter: [rising(W), falling(W)]; state [previous output(W)]: with rate = (u - y')
   / T, y = y' + T rising above the rising rate, y' + T falling below the falling one, else
   u (Simulink's Rate Limiter in discrete mode; y' starts at the initial condition). */
static double limited(const double *c, const double *state, const double *u, int i)
{
    int w = LIB_W(c);
    double T = LIB_T(c), rise = c[LIB_H + i], fall = c[LIB_H + w + i], prev = state[i];
    double rate = (u[i] - prev) / T;
    return rate > rise ? T * rise + prev : rate < fall ? T * fall + prev : u[i];
}

LIB_FOLLOWS_PREVIOUS(rate_limiter, limited)

/* backlash: [half the deadband width(W)]; state [previous output(W)]: the output follows
   the input only once the input has crossed half the deadband from it, then from that
   edge; inside, it holds. */
static double engaged(const double *c, const double *state, const double *u, int i)
{
    double half = c[LIB_H + i], prev = state[i], gap = u[i] - prev;
    return gap > half ? u[i] - half : gap < -half ? u[i] + half : isnan(gap) ? gap : prev;
}

LIB_FOLLOWS_PREVIOUS(backlash, engaged)

/* -- stop ------------------------------------------------------------------------------------ */

/* stop: [input width]; state [stopped]: an update whose input has a non-zero element (NaN
   too) sets stopped and ends the run (BLK_END_RUN, *which = that element). No outputs. */
LIB_OUTPUT(stop)
{
    (void)ctx, (void)t, (void)state, (void)inputs, (void)out, (void)which;
    return 0;
}

LIB_UPDATE(stop)
{
    (void)t;
    const double *c = ctx;
    for (int i = 0; i < (int)c[LIB_H]; i++)
        if (inputs[0][i] != 0.0) {
            state[0] = 1.0;
            *which = i;
            return BLK_END_RUN;
        }
    return 0;
}
