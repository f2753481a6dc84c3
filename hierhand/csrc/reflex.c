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

/* x (3) solving (G W G^T) x = w for the grasp matrix G of k points about the point c and
 * the point weights W (NULL: all 1): G W G^T = [[K, 0, a], [0, K, b], [a, b, s]] (K = sum
 * w_i, a = -sum w_i r_iy, b = sum w_i r_ix, both round-off about the weighted centroid,
 * s = sum w_i |r_i|^2, r_i = p_i - c). When the moment row is numerically dependent (all
 * points coincide) it is dropped, as numpy.linalg.pinv drops it. */
static void grasp_solve(int k, const double *points, const double *weights, double cx, double cy, const double w[3],
                        double x[3])
{
    double a = 0.0, b = 0.0, s = 0.0, fk = 0.0;
    for (int i = 0; i < k; i++) {
        double rx = points[2 * i] - cx;
        double ry = points[2 * i + 1] - cy;
        double weight = weights == NULL ? 1.0 : weights[i];
        a -= weight * ry;
        b += weight * rx;
        s += weight * (rx * rx + ry * ry);
        fk += weight;
    }
    double schur = s - (a * a + b * b) / fk;
    x[2] = schur > PINV_RCOND_SQUARED * hh_max(fk, s) ? (w[2] - (a * w[0] + b * w[1]) / fk) / schur : 0.0;
    x[0] = (w[0] - a * x[2]) / fk;
    x[1] = (w[1] - b * x[2]) / fk;
}

/* out (k x 2) = base - G^T x for G about the centroid c (base NULL: zero). */
static void grasp_transpose(int k, const double *points, double cx, double cy, const double x[3],
                            const double *base, double *out)
{
    for (int i = 0; i < k; i++) {
        double rx = points[2 * i] - cx;
        double ry = points[2 * i + 1] - cy;
        double bx = base == NULL ? 0.0 : base[2 * i];
        double by = base == NULL ? 0.0 : base[2 * i + 1];
        out[2 * i] = bx - (x[0] - ry * x[2]);
        out[2 * i + 1] = by - (x[1] + rx * x[2]);
    }
}

void hh_project_internal(int k, const double *points, const double *f, double *out)
{
    double cx, cy;
    centroid(k, points, &cx, &cy);
    double w[3] = {0.0, 0.0, 0.0}; /* w = G f */
    for (int i = 0; i < k; i++) {
        w[0] += f[2 * i];
        w[1] += f[2 * i + 1];
        w[2] += (points[2 * i] - cx) * f[2 * i + 1] - (points[2 * i + 1] - cy) * f[2 * i];
    }
    double x[3];
    grasp_solve(k, points, NULL, cx, cy, w, x);
    grasp_transpose(k, points, cx, cy, x, f, out); /* internal = f - G^T x */
}

void hh_distribute_wrench(int k, const double *points, const double *weights, double ox, double oy, const double w[3],
                          double *f)
{
    double cx = 0.0, cy = 0.0, total = 0.0; /* the weighted centroid */
    for (int i = 0; i < k; i++) {
        cx += weights[i] * points[2 * i];
        cy += weights[i] * points[2 * i + 1];
        total += weights[i];
    }
    cx /= total;
    cy /= total;
    /* the moment about the centroid of the wrench given about (ox, oy) */
    double about_centroid[3] = {w[0], w[1], w[2] + (ox - cx) * w[1] - (oy - cy) * w[0]};
    double x[3], minus[3];
    grasp_solve(k, points, weights, cx, cy, about_centroid, x);
    for (int i = 0; i < 3; i++)
        minus[i] = -x[i];
    grasp_transpose(k, points, cx, cy, minus, NULL, f); /* G^T x */
    for (int i = 0; i < k; i++) { /* f = W G^T x */
        f[2 * i] *= weights[i];
        f[2 * i + 1] *= weights[i];
    }
}

/* Where finger i acts on the object: for a touching finger the contact point, its tip
 * centre plus the tip radius along the contact normal (internal forces are forces between
 * the contact points: between the tip centres, a tilted squeeze would turn the object); the
 * tip centre otherwise. */
static void acting_point(const double *params, const hh_reflex_inputs *in, const int touching[3], int i,
                         double point[2])
{
    double r = touching[i] ? params[HH_REFLEX_P_TIP_RADIUS + i] : 0.0;
    point[0] = in->tip[3 * i] + r * in->normal[2 * i];
    point[1] = in->tip[3 * i + 1] + r * in->normal[2 * i + 1];
}

