/* The hand blocks' kernels (blocks/csrc/blocks_kernel.h) as kernel types: HandPlant,
 * GraspReflex, ManipulationPD, Suppresser and ObjectSupport, each a constructor that
 * builds its context from a record of doubles and the adapters from the calling
 * convention to the plant core and the laws (kernels.c, plain C99).
 *
 * The blocks' kernel() methods (Python) write the records and build their contexts
 * through these constructors (hierhand._native.Context), and an exported FMU rebuilds
 * them from the same records, with its tunable parameters written in: one path from
 * parameters to context. A hand travels in a record as a segment (hand.h,
 * HH_SEGMENT values: whether the object's inertia follows its mass and size, then the
 * hand vector), checked by hh_model_from_hand.
 *
 * Records:
 *   HandPlant       [dt, segment]
 *   GraspReflex     [segment, dt, given (HH_REFLEX_N_GIVEN, control.h)]
 *   ManipulationPD  [segment, dt, given (HH_MANIP_N_GIVEN), capacity, waypoints (HH_FINGERS x
 *                    capacity x HH_MANIP_W_COLS), meta (HH_FINGERS x HH_MANIP_N_META)]
 *   Suppresser      [given (HH_SUPPRESS_N_GIVEN), period]
 *   ObjectSupport   [segment, until]
 * dt (the reflex's and the PD's): NaN when the block has no period yet.
 */
#ifndef HIERHAND_KERNELS_H
#define HIERHAND_KERNELS_H

#include "blocks_kernel.h"

extern const blk_kernel_type hh_kernel_types[]; /* ends with a NULL name */

#endif
