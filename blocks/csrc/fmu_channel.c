/* Both ends of the channel to an FMU instance isolated in a process of its own
 * (fmu_channel.h), which hosts the FMU: "the host" below.
 *
 * The run's end: blk_host_post and blk_host_wait, which the FMU block's step
 * (fmu_block_step.c) calls for each steady step and blocks/fmu/isolation/client.py for
 * everything else. The wait spins for HOST_SPIN_NS, then sleeps on the reply counter in
 * slices of HOST_SLICE_NS; between slices it looks for the host's end of the socket pair
 * closing (its process ended), for the time the call may take, and, with the GIL taken
 * back, runs the signal handlers, so that Ctrl-C and SIGTERM stop a run whose FMU never
 * returns.
 *
 * The host's end (blocks/fmu/isolation/server.py): serve waits for the next request the
 * same way (HOST_IDLE_SPIN_NS, then slices of HOST_IDLE_NS, ending when the run's process
 * is gone; the spins of both sides adapt, see spin) and answers a steady step of a
 * co-simulation FMU with Float64 ports by itself, through the FMU's functions
 * (fmi_step_calls.h) on the channel's values, tracing each call's name into the channel.
 * Any other request, and a step that was not a plain success, goes back to Python.
 *
 * Linux only (futexes); elsewhere isolation is refused in Python and these are not called.
 */
#define _GNU_SOURCE
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#ifdef __linux__
#include <errno.h>
#include <sched.h>
#include <limits.h>
#include <linux/futex.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "fmi_step_calls.h"
#include "fmu_channel.h"
#include "fmu_step_table.h"
#include "layout_names.h"

#define HOST_SPIN_NS 50000LL        /* how long the run's side spins for an answer before it sleeps */
#define HOST_IDLE_SPIN_NS 50000LL   /* how long the host spins for the next request before it sleeps */
#define HOST_TRUST 16               /* a side's trust in spinning after a spin that paid */
#define HOST_PROBE 64               /* without trust, every HOST_PROBE-th wait spins all the same */
#define HOST_SLICE_NS 10000000LL    /* the run's sleeps between looking at the host and at signals */
#define HOST_IDLE_NS 200000000LL    /* the host's sleeps between looking for the run's process */

static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static inline void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}

#ifdef __linux__

/* Sleep while *word is seen, at most ns nanoseconds (or until woken, or a signal). */
static void futex_sleep(uint32_t *word, uint32_t seen, int64_t ns)
{
    struct timespec ts = {(time_t)(ns / 1000000000LL), (long)(ns % 1000000000LL)};
    syscall(SYS_futex, word, FUTEX_WAIT, seen, &ts, NULL, 0);
}

static void futex_wake(uint32_t *word)
{
    syscall(SYS_futex, word, FUTEX_WAKE, INT_MAX, NULL, NULL, 0);
}

/* Whether the other end of the socket pair has closed (its process ended). */
static bool closed(int fd)
{
    struct pollfd p = {fd, POLLIN | POLLRDHUP, 0};
    if (poll(&p, 1, 0) <= 0)
        return false;
    if (p.revents & (POLLHUP | POLLRDHUP | POLLERR | POLLNVAL))
        return true;
    char byte;
    return recv(fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT) == 0;
}

#else

static void futex_sleep(uint32_t *word, uint32_t seen, int64_t ns) { (void)word, (void)seen, (void)ns; }
static void futex_wake(uint32_t *word) { (void)word; }
static bool closed(int fd) { (void)fd; return true; }

#endif

/* Spin until *word differs from seen, for at most ns nanoseconds: whether it did. */
static bool spin_for(uint32_t *word, uint32_t seen, int64_t ns)
{
    int64_t until = now_ns() + ns;
    for (;;) {
        for (int i = 0; i < 64; i++) {
            if (__atomic_load_n(word, __ATOMIC_ACQUIRE) != seen)
                return true;
            cpu_relax();
        }
        if (now_ns() > until)
            return false;
    }
}

/* The processor this thread runs on (-1 if unknown). */
static int this_cpu(void)
{
#ifdef __linux__
    return sched_getcpu();
#else
    return -1;
#endif
}

/* Spin while spinning pays. Not at all while the other side last ran on this processor
   (other, its field of the channel): it cannot move while this one spins. Else *trust
   (this side's field) is set to HOST_TRUST by a spin that saw the change and halved by one
   that did not, and without trust only every HOST_PROBE-th wait spins (to find out whether
   it pays again). */
