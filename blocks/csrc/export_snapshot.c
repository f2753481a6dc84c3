/* FMU states of an exported FMU's instance: a snapshot of everything it computes with (the
 * parameters and their set flags, the inputs, and when built the arena, the run's position
 * and the blocks' states), got, set, freed and serialized as the FMI functions ask. */
#include <stdlib.h>
#include <string.h>

#include "export_internal.h"

#define SNAPSHOT_MAGIC "BLKXST02"

/* A snapshot: this header, then the parameters, their set flags (as doubles), the inputs,
   and when built the arena, the state sizes (as doubles), the states and the held outputs. */
struct blk_snapshot {
    char magic[8];
    int64_t words; /* the doubles after the header */
    int64_t phase, built, fresh, stop_defined, stop_tick, outcome_status, end_op, end_asked, held, held_tick;
    double stop_time, held_time;
    blk_position at;
    double values[];
};

static int64_t snapshot_words(const blk_instance *inst)
{
    const blk_export *x = &inst->x;
    int64_t n = 2 * x->n_params + x->n_inputs;
    if (inst->build != NULL) {
        n += x->table.header[BLK_H_ARENA] + x->n_blocks + x->n_outputs;
        for (int64_t k = 0; k < x->n_blocks; k++)
            n += inst->build->state_sizes[k] > 0 ? inst->build->state_sizes[k] : 0;
    }
    return n;
}

static blk_status missing_argument(blk_instance *inst, const char *what)
{
    LOG_ERROR(inst, "%s is NULL", what);
    return BLK_STATUS_ERROR;
}

blk_status blk_instance_get_state(blk_instance *inst, blk_snapshot **snapshot)
{
    if (snapshot == NULL)
        return missing_argument(inst, "the pointer for the FMU state");
    const blk_export *x = &inst->x;
    int64_t words = snapshot_words(inst);
    blk_snapshot *s = *snapshot;
    if (s == NULL || s->words != words) {
        blk_snapshot_free(snapshot);
        s = malloc(sizeof *s + (size_t)words * sizeof(double));
        if (s == NULL) {
            LOG_ERROR(inst, "out of memory for an FMU state");
            return BLK_STATUS_ERROR;
        }
    }
    memset(s, 0, sizeof *s);
    memcpy(s->magic, SNAPSHOT_MAGIC, 8);
    s->words = words;
    s->phase = inst->phase;
    s->built = inst->build != NULL;
    s->fresh = inst->outputs_fresh;
    s->stop_defined = inst->stop_defined;
    s->stop_tick = inst->stop_tick;
    s->stop_time = inst->stop_time;
    double *v = s->values;
    for (int64_t p = 0; p < x->n_params; p++) {
        *v++ = inst->params[p];
        *v++ = inst->set[p];
    }
    memcpy(v, inst->inputs, (size_t)x->n_inputs * sizeof(double));
    v += x->n_inputs;
    if (inst->build != NULL) {
        ex_build *b = inst->build;
        s->at = b->run.at;
        s->outcome_status = b->run.outcome.status;
        s->end_op = b->run.outcome.end_op;
        s->end_asked = b->run.outcome.end_asked;
        s->held = b->held;
        s->held_tick = b->held_tick;
        s->held_time = b->held_time;
        memcpy(v, b->arena, (size_t)x->table.header[BLK_H_ARENA] * sizeof(double));
        v += x->table.header[BLK_H_ARENA];
        for (int64_t k = 0; k < x->n_blocks; k++)
            *v++ = (double)b->state_sizes[k];
        for (int64_t k = 0; k < x->n_blocks; k++)
            if (b->state_sizes[k] > 0) {
                memcpy(v, b->states[k], (size_t)b->state_sizes[k] * sizeof(double));
                v += b->state_sizes[k];
            }
        memcpy(v, b->held_outputs, (size_t)x->n_outputs * sizeof(double));
    }
    *snapshot = s;
    return BLK_STATUS_OK;
}

