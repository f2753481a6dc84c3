/* The FMU block's compiled step (fmu_block_step.c): its functions and the layout of its
 * context (fmu_step_table.h), for blocks._native, which hands them to
 * blocks/fmu/compiled_step.py. */
#ifndef BLOCKS_FMU_BLOCK_STEP_H
#define BLOCKS_FMU_BLOCK_STEP_H

#include <Python.h>

/* {"output": address, "update": address, "slots": {name: index}, "values": {...},
   "kinds": {...}}: the step's kernel functions and its context's layout. */
PyObject *blk_fmu_block_step(void);

#endif
