/* Scheduled execution of an exported diagram FMU (FMI 3.0): one input clock per rate of the
 * diagram, one model partition per clock, activated by the importer's scheduler.
 *
 * Clocks. Every rate of the diagram's periodic blocks (a period and an offset, in base
 * ticks) is a constant periodic input clock; its priority is rate-monotonic (the fastest
 * clock 0, the highest priority). Clocks, periods and the programs their partitions run
 * are in BLK_SCHEDULED_RESOURCE, written by blocks/fmu_export/partitions.py.
 *
 * Partitions. At each instant of the diagram's tick grid, the native run's program of that
 * instant (its outputs, updates and delayed-connection samples) is cut into one program per
 * clock that ticks there, in priority order: a clock's program holds its blocks' ops and
 * every op of the instant they depend on (through the values they read and write) that a
 * clock before it did not run; the ops no clock's ops depend on (blocks of several clocks,
 * delayed-connection samples) go with the last clock of the instant. Run one after the
 * other in priority order, the partitions do what the native program does, to the bit.
 * A faster partition may thus compute a slower block's outputs at an instant they share
 * (the rate transition of the diagram: the fast block reads the slow block's new output),
 * and the slower partition then its update.
 *
 * What the importer must do: activate every clock at each of its ticks, the clocks of one
 * instant in priority order, the instants in time order; a partition activated at t must
 * have returned before one of a later instant runs. The FMU checks this and answers an
 * activation out of order with fmi3Error. It calls lockPreemption before a partition
 * computes and unlockPreemption after (a partition is one critical section: its data are
 * shared with the other partitions), so an importer that preempts keeps the semantics
 * while it holds lower-priority partitions off for that time.
 *
 * The resource: little-endian int64 words,
 *   magic BLK_SCHEDULED_MAGIC, version BLK_SCHEDULED_VERSION,
 *   the hyperperiod in base ticks, the number of clocks,
 *   per clock (in priority order): its value reference, period and offset in base ticks
 *   (0 <= offset < period), priority, its program at tick 0 (-1: none), and per hit in one
 *   hyperperiod (hyperperiod / period of them, the first at the offset) its program there
 *   (-1: none) -- programs of the op table in BLK_EXPORT_RESOURCE, run at the hit's tick,
 *   the word BLK_SCHEDULED_MAGIC again. */
#ifndef BLOCKS_EXPORT_SCHEDULED_H
#define BLOCKS_EXPORT_SCHEDULED_H

#include <stddef.h>
#include <stdint.h>

#include "export_instance.h"

#define BLK_SCHEDULED_RESOURCE "clocks.bin"
#define BLK_SCHEDULED_MAGIC 0x314b4c43584b4c42LL /* "BLKXCLK1" */
#define BLK_SCHEDULED_VERSION 1

/* The importer's preemption lock (FMI 3's fmi3LockPreemptionCallback and its unlock). */
typedef void (*blk_preemption)(void);

/* A new instance for scheduled execution: blk_instance_new, then the clocks of
   BLK_SCHEDULED_RESOURCE (an FMU exported for co-simulation alone has none: NULL after
   logging why). lock and unlock may be NULL (an importer that does not preempt). */
blk_instance *blk_instance_new_scheduled(const char *name, const char *token, const char *resource_dir,
                                         blk_logger log, void *environment, int logging_on, blk_preemption lock,
                                         blk_preemption unlock);

/* fmi3ActivateModelPartition: run clock ``clock``'s partition at ``time``, which must be
   one of its ticks, in the order the header's comment says. */
blk_status blk_instance_activate(blk_instance *inst, unsigned int clock, double time);

/* The intervals and shifts of clocks, as doubles or counter / resolution (resolution: the
   base tick's denominator); qualifiers: fmi3IntervalUnchanged (1), the clocks being constant. */
blk_status blk_instance_clock_intervals(blk_instance *inst, const unsigned int *vr, size_t n, double *decimal,
                                        uint64_t *counters, uint64_t *resolutions, int *qualifiers);
blk_status blk_instance_clock_shifts(blk_instance *inst, const unsigned int *vr, size_t n, double *decimal,
                                     uint64_t *counters, uint64_t *resolutions);

#endif