static bool spin(uint32_t *word, uint32_t seen, int32_t *trust, int32_t other, uint32_t count, int64_t ns)
{
    int cpu = this_cpu();
    if ((cpu >= 0 && cpu == other) || (*trust <= 0 && count % HOST_PROBE != 0))
        return __atomic_load_n(word, __ATOMIC_ACQUIRE) != seen;
    bool changed = spin_for(word, seen, ns);
    *trust = changed ? HOST_TRUST : *trust / 2;
    return changed;
}

void blk_host_post(host_channel *ch)
{
    ch->parent_cpu = this_cpu();
    __atomic_store_n(&ch->request, ch->request + 1, __ATOMIC_SEQ_CST);
    if (__atomic_load_n(&ch->host_waiting, __ATOMIC_SEQ_CST))
        futex_wake(&ch->request);
}

int blk_host_wait(host_channel *ch, int fd, double timeout)
{
    uint32_t target = ch->request;
    if (__atomic_load_n(&ch->reply, __ATOMIC_ACQUIRE) == target)
        return HOST_ANSWERED;
    int64_t start = now_ns(), limit = start + (int64_t)(timeout * 1e9);
    PyThreadState *released = PyEval_SaveThread();
    int outcome = HOST_ANSWERED;
    if (!spin(&ch->reply, target - 1, &ch->parent_spins, ch->host_cpu, target, HOST_SPIN_NS) ||
        __atomic_load_n(&ch->reply, __ATOMIC_ACQUIRE) != target) {
        for (;;) {
            __atomic_store_n(&ch->parent_waiting, 1, __ATOMIC_SEQ_CST);
            uint32_t seen = __atomic_load_n(&ch->reply, __ATOMIC_SEQ_CST);
            if (seen == target)
                break;
            futex_sleep(&ch->reply, seen, HOST_SLICE_NS);
            if (__atomic_load_n(&ch->reply, __ATOMIC_ACQUIRE) == target)
                break;
            if (closed(fd)) {
                outcome = HOST_GONE;
                break;
            }
            if (now_ns() > limit) {
                outcome = HOST_LATE;
                break;
            }
            PyEval_RestoreThread(released);
            int raised = PyErr_CheckSignals();
            released = PyEval_SaveThread();
            if (raised) {
                outcome = HOST_RAISED;
                break;
            }
        }
        __atomic_store_n(&ch->parent_waiting, 0, __ATOMIC_SEQ_CST);
    }
    PyEval_RestoreThread(released);
    return outcome;
}

/* The host: wait for a request it has not answered; false when the run's process is gone. */
static bool next_request(host_channel *ch, int fd)
{
    uint32_t answered = ch->reply;
    if (spin(&ch->request, answered, &ch->host_spins, ch->parent_cpu, answered, HOST_IDLE_SPIN_NS))
        return true;
    for (;;) {
        __atomic_store_n(&ch->host_waiting, 1, __ATOMIC_SEQ_CST);
        uint32_t seen = __atomic_load_n(&ch->request, __ATOMIC_SEQ_CST);
        if (seen != answered)
            break;
        futex_sleep(&ch->request, seen, HOST_IDLE_NS);
        if (__atomic_load_n(&ch->request, __ATOMIC_ACQUIRE) != answered)
            break;
        if (closed(fd)) {
            __atomic_store_n(&ch->host_waiting, 0, __ATOMIC_SEQ_CST);
            return false;
        }
    }
    __atomic_store_n(&ch->host_waiting, 0, __ATOMIC_SEQ_CST);
    return true;
}

/* The host: answer the request. */
static void answer(host_channel *ch, int how)
{
    ch->answer = how;
    ch->host_cpu = this_cpu();
    __atomic_store_n(&ch->reply, ch->request, __ATOMIC_SEQ_CST);
    if (__atomic_load_n(&ch->parent_waiting, __ATOMIC_SEQ_CST))
        futex_wake(&ch->reply);
}

/* The host's steady step over the channel's values: 0 when it was a plain success, else
   the FMU_SLOW_* kind of the call that was not, its status in *status. */
static int fast_step(const int64_t *c, const host_channel *ch, int *status)
{
    if (c[FMU_SET]) {
        *status = fmu_transfer(c, FMU_SET, true);
        if (*status > 1)
            return FMU_SLOW_SET;
    }
    bool plain;
    *status = fmu_do_step(c, ch->t, ch->h, &plain);
    if (!plain)
        return FMU_SLOW_STEP;
    if (c[FMU_GET]) {
        *status = fmu_transfer(c, FMU_GET, false);
        if (*status > 1)
            return FMU_SLOW_GET;
    }
    return 0;
}

static void *address_of(PyObject *value)
{
    return PyLong_AsVoidPtr(value);
}

