/* The grasping reflex's law (GraspReflex): directions, forces, output, update.
 *
 * The reflex runs every millisecond, so a hit does the grasp matrix solve by hand rather
 * than through a pseudo-inverse. The internal force among the k fingers of the grasp (2
 * or 3) is (I - G^+ G) push, with G the 3 x 2k grasp matrix about the grasp points'
 * centroid c (columns [I2; (-r_iy, r_ix)], r_i = p_i - c). G has full row rank unless all
 * points coincide, so G^+ G push = G^T x with (G G^T) x = G push, and
 * G G^T = [[k, 0, a], [0, k, b], [a, b, s]] (a = -sum r_iy, b = sum r_ix, both round-off
 * about the centroid, s = sum |r_i|^2) is solved by eliminating the two k pivots first.
 * When the moment row is numerically dependent (Schur complement at or below
 * numpy.linalg.pinv's cut-off) the moment equation is dropped, as pinv does.
 *
 * The projection and the centroid squeeze work on any k points (hh_project_internal,
 * hh_centroid_squeeze); internal_forces.py calls them for its project_internal and
 * internal_directions. The tip Jacobians are the plant's (kinematics.h).
 */
#include <float.h>
#include <math.h>

#include "control.h"
#include "float_ops.h"
#include "kinematics.h"

/* numpy.linalg.pinv's rcond (1e-15 on the singular values of G) squared: the cut-off on
 * the eigenvalues of G G^T. */
static const double PINV_RCOND_SQUARED = 1e-30;
/* Shortest distance toward the others' centroid that an approaching finger normalises. */
static const double SHORTEST_APPROACH = 1e-12;
/* Smallest normal force per unit scale the update divides by. */
static const double SMALLEST_GAIN = 1e-3;
/* Shortest direction an approaching finger's force is scaled up from. */
static const double SHORTEST_DIRECTION = 1e-300;

/* Unit push of a finger approaching the others: toward their centroid. */
static void approach_push(const double *tip, const int grasp[3], int i, double push[2])
{
    double sx = 0.0;
    double sy = 0.0;
    int m = 0;
    for (int j = 0; j < 3; j++)
        if (j != i && grasp[j]) {
            sx += tip[3 * j];
            sy += tip[3 * j + 1];
            m += 1;
        }
    double tx = sx / m - tip[3 * i];
    double ty = sy / m - tip[3 * i + 1];
    double d = hh_max(sqrt(tx * tx + ty * ty), SHORTEST_APPROACH);
    push[0] = tx / d;
    push[1] = ty / d;
}

/* The centroid (cx, cy) of k points (k x 2). */
static void centroid(int k, const double *points, double *cx, double *cy)
{
    *cx = 0.0;
    *cy = 0.0;
    for (int i = 0; i < k; i++) {
        *cx += points[2 * i];
        *cy += points[2 * i + 1];
    }
    *cx /= k;
    *cy /= k;
}

int hh_centroid_squeeze(int k, const double *points, double coincident_rtol, double *g)
{
    double cx, cy;
    centroid(k, points, &cx, &cy);
    double spread = 0.0;
    double size = 0.0;
    for (int i = 0; i < k; i++) {
        g[2 * i] = cx - points[2 * i];
        g[2 * i + 1] = cy - points[2 * i + 1];
        spread = hh_max(spread, hypot(g[2 * i], g[2 * i + 1]));
        size = hh_max(hh_max(size, fabs(points[2 * i])), fabs(points[2 * i + 1]));
    }
    if (spread <= coincident_rtol * hh_max(size, DBL_MIN))
        return HH_REFLEX_COINCIDENT;
    for (int i = 0; i < 2 * k; i++)
        g[i] /= spread;
    return HH_REFLEX_OK;
}

