/* The manipulation controller's law (ManipulationPD): trajectories, IK, PD, feedforward.
 *
 * hh_manipulation_output does in one call what ManipulationPD.output_reference does in
 * numpy: sample the fingertip trajectories, turn the samples into joint targets by exact
 * three-joint inverse kinematics, differentiate those centrally in time for the velocity
 * target, track both with the joint PD, and add the gravity and load feedforward. The
 * arithmetic follows inverse_kinematics.finger_ik / finger_ik_near,
 * trajectory.Trajectory.sample / velocity and Hand.bias / tip_jacobians operation by
 * operation.
 */
#include <math.h>

#include "control.h"
#include "dynamics.h"
#include "float_ops.h"
#include "kinematics.h"

static const double PI = 3.14159265358979323846;
static const double TWO_PI = 2 * 3.14159265358979323846;

/* inverse_kinematics.wrap_angle of one angle: to (-pi, pi]. */
static double wrap_angle(double a)
{
    double w = PI - hh_floored_mod(PI - a, TWO_PI);
    if (w <= -PI) /* the modulo of a tiny negative number rounds to 2 pi */
        w += TWO_PI;
    return w;
}

static double link_length(const double *finger, int i)
{
    return finger[HH_F_LINK0 + HH_F_LINK_STRIDE * i + HH_L_LENGTH];
}

int hh_ik_near(const double *finger, double reach_rtol, double x, double y, double phi, const double ref[3],
               double q[3])
{
    double l1 = link_length(finger, 0);
    double l2 = link_length(finger, 1);
    double l3 = link_length(finger, 2);
    double wx = x - l3 * cos(phi) - finger[HH_F_BASE_X];
    double wy = y - l3 * sin(phi) - finger[HH_F_BASE_Y];
    double r = hypot(wx, wy);
    double r_min = fabs(l1 - l2);
    double r_max = l1 + l2;
    double tol = reach_rtol * r_max;
    if (!(r_min - tol <= r && r <= r_max + tol))
        return 0;
    double c2 = (r * r - l1 * l1 - l2 * l2) / (2 * l1 * l2);
    double a2 = acos(hh_min(1.0, hh_max(-1.0, c2)));
    double toward = atan2(wy, wx);
    double best = 0.0;
    double best_step[3] = {0.0, 0.0, 0.0};
    for (int branch = 0; branch < 2; branch++) {
        double q2 = branch == 0 ? a2 : -a2; /* elbow +1 first: it wins ties */
        double th1 = toward - atan2(l2 * sin(q2), l1 + l2 * cos(q2));
        double q1 = th1 - finger[HH_F_BASE_ANGLE];
        double q3 = phi - th1 - q2;
        double d0 = wrap_angle(wrap_angle(q1) - ref[0]);
        double d1 = wrap_angle(wrap_angle(q2) - ref[1]);
        double d2 = wrap_angle(wrap_angle(q3) - ref[2]);
        double dd = d0 * d0 + d1 * d1 + d2 * d2;
        if (branch == 0 || dd < best) {
            best = dd;
            best_step[0] = d0;
            best_step[1] = d1;
            best_step[2] = d2;
        }
    }
    for (int j = 0; j < 3; j++)
        q[j] = ref[j] + best_step[j];
    return 1;
}

/* Waypoint k of finger f. */
static const double *waypoint(const hh_trajectories *tr, int f, long k)
{
    return tr->waypoints + ((long)f * tr->capacity + k) * HH_MANIP_W_COLS;
}

static long waypoint_count(const hh_trajectories *tr, int f)
{
    return (long)tr->meta[f * HH_MANIP_N_META + HH_MANIP_M_COUNT];
}

static int minimum_jerk(const hh_trajectories *tr, int f)
{
    return tr->meta[f * HH_MANIP_N_META + HH_MANIP_M_INTERP] == HH_MANIP_INTERP_MINJERK;
}

/* The segment of t (times[i] <= t < times[i+1], clamped to the first and last): its index,
 * normalised time tau in [0, 1] and span, as Trajectory._segment (numpy.searchsorted on
 * the right). */
static long segment(const hh_trajectories *tr, int f, long n, double t, double *tau, double *span)
{
    long count = 0;
    while (count < n && waypoint(tr, f, count)[HH_MANIP_W_T] <= t)
        count += 1;
    long i = count - 1 > 0 ? count - 1 : 0;
    if (i > n - 2)
        i = n - 2;
    double t0 = waypoint(tr, f, i)[HH_MANIP_W_T];
    *span = waypoint(tr, f, i + 1)[HH_MANIP_W_T] - t0;
    *tau = (t - t0) / *span;
    return i;
}

void hh_trajectory_sample(const hh_trajectories *tr, int f, double t, double pose[3])
{
    long n = waypoint_count(tr, f);
    const double *first = waypoint(tr, f, 0);
    const double *last = waypoint(tr, f, n - 1);
    if (t <= first[HH_MANIP_W_T] || t >= last[HH_MANIP_W_T]) {
        const double *held = t <= first[HH_MANIP_W_T] ? first : last;
        for (int c = 0; c < 3; c++)
            pose[c] = held[HH_MANIP_W_X + c];
        return;
    }
    double tau, span;
    long i = segment(tr, f, n, t, &tau, &span);
    double s = minimum_jerk(tr, f) ? tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau)) : tau;
    const double *a = waypoint(tr, f, i);
    const double *b = waypoint(tr, f, i + 1);
    for (int c = HH_MANIP_W_X; c <= HH_MANIP_W_PHI; c++)
        pose[c - HH_MANIP_W_X] = a[c] + s * (b[c] - a[c]);
}