/* The internal force at unit scale among the member fingers (largest row length 1) into g
 * (zero for the others): (I - G^+ G) push at their acting points, each member pushing
 * along its contact normal (toward the others' centroid while approaching), or the
 * centroid squeeze when that projection leaves some member not pushing. */
static int squeeze(const double *params, const hh_reflex_inputs *in, const int members[3], const int touching[3],
                   double g[3][2])
{
    double points[3][2], push[3][2], internal[3][2];
    int finger[3];
    int k = 0;
    for (int i = 0; i < 3; i++) {
        g[i][0] = 0.0;
        g[i][1] = 0.0;
        if (!members[i])
            continue;
        finger[k] = i;
        acting_point(params, in, touching, i, points[k]);
        if (touching[i]) {
            push[k][0] = in->normal[2 * i];
            push[k][1] = in->normal[2 * i + 1];
        } else {
            approach_push(in->tip, members, i, push[k]);
        }
        k += 1;
    }
    hh_project_internal(k, points[0], push[0], internal[0]);
    int pushing = 1;
    for (int j = 0; j < k; j++)
        if (internal[j][0] * push[j][0] + internal[j][1] * push[j][1] <= 0.0)
            pushing = 0;
    if (!pushing &&
        hh_centroid_squeeze(k, points[0], params[HH_REFLEX_P_COINCIDENT_RTOL], internal[0]) != HH_REFLEX_OK)
        return HH_REFLEX_COINCIDENT;
    double longest = 0.0;
    for (int j = 0; j < k; j++)
        longest = hh_max(longest, sqrt(internal[j][0] * internal[j][0] + internal[j][1] * internal[j][1]));
    for (int j = 0; j < k; j++) {
        g[finger[j]][0] = internal[j][0] / longest;
        g[finger[j]][1] = internal[j][1] / longest;
    }
    return HH_REFLEX_OK;
}

int hh_reflex_directions(const double *params, const double *state, const hh_reflex_inputs *in, double g[3][2],
                         int grasp[3], int touching[3])
{
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
    /* the squeeze is among the fingers touching when two or more do: a finger still
     * approaching does not touch the object, so its push is no part of the internal force
     * (counting it would unbalance the others' squeeze), and it approaches the touching
     * ones' centroid; with fewer touching, all of the grasp close on each other */
    int n_touching = touching[0] + touching[1] + touching[2];
    if (n_touching < 2)
        return squeeze(params, in, grasp, touching, g);
    for (int i = 0; i < 3; i++)
        if (grasp[i] && !touching[i])
            approach_push(in->tip, touching, i, g[i]);
    /* with three touching, a finger the reflex holds only in part (hold < 1: the
     * suppresser is taking it over) shares the squeeze in that part: the internal force
     * of all three, blended toward that of the other two (both internal, so the blend is) */
    int partly = -1;
    for (int i = 0; i < 3; i++)
        if (touching[i] && state[HH_REFLEX_S_HOLD + i] < 1.0 && (partly < 0 || state[HH_REFLEX_S_HOLD + i] <
                                                                                  state[HH_REFLEX_S_HOLD + partly]))
            partly = i;
    double all[3][2];
    int code = squeeze(params, in, touching, touching, all);
    if (code != HH_REFLEX_OK || n_touching < 3 || partly < 0) {
        for (int i = 0; i < 3; i++)
            if (touching[i]) {
                g[i][0] = all[i][0];
                g[i][1] = all[i][1];
            }
        return code;
    }
    int others[3] = {1, 1, 1};
    others[partly] = 0;
    double two[3][2];
    code = squeeze(params, in, others, touching, two);
    double hold = state[HH_REFLEX_S_HOLD + partly];
    for (int i = 0; i < 3; i++) {
        g[i][0] = hold * all[i][0] + (1.0 - hold) * two[i][0];
        g[i][1] = hold * all[i][1] + (1.0 - hold) * two[i][1];
    }
    return code;
}

