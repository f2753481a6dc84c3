/* The hand blocks' kernel types: constructors from records, and adapters from the kernel
 * calling convention to the very functions the blocks' Python methods call (the plant's
 * step, the laws of control.h), with the same arguments, so results are equal to the last
 * bit. See kernel_types.h and layouts.h for the records.
 *
 * None calls Python or writes anything but the state, the outputs and its own context
 * (the plant's hh_work), so each run constructs its own plant context and the blocks'
 * Kernels say nogil. Adapters whose law may stop half way through writing (reflex,
 * manipulation) compute into a local buffer and copy it out on success, as the Python
 * methods return fresh arrays; the reflex update reads a copy of the state, since it
 * writes the new state in place.
 */
#include "kernel_types.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "control.h"
#include "hand.h"

/* -- records --------------------------------------------------------------------------------- */

static int refuse(char *message, long size, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(message, (size_t)size, format, args);
    va_end(args);
    return 1;
}

static int wrong_length(char *message, long size, const char *kind, long n, long expected)
{
    return refuse(message, size, "a %s record holds %ld numbers, not %ld", kind, n, expected);
}

typedef struct {
    char *message;
    long size;
    int problems;
} first_problem;

static void keep_first(void *context, int param, const char *text)
{
    first_problem *p = context;
    if (p->problems++ == 0)
        snprintf(p->message, (size_t)p->size, "%s %s", hh_hand_param_name(param), text);
}

/* The model of a record's hand segment, stepping at dt; 0, or 1 with the first problem of
   the hand (its parameter's name and what is wrong) in message. */
static int model_of(const double *segment, double dt, hh_model *m, char *message, long size)
{
    double hand[HH_HAND_PARAMS];
    hh_hand_of_segment(segment, hand);
    first_problem p = {message, size, 0};
    return hh_model_from_hand(m, hand, dt, keep_first, &p) != 0;
}

/* -- HandPlant: inputs HH_PLANT_I_*; out: the output row (HH_O_*) --------------------------------- */

typedef struct {
    hh_model model;
    hh_work work;
} plant_context;

static int plant_construct(const double *r, long n, blk_built *built, char *message, long size)
{
    if (n != HH_PLANT_RECORD)
        return wrong_length(message, size, "HandPlant", n, HH_PLANT_RECORD);
    double dt = r[HH_PLANT_R_DT];
    if (!(dt > 0.0 && isfinite(dt)))
        return refuse(message, size, "HandPlant needs a positive period, got %g s", dt);
    plant_context *c = calloc(1, sizeof *c);
    if (c == NULL)
        return refuse(message, size, "no memory for the plant's model");
    if (model_of(r + HH_PLANT_R_SEGMENT, dt, &c->model, message, size) != 0) {
        free(c);
        return 1;
    }
    int npts = c->model.npts;
    if (hh_work_init(&c->work, npts) != 0) {
        free(c);
        return refuse(message, size, "no memory for the scratch of %d surface points", npts);
    }
    built->ctx = c;
    built->outputs = HH_N_OUTPUTS;
    built->state_size = (long)hh_state_size(&c->model);
    return 0;
}

static void plant_destroy(void *ctx)
{
    plant_context *c = ctx;
    if (c != NULL)
        hh_work_free(&c->work);
    free(c);
}

static void plant_initial(const void *ctx, double *state)
{
    hh_initial_state(&((const plant_context *)ctx)->model, state);
}

/* The plant context's scratch is written by the steps: each run has its own context. */
static int plant_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                        int *which)
{
    (void)t;
    (void)inputs;
    plant_context *c = (plant_context *)ctx;
    return hh_output(&c->model, &c->work, state, out, which);
}

static int plant_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    plant_context *c = (plant_context *)ctx;
    int done;
    return hh_step(&c->model, &c->work, state, inputs[HH_PLANT_I_TAU], inputs[HH_PLANT_I_F_EXT], &done, which);
}

static int plant_advance(const void *ctx, double t, double *state, const double *const *inputs, int n, double *rows,
                         int *done, int *which)
{
    (void)t;
    plant_context *c = (plant_context *)ctx;
    long stepped = 0;
    int code = hh_advance(&c->model, &c->work, state, inputs[HH_PLANT_I_TAU], inputs[HH_PLANT_I_F_EXT], (long)n, rows,
                          HH_N_OUTPUTS, &stepped, which);
    /* hh_advance counts the failing update; the rows before it are complete (as
       HandPlant.advance: written = max(done - 1, 0)) */
    *done = code == HH_OK ? n : (stepped > 1 ? (int)(stepped - 1) : 0);
    return code;
}

/* What a plant failure code means, as HandPlant says it (fingers by number: the names
   are the hand file's, which the record does not hold). */
