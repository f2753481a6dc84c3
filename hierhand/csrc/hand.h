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

enum { HH_FINGERS = 3, HH_LINKS = 3, HH_JOINTS = 9, HH_EDGES = 4 };

/* -- per-finger parameter row: model->fingers[f][HH_F_*] ------------------------------ */
enum {
    HH_F_BASE_X = 0,
    HH_F_BASE_Y = 1,
    HH_F_BASE_ANGLE = 2,
    HH_F_LINK0 = 3, /* link i occupies HH_F_LINK0 + HH_F_LINK_STRIDE * i + HH_L_* */
    HH_F_LINK_STRIDE = 5,
    HH_F_DAMPING = 18, /* three joints */
    HH_F_ARMATURE = 21, /* three joints */
    HH_F_TIP_RADIUS = 24,
    HH_N_FINGER_PARAMS = 25
};
enum { HH_L_LENGTH = 0, HH_L_MASS = 1, HH_L_COM_ALONG = 2, HH_L_COM_ACROSS = 3, HH_L_INERTIA = 4 };

/* -- body parameters: model->body[HH_B_*] --------------------------------------------- */
enum {
    HH_B_GX = 0,
    HH_B_GY = 1,
    HH_B_MASS = 2,
    HH_B_INERTIA = 3,
    HH_B_HALF_A = 4,
    HH_B_HALF_B = 5,
    HH_B_K_N = 6,
    HH_B_C_N = 7,
    HH_B_K_T = 8,
    HH_B_C_T = 9,
    HH_B_MU_S = 10,
    HH_B_MU_D = 11,
    HH_B_DT = 12,
    HH_N_BODY_PARAMS = 13
};

/* -- object edges in the object frame: model->edges[e][HH_E_*] -------------------------
 * Point k of edge e (k = 0 .. count-1) sits at origin + k * spacing * direction; the
 * edge's end corner is point 0 of the next edge. Points are numbered start + k. */
enum {
    HH_E_OX = 0,
    HH_E_OY = 1,
    HH_E_DX = 2,
    HH_E_DY = 3,
    HH_E_NX = 4, /* outward normal */
    HH_E_NY = 5,
    HH_E_SPACING = 6,
    HH_E_COUNT = 7,
    HH_E_START = 8,
    HH_N_EDGE_COLS = 9
};

/* -- state vector ------------------------------------------------------------------------
 * q(9) qd(9) object pose(3) object velocity(3) contact windows (3 x 4 x 2: first and last
 * point index per finger and edge that may hold an anchor), touching flags (3 x npts),
 * anchors (3 x npts x 2, in the frame of link 3 relative to the tip centre). */
enum { HH_S_Q = 0, HH_S_QD = 9, HH_S_OBJ = 18, HH_S_OBJ_VEL = 21, HH_S_WINDOW = 24, HH_S_TOUCH = 48 };

/* -- output row -------------------------------------------------------------------------- */
enum {
    HH_O_Q = 0,
    HH_O_QD = 9,
    HH_O_TIP = 18, /* per finger: tip centre x, y, absolute angle of link 3 */
    HH_O_FN = 27,
    HH_O_FT = 30,
    HH_O_RATIO = 33,
    HH_O_CONTACT = 36,
    HH_O_OBJ = 39,
    HH_O_OBJ_VEL = 42,
    HH_O_NORMAL = 45,
    HH_N_OUTPUTS = 51
};

/* -- per-finger contact summary: work->wrench[f][HH_W_*] -------------------------------- */
enum {
    HH_W_OBJ_FX = 0, /* force on the object */
    HH_W_OBJ_FY = 1,
    HH_W_OBJ_M = 2, /* its moment about the object's centre */
    HH_W_TIP_M = 3, /* moment of the force on the object about the tip centre */
    HH_W_FN = 4, /* summed normal force */
    HH_W_FT = 5, /* summed tangential force, signed along t = z x n */
    HH_W_FN_PX = 6, /* sum of f_n * p, for the force-weighted contact point */
    HH_W_FN_PY = 7,
    HH_N_WRENCH = 8
};

/* -- status codes; ``which`` then says which element or finger -------------------------- */
enum {
    HH_OK = 0,
    HH_ERR_Q = 1, /* non-finite joint angle q[which] */
    HH_ERR_QD = 2, /* non-finite joint rate qd[which] */
    HH_ERR_OBJ = 3, /* non-finite object pose obj[which] */
    HH_ERR_OBJ_VEL = 4, /* non-finite object velocity obj_vel[which] */
    HH_ERR_PENETRATION = 5, /* finger ``which``'s tip centre is inside the object */
    HH_ERR_TAU = 6, /* non-finite input tau[which] */
    HH_ERR_F_EXT = 7 /* non-finite input f_ext[which] */
};

/* -- the hand vector: every number of a hand file ----------------------------------------
 * Sections gravity, object, contact, fingers; finger f's numbers start at
 * HH_P_FINGER0 + f * HH_P_FINGER_STRIDE. Names use 1-based indices (FMI's structured
 * naming): "object.mass", "fingers[2].links[3].com[1]". */
enum {
    HH_P_GX = 0,
    HH_P_GY = 1,
    HH_P_OBJ_MASS = 2,
    HH_P_OBJ_INERTIA = 3,
    HH_P_OBJ_SIZE = 4, /* two */
    HH_P_OBJ_POS = 6, /* two */
    HH_P_OBJ_ANGLE = 8,
    HH_P_OBJ_SPACING = 9,
    HH_P_K_N = 10,
    HH_P_C_N = 11,
    HH_P_K_T = 12,
    HH_P_C_T = 13,
    HH_P_MU_S = 14,
    HH_P_MU_D = 15,
    HH_P_FINGER0 = 16,
    HH_P_FINGER_STRIDE = 28,
    HH_HAND_PARAMS = 100
};
/* offsets inside a finger's block of the hand vector */
enum {
    HH_PF_BASE = 0, /* two */
    HH_PF_BASE_ANGLE = 2,
    HH_PF_LINK0 = 3, /* link i: HH_PF_LINK0 + HH_PF_LINK_STRIDE * i + HH_PL_* */
    HH_PF_LINK_STRIDE = 5,
    HH_PF_DAMPING = 18, /* three */
    HH_PF_ARMATURE = 21, /* three */
    HH_PF_TIP_RADIUS = 24,
    HH_PF_Q0 = 25 /* three */
};
enum { HH_PL_LENGTH = 0, HH_PL_MASS = 1, HH_PL_INERTIA = 2, HH_PL_COM_ALONG = 3, HH_PL_COM_ACROSS = 4 };

#define HH_MAX_POINTS 100000 /* surface points a model may have (state memory bound) */

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
/* Check and pack a hand; returns the number of problems (0: ``m`` is ready). */
int hh_model_from_hand(hh_model *m, const double *hand, double dt, hh_report_fn report, void *context);
/* The moment of inertia of a uniform plate of mass ``mass`` and sides a, b about its
 * centre, m (a^2 + b^2) / 12: an object's inertia where its hand file gives none. */
double hh_plate_inertia(double mass, double a, double b);

/* A hand as a kernel's record carries it (kernels.h): HH_SEG_FOLLOWS, then the hand
 * vector. follows non-zero: the object's inertia is the plate inertia of its mass and size
 * (its hand file gives none and one of them was set), hh_hand_of_segment computes it. */
enum { HH_SEG_FOLLOWS = 0, HH_SEG_HAND = 1, HH_SEGMENT = 1 + HH_HAND_PARAMS };
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
