/* The FMI calls of a co-simulation step over Float64 values -- set the inputs, doStep, get
 * the outputs -- as the FMU block's step makes them in the run's process
 * (fmu_block_step.c) and the server loop of an isolated FMU makes them in a process of its
 * own (fmu_channel.c): written once, as inline functions, for both. Their context is the
 * FMU_* table of fmu_step_table.h: the FMU's component and functions, the value references,
 * the buffers. Where the table has FMU_TRACE (the isolated FMU's process), each call first
 * writes the name of the FMU function it calls there, so that a crash inside it can be named.
 */
#ifndef BLOCKS_FMI_STEP_CALLS_H
#define BLOCKS_FMI_STEP_CALLS_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "fmu_step_table.h"

/* The FMI functions the step calls (the FMI 2.0 and 3.0 signatures; statuses are ints,
   ok 0 and warning 1). */
typedef int (*fmi2_set_fn)(void *, const unsigned int *, size_t, const double *);
typedef int (*fmi2_get_fn)(void *, const unsigned int *, size_t, double *);
typedef int (*fmi2_do_step_fn)(void *, double, double, int);
typedef int (*fmi3_set_fn)(void *, const unsigned int *, size_t, const double *, size_t);
typedef int (*fmi3_get_fn)(void *, const unsigned int *, size_t, double *, size_t);
typedef int (*fmi3_do_step_fn)(void *, double, double, bool, bool *, bool *, bool *, double *);

#define FMU_SLOT(c, i, type) ((type)(intptr_t)(c)[i])

/* Name the FMU function about to be called (the name in slot name), where calls are traced. */
static inline void fmu_trace(const int64_t *c, int name)
{
    if (c[FMU_TRACE])
        strcpy(FMU_SLOT(c, FMU_TRACE, char *), FMU_SLOT(c, name, const char *));
}

/* One set or get call of a group of Float64 values; first is FMU_SET or FMU_GET, whose
   slots follow in the order of fmu_step_table.h: function, value references, their count, the buffer,
   the number of values. Returns the FMI status. */
static inline int fmu_transfer(const int64_t *c, int first, bool set)
{
    void *component = FMU_SLOT(c, FMU_COMPONENT, void *);
    const unsigned int *vrs = FMU_SLOT(c, first + 1, const unsigned int *);
    size_t nvr = (size_t)c[first + 2], count = (size_t)c[first + 4];
    double *buf = FMU_SLOT(c, first + 3, double *);
    bool fmi3 = c[FMU_VERSION] == 3;
    fmu_trace(c, set ? FMU_TRACE_SET : FMU_TRACE_GET);
    if (set)
        return fmi3 ? FMU_SLOT(c, first, fmi3_set_fn)(component, vrs, nvr, buf, count)
                    : FMU_SLOT(c, first, fmi2_set_fn)(component, vrs, nvr, buf);
    return fmi3 ? FMU_SLOT(c, first, fmi3_get_fn)(component, vrs, nvr, buf, count)
                : FMU_SLOT(c, first, fmi2_get_fn)(component, vrs, nvr, buf);
}

/* doStep from t over h: its status, and in *plain whether that was a plain success (not
   worse than a warning, and for FMI 3 neither a request to terminate nor an early return;
   its output arguments are left in the FMU_FLAGS variables). */
static inline int fmu_do_step(const int64_t *c, double t, double h, bool *plain)
{
    void *component = FMU_SLOT(c, FMU_COMPONENT, void *);
    int status;
    fmu_trace(c, FMU_TRACE_STEP);
    if (c[FMU_VERSION] == 3) {
        bool *terminate = FMU_SLOT(c, FMU_FLAGS + 1, bool *), *early = FMU_SLOT(c, FMU_FLAGS + 2, bool *);
        status = FMU_SLOT(c, FMU_DO_STEP, fmi3_do_step_fn)(component, t, h, true, FMU_SLOT(c, FMU_FLAGS, bool *),
                                                            terminate, early, FMU_SLOT(c, FMU_FLAGS + 3, double *));
        *plain = status <= 1 && !*terminate && !*early;
    } else {
        status = FMU_SLOT(c, FMU_DO_STEP, fmi2_do_step_fn)(component, t, h, 1);
        *plain = status <= 1;
    }
    return status;
}

#endif
