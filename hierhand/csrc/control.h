/* The hierarchical controller's compiled laws: grasping reflex, manipulation PD,
 * suppresser.
 *
 * Each law is one call over flat double arrays that the caller owns: the block's
 * constants packed once into a parameter vector (slots HH_REFLEX_P_*, HH_MANIP_P_*,
 * HH_SUPPRESS_P_*, declared with every other layout in layouts.h), the inputs of one hit, and an output vector. Nothing is allocated and
 * nothing global changes, so a call costs microseconds and calls are independent. The
 * finger geometry comes from an hh_model through the inline kinematics and dynamics the
 * plant's step uses (kinematics.h, dynamics.h).
 *
 * These functions are the laws: the blocks and the Python API of hierhand.control
 * (internal_directions, project_internal, finger_ik, finger_fk, wrap_angle, Trajectory,
 * suppress, ...) call them, and nothing in the package computes them a second time.
 * Readable numpy formulations live in the tests (tests/hierhand/control/oracles.py),
 * which compare them with these to round-off. Numbers that Python defines (tolerances,
 * the derivative step) arrive as arguments or in the parameter vectors, so each has one
 * definition.
 *
 * Failures are status codes (HH_REFLEX_*, HH_MANIP_*), never aborts.
 */
#ifndef HIERHAND_CONTROL_H
#define HIERHAND_CONTROL_H

#include "hand.h"

/* == grasping reflex (reflex.c) =========================================================
 *
 * The fingers in contact (fn > threshold) are squeezed together by the internal force
 * (I - G^+ G) push at their contact points, each pushing along its contact normal; those
 * listed in the block's 'grasp' that are not touching, and that the reflex was not letting
 * go of when they last touched, approach the others. One integral loop scales the squeeze
 * until every contact the reflex holds has the normal force it needs; the suppresser's
 * share sets how much it holds each (the hand-over to voluntary motion). */

/* Its arrays' slots are in layouts.h: params HH_REFLEX_P_*, state HH_REFLEX_S_* (the force
 * scale, per finger whether the reflex was letting go of it when it last touched, per finger
 * how much it holds it), output HH_REFLEX_O_*, status codes HH_REFLEX_OK, _COINCIDENT,
 * _NO_PERIOD. */

/* Inputs of one hit, as the plant's output ports give them. */
typedef struct hh_reflex_inputs {
    const double *tip; /* 9: per finger tip centre x, y and link-3 angle */
    const double *normal; /* 6: per finger the contact normal (into the object) */
    const double *fn; /* 3: normal force per finger */
    const double *share; /* 3: per finger, the share of its grasping torque its actuator command keeps
                            (the suppresser's output 'share'; 1 when nothing overrides the reflex);
                            read by hh_reflex_update only */
} hh_reflex_inputs;

/* The internal part (I - G^+ G) f of the stacked forces f (k x 2) at the points (k x 2,
 * k >= 1) into out (k x 2): what is left of f once the part that would move the object
 * is removed. G G^T is solved in closed form about the points' centroid; when the moment
 * row is numerically dependent (all points coincide) it is dropped, as numpy.linalg.pinv
 * drops it. The result does not depend on the point the moments are taken about. */
void hh_project_internal(int k, const double *points, const double *f, double *out);

/* The forces f (k x 2) at the points (k x 2, 1 <= k <= 3) that together give the object
 * the wrench w (fx, fy and the moment about (ox, oy)) with the least sum of |f_i|^2 /
 * weight_i (weights > 0): W G^T (G W G^T)^-1 w, the part of Yoshikawa-Nagai's
 * decomposition that carries a load (the internal part is hh_project_internal's), shared
 * in proportion to the weights. With one point, or points that coincide, the moment is
 * dropped, as numpy.linalg.pinv drops it. */
void hh_distribute_wrench(int k, const double *points, const double *weights, double ox, double oy, const double w[3],
                          double *f);

/* The centroid squeeze g_i = c - p_i of k points (k x 2), c their centroid, divided by its
 * longest row, into g (k x 2): an internal force set for any k >= 2, pushing every point
 * toward the centroid. HH_REFLEX_COINCIDENT when its longest row is at most
 * coincident_rtol times the largest coordinate (g then incomplete). */
int hh_centroid_squeeze(int k, const double *points, double coincident_rtol, double *g);

