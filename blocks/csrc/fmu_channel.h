/* The channel between a run and an FMU instance isolated in a process of its own, which
 * hosts the FMU (fmu_channel.c; blocks/fmu/isolation/client.py and
 * blocks/fmu/isolation/server.py are its two ends in Python).
 *
 * The channel is one shared-memory region: this header, then the input values, then the
 * output values (float64, port after port in the block's order). A request is one bump of
 * `request` by the run's process; the host answers by setting `reply` to it. Both sides
 * first spin on the counter for a few microseconds (the other side is usually that quick:
 * an FMU step), then sleep on it (a futex) and are woken by the other side only when they
 * said they sleep. So a steady co-simulation step is one round trip through shared memory
 * without a system call. Where spinning does not pay (both processes share one processor,
 * or the other side takes longer than the spin), a side soon stops spinning, and a round
 * trip is two wake-ups. Messages (instantiate, initialise, terminate, failures) travel as
 * pickles over the socket pair the two processes also share, whose end-of-file is how each
 * side learns that the other has died.
 */
#ifndef BLOCKS_FMU_CHANNEL_H
#define BLOCKS_FMU_CHANNEL_H

#include <Python.h>

#include <stdint.h>

enum { HOST_CALL_BYTES = 64, HOST_LOG_LINES = 8, HOST_LOG_BYTES = 512 };

typedef struct {
    uint32_t request;        /* bumped by the run's process for each request (a futex word) */
    uint32_t reply;          /* set to request by the host once it has answered (a futex word) */
    uint32_t host_waiting;   /* the host sleeps on request: a request must wake it */
    uint32_t parent_waiting; /* the run's process sleeps on reply: the answer must wake it */
    int32_t command;         /* what is asked: HOST_STEP or HOST_MESSAGE */
    int32_t answer;          /* how it was answered: HOST_DONE or HOST_MESSAGE */
    int32_t parent_spins;    /* how much each side trusts spinning (each writes its own): */
    int32_t host_spins;      /* spins that came to nothing lower it, see fmu_channel.c */
    int32_t parent_cpu;      /* the processor each side last ran on (each writes its own): */
    int32_t host_cpu;        /* spinning on the other side's processor cannot pay */
    double t, h;             /* HOST_STEP: from t over h */
    int64_t inputs;          /* where the input values start (bytes from the channel's start), */
    int64_t outputs;         /* and the output values */
    char call[HOST_CALL_BYTES]; /* the FMU function the host called last (NUL-terminated) */
    uint32_t logged;         /* FMU log messages since the instance (re)started; the last */
    uint32_t unused;         /* HOST_LOG_LINES are in log, message i in log[i % HOST_LOG_LINES] */
    char log[HOST_LOG_LINES][HOST_LOG_BYTES];
} host_channel;

/* Requests. HOST_STEP: set the inputs, step from t over h, get the outputs (or the host's
   Python side says what else happened, as a message); HOST_MESSAGE: a message follows on
   the socket. */
enum { HOST_STEP = 1, HOST_MESSAGE = 2 };
/* Answers: HOST_DONE, the step succeeded and the outputs are in the channel; HOST_MESSAGE,
   a message follows on the socket. */
enum { HOST_DONE = 1 };
/* What waiting for an answer came to. */
enum { HOST_ANSWERED = 0, HOST_GONE = 1, HOST_LATE = 2, HOST_RAISED = -1 };
/* What the host's wait for a request came to besides a request: the run's process is gone. */
enum { HOST_ORPHAN = -1 };

/* The run's side: bump request and wake the host if it sleeps. */
void blk_host_post(host_channel *ch);

/* The run's side: wait until the host answers the last request (HOST_ANSWERED), its
   process ends (HOST_GONE: end-of-file on fd, the run's end of the socket pair) or timeout
   seconds pass (HOST_LATE). Called with the GIL; releases it while it waits and takes it
   back to run signal handlers: HOST_RAISED when one raised (Ctrl-C), its exception set. */
int blk_host_wait(host_channel *ch, int fd, double timeout);

/* {"layout": {...}, "post": ..., "wait": ..., "serve": ..., "answer": ...}: the channel's
   layout (offsets of host_channel) and the Python functions of both ends. */
PyObject *blk_fmu_channel_functions(void);

#endif