static void plant_failure(const void *ctx, int code, int which, const char *phase, double t, char *message,
                          long size)
{
    (void)ctx;
    char when[64];
    snprintf(when, sizeof when, "%s t=%.10g s", strcmp(phase, "output") != 0 ? "in the step at" : "at", t);
    static const char *axes[] = {"x", "y", "theta"}, *rates[] = {"vx", "vy", "omega"};
    int finger = (which / 3) % HH_FINGERS + 1;
    size_t n = (size_t)size;
    switch (code) {
    case HH_ERR_PENETRATION:
        snprintf(message, n,
                 "contact penetration deeper than the fingertip radius %s: the tip centre of finger %d is inside "
                 "the object; the contact is too soft for the forces or the step too large",
                 when, which % HH_FINGERS + 1);
        break;
    case HH_ERR_Q:
        snprintf(message, n, "non-finite value %s: joint angle q[%d] (finger %d joint %d) is not finite", when,
                 which + 1, finger, which % 3 + 1);
        break;
    case HH_ERR_QD:
        snprintf(message, n, "non-finite value %s: joint velocity qd[%d] (finger %d joint %d) is not finite", when,
                 which + 1, finger, which % 3 + 1);
        break;
    case HH_ERR_OBJ:
        snprintf(message, n, "non-finite value %s: object pose obj[%d] (%s) is not finite", when, which + 1,
                 axes[which % 3]);
        break;
    case HH_ERR_OBJ_VEL:
        snprintf(message, n, "non-finite value %s: object velocity obj_vel[%d] (%s) is not finite", when, which + 1,
                 rates[which % 3]);
        break;
    case HH_ERR_TAU:
        snprintf(message, n, "non-finite input %s: tau[%d] (finger %d joint %d)", when, which + 1, finger,
                 which % 3 + 1);
        break;
    case HH_ERR_F_EXT:
        snprintf(message, n, "non-finite input %s: f_ext[%d]", when, which + 1);
        break;
    default:
        snprintf(message, n, "the plant failed %s (code %d)", when, code);
    }
}

/* -- GraspReflex: inputs HH_REFLEX_I_*; out: HH_REFLEX_O_* --------------------------------------- */

typedef struct {
    hh_model model;
    double params[HH_REFLEX_N_PARAMS];
} reflex_context;

static int reflex_construct(const double *r, long n, blk_built *built, char *message, long size)
{
    if (n != HH_REFLEX_RECORD)
        return wrong_length(message, size, "GraspReflex", n, HH_REFLEX_RECORD);
    reflex_context *c = calloc(1, sizeof *c);
    if (c == NULL)
        return refuse(message, size, "no memory for the reflex's model");
    double hand[HH_HAND_PARAMS];
    hh_hand_of_segment(r + HH_REFLEX_R_SEGMENT, hand);
    if (model_of(r + HH_REFLEX_R_SEGMENT, 0.0, &c->model, message, size) != 0 ||
        hh_reflex_pack(r + HH_REFLEX_R_GIVEN, hand, r[HH_REFLEX_R_DT], c->params, message, (size_t)size) != 0) {
        free(c);
        return 1;
    }
    built->ctx = c;
    built->outputs = HH_REFLEX_N_OUT;
    built->state_size = HH_REFLEX_N_STATE;
    return 0;
}

/* [the approach force as the grasp force scale, nothing handed over (3), held whole (3)]:
   GraspReflex.initial_state */
static void reflex_initial(const void *ctx, double *state)
{
    const reflex_context *c = ctx;
    state[HH_REFLEX_S_SCALE] = c->params[HH_REFLEX_P_APPROACH];
    for (int f = 0; f < HH_FINGERS; f++) {
        state[HH_REFLEX_S_HANDED + f] = 0.0;
        state[HH_REFLEX_S_HOLD + f] = 1.0;
    }
}

static int reflex_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                         int *which)
{
    (void)t;
    const reflex_context *c = ctx;
    hh_reflex_inputs in = {.tip = inputs[HH_REFLEX_I_TIP],
                           .normal = inputs[HH_REFLEX_I_NORMAL],
                           .fn = inputs[HH_REFLEX_I_FN],
                           .share = NULL};
    double buffer[HH_REFLEX_N_OUT];
    *which = 0;
    int code = hh_reflex_output(&c->model, c->params, state, &in, inputs[HH_REFLEX_I_Q], buffer);
    if (code == HH_REFLEX_OK)
        memcpy(out, buffer, sizeof buffer);
    return code;
}