int hh_trajectory_moving(const hh_trajectories *tr, int f, double t)
{
    long n = waypoint_count(tr, f);
    if (t < waypoint(tr, f, 0)[HH_MANIP_W_T] || t >= waypoint(tr, f, n - 1)[HH_MANIP_W_T])
        return 0;
    double tau, span;
    long i = segment(tr, f, n, t, &tau, &span);
    double rate = minimum_jerk(tr, f) ? 30.0 * tau * tau * ((1.0 - tau) * (1.0 - tau)) : 1.0;
    double k = rate / span;
    const double *a = waypoint(tr, f, i);
    const double *b = waypoint(tr, f, i + 1);
    for (int c = HH_MANIP_W_X; c <= HH_MANIP_W_PHI; c++)
        if (k * (b[c] - a[c]) != 0.0)
            return 1;
    return 0;
}

/* Joint targets q (3) of finger f for its trajectory's pose at time t; 0 if unreachable. */
static int target_at(const hh_model *m, const double *params, const hh_trajectories *tr, int f, double t,
                     double q[3])
{
    double pose[3];
    hh_trajectory_sample(tr, f, t, pose);
    return hh_ik_near(m->fingers[f], params[HH_MANIP_P_REACH_RTOL], pose[0], pose[1], pose[2],
                      params + HH_MANIP_P_Q0 + 3 * f, q);
}

/* Joint position and velocity targets (9 each); HH_MANIP_OK or HH_MANIP_UNREACHABLE + f. */
static int reference(const hh_model *m, const double *params, const hh_trajectories *tr, double t, double *q_ref,
                     double *qd_ref)
{
    for (int j = 0; j < HH_JOINTS; j++) {
        q_ref[j] = params[HH_MANIP_P_Q0 + j];
        qd_ref[j] = 0.0;
    }
    double h = params[HH_MANIP_P_STEP];
    for (int f = 0; f < HH_FINGERS; f++) {
        if (waypoint_count(tr, f) == 0)
            continue;
        if (!target_at(m, params, tr, f, t, q_ref + 3 * f))
            return HH_MANIP_UNREACHABLE + f;
        if (hh_trajectory_moving(tr, f, t)) {
            double ahead[3], behind[3];
            if (!target_at(m, params, tr, f, t + h, ahead) || !target_at(m, params, tr, f, t - h, behind))
                return HH_MANIP_UNREACHABLE + f;
            for (int j = 0; j < 3; j++)
                qd_ref[3 * f + j] = (ahead[j] - behind[j]) / (2 * h);
        }
    }
    return HH_MANIP_OK;
}

/* The fingers' gravity torques (if enabled) plus J^T of the object's load shared by the
 * fingers carrying it (if enabled), into tau_ff (9). The load is the weight less what the
 * support carries: before the hand-over the fingers must not lift the object a second
 * time, which would load every contact tangentially while the grasp closes. */
static void feedforward(const hh_model *m, const double *params, const double *q, const double *fn,
                        const double *support, double *tau_ff)
{
    for (int j = 0; j < HH_JOINTS; j++)
        tau_ff[j] = 0.0;
    int gravity = params[HH_MANIP_P_GRAVITY_COMP] != 0.0;
    double threshold = params[HH_MANIP_P_THRESHOLD];
    int carrying = 0;
    if (params[HH_MANIP_P_LOAD_COMP] != 0.0)
        for (int f = 0; f < HH_FINGERS; f++)
            if (fn[f] > threshold)
                carrying += 1;
    if (!gravity && carrying == 0)
        return;
    static const double at_rest[3] = {0.0, 0.0, 0.0};
    double sx = 0.0, sy = 0.0; /* each carrying finger's share of the weight */
    if (carrying) {
        sx = -(params[HH_MANIP_P_WX] + support[0]) / carrying;
        sy = -(params[HH_MANIP_P_WY] + support[1]) / carrying;
    }
    for (int f = 0; f < HH_FINGERS; f++) {
        const double *finger = m->fingers[f];
        double u[3][2], pts[4][2];
        hh_finger_frames(finger, q + 3 * f, u, pts);
        if (gravity)
            hh_finger_bias(finger, (const double(*)[2])u, at_rest, params[HH_MANIP_P_GX], params[HH_MANIP_P_GY],
                           tau_ff + 3 * f);
        if (carrying && fn[f] > threshold) {
            double jac[2][3];
            hh_finger_point_jacobian((const double(*)[2])pts, pts[3][0], pts[3][1], jac);
            for (int j = 0; j < 3; j++)
                tau_ff[3 * f + j] += jac[0][j] * sx + jac[1][j] * sy;
        }
    }
}

int hh_manipulation_output(const hh_model *m, const double *params, const hh_trajectories *tr, double t,
                           const double *q, const double *qd, const double *fn, const double *support, double *out)
{
    double qd_ref[HH_JOINTS];
    double *q_ref = out + HH_MANIP_O_Q_REF;
    int code = reference(m, params, tr, t, q_ref, qd_ref);
    if (code != HH_MANIP_OK)
        return code;
    for (int j = 0; j < HH_JOINTS; j++)
        out[HH_MANIP_O_TAU_M + j] = params[HH_MANIP_P_KP + j] * (q_ref[j] - q[j]) +
                                     params[HH_MANIP_P_KD + j] * (qd_ref[j] - qd[j]);
    feedforward(m, params, q, fn, support, out + HH_MANIP_O_TAU_FF);
    return HH_MANIP_OK;
}