/* The internal force per finger at unit scale, g (3 x 2: largest row length 1, zero
 * outside the grasp or with fewer than two fingers in it), and the flags grasp and
 * touching (0 or 1). With two or more touching: the internal force among them at their
 * contact points, blended toward that of the other two by the hold (state) of a third one
 * held in part; a finger approaching gets a unit push toward the touching ones. With fewer
 * touching: the internal force among all of the grasp. Where the projection leaves some
 * finger not pushing (g_i . push_i <= 0), the centroid squeeze c - p_i instead.
 * HH_REFLEX_OK or HH_REFLEX_COINCIDENT (g then incomplete). */
int hh_reflex_directions(const double *params, const double *state, const hh_reflex_inputs *in, double g[3][2],
                         int grasp[3], int touching[3]);

/* Fingertip force commands f (3 x 2) from the directions: g_i times the state's scale for
 * a touching finger, g_i scaled to the approach force otherwise. */
void hh_reflex_forces(const double *params, const double *state, const double g[3][2], const int touching[3],
                      double f[3][2]);

/* out (HH_REFLEX_N_OUT): tau_g = J_i^T f_i per finger (J_i: Jacobian of finger i's contact
 * point, or of its tip centre while it does not touch, at joint angles q), |f_i|, and the
 * grasp flags. Status as hh_reflex_directions. */
int hh_reflex_output(const hh_model *m, const double *params, const double *state, const hh_reflex_inputs *in,
                     const double *q, double *out);

/* next (HH_REFLEX_N_STATE): each touching finger's hold (the two with the largest share 1,
 * a third 1 down to hold_share falling linearly to 0 at release_share; in->share NULL or
 * params[HH_REFLEX_P_FOLLOW] zero: 1), the hold of a finger out of contact kept; with two or
 * more fingers touching, the scale moves by ki dt max_i hold_i (need_i - fn_i) /
 * max(g_i . n_i, 1e-3) over them, need_i = max(min_force |g_i|, |ft_i| / ratio), clipped to
 * [0, max_force]; a touching finger is marked handed over (1) when its hold is below 1, held
 * (0) otherwise, a finger out of contact keeps its mark. HH_REFLEX_OK, HH_REFLEX_NO_PERIOD or
 * HH_REFLEX_COINCIDENT. */
int hh_reflex_update(const double *params, const double *state, const hh_reflex_inputs *in, const double *ft,
                     double *next);

/* == manipulation PD (manipulation.c) ===================================================
 *
 * Fingertip trajectories (timed waypoints t, x, y, phi) are sampled, turned into joint
 * targets by exact inverse kinematics (the elbow branch nearest q0, each angle as its
 * representative nearest q0), differentiated centrally in time for the velocity target
 * and tracked by a joint PD; the fingers' gravity torques and the object's weight, shared
 * by the fingers carrying it, are fed forward. */

/* Its arrays' slots are in layouts.h: params HH_MANIP_P_*, output HH_MANIP_O_* (rows tau_m,
 * tau_ff, q_ref), status HH_MANIP_OK, HH_MANIP_UNREACHABLE + f when a target of finger f is
 * out of its reach, HH_MANIP_NO_PERIOD when matched gains have no period to be matched to.
 *
 * Trajectories: finger f's waypoint k is the row waypoints + (f * capacity + k) *
 * HH_MANIP_W_COLS (slots HH_MANIP_W_*); its meta row meta + f * HH_MANIP_N_META holds the
 * waypoint count (0: no trajectory, the finger holds q0) and the interpolation
 * (HH_MANIP_INTERP_*), both as doubles. Times strictly increase. */
typedef struct hh_trajectories {
    const double *waypoints; /* HH_FINGERS x capacity x HH_MANIP_W_COLS */
    const double *meta; /* HH_FINGERS x HH_MANIP_N_META */
    long capacity; /* waypoint rows per finger */
} hh_trajectories;

/* One trajectory: count >= 1 rows (t, x, y, phi) with strictly increasing t. */
typedef struct hh_trajectory {
    const double *waypoints; /* count x HH_MANIP_W_COLS */
    long count;
    int minimum_jerk; /* 1: minimum-jerk segments, 0: linear */
} hh_trajectory;

/* Finger f's trajectory of tr (count 0: the finger has none). */
hh_trajectory hh_finger_trajectory(const hh_trajectories *tr, int f);