static int reflex_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    const reflex_context *c = ctx;
    hh_reflex_inputs in = {.tip = inputs[HH_REFLEX_I_TIP],
                           .normal = inputs[HH_REFLEX_I_NORMAL],
                           .fn = inputs[HH_REFLEX_I_FN],
                           .share = inputs[HH_REFLEX_I_SHARE]};
    double current[HH_REFLEX_N_STATE], next[HH_REFLEX_N_STATE];
    memcpy(current, state, sizeof current);
    *which = 0;
    int code = hh_reflex_update(c->params, current, &in, inputs[HH_REFLEX_I_FT], next);
    if (code == HH_REFLEX_OK)
        memcpy(state, next, sizeof next);
    return code;
}

static void reflex_failure(const void *ctx, int code, int which, const char *phase, double t, char *message,
                           long size)
{
    (void)ctx;
    (void)which;
    if (code == HH_REFLEX_COINCIDENT)
        snprintf(message, (size_t)size, "%s at t=%.10g s: internal forces are undefined: all contact points coincide",
                 phase, t);
    else
        snprintf(message, (size_t)size, "%s at t=%.10g s failed with code %d", phase, t, code);
}

/* -- ManipulationPD: inputs HH_MANIP_I_*; out: HH_MANIP_O_* ---------------------------------------- */

typedef struct {
    hh_model model;
    double params[HH_MANIP_N_PARAMS];
    double meta[HH_FINGERS * HH_MANIP_N_META];
    long capacity;
    double waypoints[]; /* HH_FINGERS x capacity x HH_MANIP_W_COLS */
} manip_context;

static int manip_construct(const double *r, long n, blk_built *built, char *message, long size)
{
    long head = HH_MANIP_RECORD_HEAD;
    if (n < head)
        return wrong_length(message, size, "ManipulationPD", n, head);
    double capacity = r[HH_MANIP_R_CAPACITY];
    long rows = (long)capacity;
    if (!(capacity >= 1 && capacity == (double)rows && rows <= (n - head) / (HH_FINGERS * HH_MANIP_W_COLS)))
        return refuse(message, size, "a ManipulationPD record gives %g waypoint rows per finger for %ld numbers",
                      capacity, n);
    long points = HH_FINGERS * rows * HH_MANIP_W_COLS, expected = head + points + HH_FINGERS * HH_MANIP_N_META;
    if (n != expected)
        return wrong_length(message, size, "ManipulationPD", n, expected);
    const double *meta = r + HH_MANIP_R_WAYPOINTS + points;
    for (int f = 0; f < HH_FINGERS; f++) {
        double count = meta[f * HH_MANIP_N_META + HH_MANIP_M_COUNT];
        if (!(count >= 0 && count <= (double)rows && count == floor(count)))
            return refuse(message, size, "finger %d's trajectory has %g waypoints, room for %ld", f + 1, count, rows);
    }
    manip_context *c = calloc(1, sizeof *c + (size_t)points * sizeof(double));
    if (c == NULL)
        return refuse(message, size, "no memory for the PD's trajectories");
    double hand[HH_HAND_PARAMS];
    hh_hand_of_segment(r + HH_MANIP_R_SEGMENT, hand);
    if (model_of(r + HH_MANIP_R_SEGMENT, 0.0, &c->model, message, size) != 0 ||
        hh_manip_pack(r + HH_MANIP_R_GIVEN, hand, r[HH_MANIP_R_DT], c->params, message, (size_t)size) != 0) {
        free(c);
        return 1;
    }
    c->capacity = rows;
    memcpy(c->waypoints, r + HH_MANIP_R_WAYPOINTS, (size_t)points * sizeof(double));
    memcpy(c->meta, meta, sizeof c->meta);
    built->ctx = c;
    built->outputs = HH_MANIP_N_OUT;
    built->state_size = 0;
    return 0;
}

static int manip_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                        int *which)
{
    (void)state;
    const manip_context *c = ctx;
    hh_trajectories tr = {.waypoints = c->waypoints, .meta = c->meta, .capacity = c->capacity};
    double buffer[HH_MANIP_N_OUT];
    hh_manip_inputs in = {.q = inputs[HH_MANIP_I_Q],
                          .qd = inputs[HH_MANIP_I_QD],
                          .fn = inputs[HH_MANIP_I_FN],
                          .support = inputs[HH_MANIP_I_SUPPORT],
                          .normal = inputs[HH_MANIP_I_NORMAL],
                          .obj = inputs[HH_MANIP_I_OBJ]};
    int status = hh_manipulation_output(&c->model, c->params, &tr, t, &in, buffer);
    if (status == HH_MANIP_OK) {
        *which = 0;
        memcpy(out, buffer, sizeof buffer);
    } else {
        *which = status - HH_MANIP_UNREACHABLE; /* the finger out of reach */
    }
    return status;
}

