/* The inner loops of a model-exchange FMU's integration (blocks/fmu/solvers.py), in C so
 * that no Python runs between the FMU's own functions:
 *
 * - blk_me_euler: forward Euler steps between two times along the hit interval's grid of
 *   sub-steps, stopping at the first state event (an event indicator changing sign, located
 *   by bisection to a time tolerance), at a step event or a request to terminate from
 *   completedIntegratorStep;
 * - blk_me_rhs, blk_me_roots: the right-hand side and the root function CVode calls (the
 *   CVRhsFn and CVRootFn of SUNDIALS 7, the CVode that fmpy ships), which set the time and
 *   the states and get the derivatives or the event indicators.
 *
 * Their context is one FMU instance's int64 table (ME_* slots of fmu_me_integration.h),
 * made and filled by blocks/fmu/solvers.py: the FMU's component and functions, the
 * buffers. A call that returns worse than a warning is recorded there (which call, its
 * status, the time) for the Python side's message; where the table has ME_TRACE (an FMU
 * isolated in a process of its own, fmu_channel.h), each call first writes the name of the
 * FMU function it calls there. Called through ctypes, without the GIL; nothing here but
 * blk_fmu_me_functions (the layout for Python) touches Python.
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "fmu_me_integration.h"
#include "layout_names.h"

typedef int (*set_time_fn)(void *, double);
typedef int (*states_fn)(void *, double *, size_t);
typedef int (*fmi2_completed_fn)(void *, int, int *, int *);
typedef int (*fmi3_completed_fn)(void *, bool, bool *, bool *);
typedef double *(*array_fn)(void *);

#define SLOT(c, i, type) ((type)(intptr_t)(c)[i])
#define MAX_BISECTIONS 200

/* Name the FMU function of the call about to be made, where calls are traced. */
static void trace(const int64_t *c, int call)
{
    if (c[ME_TRACE])
        strcpy(SLOT(c, ME_TRACE, char *), SLOT(c, ME_TRACE_NAMES, const char *const *)[call]);
}

/* Record the failed call and its status at time t; ME_CALL_FAILED. */
static int failed(int64_t *c, int call, int status, double t)
{
    c[ME_FAILED] = call;
    c[ME_FAILED_STATUS] = status;
    SLOT(c, ME_VALUES, double *)[ME_V_FAILED_TIME] = t;
    return ME_CALL_FAILED;
}

/* The FMU at time t with the states x: setTime, setContinuousStates. */
static int place(int64_t *c, double t, double *x)
{
    void *component = SLOT(c, ME_COMPONENT, void *);
    trace(c, ME_CALL_SET_TIME);
    int status = SLOT(c, ME_SET_TIME, set_time_fn)(component, t);
    if (status > 1)
        return failed(c, ME_CALL_SET_TIME, status, t);
    if (c[ME_NX] > 0) {
        trace(c, ME_CALL_SET_STATES);
        status = SLOT(c, ME_SET_STATES, states_fn)(component, x, (size_t)c[ME_NX]);
        if (status > 1)
            return failed(c, ME_CALL_SET_STATES, status, t);
    }
    return 0;
}

static int call(int64_t *c, int slot, int which, double *out, size_t n, double t)
{
    trace(c, which);
    int status = SLOT(c, slot, states_fn)(SLOT(c, ME_COMPONENT, void *), out, n);
    return status > 1 ? failed(c, which, status, t) : 0;
}

/* Whether an event indicator changed sign from z to z_new (to zero or across it), as
   FMI's importers (and fmpy's Euler) detect state events. */
static bool crossed(const double *z, const double *z_new, int64_t nz)
{
    for (int64_t i = 0; i < nz; i++)
        if ((z[i] < 0.0 && z_new[i] >= 0.0) || (z[i] > 0.0 && z_new[i] <= 0.0))
            return true;
    return false;
}

/* completedIntegratorStep after a step to t, if the FMU needs it: ME_REACHED, a step
   event, a request to terminate, or a failure. */
