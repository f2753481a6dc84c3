/* The manipulation controller's law (ManipulationPD): trajectories, IK, PD, feedforward.
 *
 * hh_manipulation_output does in one call what the block's output is: sample the
 * fingertip trajectories, turn the samples into joint targets by exact three-joint
 * inverse kinematics, differentiate those centrally in time for the velocity target,
 * track both with the joint PD, and add the gravity and load feedforward. The pieces
 * (hh_wrap_angle, hh_finger_ik, hh_ik_near, hh_trajectory_sample / _velocity) are the
 * Python API's too: inverse_kinematics.py and trajectory.py call them.
 */
#include <math.h>

#include "control.h"
#include "dynamics.h"
#include "float_ops.h"
#include "kinematics.h"

static const double PI = 3.14159265358979323846;
static const double TWO_PI = 2 * 3.14159265358979323846;

double hh_wrap_angle(double a)
{
    double w = PI - hh_floored_mod(PI - a, TWO_PI);
    if (w <= -PI) /* the modulo of a tiny negative number rounds to 2 pi */
        w += TWO_PI;
    return w;
}

void hh_finger_fk(const double *finger, const double q[3], double pose[3])
{
    double u[3][2], pts[4][2];
    pose[2] = hh_finger_frames(finger, q, u, pts);
    pose[0] = pts[3][0];
    pose[1] = pts[3][1];
}

static double link_length(const double *finger, int i)
{
    return finger[HH_F_LINK0 + HH_F_LINK_STRIDE * i + HH_L_LENGTH];
}

/* The wrist point (joint 3) of a tip target, seen from the finger base: its direction
 * ``toward`` and the size ``bend`` of the elbow angle q2 that reaches it. reach as
 * hh_finger_ik; 0 when out of reach. */
static int wrist(const double *finger, double reach_rtol, double x, double y, double phi, double reach[3],
                 double *toward, double *bend)
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
    reach[0] = r;
    reach[1] = r_min;
    reach[2] = r_max;
    if (!(r_min - tol <= r && r <= r_max + tol))
        return 0;
    double c2 = (r * r - l1 * l1 - l2 * l2) / (2 * l1 * l2);
    *bend = acos(hh_min(1.0, hh_max(-1.0, c2)));
    *toward = atan2(wy, wx);
    return 1;
}

/* Joint angles (wrapped) of the branch with elbow angle q2 for the wrist direction toward. */
static void branch(const double *finger, double phi, double toward, double q2, double q[3])
{
    double l1 = link_length(finger, 0);
    double l2 = link_length(finger, 1);
    double th1 = toward - atan2(l2 * sin(q2), l1 + l2 * cos(q2));
    q[0] = hh_wrap_angle(th1 - finger[HH_F_BASE_ANGLE]);
    q[1] = hh_wrap_angle(q2);
    q[2] = hh_wrap_angle(phi - th1 - q2);
}

int hh_finger_ik(const double *finger, double reach_rtol, double x, double y, double phi, int elbow, double q[3],
                 double reach[3])
{
    double toward, bend;
    if (!wrist(finger, reach_rtol, x, y, phi, reach, &toward, &bend))
        return 0;
    branch(finger, phi, toward, elbow > 0 ? bend : -bend, q);
    return 1;
}