static void manip_failure(const void *ctx, int code, int which, const char *phase, double t, char *message,
                          long size)
{
    (void)ctx;
    if (code == HH_MANIP_NO_PERIOD)
        snprintf(message, (size_t)size, "%s at t=%.10g s: its gains are matched to its period, and it has none",
                 phase, t);
    else
        snprintf(message, (size_t)size, "%s at t=%.10g s: a target of finger %d is out of its reach", phase, t,
                 which + 1);
}

/* -- Suppresser: inputs HH_SUPPRESS_I_*; out: HH_SUPPRESS_O_* -------------------------------------- */

static int suppress_construct(const double *r, long n, blk_built *built, char *message, long size)
{
    if (n != HH_SUPPRESS_RECORD)
        return wrong_length(message, size, "Suppresser", n, HH_SUPPRESS_RECORD);
    double *params = malloc(HH_SUPPRESS_N_PARAMS * sizeof(double));
    if (params == NULL)
        return refuse(message, size, "no memory for the suppresser's parameters");
    const double *given = r + HH_SUPPRESS_R_GIVEN;
    if (hh_suppress_pack(given, r[HH_SUPPRESS_R_PERIOD], params, message, (size_t)size) != 0) {
        free(params);
        return 1;
    }
    built->ctx = params;
    built->outputs = HH_SUPPRESS_N_OUT;
    built->state_size = given[HH_SUPPRESS_G_TIME_CONSTANT] > 0 ? HH_JOINTS : 0;
    return 0;
}

/* The low-passed suppression inputs start at zero (Suppresser.initial_state). */
static void suppress_initial(const void *ctx, double *state)
{
    (void)ctx;
    for (int i = 0; i < HH_JOINTS; i++)
        state[i] = 0.0;
}

static int suppress_output(const void *ctx, double t, const double *state, const double *const *inputs,
                           double *out, int *which)
{
    (void)t;
    *which = 0;
    hh_suppress((const double *)ctx, inputs[HH_SUPPRESS_I_TAU_G], state, inputs[HH_SUPPRESS_I_TAU_M],
                inputs[HH_SUPPRESS_I_TAU_FF], out); /* state NULL: static law */
    return 0;
}

static int suppress_update(const void *ctx, double t, double *state, const double *const *inputs, int *which)
{
    (void)t;
    *which = 0;
    double next[HH_JOINTS];
    hh_suppress_update((const double *)ctx, state, inputs[HH_SUPPRESS_I_TAU_G], inputs[HH_SUPPRESS_I_TAU_M], next);
    memcpy(state, next, sizeof next);
    return 0;
}

/* -- ObjectSupport: no inputs; out: y (3) = the force while t < until, else zero -------------- */

static int support_construct(const double *r, long n, blk_built *built, char *message, long size)
{
    if (n != HH_SUPPORT_RECORD)
        return wrong_length(message, size, "ObjectSupport", n, HH_SUPPORT_RECORD);
    double hand[HH_HAND_PARAMS], *c = malloc(HH_SUPPORT_N_CONTEXT * sizeof(double));
    if (c == NULL)
        return refuse(message, size, "no memory for the support's force");
    hh_hand_of_segment(r + HH_SUPPORT_R_SEGMENT, hand);
    if (hh_support_pack(r[HH_SUPPORT_R_UNTIL], hand, c, message, (size_t)size) != 0) {
        free(c);
        return 1;
    }
    built->ctx = c;
    built->outputs = 3;
    built->state_size = 0;
    return 0;
}

static int support_output(const void *ctx, double t, const double *state, const double *const *inputs, double *out,
                          int *which)
{
    (void)state;
    (void)inputs;
    const double *c = (const double *)ctx;
    int on = t < c[HH_SUPPORT_C_UNTIL];
    for (int i = 0; i < 3; i++)
        out[i] = on ? c[HH_SUPPORT_C_FORCE + i] : 0.0;
    *which = 0;
    return 0;
}

/* -- the types (layouts.h lists them with their records) ---------------------------------------- */

const blk_kernel_type hh_plant_kernel_type[] = {
    {"HandPlant", plant_construct, plant_destroy, plant_initial, plant_output, plant_update, plant_advance,
     plant_failure},
    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL},
};
const blk_kernel_type hh_reflex_kernel_type[] = {
    {"GraspReflex", reflex_construct, free, reflex_initial, reflex_output, reflex_update, NULL, reflex_failure},
    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL},
};
const blk_kernel_type hh_manip_kernel_type[] = {
    {"ManipulationPD", manip_construct, free, NULL, manip_output, NULL, NULL, manip_failure},
    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL},
};
const blk_kernel_type hh_suppress_kernel_type[] = {
    {"Suppresser", suppress_construct, free, suppress_initial, suppress_output, suppress_update, NULL, NULL},
    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL},
};
const blk_kernel_type hh_support_kernel_type[] = {
    {"ObjectSupport", support_construct, free, NULL, support_output, NULL, NULL, NULL},
    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL},
};
