/* The hand/object plant core: three planar 3-joint fingers with circular tips and a
 * square object, the paper's point-set penalty contact, semi-implicit Euler.
 *
 * Plain C99 over flat arrays, libc and libm only. The same sources run inside the Python
 * extension that HandPlant calls and inside the exported FMUs.
 *
 * As in MuJoCo, constant parameters (hh_model) are kept apart from what changes: the
 * plant's state is one flat double vector owned by the caller (layout HH_S_*), and the
 * scratch a step needs lives in an hh_work the caller allocates once per model.
 *
 * A hand is given as the vector of its hand-file numbers (HH_HAND_PARAMS of them, order
 * and names in hh_hand_param_name); hh_model_from_hand checks and packs it.
 */
#ifndef HIERHAND_HAND_H
#define HIERHAND_HAND_H

#include <stddef.h>

#include "layouts.h" /* the slots of its arrays (HH_F_*, HH_B_*, HH_E_*, HH_S_*, HH_O_*, HH_W_*, HH_P_*) */

/* Constant parameters of a hand and its object, packed for the step. */
typedef struct hh_model {
    double fingers[HH_FINGERS][HH_N_FINGER_PARAMS];
    double body[HH_N_BODY_PARAMS];
    double edges[HH_EDGES][HH_N_EDGE_COLS];
    double q0[HH_JOINTS]; /* initial joint angles */
    double pose0[3]; /* initial object pose x, y, theta */
    int npts; /* surface points of the object */
} hh_model;

/* Scratch for evaluating and stepping one model (allocate with hh_work_init). */
typedef struct hh_work {
    double u[HH_FINGERS][3][2]; /* link directions */
    double pts[HH_FINGERS][4][2]; /* joints 1-3 and the tip centre */
    double jac[HH_FINGERS][2][3]; /* tip-centre Jacobians */
    double tip[HH_FINGERS][3]; /* tip centre x, y and link-3 angle */
    double gen[HH_JOINTS]; /* joint torques from contact */
    double wrench[HH_FINGERS][HH_N_WRENCH]; /* per-finger contact summary */
    double mass[3][3];
    long window[HH_FINGERS][HH_EDGES][2]; /* visited point ranges */
    double *pend_anchor; /* HH_FINGERS x npts x 2 */
    unsigned char *pend_flag; /* HH_FINGERS x npts */
    int npts;
} hh_work;

/* Called once per problem found in a hand vector: ``param`` is the index of the number
 * the problem is about, ``text`` what is wrong with it (without its name). */
typedef void (*hh_report_fn)(void *context, int param, const char *text);

/* -- the hand vector ------------------------------------------------------------------- */
const char *hh_hand_param_name(int param); /* NULL outside 0 .. HH_HAND_PARAMS-1 */
const char *hh_hand_param_doc(int param); /* what the number is, with its unit */
int hh_hand_param_at_least_zero(int param); /* 1: the number must be >= 0 (or > 0) */
/* Check and pack a hand; returns the number of problems (0: ``m`` is ready). */
int hh_model_from_hand(hh_model *m, const double *hand, double dt, hh_report_fn report, void *context);
/* The moment of inertia of a uniform plate of mass ``mass`` and sides a, b about its
 * centre, m (a^2 + b^2) / 12: an object's inertia where its hand file gives none. */
double hh_plate_inertia(double mass, double a, double b);

/* A hand as a kernel's record carries it (layouts.h, HH_SEG_*): a flag, non-zero when the
 * object's inertia is the plate inertia of its mass and size (its hand file gives none and
 * one of them was set), then the hand vector. The hand of a segment, that inertia computed: */
void hh_hand_of_segment(const double *segment, double *hand);

/* -- state ------------------------------------------------------------------------------ */
size_t hh_state_size(const hh_model *m);
void hh_initial_state(const hh_model *m, double *state);

/* -- scratch ------------------------------------------------------------------------------ */
int hh_work_init(hh_work *w, int npts); /* 0 on success, -1 out of memory */
void hh_work_free(hh_work *w);

/* -- stepping -------------------------------------------------------------------------------
 * Each returns HH_OK or an error code with *which naming the element; *done counts the
 * updates completed when the error was found (0: the starting state or the inputs). */
int hh_step(const hh_model *m, hh_work *w, double *state, const double *tau, const double *f_ext, int *done,
            int *which);
/* n updates, each followed by its output row: row i at rows + i * row_stride (a stride of
 * 0 keeps only the last). Equals n times hh_step then hh_output, bit for bit. */
int hh_advance(const hh_model *m, hh_work *w, double *state, const double *tau, const double *f_ext, long n,
               double *rows, ptrdiff_t row_stride, long *done, int *which);
int hh_output(const hh_model *m, hh_work *w, const double *state, double *row, int *which);
/* Tip poses (w->tip) and contact summaries (w->wrench) of a state. */
int hh_contact(const hh_model *m, hh_work *w, const double *state, int *which);

/* -- kinematics and dynamics of the fingers (the functions the step uses) ------------------ */
/* Link directions u (3 x 3 x 2), joint points and tip centres pts (3 x 4 x 2) and link-3
 * angles phi (3) at joint angles q (9). */
void hh_frames(const hh_model *m, const double *q, double *u, double *pts, double *phi);
/* Jacobian (2 x 3) of the point (px, py) moving with link 3 of finger f, at q. */
void hh_point_jacobian(const hh_model *m, const double *q, int f, double px, double py, double *jac);
/* Joint-space mass matrix (9 x 9, row-major, block-diagonal) including armature. */
void hh_mass_matrix(const hh_model *m, const double *q, double *mass);
/* Coriolis/centrifugal + gravity + joint damping (9): tau = M qdd + bias. */
void hh_bias(const hh_model *m, const double *q, const double *qd, double *bias);

#endif
