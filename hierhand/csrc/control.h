/* The hierarchical controller's compiled laws: grasping reflex, manipulation PD,
 * suppresser. Work in progress: the layouts below are fixed; the functions follow. */
#ifndef HIERHAND_CONTROL_H
#define HIERHAND_CONTROL_H

#include "hand.h"

#endif
