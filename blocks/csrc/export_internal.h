/* What the files of an exported FMU's instance share (export_instance.h is the instance's
 * interface to the FMI wrappers; this header is not for them): the diagram as the
 * resources describe it, the kernels built from it, the instance itself, and each file's
 * entries for the others. One file per concern, each depending only on those before it:
 *
 * - export_log.c: the instance's log, and the messages that name a block, a failed run
 *   or a call in the wrong phase;
 * - export_resources.c: reading the resources (BLK_EXPORT_RESOURCE) into a blk_export;
 * - export_step.c: the outputs at the run's tick and a communication step;
 * - export_build.c: the kernels built from the records and the parameters, and released;
 * - export_lifecycle.c: instantiation, the phases (initialization, termination, reset);
 * - export_variables.c: values got and set by value reference;
 * - export_snapshot.c: FMU states (get, set, serialize);
 * - export_scheduled.c: scheduled execution, its clocks and partitions (export_scheduled.h).
 */
#ifndef BLOCKS_EXPORT_INTERNAL_H
#define BLOCKS_EXPORT_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "blocks_kernel.h"
#include "core.h"
#include "export_instance.h"

#define STEP_TOLERANCE 1e-6 /* a communication step may miss a whole number of ticks by this many */
#define EXACT_TICKS 9007199254740992.0 /* 2^53: tick times are exact while tick * num stays below */

/* -- the diagram, as the resources describe it ------------------------------------------- */

typedef struct {
    char *name, *kind;
    const blk_kernel_type *type;
    const double *record;
    int64_t n_record;
    const double *state; /* the state Python gave the block, n_state values */
    int64_t n_state;
    int built_state; /* the kind builds the state */
} ex_block;

typedef struct {
    double start;
    int64_t n;
    const int64_t *offsets;
} ex_input;

typedef struct {
    int64_t block, slot, finite;
    char *name;
} ex_param;

typedef struct {
    int64_t block, slot, n_when, n_unless;
    const int64_t *when, *unless;
} ex_follow;

typedef struct {
    int64_t block, slot, source, source_slot, length;
} ex_link;

struct blk_export {
    int64_t *data;
    char *token, *model;
    int64_t grid, vr_input, vr_output, vr_param;
    int64_t initial_outputs, between, lazy;
    blk_table table;
    const double *arena0;
    int64_t n_blocks, n_inputs, n_outputs, n_params, n_follows, n_links;
    ex_block *blocks;
    ex_input *inputs;
    const int64_t *outputs;
    ex_param *params;
    ex_follow *follows;
    const ex_link *links;
};

/* The kernels of one initialized instance. */
typedef struct {
    double **records;
    blk_built *built;
    blk_kernel *kernels;
    double **states;
    int64_t *state_sizes;
    double *arena;
    blk_run run;
    /* Between grid points (a communication step that ended off the grid): the outputs of
       held_tick, the last grid point passed, held until the next one; the run is past
       held_tick's ops and the instance's time is held_time. */
    int held;
    int64_t held_tick;
    double held_time;
    double *held_outputs;
} ex_build;

struct blk_instance {
    char *name;
    blk_logger log;
    void *environment;
    int log_events;
    blk_export x;
    double *params;
    unsigned char *set;
    double *inputs;
    ex_build *build; /* NULL until the kernels are built */
    int outputs_fresh;
    int stop_defined;
    int64_t stop_tick;
    double stop_time;
    blk_phase phase;
    struct ex_scheduled *scheduled; /* scheduled execution's clocks (one allocation); NULL: co-simulation */
};

#define LOG_ERROR(inst, ...) blk_instance_log((inst), BLK_STATUS_ERROR, BLK_LOG_ERROR, __VA_ARGS__)
#define LOG_EVENT(inst, ...) blk_instance_log((inst), BLK_STATUS_OK, BLK_LOG_EVENTS, __VA_ARGS__)

/* The time of a tick: tick * num / den of the base tick, exact below EXACT_TICKS. */
static inline double ex_tick_time(const blk_instance *inst, int64_t tick)
{
    const int64_t *h = inst->x.table.header;
    return (double)(tick * h[BLK_H_TICK_NUM]) / (double)h[BLK_H_TICK_DEN];
}

/* -- export_log.c ------------------------------------------------------------------------ */

/* Block b's name. */
const char *ex_block_name(const blk_instance *inst, int64_t b);
/* "block 'name' (Kind): " before a block's message, or nothing in a one-block diagram. */
void ex_block_prefix(const blk_instance *inst, int64_t b, char *out, size_t size);
/* Log the failure of the run's outcome. */
void ex_describe_failure(blk_instance *inst);
/* Log that ``what`` is not allowed in the instance's phase; BLK_STATUS_ERROR. */
blk_status ex_wrong_phase(blk_instance *inst, const char *what);

/* -- export_resources.c ------------------------------------------------------------------ */

/* Read BLK_EXPORT_RESOURCE from ``folder`` into inst->x: 0, or -1 after logging why. */
int ex_read_resources(blk_instance *inst, const char *token, const char *folder);
void ex_free_export(blk_export *x);
/* The words of resource file ``name`` in ``folder`` (malloc'ed), *n of them; NULL after logging why. */
int64_t *ex_read_resource_words(blk_instance *inst, const char *folder, const char *name, int64_t *n);

/* -- export_step.c ----------------------------------------------------------------------- */

/* The outputs at the run's tick from the inputs now: 0; -1 after logging the failure (the
   instance then failed); 1 in initialization mode, where a failure waits for the inputs. */
int ex_refresh_outputs(blk_instance *inst);

/* -- export_build.c ---------------------------------------------------------------------- */

/* Build every kernel from the current parameters and the run at t = 0 with its outputs
   (nothing when built); 0, or -1 after logging why. */
int ex_build_kernels(blk_instance *inst);
/* Release the kernels (the next use builds them again from the parameters). */
void ex_release_build(blk_instance *inst);

#endif