/* Inputs of one hit, as the plant's output ports give them. */
typedef struct hh_manip_inputs {
    const double *q; /* 9 joint angles */
    const double *qd; /* 9 joint rates */
    const double *fn; /* 3: normal force per finger */
    const double *support; /* 3: the force (fx, fy, torque) something else applies to the object */
    const double *normal; /* 6: per finger the contact normal (into the object) */
    const double *obj; /* 3: the object's pose x, y, theta */
} hh_manip_inputs;

/* An angle wrapped to (-pi, pi]. */
double hh_wrap_angle(double a);

/* Tip centre x, y and link-3 angle phi (not wrapped) of the finger with parameter row
 * ``finger`` at joint angles q (3): the plant's kinematics (kinematics.h). */
void hh_finger_fk(const double *finger, const double q[3], double pose[3]);

/* Joint angles q (3, wrapped to (-pi, pi]) of the finger with parameter row ``finger``
 * (hh_model.fingers[f]) placing its tip centre at (x, y) with link 3 at absolute angle
 * phi, on the elbow branch ``elbow``: +1 gives q2 >= 0, -1 q2 <= 0. reach (3) receives
 * the wrist point's distance from the base and the reachable range [|l1 - l2|, l1 + l2].
 * Returns 1, or 0 when the distance is outside the range by more than reach_rtol (l1 +
 * l2) (q untouched). */
int hh_finger_ik(const double *finger, double reach_rtol, double x, double y, double phi, int elbow, double q[3],
                 double reach[3]);

/* As hh_finger_ik, but of the two elbow branches the one nearer ref (wrapped
 * differences, summed squares; elbow +1 on a tie), each angle as its representative
 * nearest ref. */
int hh_ik_near(const double *finger, double reach_rtol, double x, double y, double phi, const double ref[3],
               double q[3], double reach[3]);

/* Pose (x, y, phi) of a trajectory at time t: the first waypoint before it, the last
 * after it, linear or minimum-jerk in between; NaN at a NaN time. */
void hh_trajectory_sample(const hh_trajectory *tr, double t, double pose[3]);

/* Analytic time derivative of hh_trajectory_sample, right-continuous: at a waypoint the
 * velocity of the segment starting there, zero before the first waypoint and from the
 * last one on; NaN at a NaN time. */
void hh_trajectory_velocity(const hh_trajectory *tr, double t, double velocity[3]);

/* The gains (kp_T, kd_T) that a torque held for each period T needs so that a joint of
 * inertia J follows its target with the closed-loop poles e^{sT} of the continuous PD loop
 * J s^2 + kd s + kp = 0 (pole matching under a zero-order hold): with z1, z2 = e^{s T},
 * kp_T = J (1 - (z1 + z2) + z1 z2) / T^2 and kd_T = J (3 - (z1 + z2) - z1 z2) / (2 T). The
 * sampled loop is then stable for every kp, kd > 0, where kp and kd applied as they are
 * and held for T go unstable once kd T / J exceeds 2 (or kp T^2 / J exceeds 2 kd T / J).
 * kp_T <= kp and kd_T <= kd; both tend to kp, kd as T -> 0. */
void hh_matched_gains(double inertia, double kp, double kd, double period, double *kp_t, double *kd_t);

/* out (HH_MANIP_N_OUT) at time t from the inputs of one hit: tau_m = kp_T (q_ref - q) +
 * kd_T (qd_ref - qd) with the gains hh_matched_gains gives for each joint's own inertia
 * (the diagonal of its finger's mass matrix at q, armature included) where
 * params[HH_MANIP_P_MATCHED] is set, kp and kd as they are otherwise; tau_ff the fingers'
 * gravity torques and J^T of the object's load (its weight plus the support force and
 * torque), shared among the fingers carrying it (fn above the threshold) by
 * hh_distribute_wrench at their contact points (tip centre plus radius along the normal),
 * weighted by their normal forces, so that the shares also balance the load's moment about
 * the object's centre; q_ref.
 * HH_MANIP_OK, HH_MANIP_UNREACHABLE + f or HH_MANIP_NO_PERIOD (out then incomplete). */
int hh_manipulation_output(const hh_model *m, const double *params, const hh_trajectories *tr, double t,
                           const hh_manip_inputs *in, double *out);