int hh_ik_near(const double *finger, double reach_rtol, double x, double y, double phi, const double ref[3],
               double q[3], double reach[3])
{
    double toward, bend;
    if (!wrist(finger, reach_rtol, x, y, phi, reach, &toward, &bend))
        return 0;
    double best = 0.0;
    double best_step[3] = {0.0, 0.0, 0.0};
    for (int elbow = 0; elbow < 2; elbow++) {
        double angles[3];
        branch(finger, phi, toward, elbow == 0 ? bend : -bend, angles); /* elbow +1 first: it wins ties */
        double d0 = hh_wrap_angle(angles[0] - ref[0]);
        double d1 = hh_wrap_angle(angles[1] - ref[1]);
        double d2 = hh_wrap_angle(angles[2] - ref[2]);
        double dd = d0 * d0 + d1 * d1 + d2 * d2;
        if (elbow == 0 || dd < best) {
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

hh_trajectory hh_finger_trajectory(const hh_trajectories *tr, int f)
{
    const double *meta = tr->meta + f * HH_MANIP_N_META;
    hh_trajectory one = {
        .waypoints = tr->waypoints + (long)f * tr->capacity * HH_MANIP_W_COLS,
        .count = (long)meta[HH_MANIP_M_COUNT],
        .minimum_jerk = meta[HH_MANIP_M_INTERP] == HH_MANIP_INTERP_MINJERK,
    };
    return one;
}

/* Waypoint k of a trajectory. */
static const double *waypoint(const hh_trajectory *tr, long k)
{
    return tr->waypoints + k * HH_MANIP_W_COLS;
}

/* The segment of t (times[i] <= t < times[i+1], clamped to the first and last): its index,
 * normalised time tau in [0, 1] and span (searchsorted on the right). Needs two
 * waypoints or more. */
static long segment(const hh_trajectory *tr, double t, double *tau, double *span)
{
    long n = tr->count;
    long count = 0;
    while (count < n && waypoint(tr, count)[HH_MANIP_W_T] <= t)
        count += 1;
    long i = count - 1 > 0 ? count - 1 : 0;
    if (i > n - 2)
        i = n - 2;
    double t0 = waypoint(tr, i)[HH_MANIP_W_T];
    *span = waypoint(tr, i + 1)[HH_MANIP_W_T] - t0;
    *tau = (t - t0) / *span;
    return i;
}

/* NaN into the three values of v: the pose or velocity at a NaN time. */
static void not_a_time(double v[3])
{
    for (int c = 0; c < 3; c++)
        v[c] = NAN;
}

void hh_trajectory_sample(const hh_trajectory *tr, double t, double pose[3])
{
    const double *first = waypoint(tr, 0);
    const double *last = waypoint(tr, tr->count - 1);
    if (t <= first[HH_MANIP_W_T] || t >= last[HH_MANIP_W_T]) {
        const double *held = t <= first[HH_MANIP_W_T] ? first : last;
        for (int c = 0; c < 3; c++)
            pose[c] = held[HH_MANIP_W_X + c];
        return;
    }
    if (isnan(t)) {
        not_a_time(pose);
        return;
    }
    double tau, span;
    long i = segment(tr, t, &tau, &span);
    double s = tr->minimum_jerk ? tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau)) : tau;
    const double *a = waypoint(tr, i);
    const double *b = waypoint(tr, i + 1);
    for (int c = HH_MANIP_W_X; c <= HH_MANIP_W_PHI; c++)
        pose[c - HH_MANIP_W_X] = a[c] + s * (b[c] - a[c]);
}

void hh_trajectory_velocity(const hh_trajectory *tr, double t, double velocity[3])
{
    if (t < waypoint(tr, 0)[HH_MANIP_W_T] || t >= waypoint(tr, tr->count - 1)[HH_MANIP_W_T]) {
        for (int c = 0; c < 3; c++)
            velocity[c] = 0.0;
        return;
    }
    if (isnan(t)) {
        not_a_time(velocity);
        return;
    }
    double tau, span;
    long i = segment(tr, t, &tau, &span);
    double rate = tr->minimum_jerk ? 30.0 * tau * tau * ((1.0 - tau) * (1.0 - tau)) : 1.0;
    double k = rate / span;
    const double *a = waypoint(tr, i);
    const double *b = waypoint(tr, i + 1);
    for (int c = HH_MANIP_W_X; c <= HH_MANIP_W_PHI; c++)
        velocity[c - HH_MANIP_W_X] = k * (b[c] - a[c]);
}

/* 1 when the trajectory's velocity at t has a non-zero component, else 0. */
static int moving(const hh_trajectory *tr, double t)
{
    double velocity[3];
    hh_trajectory_velocity(tr, t, velocity);
    return velocity[0] != 0.0 || velocity[1] != 0.0 || velocity[2] != 0.0;
}

/* Joint targets q (3) of finger f for its trajectory's pose at time t; 0 if unreachable. */
static int target_at(const hh_model *m, const double *params, const hh_trajectory *tr, int f, double t, double q[3])
{
    double pose[3], reach[3];
    hh_trajectory_sample(tr, t, pose);
    return hh_ik_near(m->fingers[f], params[HH_MANIP_P_REACH_RTOL], pose[0], pose[1], pose[2],
                      params + HH_MANIP_P_Q0 + 3 * f, q, reach);
}

/* Joint position and velocity targets (9 each); HH_MANIP_OK or HH_MANIP_UNREACHABLE + f. */
static int reference(const hh_model *m, const double *params, const hh_trajectories *trajectories, double t,
                     double *q_ref, double *qd_ref)
{
    for (int j = 0; j < HH_JOINTS; j++) {
        q_ref[j] = params[HH_MANIP_P_Q0 + j];
        qd_ref[j] = 0.0;
    }
    double h = params[HH_MANIP_P_STEP];
    for (int f = 0; f < HH_FINGERS; f++) {
        hh_trajectory tr = hh_finger_trajectory(trajectories, f);
        if (tr.count == 0)
            continue;
        if (!target_at(m, params, &tr, f, t, q_ref + 3 * f))
            return HH_MANIP_UNREACHABLE + f;
        if (moving(&tr, t)) {
            double ahead[3], behind[3];
            if (!target_at(m, params, &tr, f, t + h, ahead) || !target_at(m, params, &tr, f, t - h, behind))
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
 * time, which would load every contact tangentially while the grasp closes. It is shared
 * by the grasp matrix at the contact points, so the shares balance its moment about the
 * object's centre too (an even split leaves the fingers of a tilted pinch to take up the
 * moment with posture errors, which turn the object), and in proportion to the normal
 * forces, what each contact can carry by friction: a finger that is letting go sheds its
 * load as its normal force falls, instead of being pushed along the face by it. */
static void feedforward(const hh_model *m, const double *params, const hh_manip_inputs *in, double *tau_ff)
{
    for (int j = 0; j < HH_JOINTS; j++)
        tau_ff[j] = 0.0;
    int gravity = params[HH_MANIP_P_GRAVITY_COMP] != 0.0;
    double threshold = params[HH_MANIP_P_THRESHOLD];
    int carrying[HH_FINGERS];
    double points[HH_FINGERS][2], shares[HH_FINGERS][2], weights[HH_FINGERS];
    int k = 0;
    for (int f = 0; f < HH_FINGERS; f++) {
        double u[3][2], pts[4][2];
        hh_finger_frames(m->fingers[f], in->q + 3 * f, u, pts);
        carrying[f] = params[HH_MANIP_P_LOAD_COMP] != 0.0 && in->fn[f] > threshold;
        if (carrying[f]) {
            double radius = m->fingers[f][HH_F_TIP_RADIUS];
            points[k][0] = pts[3][0] + radius * in->normal[2 * f];
            points[k][1] = pts[3][1] + radius * in->normal[2 * f + 1];
            weights[k] = in->fn[f];
            k += 1;
        }
    }
    if (k > 0) {
        double load[3] = {-(params[HH_MANIP_P_WX] + in->support[0]), -(params[HH_MANIP_P_WY] + in->support[1]),
                          -in->support[2]};
        hh_distribute_wrench(k, points[0], weights, in->obj[0], in->obj[1], load, shares[0]);
    }
    static const double at_rest[3] = {0.0, 0.0, 0.0};
    int c = 0;
    for (int f = 0; f < HH_FINGERS; f++) {
        const double *finger = m->fingers[f];
        double u[3][2], pts[4][2];
        hh_finger_frames(finger, in->q + 3 * f, u, pts);
        if (gravity)
            hh_finger_bias(finger, (const double(*)[2])u, at_rest, params[HH_MANIP_P_GX], params[HH_MANIP_P_GY],
                           tau_ff + 3 * f);
        if (carrying[f]) {
            double jac[2][3];
            hh_finger_point_jacobian((const double(*)[2])pts, points[c][0], points[c][1], jac);
            for (int j = 0; j < 3; j++)
                tau_ff[3 * f + j] += jac[0][j] * shares[c][0] + jac[1][j] * shares[c][1];
            c += 1;
        }
    }
}

void hh_matched_gains(double inertia, double kp, double kd, double period, double *kp_t, double *kd_t)
{
    double rate = kd / (2.0 * inertia); /* the poles s = -rate +- sqrt(rate^2 - kp / J) */
    double discriminant = rate * rate - kp / inertia;
    double root = sqrt(fabs(discriminant));
    double sum = discriminant >= 0.0 ? exp((root - rate) * period) + exp(-(root + rate) * period)
                                     : 2.0 * exp(-rate * period) * cos(root * period);
    double product = exp(-2.0 * rate * period);
    *kp_t = inertia * (1.0 - sum + product) / (period * period);
    *kd_t = inertia * (3.0 - sum - product) / (2.0 * period);
}

/* The PD torque tau_m (9) toward q_ref, qd_ref: per joint the gains of hh_matched_gains
 * for its own inertia, or kp and kd as they are. */
static void pd_torque(const hh_model *m, const double *params, const double *q, const double *qd,
                      const double *q_ref, const double *qd_ref, double *tau_m)
{
    int matched = params[HH_MANIP_P_MATCHED] != 0.0;
    for (int f = 0; f < HH_FINGERS; f++) {
        double mass[3][3];
        if (matched) {
            double u[3][2], pts[4][2];
            hh_finger_frames(m->fingers[f], q + 3 * f, u, pts);
            hh_finger_mass_matrix(m->fingers[f], (const double(*)[2])u, mass);
        }
        for (int i = 0; i < 3; i++) {
            int j = 3 * f + i;
            double kp = params[HH_MANIP_P_KP + j];
            double kd = params[HH_MANIP_P_KD + j];
            if (matched)
                hh_matched_gains(mass[i][i], kp, kd, params[HH_MANIP_P_DT], &kp, &kd);
            tau_m[j] = kp * (q_ref[j] - q[j]) + kd * (qd_ref[j] - qd[j]);
        }
    }
}

/* How deep a fingertip of radius r sits in a flat face of the object when it presses with
 * normal force fn: the contact law sums k_n times each surface point's depth, and the points
 * (spacing s: the perimeter over their number) under a circle pressed delta deep lie
 * within sqrt(2 r delta) of its centre, delta - x^2 / (2 r) deep, so
 * fn / k_n = (4 / 3) delta^(3/2) sqrt(2 r) / s. */
static double contact_depth(const hh_model *m, int f, double fn)
{
    double spacing = 4.0 * (m->body[HH_B_HALF_A] + m->body[HH_B_HALF_B]) / (m->npts > 0 ? m->npts : 1);
    double summed = fn / m->body[HH_B_K_N];
    return pow(0.75 * spacing * summed / sqrt(2.0 * m->fingers[f][HH_F_TIP_RADIUS]), 2.0 / 3.0);
}

/* Moves the joint targets q_ref (9) of each finger in contact so that its tip centre sits
 * deeper along the contact normal: CONTACT_AIM times the depth at which the contact law holds
 * it at the measured normal force (contact_depth), or with CONTACT_AIM 0, fn / k_n (the summed
 * depth of the points under the tip, several times its own). A planned fingertip pose lies
 * on the object's surface; a tip that squeezes sits inside it, and a PD aimed at the surface
 * would push back against the squeeze. A shifted target out of reach leaves the finger's
 * target as it was. */
static void contact_offset(const hh_model *m, const double *params, const hh_manip_inputs *in, double *q_ref)
{
    if (params[HH_MANIP_P_CONTACT_COMP] == 0.0)
        return;
    for (int f = 0; f < HH_FINGERS; f++) {
        if (!(in->fn[f] > params[HH_MANIP_P_THRESHOLD]))
            continue;
        double aim = params[HH_MANIP_P_CONTACT_AIM];
        double depth = aim > 0.0 ? aim * contact_depth(m, f, in->fn[f]) : in->fn[f] / m->body[HH_B_K_N];
        double pose[3], q[3], reach[3];
        hh_finger_fk(m->fingers[f], q_ref + 3 * f, pose);
        if (hh_ik_near(m->fingers[f], params[HH_MANIP_P_REACH_RTOL], pose[0] + depth * in->normal[2 * f],
                       pose[1] + depth * in->normal[2 * f + 1], pose[2], q_ref + 3 * f, q, reach))
            for (int j = 0; j < 3; j++)
                q_ref[3 * f + j] = q[j];
    }
}

int hh_manipulation_output(const hh_model *m, const double *params, const hh_trajectories *tr, double t,
                           const hh_manip_inputs *in, double *out)
{
    if (params[HH_MANIP_P_MATCHED] != 0.0 && !(params[HH_MANIP_P_DT] > 0.0))
        return HH_MANIP_NO_PERIOD;
    double qd_ref[HH_JOINTS];
    double *q_ref = out + HH_MANIP_O_Q_REF;
    int code = reference(m, params, tr, t, q_ref, qd_ref);
    if (code != HH_MANIP_OK)
        return code;
    contact_offset(m, params, in, q_ref);
    pd_torque(m, params, in->q, in->qd, q_ref, qd_ref, out + HH_MANIP_O_TAU_M);
    feedforward(m, params, in, out + HH_MANIP_O_TAU_FF);
    return HH_MANIP_OK;
}
