/* core.h: the op table of a run and the one interpreter of it, in C99 with libc only.
 *
 * A loaded diagram compiles to an op table (blocks/engine/optable.py): plain int64 arrays and
 * one float64 array, no pointers, so it can be saved, shipped and read back. This core
 * runs such a table over kernels given as function pointers and contexts (the calling
 * convention of blocks_kernel.h): the outputs, updates and advances of the blocks, the
 * logging of their outputs with decimation, the copies of delayed connections, the end
 * of a run asked by a block, and failures with their block, phase, tick and the rows an
 * advance completed. It knows nothing of Python: a host (the Run of the CPython module,
 * native_run.h; an exported FMU's instance, export_instance.h; any C program) binds the
 * kernels, provides the memory, and may hook in callbacks for blocks without a kernel,
 * for locks around kernels, for the checks for an interrupt between events, and for
 * requests to end the run.
 *
 * Layouts. Every table is an int64 array of rows of the width named *_N; "offset" means
 * an index into the run's arena (float64 values), never a pointer.
 *
 *   header     one row of BLK_H_N: the hyperperiod and the run's length in base ticks, the
 *              base tick as num / den seconds, the initial and the final program, the
 *              arena's size
 *   blocks     per block: its outputs' offset and summed width, its inputs (a range of the
 *              inputs table), its period in ticks (0: inherited), where its advance rows go
 *              (offset, capacity in rows), its output ports (a range of the ports table)
 *   inputs     per input port, blocks in order and each block's ports in Block.inputs
 *              order: the offset of the values it reads, its width
 *   ports      per output port, likewise in Block.outputs order: its block, offset, width
 *   ops        [code, a, b, c, d]:
 *                BLK_OUTPUT  [block, first log, end log, selection]: the outputs at the
 *                            event's tick, logged to the log entries first..end-1; the
 *                            selection (index into selections; -1: all ports) is the
 *                            ports this step stands for (the others a later step of the
 *                            same block computes; a kernel always writes all of them)
 *                BLK_UPDATE  [block, 0, 0, 0]
 *                BLK_ADVANCE [block, first log, end log, last]: hits of the block up to the
 *                            next event, in chunks of at most its rows' capacity, each
 *                            row logged; last: the event's last advance (how far an
 *                            interrupted run got is how far this one got)
 *                BLK_COPY    [copy, 0, 0, 0]: a row of the copies table
 *   copies     [destination, source, width]: a delayed connection sampling its source, an
 *              input that holds its default until its source first fires, or a run of
 *              elements of an input that connections by element assemble
 *   programs   [first op, end op, final]: what runs at an event; final: the program that
 *              ends a run at such an event when a block asked for the end (-1: none)
 *   events     [tick, program]: the events of one hyperperiod, by tick (0 <= tick <
 *              hyperperiod); those of later hyperperiods are these shifted by it
 *   logs       [block, column, width, decimate, capacity]: a logged signal, the column of
 *              its first element among the block's outputs; every decimate-th hit is kept,
 *              at most capacity rows
 *   selections [count, port, port, ...] runs, ports numbered within their block
 *
 * A run: the initial program at tick 0, its advances stepping to the first event; then
 * the events in order, each program's advances stepping to the next event; then at the
 * end tick (n_ticks, or the next hit of the first block that asked to end, if earlier) the
 * final program: outputs only, logged. Time is t = k * num / den, computed in double from
 * the integer tick k; the host makes sure k * num stays below 2^53 (exact).
 */
#ifndef BLOCKS_CORE_H
#define BLOCKS_CORE_H

#include <stddef.h>
#include <stdint.h>

#include "blocks_kernel.h"

enum { BLK_H_HYPERPERIOD, BLK_H_N_TICKS, BLK_H_TICK_NUM, BLK_H_TICK_DEN, BLK_H_INITIAL, BLK_H_FINAL, BLK_H_ARENA,
       BLK_H_N };