void hh_project_internal(int k, const double *points, const double *f, double *out)
{
    double cx, cy;
    centroid(k, points, &cx, &cy);
    /* w = G f, and G G^T = [[k, 0, a], [0, k, b], [a, b, s]] */
    double w0 = 0.0, w1 = 0.0, w2 = 0.0;
    double a = 0.0, b = 0.0, s = 0.0;
    for (int i = 0; i < k; i++) {
        double rx = points[2 * i] - cx;
        double ry = points[2 * i + 1] - cy;
        w0 += f[2 * i];
        w1 += f[2 * i + 1];
        w2 += rx * f[2 * i + 1] - ry * f[2 * i];
        a -= ry;
        b += rx;
        s += rx * rx + ry * ry;
    }
    double fk = (double)k;
    double schur = s - (a * a + b * b) / fk;
    /* all points coinciding leave the moment row empty: pinv drops it */
    double x2 = schur > PINV_RCOND_SQUARED * hh_max(fk, s) ? (w2 - (a * w0 + b * w1) / fk) / schur : 0.0;
    double x0 = (w0 - a * x2) / fk;
    double x1 = (w1 - b * x2) / fk;
    /* internal = f - G^T x */
    for (int i = 0; i < k; i++) {
        double rx = points[2 * i] - cx;
        double ry = points[2 * i + 1] - cy;
        out[2 * i] = f[2 * i] - (x0 - ry * x2);
        out[2 * i + 1] = f[2 * i + 1] - (x1 + rx * x2);
    }
}

int hh_reflex_directions(const double *params, const double *state, const hh_reflex_inputs *in, double g[3][2],
                         int grasp[3], int touching[3])
{
    const double *tip = in->tip;
    double threshold = params[HH_REFLEX_P_THRESHOLD];
    int k = 0;
    for (int i = 0; i < 3; i++) {
        touching[i] = in->fn[i] > threshold;
        int approaching =
            params[HH_REFLEX_P_INITIAL + i] != 0.0 && state[HH_REFLEX_S_HANDED + i] == 0.0 && !touching[i];
        grasp[i] = touching[i] || approaching;
        g[i][0] = 0.0;
        g[i][1] = 0.0;
        if (grasp[i])
            k += 1;
    }
    if (k < 2)
        return HH_REFLEX_OK;
    /* the grasp's points and pushes, in finger order: the contact normal, or toward the
     * others' centroid while approaching */
    double points[3][2], push[3][2], internal[3][2];
    int finger[3];
    int m = 0;
    for (int i = 0; i < 3; i++) {
        if (!grasp[i])
            continue;
        finger[m] = i;
        points[m][0] = tip[3 * i];
        points[m][1] = tip[3 * i + 1];
        if (touching[i]) {
            push[m][0] = in->normal[2 * i];
            push[m][1] = in->normal[2 * i + 1];
        } else {
            approach_push(tip, grasp, i, push[m]);
        }
        m += 1;
    }
    hh_project_internal(k, points[0], push[0], internal[0]);
    /* the centroid squeeze instead if a finger would not push */
    int pushing = 1;
    for (int j = 0; j < k; j++)
        if (internal[j][0] * push[j][0] + internal[j][1] * push[j][1] <= 0.0)
            pushing = 0;
    if (!pushing &&
        hh_centroid_squeeze(k, points[0], params[HH_REFLEX_P_COINCIDENT_RTOL], internal[0]) != HH_REFLEX_OK)
        return HH_REFLEX_COINCIDENT;
    for (int j = 0; j < k; j++) {
        g[finger[j]][0] = internal[j][0];
        g[finger[j]][1] = internal[j][1];
    }
    double longest = 0.0;
    for (int i = 0; i < 3; i++)
        longest = hh_max(longest, sqrt(g[i][0] * g[i][0] + g[i][1] * g[i][1]));
    for (int i = 0; i < 3; i++) {
        g[i][0] /= longest;
        g[i][1] /= longest;
    }
    return HH_REFLEX_OK;
}

void hh_reflex_forces(const double *params, const double *state, const double g[3][2], const int touching[3],
                      double f[3][2])
{
    for (int i = 0; i < 3; i++) {
        double length = sqrt(g[i][0] * g[i][0] + g[i][1] * g[i][1]);
        double handed = state[HH_REFLEX_S_HANDED + i];
        double scale = !touching[i] ? params[HH_REFLEX_P_APPROACH] / hh_max(length, SHORTEST_DIRECTION)
                       : handed > 0.0 ? hh_min(state[HH_REFLEX_S_SCALE], handed)
                                      : state[HH_REFLEX_S_SCALE];
        f[i][0] = g[i][0] * scale;
        f[i][1] = g[i][1] * scale;
    }
}