static int completed(int64_t *c, double t)
{
    if (!c[ME_COMPLETED])
        return ME_REACHED;
    void *component = SLOT(c, ME_COMPONENT, void *);
    int status;
    bool enter, terminate;
    trace(c, ME_CALL_COMPLETED);
    if (c[ME_VERSION] == 3) {
        status = SLOT(c, ME_COMPLETED, fmi3_completed_fn)(component, true, &enter, &terminate);
    } else {
        int enter2 = 0, terminate2 = 0;
        status = SLOT(c, ME_COMPLETED, fmi2_completed_fn)(component, 1, &enter2, &terminate2);
        enter = enter2 != 0, terminate = terminate2 != 0;
    }
    if (status > 1)
        return failed(c, ME_CALL_COMPLETED, status, t);
    return terminate ? ME_TERMINATE : enter ? ME_STEP_EVENT : ME_REACHED;
}

/* The time of the state event in the Euler step from t over hs (the states moving from
   x0 along dx): bisection on the indicators to the tolerance ME_V_LOCATE, keeping the end
   where they have crossed. Leaves the FMU, and x, at the event. */
static int locate(int64_t *c, double t, double hs, const double *x0, const double *dx, double *x, double *event)
{
    int64_t nx = c[ME_NX], nz = c[ME_NZ];
    const double *z = SLOT(c, ME_Z, double *);
    double *z_new = SLOT(c, ME_Z_NEW, double *);
    double tolerance = SLOT(c, ME_VALUES, double *)[ME_V_LOCATE];
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < MAX_BISECTIONS && (hi - lo) * hs > tolerance; i++) {
        double mid = 0.5 * (lo + hi);
        for (int64_t j = 0; j < nx; j++)
            x[j] = x0[j] + mid * hs * dx[j];
        int code = place(c, t + mid * hs, x);
        if (code == 0)
            code = call(c, ME_GET_INDICATORS, ME_CALL_GET_INDICATORS, z_new, (size_t)nz, t + mid * hs);
        if (code)
            return code;
        if (crossed(z, z_new, nz))
            hi = mid;
        else
            lo = mid;
    }
    *event = hi == 1.0 ? t + hs : t + hi * hs;
    for (int64_t j = 0; j < nx; j++)
        x[j] = x0[j] + hi * hs * dx[j];
    return place(c, *event, x);
}

/* Forward Euler from start to stop, each step ending at the next point of the grid
   base + (end - base) k / n (k = 1 .. n, the last one end itself) or at stop. The FMU is
   at start with the states ME_X (and the indicators ME_Z there); it is left at the time
   reached (ME_V_REACHED) with the states there. Returns an ME_* outcome of fmu_me_integration.h. */
static long euler(int64_t *c, double start, double stop, double base, double end, long n)
{
    int64_t nx = c[ME_NX], nz = c[ME_NZ];
    double *v = SLOT(c, ME_VALUES, double *);
    double *x = SLOT(c, ME_X, double *), *dx = SLOT(c, ME_DX, double *), *x0 = SLOT(c, ME_X_START, double *);
    double *z = SLOT(c, ME_Z, double *), *z_new = SLOT(c, ME_Z_NEW, double *);
    double step = (end - base) / (double)n, eps = 1e-9 * step;
    double t = start;
    long k = (long)floor((start - base) / step + 1e-9) + 1;
    c[ME_FAILED] = ME_CALL_NONE;
    while (t < stop - eps) {
        double grid = k >= n ? end : base + (end - base) * ((double)k / (double)n);
        bool on_grid = grid <= stop + eps;
        double tb = on_grid ? grid : stop, hs = tb - t;
        int code = nx > 0 ? call(c, ME_GET_DERIVATIVES, ME_CALL_GET_DERIVATIVES, dx, (size_t)nx, t) : 0;
        if (code)
            return code;
        memcpy(x0, x, (size_t)nx * sizeof(double));
        for (int64_t j = 0; j < nx; j++)
            x[j] += hs * dx[j];
        code = place(c, tb, x);
        if (code == 0 && nz > 0)
            code = call(c, ME_GET_INDICATORS, ME_CALL_GET_INDICATORS, z_new, (size_t)nz, tb);
        if (code)
            return code;
        if (nz > 0 && crossed(z, z_new, nz)) {
            double event;
            code = locate(c, t, hs, x0, dx, x, &event);
            if (code)
                return code;
            v[ME_V_REACHED] = event;
            code = completed(c, event);
            return code == ME_REACHED ? ME_STATE_EVENT : code;
        }
        v[ME_V_REACHED] = tb;
        code = completed(c, tb);
        if (code != ME_REACHED)
            return code;
        memcpy(z, z_new, (size_t)nz * sizeof(double));
        t = tb;
        if (on_grid)
            k++;
    }
    v[ME_V_REACHED] = t;
    return ME_REACHED;
}