enum { BLK_B_OUT, BLK_B_WIDTH, BLK_B_FIRST_INPUT, BLK_B_N_INPUTS, BLK_B_PERIOD, BLK_B_ROWS, BLK_B_ROWS_CAPACITY,
       BLK_B_FIRST_PORT, BLK_B_N_PORTS, BLK_B_N };
enum { BLK_I_OFFSET, BLK_I_WIDTH, BLK_I_N };
enum { BLK_P_BLOCK, BLK_P_OFFSET, BLK_P_WIDTH, BLK_P_N };
enum { BLK_OP_CODE, BLK_OP_A, BLK_OP_B, BLK_OP_C, BLK_OP_D, BLK_OP_N };
enum { BLK_OUTPUT, BLK_UPDATE, BLK_ADVANCE, BLK_COPY };
enum { BLK_C_DST, BLK_C_SRC, BLK_C_WIDTH, BLK_C_N };
enum { BLK_PR_FIRST, BLK_PR_END, BLK_PR_FINAL, BLK_PR_N };
enum { BLK_E_TICK, BLK_E_PROGRAM, BLK_E_N };
enum { BLK_L_BLOCK, BLK_L_COLUMN, BLK_L_WIDTH, BLK_L_DECIMATE, BLK_L_CAPACITY, BLK_L_N };
/* a log entry's counters in a run: rows written, hits seen */
enum { BLK_LC_ROWS, BLK_LC_HITS, BLK_LC_N };

/* The tables, in this order, as a host holds them: each a pointer and its number of rows
   (selections: of values). */
typedef struct {
    const int64_t *header, *blocks, *inputs, *ports, *ops, *copies, *programs, *events, *logs, *selections;
    int64_t n_blocks, n_inputs, n_ports, n_ops, n_copies, n_programs, n_events, n_logs, n_selections;
} blk_table;

/* A table checked for what the interpreter relies on (every index and offset in range,
   every program that can end a run has a final one, the base tick positive): NULL, or what
   is wrong. A host reading a table from a file checks it before running it. */
const char *blk_table_check(const blk_table *t);

/* The packed form of a table, the one a file holds: int64 words, native byte order. The
   word BLK_PACK_MAGIC, BLK_PACK_VERSION, the ten row counts (header first, in the order of
   blk_table), the ten tables' values one after the other, then the arena's initial values
   (header[BLK_H_ARENA] doubles). blk_table_unpack points t and *initial into data (8-byte
   aligned, size bytes): NULL, or what is wrong with it. */
#define BLK_PACK_MAGIC 0x454c4241544b4c42LL /* "BLKTABLE" */
#define BLK_PACK_VERSION 1
const char *blk_table_unpack(const void *data, size_t size, blk_table *t, const double **initial);

/* A block's bound kernel. output == NULL: a block without one, whose ops the host's call
   hook runs (a Python block). state as blocks_kernel.h says; nogil: see the gil hook. */
typedef struct {
    blk_output_fn output;
    blk_update_fn update;
    blk_advance_fn advance;
    const void *ctx;
    double *state;
    int nogil;
} blk_kernel;

/* What a host may hook in (any may be NULL but call, where a block has no kernel).
   call:  run op number op of a block without a kernel at tick (time t): an output writes
          the ports its selection names into the arena; an update; an advance of n hits
          into rows, as a kernel's advance (n rows, *done on failure). Returns 0 or a code,
          as a kernel does (BLK_END_RUN from an update asks to end the run).
   gil:   called before each kernel call and call hook, needed = 0 for a kernel that may
          run without the host's lock (blk_kernel.nogil), 1 otherwise.
   poll:  after each event and between the chunks of an advance, with the tick every block
          has reached: nonzero stops the run there (an interrupt).
   end:   an update (op) at tick asked to end the run: 0 accepts, nonzero fails the update
          with code BLK_END_RUN. Without the hook every request is accepted. */
