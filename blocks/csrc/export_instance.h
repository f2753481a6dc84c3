/* One instance of an exported diagram FMU, independent of the FMI version: the interface
 * the FMI wrappers call (its files are listed in export_internal.h).
 *
 * An exported FMU runs a diagram's op table (core.h) over the kernels of its blocks,
 * which it rebuilds from their records (blocks_kernel.h, kernel types) when it is
 * initialised. The FMI 2 and FMI 3 wrappers (export_fmi2.c, export_fmi3.c) translate
 * their calls into these functions, as the Modelica Association's Reference FMUs share
 * one model between both interfaces. Everything the FMU knows of its diagram is in its
 * resources (BLK_EXPORT_RESOURCE, written by blocks/fmu_export), so one binary serves
 * every diagram whose kernel types it holds.
 *
 * Time. The internal step is the diagram's base tick; the grid is the base tick, or the
 * period of the blocks the table advances in one call, counted in integers from t = 0 so
 * time never drifts. A communication step may be any length (importers such as
 * OMSimulator step every FMU at the smallest step of all): it runs every grid point up to
 * its end with the inputs set at its start. The FMU's outputs at a communication point on
 * the grid are the diagram's outputs there, computed from the inputs set there (an output
 * the inputs feed through blocks with feedthrough changes when they are set); between grid
 * points they hold the last grid point's, as the diagram's samples hold between hits.
 *
 * Variables, by value reference: 0 the time (FMI 3's independent variable), then the
 * inputs, the outputs and the parameters, each a range that starts where the resources
 * say. A parameter is a slot of a block's record; setting one marks it set, which is what
 * a follow rule asks (a derived value follows the values it derives from once one of
 * them is set).
 */
#ifndef BLOCKS_EXPORT_INSTANCE_H
#define BLOCKS_EXPORT_INSTANCE_H

#include <stddef.h>
#include <stdint.h>

#include "blocks_kernel.h"
#include "core.h"

/* Statuses, numbered as fmi2Status and fmi3Status both are. */
typedef enum {
    BLK_STATUS_OK = 0,
    BLK_STATUS_WARNING = 1,
    BLK_STATUS_DISCARD = 2,
    BLK_STATUS_ERROR = 3,
    BLK_STATUS_FATAL = 4
} blk_status;

/* Log categories declared in modelDescription.xml. */
#define BLK_LOG_EVENTS "logEvents"
#define BLK_LOG_WARNING "logStatusWarning"
#define BLK_LOG_ERROR "logStatusError"

#define BLK_EXPORT_RESOURCE "diagram.bin"

/* The resource file: little-endian int64 words (doubles as their IEEE 754 bits):
 *   magic BLK_EXPORT_MAGIC, version BLK_EXPORT_VERSION,
 *   the token (a string: its length in bytes, then its bytes in whole words, zero padded),
 *   the model's name (a string),
 *   the grid (in base ticks: where a communication step runs to, between which outputs hold),
 *   the value references of the first input, output and parameter,
 *   the programs of the outputs at t = 0 (before the first step), between events (-1:
 *   none), of the outputs that are lazy (-1: none),
 *   the packed op table (its length in words, then OpTable.pack's words),
 *   blocks: their count, then per block: its name and its kind (strings), its record (a
 *   count, then the numbers), its initial state (a count, -1 when the kind builds it, then
 *   the numbers),
 *   inputs: their count, per input its start value and the arena offsets it is written to
 *   (a count, then the offsets),
 *   outputs: their count, per output its arena offset,
 *   parameters: their count, per parameter its block, its slot, whether it must be finite
 *   and its name (a string),
 *   follow rules: their count, per rule its block, its flag slot, the parameters that set
 *   it (a count, then their indices) and those that prevent it (likewise),
 *   links: their count, per link its block, slot, source block, source slot, length,
 *   the word BLK_EXPORT_MAGIC again,
 *   the CRC-32 (zlib's) of every byte before it, as a word: checked before anything else
 *   is read, so that a damaged file is refused whole rather than trusted in part (a
 *   block's record holds sizes its kernel believes). */