blk_status blk_instance_set_state(blk_instance *inst, const blk_snapshot *s)
{
    const blk_export *x = &inst->x;
    if (s == NULL || memcmp(s->magic, SNAPSHOT_MAGIC, 8) != 0) {
        LOG_ERROR(inst, "not an FMU state of this FMU");
        return BLK_STATUS_ERROR;
    }
    ex_release_build(inst);
    const double *v = s->values;
    for (int64_t p = 0; p < x->n_params; p++) {
        inst->params[p] = *v++;
        inst->set[p] = *v++ != 0.0;
    }
    memcpy(inst->inputs, v, (size_t)x->n_inputs * sizeof(double));
    v += x->n_inputs;
    inst->stop_defined = (int)s->stop_defined;
    inst->stop_tick = s->stop_tick;
    inst->stop_time = s->stop_time;
    if (s->built) {
        if (ex_build_kernels(inst) != 0 || snapshot_words(inst) != s->words) {
            if (inst->build != NULL)
                LOG_ERROR(inst, "the FMU state holds %lld values, its parameters give %lld", (long long)s->words,
                          (long long)snapshot_words(inst));
            ex_release_build(inst);
            inst->phase = BLK_FAILED;
            return BLK_STATUS_ERROR;
        }
        ex_build *b = inst->build;
        memcpy(b->arena, v, (size_t)x->table.header[BLK_H_ARENA] * sizeof(double));
        v += x->table.header[BLK_H_ARENA] + x->n_blocks;
        for (int64_t k = 0; k < x->n_blocks; k++)
            if (b->state_sizes[k] > 0) {
                memcpy(b->states[k], v, (size_t)b->state_sizes[k] * sizeof(double));
                v += b->state_sizes[k];
            }
        memcpy(b->held_outputs, v, (size_t)x->n_outputs * sizeof(double));
        b->held = (int)s->held;
        b->held_tick = s->held_tick;
        b->held_time = s->held_time;
        b->run.at = s->at;
        b->run.outcome.status = (int)s->outcome_status;
        b->run.outcome.end_op = s->end_op;
        b->run.outcome.end_asked = s->end_asked;
        inst->outputs_fresh = (int)s->fresh;
    }
    inst->phase = (blk_phase)s->phase;
    return BLK_STATUS_OK;
}

blk_status blk_snapshot_free(blk_snapshot **snapshot)
{
    if (snapshot != NULL) {
        free(*snapshot);
        *snapshot = NULL;
    }
    return BLK_STATUS_OK;
}

static size_t snapshot_bytes(const blk_snapshot *snapshot)
{
    return sizeof *snapshot + (size_t)snapshot->words * sizeof(double);
}

blk_status blk_snapshot_size(blk_instance *inst, const blk_snapshot *snapshot, size_t *size)
{
    if (snapshot == NULL || size == NULL)
        return missing_argument(inst, snapshot == NULL ? "the FMU state" : "the pointer for its size");
    *size = snapshot_bytes(snapshot);
    return BLK_STATUS_OK;
}

blk_status blk_snapshot_serialize(blk_instance *inst, const blk_snapshot *snapshot, unsigned char *bytes, size_t size)
{
    if (snapshot == NULL || bytes == NULL)
        return missing_argument(inst, snapshot == NULL ? "the FMU state" : "the buffer for the serialized state");
    size_t need = snapshot_bytes(snapshot);
    if (size < need) {
        LOG_ERROR(inst, "the buffer for the serialized FMU state holds %zu bytes, it needs %zu", size, need);
        return BLK_STATUS_ERROR;
    }
    memcpy(bytes, snapshot, need);
    return BLK_STATUS_OK;
}

blk_status blk_snapshot_deserialize(blk_instance *inst, const unsigned char *bytes, size_t size,
                                    blk_snapshot **snapshot)
{
    if (bytes == NULL || snapshot == NULL)
        return missing_argument(inst, bytes == NULL ? "the serialized state" : "the pointer for the FMU state");
    blk_snapshot head;
    if (size < sizeof head) {
        LOG_ERROR(inst, "a serialized FMU state of %zu bytes is too short", size);
        return BLK_STATUS_ERROR;
    }
    memcpy(&head, bytes, sizeof head);
    if (memcmp(head.magic, SNAPSHOT_MAGIC, 8) != 0 || head.words < 0 ||
        (uint64_t)head.words > (size - sizeof head) / sizeof(double) ||
        size != sizeof head + (size_t)head.words * sizeof(double) || head.phase < BLK_INSTANTIATED ||
        head.phase > BLK_FAILED) {
        LOG_ERROR(inst, "the bytes are not a serialized FMU state of this FMU");
        return BLK_STATUS_ERROR;
    }
    blk_snapshot *s = malloc(size);
    if (s == NULL) {
        LOG_ERROR(inst, "out of memory for an FMU state");
        return BLK_STATUS_ERROR;
    }
    memcpy(s, bytes, size);
    blk_snapshot_free(snapshot);
    *snapshot = s;
    return BLK_STATUS_OK;
}