long blk_me_euler(void *ctx, double start, double stop, double base, double end, long n)
{
    return euler((int64_t *)ctx, start, stop, base, end, n);
}

/* CVode's right-hand side: the derivatives at t, y. A discard asks CVode for a smaller
   step (a recoverable error); worse ends the integration. Without states (CVode then
   integrates one dummy state), only the time is set. */
int blk_me_rhs(double t, void *y, void *ydot, void *user_data)
{
    int64_t *c = user_data;
    array_fn array = SLOT(c, ME_ARRAY, array_fn);
    double *dx = array(ydot);
    if (place(c, t, array(y)))
        return -1;
    if (c[ME_NX] == 0) {
        dx[0] = 0.0;
        return 0;
    }
    trace(c, ME_CALL_GET_DERIVATIVES);
    int status = SLOT(c, ME_GET_DERIVATIVES, states_fn)(SLOT(c, ME_COMPONENT, void *), dx, (size_t)c[ME_NX]);
    if (status > 1) {
        failed(c, ME_CALL_GET_DERIVATIVES, status, t);
        return status == 2 ? 1 : -1;
    }
    return 0;
}

/* CVode's root function: the event indicators at t, y. */
int blk_me_roots(double t, void *y, double *gout, void *user_data)
{
    int64_t *c = user_data;
    if (place(c, t, SLOT(c, ME_ARRAY, array_fn)(y)))
        return -1;
    return call(c, ME_GET_INDICATORS, ME_CALL_GET_INDICATORS, gout, (size_t)c[ME_NZ], t) ? -1 : 0;
}

static const named slots[] = {
    {"component", ME_COMPONENT}, {"version", ME_VERSION}, {"set_time", ME_SET_TIME},
    {"set_states", ME_SET_STATES}, {"get_derivatives", ME_GET_DERIVATIVES}, {"get_indicators", ME_GET_INDICATORS},
    {"completed", ME_COMPLETED}, {"array", ME_ARRAY}, {"nx", ME_NX}, {"nz", ME_NZ}, {"values", ME_VALUES},
    {"x", ME_X}, {"dx", ME_DX}, {"x_start", ME_X_START}, {"z", ME_Z}, {"z_new", ME_Z_NEW}, {"failed", ME_FAILED},
    {"failed_status", ME_FAILED_STATUS}, {"trace", ME_TRACE}, {"trace_names", ME_TRACE_NAMES},
    {"size", ME_TABLE_SIZE}, {NULL, 0}};
static const named values[] = {
    {"reached", ME_V_REACHED}, {"failed_time", ME_V_FAILED_TIME}, {"locate", ME_V_LOCATE}, {"size", ME_V_SIZE},
    {NULL, 0}};
static const named calls[] = {
    {"set_time", ME_CALL_SET_TIME}, {"set_states", ME_CALL_SET_STATES}, {"get_derivatives", ME_CALL_GET_DERIVATIVES},
    {"get_indicators", ME_CALL_GET_INDICATORS}, {"completed", ME_CALL_COMPLETED}, {NULL, 0}};
static const named outcomes[] = {
    {"reached", ME_REACHED}, {"state_event", ME_STATE_EVENT}, {"step_event", ME_STEP_EVENT},
    {"terminate", ME_TERMINATE}, {"failed", ME_CALL_FAILED}, {NULL, 0}};

PyObject *blk_fmu_me_functions(void)
{
    return Py_BuildValue("{s:N,s:N,s:N,s:N,s:N,s:N,s:N}", "euler", PyLong_FromVoidPtr((void *)blk_me_euler), "rhs",
                         PyLong_FromVoidPtr((void *)blk_me_rhs), "roots", PyLong_FromVoidPtr((void *)blk_me_roots),
                         "slots", blk_names(slots), "values", blk_names(values), "calls", blk_names(calls),
                         "outcomes", blk_names(outcomes));
}
