/* The Run object of blocks._native: one run of an op table (blocks/engine/optable.py)
 * through the C core (core.h), bound by blocks/engine/native_run.py. A Run holds the
 * tables, the run's arena, log buffers and counters (numpy arrays it keeps alive), one
 * kernel row per block, and for each block without a kernel its Python methods; run()
 * hands all of it to blk_run_table, which interprets the whole run in one call.
 *
 * The Run's parts are one file each, and this header is what they share: the object's
 * layout, the GIL and the exception over one run (inline, below), and each part's entry:
 *
 * - native_run.c: the type itself (Run(...), run(), the object's end);
 * - native_run_bind.c: its arguments checked and bound into the core's structs;
 * - native_run_hooks.c: the hooks the core calls (a Python block's op, the GIL, polling
 *   for Ctrl-C and progress, a request to end the run);
 * - native_python_blocks.c: a Python block's output, update and advance.
 */
#ifndef BLOCKS_NATIVE_RUN_H
#define BLOCKS_NATIVE_RUN_H

#include <Python.h>

#include <stdint.h>

#include "blocks_kernel.h"
#include "core.h"

/* -- the object ------------------------------------------------------------------------ */

/* A connected input of a Python block: its arena slice and the array its mapping holds. */
typedef struct {
    PyObject *key, *value; /* the port's name, the array its mapping holds */
    double *arena, *seen, *data; /* where it reads, what the block last saw, value's data if ours */
    Py_ssize_t width;
} py_input;

/* An output port of a Python block: its name and arena slice. */
typedef struct {
    PyObject *key;
    double *arena;
    Py_ssize_t width;
} py_port;

/* A block without a kernel: its Python methods, input mapping and ports. */
typedef struct {
    PyObject *output, *update, *inputs, *ended; /* ended: the EndRun of its last update */
    Py_ssize_t state; /* its index in the states list */
    py_input *in;
    py_port *out;
    Py_ssize_t n_in, n_out;
} py_block;

/* The GIL over one run: saved non-NULL while released; signals: this thread handles
   signals; release: the GIL may be released at all. */
typedef struct {
    PyThreadState *saved;
    int signals, release;
} gil;

/* The Run. */
typedef struct {
    PyObject_HEAD
    blk_table table;
    blk_run run;
    blk_kernel *kernels;
    double **logs;
    py_block *python; /* per block; output NULL: the block has a kernel */
    PyObject *owners, *states, *side, *progress, *width_cache;
    PyObject *raised; /* the exception a hook or Python block stopped the run with */
    PyObject *end_reason; /* the EndRun of the first accepted request to end the run */
    PyTypeObject *ndarray;
    PyObject *empty, *end_run;
    gil g;
    int64_t polls;
    int ran;
} RunObject;

/* -- the GIL and the exception over one run ------------------------------------------ */

static inline void run_gil_hold(gil *g)
{
    if (g->saved != NULL) {
        PyEval_RestoreThread(g->saved);
        g->saved = NULL;
    }
}

/* Another thread with a Python thread state exists: one that could take a released GIL.
   Read with the GIL held: Python threads start and end under it; a C thread whose first
   PyGILState_Ensure is under way may be missed until the next check. */
static inline int run_other_threads(void)
{
    PyThreadState *self = PyThreadState_Get();
    PyThreadState *first = PyInterpreterState_ThreadHead(PyThreadState_GetInterpreter(self));
    return first != self || PyThreadState_Next(first) != NULL;
}

/* Keep the exception now set as the run's (the first one kept wins); BLK_RAISED. */
static inline int run_keep_raised(RunObject *r)
{
    PyObject *type, *value, *traceback;
    PyErr_Fetch(&type, &value, &traceback);
    if (type == NULL)
        return BLK_RAISED;
    PyErr_NormalizeException(&type, &value, &traceback);
    if (traceback != NULL && value != NULL)
        PyException_SetTraceback(value, traceback);
    Py_XDECREF(type);
    Py_XDECREF(traceback);
    if (r->raised == NULL)
        r->raised = value;
    else
        Py_XDECREF(value);
    return BLK_RAISED;
}

/* -- each part's entry ------------------------------------------------------------------ */

/* native_python_blocks.c: op (BLK_OUTPUT, BLK_UPDATE or BLK_ADVANCE) of a Python block at
   t (an advance: over n ticks, *done of them done); 0, BLK_END_RUN or BLK_RAISED. */
int run_python_op(RunObject *r, int64_t op, double t, int n, int *done);

/* native_run_hooks.c: the hooks of r's run (blk_hooks of core.h). */
blk_hooks run_hooks(RunObject *r);

/* A kernel row's state column that names the block's entry of the states list (its
   array's data, bound with the row) rather than an address. */
#define RUN_STATE_OF_LIST (-1)

/* native_run_bind.c: the tables, arena, logs, counters, kernel rows and Python blocks of
   Run(...) checked and bound into r->table, r->run and r->python; -1 with an exception. */
int run_bind(RunObject *r, PyObject *tables, PyObject *arena, PyObject *logs, PyObject *counters, PyObject *kernels,
             PyObject *python);

/* native_run.c: the type blocks._native.Run. */
extern PyTypeObject blk_run_type;

#endif