/* == suppresser (suppresser.c) ===========================================================
 *
 * tau_g_eff = tau_g * sigmoid(S_a (S_b - g(tau_m))) per joint, g = |tau_m| (magnitude) or
 * tau_m signed positive against the joint's grasping torque (signed: -tau_m where
 * tau_g >= 0, tau_m where tau_g < 0), or tau_g unchanged (pass); the command is
 * tau_g_eff + tau_m + tau_ff. share_i, per finger, is how much of the finger's grasping
 * torque tau_g_i the suppresser lets through: tau_g_eff_i . tau_g_i / |tau_g_i|^2, 1 where
 * tau_g_i is zero or in pass mode. */

/* Its arrays' slots are in layouts.h: params HH_SUPPRESS_P_*, modes HH_SUPPRESS_PASS,
 * _MAGNITUDE, _SIGNED, output HH_SUPPRESS_O_* (tau, tau_g_eff, share). */

/* out (HH_SUPPRESS_N_OUT) from the torques tau_g, tau_m, tau_ff (9 each) and the
 * suppression inputs g (9): the low-passed ones of the block's state, or NULL for the static
 * law (g from tau_m now, hh_suppression_input). */
void hh_suppress(const double *params, const double *tau_g, const double *g, const double *tau_m,
                 const double *tau_ff, double *out);

/* next (9): the low-passed suppression inputs, state + alpha (hh_suppression_input(tau_g,
 * tau_m) - state) per joint (alpha params[HH_SUPPRESS_P_ALPHA]); unchanged in pass mode. */
void hh_suppress_update(const double *params, const double *state, const double *tau_g, const double *tau_m,
                        double *next);

/* The logistic function 1 / (1 + exp(-x)), without overflow for large |x|. */
double hh_sigmoid(double x);

/* One joint's suppression input g(tau_m): |tau_m| in mode HH_SUPPRESS_MAGNITUDE, tau_m
 * signed positive against tau_g in HH_SUPPRESS_SIGNED (-tau_m where tau_g >= 0). */
double hh_suppression_input(double tau_g, double tau_m, double mode);

/* One joint's suppressed grasping torque for the suppression input g:
 * tau_g * sigmoid(S_a (S_b - g)), tau_g in HH_SUPPRESS_PASS. */
double hh_suppressed(double tau_g, double g, double s_a, double s_b, double mode);

/* share (3) of the torques tau_g and tau_g_eff (9 each), as the suppresser's output of
 * that name when it does suppress. */
void hh_finger_shares(const double *tau_g, const double *tau_g_eff, double share[3]);

/* == the blocks' parameters (control_params.c) ============================================
 *
 * Each controller block's numbers as the block is given them ("given", slots *_G_* of
 * layouts.h), checked and packed into its law's parameter vector: the one definition of the
 * checks and of the values derived from them, which the blocks call when they are made and
 * an exported FMU calls when it rebuilds them (kernel_types.h). Each returns 0, or 1 with
 * one line in message saying which parameter is wrong and why (numbers written as Python
 * writes them), the vector then incomplete. A hand is a hand vector (HH_HAND_PARAMS). */

/* Write x as Python's repr of a float does (shortest round trip; "3.0", "nan", "inf"). */
void hh_number_text(double x, char *out, size_t size);

/* params (HH_REFLEX_N_PARAMS) of GraspReflex: the ratio target safety_ratio / (1 + margin),
 * the hand's tip radii, the period dt (NaN: not bound yet). */
int hh_reflex_pack(const double *given, const double *hand, double dt, double *params, char *message, size_t size);

/* params (HH_MANIP_N_PARAMS) of ManipulationPD: q0 and gravity from the hand, the weight
 * its object's mass times gravity, the period dt (NaN: none). */
int hh_manip_pack(const double *given, const double *hand, double dt, double *params, char *message, size_t size);

/* params (HH_SUPPRESS_N_PARAMS) of Suppresser: mode PASS when not enabled, the low-pass
 * step 1 - exp(-period / time_constant) when filtered and period > 0 (else 1). */
int hh_suppress_pack(const double *given, double period, double *params, char *message, size_t size);

/* ObjectSupport's context (HH_SUPPORT_C_*: the force fx, fy, torque, then until): the hand's object weight
 * turned upwards, 0 - m g, while t < until. */
int hh_support_pack(double until, const double *hand, double *context, char *message, size_t size);

#endif
