/* The inner loops of a model-exchange FMU's integration (fmu_me_integration.c): the layout
 * of their context, for blocks._native, which hands it and the functions to
 * blocks/fmu/solvers.py. */
#ifndef BLOCKS_FMU_ME_INTEGRATION_H
#define BLOCKS_FMU_ME_INTEGRATION_H

#include <Python.h>

/* The context: an int64 table, pointers stored as integers. */
enum {
    ME_COMPONENT,       /* the fmi2Component / fmi3Instance */
    ME_VERSION,         /* 2 or 3 */
    ME_SET_TIME,        /* the FMU's functions: setTime, */
    ME_SET_STATES,      /* setContinuousStates, */
    ME_GET_DERIVATIVES, /* getDerivatives / getContinuousStateDerivatives, */
    ME_GET_INDICATORS,  /* getEventIndicators, */
    ME_COMPLETED,       /* completedIntegratorStep (0: the FMU does not need it) */
    ME_ARRAY,           /* N_VGetArrayPointer of SUNDIALS' serial vectors (CVode's callbacks only) */
    ME_NX,              /* the number of continuous states */
    ME_NZ,              /* the number of event indicators */
    ME_VALUES,          /* double *: ME_V_* */
    ME_X,               /* double *: the states (nx) */
    ME_DX,              /* double *: their derivatives (nx) */
    ME_X_START,         /* double *: the states at the start of an Euler step (nx) */
    ME_Z,               /* double *: the event indicators at the start of an Euler step (nz) */
    ME_Z_NEW,           /* double *: the event indicators at its end (nz) */
    ME_FAILED,          /* out: which call failed (ME_CALL_*), 0 for none */
    ME_FAILED_STATUS,   /* out: the status it returned */
    ME_TRACE,           /* isolated FMU: char *, where each call first writes the FMU function it calls, */
    ME_TRACE_NAMES,     /* and const char **, their names by ME_CALL_* (0: no trace) */
    ME_TABLE_SIZE
};

/* The values array. */
enum {
    ME_V_REACHED,     /* out: the time an Euler integration reached */
    ME_V_FAILED_TIME, /* out: the FMU's time at the failed call */
    ME_V_LOCATE,      /* in: how closely a state event is located in time (s) */
    ME_V_SIZE
};

/* The FMU calls, as ME_FAILED names them. */
enum { ME_CALL_NONE, ME_CALL_SET_TIME, ME_CALL_SET_STATES, ME_CALL_GET_DERIVATIVES, ME_CALL_GET_INDICATORS,
       ME_CALL_COMPLETED };

/* What an Euler integration (blk_me_euler) ended with; a negative value: a failed call. */
enum { ME_REACHED, ME_STATE_EVENT, ME_STEP_EVENT, ME_TERMINATE, ME_CALL_FAILED = -1 };

/* {"euler": address, "rhs": address, "roots": address, "slots": {...}, "values": {...},
   "calls": {...}, "outcomes": {...}}: the functions and the layout of their context. */
PyObject *blk_fmu_me_functions(void);

#endif