#define BLK_EXPORT_MAGIC 0x31554d46584b4c42LL /* "BLKXFMU1" */
#define BLK_EXPORT_VERSION 2

/* The host's logger; the wrapper adapts it to its FMI version's callback. */
typedef void (*blk_logger)(void *environment, const char *instance, blk_status status, const char *category,
                           const char *message);

typedef enum {
    BLK_INSTANTIATED,
    BLK_INITIALIZATION,
    BLK_STEPPING,
    BLK_TERMINATED,
    BLK_FAILED
} blk_phase;

typedef struct blk_export blk_export; /* the diagram as the resources describe it */
typedef struct blk_instance blk_instance;

/* A new instance, or NULL after logging why. ``token`` must equal the one in the
 * resources (the modelDescription's guid / instantiationToken); ``resource_dir`` is a
 * folder path. */
blk_instance *blk_instance_new(const char *name, const char *token, const char *resource_dir, blk_logger log,
                               void *environment, int logging_on);
void blk_instance_free(blk_instance *inst);

void blk_instance_log(const blk_instance *inst, blk_status status, const char *category, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

blk_phase blk_instance_phase(const blk_instance *inst);

/* fmi2SetDebugLogging / fmi3SetDebugLogging: logEvents on when ``on`` and either no
 * categories or logEvents among them; an unknown category is a logged error. */
blk_status blk_instance_set_logging(blk_instance *inst, int on, size_t n, const char *const categories[]);

/* The folder of a file: URI ("file:///a/b/resources" or "file:/a/b"), percent-decoded,
 * into ``out``; 0 on success. */
int blk_path_from_uri(const char *uri, char *out, size_t size);

/* Initialization: the start time must be 0 (the diagram's time starts there); a stop
 * time, if defined, is where the run ends (a step past it is an error). */
blk_status blk_instance_setup(blk_instance *inst, double start_time, int stop_defined, double stop_time);
blk_status blk_instance_enter_initialization(blk_instance *inst);
blk_status blk_instance_exit_initialization(blk_instance *inst);
blk_status blk_instance_get(blk_instance *inst, const unsigned int *vr, size_t n, double *values);
blk_status blk_instance_set(blk_instance *inst, const unsigned int *vr, size_t n, const double *values);
/* A step of any length; *terminated: the diagram ended (a block asked to end the run), at time
   blk_instance_time, which a step then no longer passes. */
blk_status blk_instance_do_step(blk_instance *inst, double current_time, double step, int *terminated);
double blk_instance_time(const blk_instance *inst);
blk_status blk_instance_terminate(blk_instance *inst);
blk_status blk_instance_reset(blk_instance *inst);

/* FMU states: a snapshot of everything an instance computes with. The functions take
 * the FMI functions' arguments as they come (NULL pointers included: logged errors). */
typedef struct blk_snapshot blk_snapshot;
blk_status blk_instance_get_state(blk_instance *inst, blk_snapshot **snapshot); /* reuses *snapshot if set */
blk_status blk_instance_set_state(blk_instance *inst, const blk_snapshot *snapshot);
blk_status blk_snapshot_free(blk_snapshot **snapshot); /* frees *snapshot, sets it to NULL */
blk_status blk_snapshot_size(blk_instance *inst, const blk_snapshot *snapshot, size_t *size);
blk_status blk_snapshot_serialize(blk_instance *inst, const blk_snapshot *snapshot, unsigned char *bytes,
                                  size_t size);
blk_status blk_snapshot_deserialize(blk_instance *inst, const unsigned char *bytes, size_t size,
                                    blk_snapshot **snapshot);

/* The kernel types this binary holds: tables of types (each ending with a NULL name), the
   list ending with NULL. Each binary defines it (library_kernel_set.c: the library's; an
   application's own file adds its types). */
extern const blk_kernel_type *const blk_export_kernel_sets[];

#endif
