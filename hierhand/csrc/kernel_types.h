/* The hand's kernel types (blocks/csrc/blocks_kernel.h): HandPlant, GraspReflex,
 * ManipulationPD, Suppresser, ObjectSupport (kernel_types.c) and JointLowPass
 * (joint_low_pass.c), each a constructor that builds its context from a record of doubles
 * and the adapters from the calling convention to the plant core and the laws (plain C99).
 *
 * The blocks' kernel() methods (Python) write the records and build their contexts
 * through these constructors (hierhand._native.Context), and an exported FMU rebuilds
 * them from the same records, with its tunable parameters written in: one path from
 * parameters to context. The records' slots are layouts.h's (HH_RECORDS: one per kernel
 * type, with the table that defines the type). A hand travels in a record as a segment
 * (HH_SEG_*: whether the object's inertia follows its mass and size, then the hand vector),
 * checked by hh_model_from_hand. A record's DT or PERIOD is NaN while its block has none.
 */
#ifndef HIERHAND_KERNEL_TYPES_H
#define HIERHAND_KERNEL_TYPES_H

#include "blocks_kernel.h"
#include "layouts.h"

/* Each type's table (its type, then a NULL name), as HH_RECORDS names it. */
#define HH_DECLARE_KERNEL_TYPE(NAME, P, SLOTS, SIZE, TYPES, BLOCK) extern const blk_kernel_type TYPES[];
HH_RECORDS(HH_DECLARE_KERNEL_TYPE)

/* Every table of HH_RECORDS, then NULL: the kernel types the extension and the FMU
 * binaries hold (a list of the form of blk_export_kernel_sets). */
#define HH_KERNEL_TYPE_TABLE(NAME, P, SLOTS, SIZE, TYPES, BLOCK) TYPES,
#define HH_KERNEL_TYPE_TABLES HH_RECORDS(HH_KERNEL_TYPE_TABLE) NULL

#endif