void hh_reflex_forces(const double *params, const double *state, const double g[3][2], const int touching[3],
                      double f[3][2])
{
    for (int i = 0; i < 3; i++) {
        double length = sqrt(g[i][0] * g[i][0] + g[i][1] * g[i][1]);
        double scale = !touching[i] ? params[HH_REFLEX_P_APPROACH] / hh_max(length, SHORTEST_DIRECTION)
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
        double u[3][2], pts[4][2], jac[2][3], point[2];
        hh_finger_frames(m->fingers[i], q + 3 * i, u, pts);
        acting_point(params, in, touching, i, point);
        /* the point's offset from the tip centre as measured, carried to the tip at q */
        hh_finger_point_jacobian((const double(*)[2])pts, pts[3][0] + point[0] - in->tip[3 * i],
                                 pts[3][1] + point[1] - in->tip[3 * i + 1], jac);
        for (int j = 0; j < 3; j++)
            out[HH_REFLEX_O_TAU_G + 3 * i + j] = jac[0][j] * f[i][0] + jac[1][j] * f[i][1];
        out[HH_REFLEX_O_FORCE + i] = sqrt(f[i][0] * f[i][0] + f[i][1] * f[i][1]);
        out[HH_REFLEX_O_ACTIVE + i] = grasp[i] ? 1.0 : 0.0;
    }
    return HH_REFLEX_OK;
}

/* How much the reflex holds each finger (hold, 3): two fingers are the grasp, so the two
 * touching fingers the suppresser spares most (largest share) it holds whole, and makes up
 * with squeeze what the suppresser takes from them. Any other touching finger it holds by 1
 * while the suppresser lets through at least hold_share of its grasping torque (the
 * sigmoid at rest passes a little less than all of it), falling linearly to 0 as its share
 * falls to release_share: a contact whose command the sigmoid is switching off is not the
 * reflex's to correct. It drives the integrator by that much (counting it
 * whole would wind the shared scale up while voluntary motion pulls the finger off the
 * object: its |f_t| / f_n climbs as it lets go of its load), and shares the squeeze by that
 * much from the next hit on (hh_reflex_directions). A finger not touching keeps its hold. */
static void holds(const double *params, const double *state, const double *share, const int touching[3],
                  double hold[3])
{
    int kept[3] = {0, 0, 0};
    for (int n = 0; n < 2; n++) {
        int best = -1;
        for (int i = 0; i < 3; i++)
            if (touching[i] && !kept[i] && (best < 0 || (share != NULL && share[i] > share[best])))
                best = i;
        if (best >= 0)
            kept[best] = 1;
    }
    double release = params[HH_REFLEX_P_RELEASE_SHARE];
    double whole = params[HH_REFLEX_P_HOLD_SHARE];
    for (int i = 0; i < 3; i++) {
        if (!touching[i])
            hold[i] = state[HH_REFLEX_S_HOLD + i];
        else if (share == NULL || kept[i])
            hold[i] = 1.0;
        else /* release_share < hold_share, checked by the block */
            hold[i] = hh_min(hh_max((share[i] - release) / (whole - release), 0.0), 1.0);
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
    double scale = state[HH_REFLEX_S_SCALE];
    double weight[3];
    holds(params, state, params[HH_REFLEX_P_FOLLOW] != 0.0 ? in->share : NULL, touching, weight);
    int held = 0;
    double shortfall = -INFINITY;
    for (int i = 0; i < 3; i++)
        if (grasp[i] && touching[i]) {
            held += 1;
            if (weight[i] == 0.0) /* wholly handed over: not the reflex's to correct at all */
                continue;
            double gain = g[i][0] * in->normal[2 * i] + g[i][1] * in->normal[2 * i + 1]; /* per unit scale */
            double length = sqrt(g[i][0] * g[i][0] + g[i][1] * g[i][1]);
            double need = hh_max(params[HH_REFLEX_P_MIN_FORCE] * length, fabs(ft[i]) / params[HH_REFLEX_P_RATIO]);
            shortfall = hh_max(shortfall, weight[i] * (need - in->fn[i]) / hh_max(gain, SMALLEST_GAIN));
        }
    if (held >= 2)
        scale = hh_min(hh_max(scale + params[HH_REFLEX_P_KI] * dt * shortfall + params[HH_REFLEX_P_CATCH_UP] * hh_max(shortfall, 0.0), 0.0), params[HH_REFLEX_P_MAX_FORCE]);
    next[HH_REFLEX_S_SCALE] = scale;
    /* whether a finger was the reflex's or voluntary motion's when it last touched: a
     * finger that loses contact while the reflex holds it whole (a bounce) is pushed back,
     * one the reflex was letting go of (hold below 1: the suppresser was taking it over) is
     * left alone */
    for (int i = 0; i < 3; i++) {
        double handed = state[HH_REFLEX_S_HANDED + i];
        if (touching[i])
            handed = weight[i] < 1.0 ? 1.0 : 0.0;
        next[HH_REFLEX_S_HANDED + i] = handed;
        next[HH_REFLEX_S_HOLD + i] = weight[i];
    }
    return HH_REFLEX_OK;
}