int hh_reflex_output(const hh_model *m, const double *params, const double *state, const hh_reflex_inputs *in,
                     const double *q, double *out)
{
    double g[3][2], f[3][2];
    int grasp[3], touching[3];
    int code = hh_reflex_directions(params, state, in, g, grasp, touching);
    if (code != HH_REFLEX_OK)
        return code;
    hh_reflex_forces(params, state, (const double(*)[2])g, touching, f);
    for (int i = 0; i < 3; i++) {
        double u[3][2], pts[4][2], jac[2][3];
        hh_finger_frames(m->fingers[i], q + 3 * i, u, pts);
        hh_finger_point_jacobian((const double(*)[2])pts, pts[3][0], pts[3][1], jac);
        for (int j = 0; j < 3; j++)
            out[HH_REFLEX_O_TAU + 3 * i + j] = jac[0][j] * f[i][0] + jac[1][j] * f[i][1];
        out[HH_REFLEX_O_FORCE + i] = sqrt(f[i][0] * f[i][0] + f[i][1] * f[i][1]);
        out[HH_REFLEX_O_ACTIVE + i] = grasp[i] ? 1.0 : 0.0;
    }
    return HH_REFLEX_OK;
}

/* The fingers the suppresser has handed to voluntary motion: among those held (in the
 * grasp and touching), a finger whose command keeps less than release_share of its
 * grasping torque, least share first, as long as two fingers stay held. Its contact force
 * is no longer the reflex's to restore; counting it would wind the shared scale up while
 * the finger is pulled off. Two fingers always stay with the reflex: they are the grasp
 * (a pinch whose posture PD resists the squeeze keeps only about 0.9 of its torque). */
static void hand_over(const double *params, const double *share, const int grasp[3], const int touching[3],
                      int released[3])
{
    int held = 0;
    for (int i = 0; i < 3; i++) {
        released[i] = 0;
        held += grasp[i] && touching[i];
    }
    if (share == NULL)
        return;
    while (held > 2) {
        int least = -1;
        for (int i = 0; i < 3; i++)
            if (grasp[i] && touching[i] && !released[i] && share[i] < params[HH_REFLEX_P_RELEASE_SHARE] &&
                (least < 0 || share[i] < share[least]))
                least = i;
        if (least < 0)
            return;
        released[least] = 1;
        held -= 1;
    }
}

int hh_reflex_update(const double *params, const double *state, const hh_reflex_inputs *in, const double *ft,
                     double *next)
{
    double dt = params[HH_REFLEX_P_DT];
    if (!(dt > 0.0))
        return HH_REFLEX_NO_PERIOD;
    double g[3][2];
    int grasp[3], touching[3];
    int code = hh_reflex_directions(params, state, in, g, grasp, touching);
    if (code != HH_REFLEX_OK)
        return code;
    int released[3];
    hand_over(params, in->share, grasp, touching, released);
    double scale = state[HH_REFLEX_S_SCALE];
    int held = 0;
    double shortfall = -INFINITY;
    for (int i = 0; i < 3; i++)
        if (grasp[i] && touching[i] && !released[i]) {
            held += 1;
            double gain = g[i][0] * in->normal[2 * i] + g[i][1] * in->normal[2 * i + 1]; /* per unit scale */
            double length = sqrt(g[i][0] * g[i][0] + g[i][1] * g[i][1]);
            double need = hh_max(params[HH_REFLEX_P_MIN_FORCE] * length, fabs(ft[i]) / params[HH_REFLEX_P_RATIO]);
            shortfall = hh_max(shortfall, (need - in->fn[i]) / hh_max(gain, SMALLEST_GAIN));
        }
    if (held >= 2)
        scale = hh_min(hh_max(scale + params[HH_REFLEX_P_KI] * dt * shortfall, 0.0), params[HH_REFLEX_P_MAX_FORCE]);
    next[HH_REFLEX_S_SCALE] = scale;
    /* whether a finger was the reflex's or voluntary motion's when it last touched: a
     * finger that loses contact while the reflex holds it (a bounce) is pushed back, one
     * that voluntary motion took off is left alone. A finger handed over keeps at most the
     * squeeze it had then: the squeeze the others need as they take its load over must not
     * press it back onto the object */
    for (int i = 0; i < 3; i++) {
        double handed = state[HH_REFLEX_S_HANDED + i];
        if (touching[i])
            handed = !released[i] ? 0.0 : handed > 0.0 ? handed : hh_max(state[HH_REFLEX_S_SCALE], DBL_MIN);
        next[HH_REFLEX_S_HANDED + i] = handed;
    }
    return HH_REFLEX_OK;
}