typedef struct {
    void *host;
    int (*call)(void *host, int64_t op, int64_t tick, double t, int n, double *rows, int *done, int *which);
    void (*gil)(void *host, int needed);
    int (*poll)(void *host, int64_t reached);
    int (*end)(void *host, int64_t op, int which, int64_t tick);
} blk_hooks;

enum { BLK_RUN_COMPLETE, BLK_RUN_FAILED, BLK_RUN_STOPPED, BLK_RUN_BAD };

/* The code of a failed op whose outputs hold a value that is not finite (a NaN or an
   infinity): the core checks what every output and advance computes, unless the run
   allows such values (blk_run.allow_nonfinite). which: the value's index among the
   block's outputs, whose place in the arena then holds the outputs in question (for an
   advance, the row that has it; the rows before it are logged). */
#define BLK_NONFINITE (-3)

/* How a run went. complete: it ended at tick end. failed: op failed with code (which: its
   detail) at tick; an advance's completed rows are logged. stopped: poll or the stop flag
   stopped it. reached: every block was computed up to this tick (an interrupted run's
   time). end_op / end_asked: the update that first asked to end the run, and its tick
   (-1: none). bad: the table or the hooks cannot run (message). */
typedef struct {
    int status;
    int code, which;
    int64_t end, reached, op, tick, end_op, end_asked;
    const char *message;
} blk_outcome;

/* Where a run is, between the calls of a run in parts (blk_run_until): every op of the
   ticks before tick is done; pending >= 0: the advances of that program, which ran its
   other ops at an earlier event, still step from tick to span_end (the next event, or
   the end); pending < 0: tick is the next event's (or the end). after: the first event
   after the program running now; end and end_program: the tick the run ends at and the
   program it ends with there (-1: the header's final program, the end not asked for);
   tail: where pending's advances start among the ops. Plain numbers (and the input
   pointers, into the arena), so a host can save and restore a position. */
typedef struct {
    int64_t cycle, row; /* after: its hyperperiod and its row of the events */
    int64_t tick, pending, span_end, tail, end, end_program;
    int started; /* the initial program has run */
} blk_position;

/* One run: the table, the arena (header[BLK_H_ARENA] values, holding the table's initial
   values), one kernel per block, per log entry its buffer (capacity x width values) and
   counters (BLK_LC_N each, zero), the hooks. stop: any thread or a signal handler may set
   it; the run stops at the next check, after an event or a chunk. allow_nonfinite: zero
   (the default) fails an op whose outputs are not finite (BLK_NONFINITE). at and pointers
   belong to the core (blk_run_begin sets them). */
typedef struct {
    const blk_table *table;
    double *arena;
    const blk_kernel *kernels;
    double *const *logs;
    int64_t *counters;
    blk_hooks hooks;
    volatile int stop;
    blk_outcome outcome;
    int allow_nonfinite;
    blk_position at;
    const double **pointers; /* per input port, where it reads */
} blk_run;

/* Run the table from tick 0 to its end; returns run->outcome.status. */
int blk_run_table(blk_run *run);

/* A run in parts, as an exported FMU steps one (blk_run_table is these four):
   blk_run_begin checks the kernels against the ops and prepares a run at tick 0, nothing
   run (BLK_RUN_BAD, or 0). blk_run_until runs every op of the ticks before stop (the
   initial program first) and the advances up to stop, which must be a hit of every
   advanced block; it stops earlier at the run's end (at.end) and returns 0 while the run
   goes on, or the outcome's status (failed, stopped: the run cannot go on).
   blk_run_outputs runs program (one of outputs only: a final program) at at.tick.
   blk_run_release frees what begin took. */
int blk_run_begin(blk_run *run);
int blk_run_until(blk_run *run, int64_t stop);
int blk_run_outputs(blk_run *run, int64_t program);
void blk_run_release(blk_run *run);

#endif