/* post(channel) */
static PyObject *py_post(PyObject *self, PyObject *arg)
{
    (void)self;
    host_channel *ch = address_of(arg);
    if (ch == NULL && PyErr_Occurred())
        return NULL;
    blk_host_post(ch);
    Py_RETURN_NONE;
}

/* wait(channel, fd, timeout) -> HOST_ANSWERED, HOST_GONE or HOST_LATE (a signal handler's
   exception is raised) */
static PyObject *py_wait(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *channel;
    int fd;
    double timeout;
    if (!PyArg_ParseTuple(args, "Oid", &channel, &fd, &timeout))
        return NULL;
    host_channel *ch = address_of(channel);
    if (ch == NULL && PyErr_Occurred())
        return NULL;
    int outcome = blk_host_wait(ch, fd, timeout);
    if (outcome == HOST_RAISED)
        return NULL;
    return PyLong_FromLong(outcome);
}

/* serve(channel, fd, table) -> (command, kind, status): the host's loop. Answers steady
   steps itself while table (an FMU_* table, 0 for none) says FMU_READY; returns the first
   request it does not answer (kind: the FMU_SLOW_* call of a step that was not a plain
   success, 0 for none), or (HOST_ORPHAN, 0, 0) once the run's process is gone. */
static PyObject *py_serve(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *channel, *table;
    int fd;
    if (!PyArg_ParseTuple(args, "OiO", &channel, &fd, &table))
        return NULL;
    host_channel *ch = address_of(channel);
    const int64_t *c = address_of(table);
    if (PyErr_Occurred())
        return NULL;
    for (;;) {
        if (!next_request(ch, fd))
            return Py_BuildValue("(iii)", HOST_ORPHAN, 0, 0);
        if (ch->command != HOST_STEP || c == NULL || !c[FMU_READY])
            return Py_BuildValue("(iii)", ch->command, 0, 0);
        int status = 0, kind = fast_step(c, ch, &status);
        if (kind)
            return Py_BuildValue("(iii)", HOST_STEP, kind, status);
        answer(ch, HOST_DONE);
    }
}

/* answer(channel, how) */
static PyObject *py_answer(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *channel;
    int how;
    if (!PyArg_ParseTuple(args, "Oi", &channel, &how))
        return NULL;
    host_channel *ch = address_of(channel);
    if (ch == NULL && PyErr_Occurred())
        return NULL;
    answer(ch, how);
    Py_RETURN_NONE;
}

static PyMethodDef functions[] = {
    {"post", py_post, METH_O, "post(channel): a request is in the channel."},
    {"wait", py_wait, METH_VARARGS, "wait(channel, fd, timeout): how waiting for the host's answer ended."},
    {"serve", py_serve, METH_VARARGS, "serve(channel, fd, table): the host's loop, until a request for Python."},
    {"answer", py_answer, METH_VARARGS, "answer(channel, how): the host has answered the request."},
    {NULL, NULL, 0, NULL},
};

static const named layout[] = {
    {"request", offsetof(host_channel, request)}, {"reply", offsetof(host_channel, reply)},
    {"command", offsetof(host_channel, command)}, {"answer", offsetof(host_channel, answer)},
    {"t", offsetof(host_channel, t)}, {"h", offsetof(host_channel, h)},
    {"inputs", offsetof(host_channel, inputs)}, {"outputs", offsetof(host_channel, outputs)},
    {"call", offsetof(host_channel, call)}, {"call_bytes", HOST_CALL_BYTES},
    {"logged", offsetof(host_channel, logged)}, {"log", offsetof(host_channel, log)},
    {"log_lines", HOST_LOG_LINES}, {"log_bytes", HOST_LOG_BYTES}, {"size", sizeof(host_channel)}, {NULL, 0}};
static const named codes[] = {
    {"step", HOST_STEP}, {"message", HOST_MESSAGE}, {"done", HOST_DONE}, {"answered", HOST_ANSWERED},
    {"gone", HOST_GONE}, {"late", HOST_LATE}, {"orphan", HOST_ORPHAN}, {NULL, 0}};

PyObject *blk_fmu_channel_functions(void)
{
    PyObject *found = Py_BuildValue("{s:N,s:N}", "layout", blk_names(layout), "codes", blk_names(codes));
    for (PyMethodDef *f = functions; found != NULL && f->ml_name != NULL; f++) {
        PyObject *function = PyCFunction_New(f, NULL);
        if (function == NULL || PyDict_SetItemString(found, f->ml_name, function) != 0)
            Py_CLEAR(found);
        Py_XDECREF(function);
    }
    return found;
}
