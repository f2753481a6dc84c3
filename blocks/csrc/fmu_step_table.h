/* The context of a co-simulation FMU's steady step: one int64 table (pointers stored as
 * integers) of FMU_* slots, then the ports. The FMU block's step in the run's process
 * (fmu_block_step.c) and the server loop of an FMU isolated in a process of its own
 * (fmu_channel.c) both read it, and the FMI calls over it (fmi_step_calls.h) take it; so
 * its layout is a header of its own, which all three include and which includes nothing.
 * blocks/fmu/compiled_step.py and blocks/fmu/isolation/server.py fill it, by the names
 * that fmu_block_step.c hands Python.
 *
 * In the run's process the table holds the FMU's component and functions; in the process
 * that hosts an isolated FMU it holds them and FMU_TRACE*, and the run's table of such an
 * instance holds FMU_CHANNEL and FMU_SOCKET instead of the FMU's functions. */
#ifndef BLOCKS_FMU_STEP_TABLE_H
#define BLOCKS_FMU_STEP_TABLE_H

/* The slots. */
enum {
    FMU_SLOW,      /* PyObject *: slow(kind, t, status) -> 0, or 1 when the update ended the run */
    FMU_CHECK,     /* PyObject *: interrupt.check, called after each doStep */
    FMU_HOOK,      /* PyObject *: interrupt's sys.unraisablehook (another there: slow arms it again) */
    FMU_LOG_ARM,   /* FMI 2: fmpy's addLoggerProxy, called with FMU_LOG_ARG before a step; 0 for FMI 3 */
    FMU_LOG_ARG,
    FMU_VALUES,    /* double *: the FMU's time, the step, the outputs held there (FMU_V_*) */
    FMU_INPUTS,    /* the inputs of the call that went to slow, for the Python side */
    FMU_WIDTH,     /* the summed width of the output ports */
    FMU_STARTED,   /* the FMU is initialised: the held outputs are its outputs */
    FMU_READY,     /* the steady step applies: started, not broken, not ended */
    FMU_VERSION,   /* 2 or 3 */
    FMU_COMPONENT, /* the fmi2Component / fmi3Instance */
    FMU_SET,       /* set: the function (0: no inputs), value references, their count, */
    FMU_SET_VRS,   /* the value buffer, the number of values (FMI 3), in this order */
    FMU_SET_NVR,
    FMU_SET_BUF,
    FMU_SET_COUNT,
    FMU_DO_STEP,
    FMU_GET, /* get: as set (0: no outputs) */
    FMU_GET_VRS,
    FMU_GET_NVR,
    FMU_GET_BUF,
    FMU_GET_COUNT,
    FMU_FLAGS, /* FMI 3 doStep's output arguments: eventHandlingNeeded, terminateSimulation, earlyReturn, */
    FMU_N_IN = FMU_FLAGS + 4, /* lastSuccessfulTime (the instance's own) */
    FMU_N_OUT,
    FMU_CHANNEL,    /* an instance hosted in a process of its own: its host_channel * (fmu_channel.h), else 0; */
    FMU_SOCKET,     /* the run's end of its socket pair; the set and get buffers are the channel's values */
    FMU_TRACE,      /* in the host: char *, where each call writes the FMU function it calls (0: no trace), */
    FMU_TRACE_SET,  /* and the names of the set, doStep and get functions (const char *) */
    FMU_TRACE_STEP,
    FMU_TRACE_GET,
    FMU_PORTS /* then [offset in the set buffer, width] per input port in Block.inputs order, and
                 [offset in the get buffer, width] per output port in Block.outputs order */
};

/* The values array. */
enum { FMU_V_TIME, FMU_V_STEP, FMU_V_TIMEOUT, FMU_V_HELD }; /* FMU_V_TIMEOUT: a hosted call's, in seconds */

/* What slow is asked to do. */
enum {
    FMU_SLOW_OUTPUT, /* the outputs of an FMU not yet initialised */
    FMU_SLOW_UPDATE, /* the whole update (not ready, or a step at the wrong time) */
    FMU_SLOW_ARM,    /* interrupt.arm() */
    FMU_SLOW_SET,    /* setting the inputs returned status */
    FMU_SLOW_STEP,   /* doStep returned status, or asked to terminate, or returned early */
    FMU_SLOW_GET,    /* getting the outputs returned status (the FMU's time is past the step) */
    FMU_SLOW_HOSTED  /* a hosted step that was not a plain success: status is how waiting ended (HOST_*,
                        fmu_channel.h) */
};

#endif
