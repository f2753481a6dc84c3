/* The plant's step: contact evaluation, semi-implicit Euler, output rows.
 *
 * One step from state k: evaluate the kinematics and contact forces of state k (a pure
 * function of the state), commit the anchor changes, then integrate velocity first and
 * position with the new velocity (semi-implicit, or symplectic, Euler):
 *
 *     qd += dt * M(q)^-1 (tau + J^T f_contact - h(q, qd));   q += dt * qd
 *
 * and likewise for the object. Why not explicit Euler (the paper's "Euler's method"):
 * explicit Euler adds energy to every undamped oscillation, so a penalty contact needs
 * heavy damping to stay stable above about 1e4 N/m; semi-implicit Euler keeps
 * oscillators' energy bounded and stays stable up to about 3e5 N/m at 0.1 ms, at the same
 * cost.
 *
 * hh_advance runs n steps and the output rows after each. The evaluation of state k+1
 * gives both the outputs after step k and the forces of step k+1, so it is done once;
 * hh_step and hh_output call the very same functions, so n updates each followed by an
 * output give bit-identical results.
 */
#include <math.h>
#include <stdlib.h>

#include "blocks_kernel.h"
#include "contact.h"
#include "dynamics.h"
#include "hand.h"
#include "kinematics.h"

size_t hh_state_size(const hh_model *m)
{
    return HH_S_TOUCH + 9 * (size_t)m->npts;
}

void hh_initial_state(const hh_model *m, double *state)
{
    size_t n = hh_state_size(m);
    for (size_t i = 0; i < n; i++)
        state[i] = 0.0;
    for (int i = 0; i < HH_JOINTS; i++)
        state[HH_S_Q + i] = m->q0[i];
    for (int i = 0; i < 3; i++)
        state[HH_S_OBJ + i] = m->pose0[i];
    for (int i = 0; i < HH_FINGERS * HH_EDGES; i++)
        state[HH_S_WINDOW + 2 * i + 1] = -1.0;
}

int hh_work_init(hh_work *w, int npts)
{
    size_t n = npts > 0 ? (size_t)npts : 1;
    w->npts = npts;
    w->pend_anchor = malloc(sizeof(double) * 2 * HH_FINGERS * n);
    w->pend_flag = malloc(HH_FINGERS * n);
    if (w->pend_anchor == NULL || w->pend_flag == NULL) {
        hh_work_free(w);
        return -1;
    }
    return 0;
}

void hh_work_free(hh_work *w)
{
    free(w->pend_anchor);
    free(w->pend_flag);
    w->pend_anchor = NULL;
    w->pend_flag = NULL;
}

/* Kinematics and contact forces of ``state`` into the work; HH_OK or the code, with the
 * finger in *which. */
static int evaluate(const hh_model *m, hh_work *w, const double *state, int *which)
{
    hh_object_motion obj;
    obj.ox = state[HH_S_OBJ];
    obj.oy = state[HH_S_OBJ + 1];
    double th = state[HH_S_OBJ + 2];
    obj.co = cos(th);
    obj.so = sin(th);
    obj.ovx = state[HH_S_OBJ_VEL];
    obj.ovy = state[HH_S_OBJ_VEL + 1];
    obj.ow = state[HH_S_OBJ_VEL + 2];
    for (int f = 0; f < HH_FINGERS; f++) {
        const double *row = m->fingers[f];
        double phi = hh_finger_frames(row, state + HH_S_Q + 3 * f, w->u[f], w->pts[f]);
        double cx = w->pts[f][3][0];
        double cy = w->pts[f][3][1];
        double(*jac)[3] = w->jac[f];
        hh_finger_point_jacobian((const double(*)[2])w->pts[f], cx, cy, jac);
        double qd0 = state[HH_S_QD + 3 * f];
        double qd1 = state[HH_S_QD + 3 * f + 1];
        double qd2 = state[HH_S_QD + 3 * f + 2];
        hh_tip tip;
        tip.cx = cx;
        tip.cy = cy;
        tip.cphi = w->u[f][2][0];
        tip.sphi = w->u[f][2][1];
        tip.vcx = jac[0][0] * qd0 + jac[0][1] * qd1 + jac[0][2] * qd2;
        tip.vcy = jac[1][0] * qd0 + jac[1][1] * qd1 + jac[1][2] * qd2;
        tip.wphi = qd0 + qd1 + qd2;
        tip.radius = row[HH_F_TIP_RADIUS];
        w->tip[f][0] = cx;
        w->tip[f][1] = cy;
        w->tip[f][2] = phi;
        int code = hh_finger_contact(m, w, state, f, &tip, &obj);
        if (code != HH_OK) {
            *which = f;
            return code;
        }
        /* the finger gets minus the force on the object, and minus its moment about c */
        double fx = w->wrench[f][HH_W_OBJ_FX];
        double fy = w->wrench[f][HH_W_OBJ_FY];
        double mc = w->wrench[f][HH_W_TIP_M];
        for (int j = 0; j < 3; j++)
            w->gen[3 * f + j] = -(jac[0][j] * fx + jac[1][j] * fy) - mc;
    }
    return HH_OK;
}

static void commit(const hh_model *m, const hh_work *w, double *state)
{
    for (int f = 0; f < HH_FINGERS; f++)
        hh_commit_anchors(m, w, state, f);
}

/* Semi-implicit Euler step of fingers and object with the evaluated contact forces. */
static void integrate(const hh_model *m, hh_work *w, double *state, const double *tau, const double *f_ext)
{
    const double *body = m->body;
    double dt = body[HH_B_DT];
    double gx = body[HH_B_GX];
    double gy = body[HH_B_GY];
    for (int f = 0; f < HH_FINGERS; f++) {
        const double *row = m->fingers[f];
        int iq = HH_S_Q + 3 * f;
        int iv = HH_S_QD + 3 * f;
        double qd[3] = {state[iv], state[iv + 1], state[iv + 2]};
        double h[3], rhs[3], a[3];
        hh_finger_mass_matrix(row, (const double(*)[2])w->u[f], w->mass);
        hh_finger_bias(row, (const double(*)[2])w->u[f], qd, gx, gy, h);
        for (int j = 0; j < 3; j++)
            rhs[j] = tau[3 * f + j] + w->gen[3 * f + j] - h[j];
        hh_solve_spd3((const double(*)[3])w->mass, rhs, a);
        for (int j = 0; j < 3; j++) {
            qd[j] += dt * a[j];
            state[iv + j] = qd[j];
        }
        for (int j = 0; j < 3; j++)
            state[iq + j] += dt * qd[j];
    }
    double fx = f_ext[0];
    double fy = f_ext[1];
    double mz = f_ext[2];
    for (int f = 0; f < HH_FINGERS; f++) {
        fx += w->wrench[f][HH_W_OBJ_FX];
        fy += w->wrench[f][HH_W_OBJ_FY];
        mz += w->wrench[f][HH_W_OBJ_M];
    }
    double vx = state[HH_S_OBJ_VEL] + dt * (fx / body[HH_B_MASS] + gx);
    double vy = state[HH_S_OBJ_VEL + 1] + dt * (fy / body[HH_B_MASS] + gy);
    double wz = state[HH_S_OBJ_VEL + 2] + dt * (mz / body[HH_B_INERTIA]);
    state[HH_S_OBJ_VEL] = vx;
    state[HH_S_OBJ_VEL + 1] = vy;
    state[HH_S_OBJ_VEL + 2] = wz;
    state[HH_S_OBJ] += dt * vx;
    state[HH_S_OBJ + 1] += dt * vy;
    state[HH_S_OBJ + 2] += dt * wz;
}

static int first_non_finite(const double *x, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i]))
            return i;
    return -1;
}

/* The first non-finite quantity of the rigid-body state (HH_S_Q to HH_S_WINDOW, looked over
 * at once first). Velocities first: a blow-up shows in them one step before it reaches the
 * positions. */
BLK_VECTORISED static int check_state(const double *state, int *which)
{
    static const int order[4][3] = {
        {HH_S_QD, 9, HH_ERR_QD}, {HH_S_Q, 9, HH_ERR_Q}, {HH_S_OBJ_VEL, 3, HH_ERR_OBJ_VEL}, {HH_S_OBJ, 3, HH_ERR_OBJ}};
    if (blk_all_finite(state + HH_S_Q, HH_S_WINDOW - HH_S_Q))
        return HH_OK;
    for (int k = 0; k < 4; k++) {
        int i = first_non_finite(state + order[k][0], order[k][1]);
        if (i >= 0) {
            *which = i;
            return order[k][2];
        }
    }
    return HH_OK;
}

static int check_inputs(const double *tau, const double *f_ext, int *which)
{
    int i = first_non_finite(tau, 9);
    if (i >= 0) {
        *which = i;
        return HH_ERR_TAU;
    }
    i = first_non_finite(f_ext, 3);
    if (i >= 0) {
        *which = i;
        return HH_ERR_F_EXT;
    }
    return HH_OK;
}

static void write_outputs(const hh_work *w, const double *state, double *row)
{
    for (int i = 0; i < 9; i++) {
        row[HH_O_Q + i] = state[HH_S_Q + i];
        row[HH_O_QD + i] = state[HH_S_QD + i];
    }
    for (int f = 0; f < HH_FINGERS; f++) {
        row[HH_O_TIP + 3 * f] = w->tip[f][0];
        row[HH_O_TIP + 3 * f + 1] = w->tip[f][1];
        row[HH_O_TIP + 3 * f + 2] = w->tip[f][2];
        double fn = w->wrench[f][HH_W_FN];
        double ft = w->wrench[f][HH_W_FT];
        row[HH_O_FN + f] = fn;
        row[HH_O_FT + f] = ft;
        row[HH_O_NORMAL + 2 * f] = 0.0;
        row[HH_O_NORMAL + 2 * f + 1] = 0.0;
        if (fn > 0.0) {
            row[HH_O_RATIO + f] = fabs(ft) / fn;
            row[HH_O_CONTACT + f] = 1.0;
            double nx = w->wrench[f][HH_W_FN_PX] / fn - w->tip[f][0];
            double ny = w->wrench[f][HH_W_FN_PY] / fn - w->tip[f][1];
            double length = sqrt(nx * nx + ny * ny);
            if (length > 0.0) {
                row[HH_O_NORMAL + 2 * f] = nx / length;
                row[HH_O_NORMAL + 2 * f + 1] = ny / length;
            }
        } else {
            row[HH_O_RATIO + f] = 0.0;
            row[HH_O_CONTACT + f] = 0.0;
        }
    }
    for (int i = 0; i < 3; i++) {
        row[HH_O_OBJ + i] = state[HH_S_OBJ + i];
        row[HH_O_OBJ_VEL + i] = state[HH_S_OBJ_VEL + i];
    }
}

/* Check the inputs and the state and evaluate the contacts before the first update. */
static int start_steps(const hh_model *m, hh_work *w, const double *state, const double *tau,
                       const double *f_ext, int *which)
{
    int code = check_inputs(tau, f_ext, which);
    if (code == HH_OK)
        code = check_state(state, which);
    if (code == HH_OK)
        code = evaluate(m, w, state, which);
    return code;
}

int hh_step(const hh_model *m, hh_work *w, double *state, const double *tau, const double *f_ext, int *done,
            int *which)
{
    *done = 0;
    *which = 0;
    int code = start_steps(m, w, state, tau, f_ext, which);
    if (code != HH_OK)
        return code;
    commit(m, w, state);
    integrate(m, w, state, tau, f_ext);
    *done = 1;
    return check_state(state, which);
}

int hh_advance(const hh_model *m, hh_work *w, double *state, const double *tau, const double *f_ext, long n,
               double *rows, ptrdiff_t row_stride, long *done, int *which)
{
    *done = 0;
    *which = 0;
    int code = start_steps(m, w, state, tau, f_ext, which);
    if (code != HH_OK)
        return code;
    for (long i = 0; i < n; i++) {
        commit(m, w, state);
        integrate(m, w, state, tau, f_ext);
        *done = i + 1;
        code = check_state(state, which);
        if (code == HH_OK)
            code = evaluate(m, w, state, which);
        if (code != HH_OK)
            return code;
        write_outputs(w, state, rows + i * row_stride);
    }
    return HH_OK;
}

int hh_output(const hh_model *m, hh_work *w, const double *state, double *row, int *which)
{
    *which = 0;
    int code = check_state(state, which);
    if (code == HH_OK)
        code = evaluate(m, w, state, which);
    if (code == HH_OK)
        write_outputs(w, state, row);
    return code;
}

int hh_contact(const hh_model *m, hh_work *w, const double *state, int *which)
{
    *which = 0;
    return evaluate(m, w, state, which);
}

/* -- queries: the kinematics and dynamics the step uses, for callers outside it ---------- */

void hh_frames(const hh_model *m, const double *q, double *u, double *pts, double *phi)
{
    for (int f = 0; f < HH_FINGERS; f++)
        phi[f] = hh_finger_frames(m->fingers[f], q + 3 * f, (double(*)[2])(u + 6 * f),
                                  (double(*)[2])(pts + 8 * f));
}

void hh_point_jacobian(const hh_model *m, const double *q, int f, double px, double py, double *jac)
{
    double u[3][2], pts[4][2];
    hh_finger_frames(m->fingers[f], q + 3 * f, u, pts);
    hh_finger_point_jacobian((const double(*)[2])pts, px, py, (double(*)[3])jac);
}

void hh_mass_matrix(const hh_model *m, const double *q, double *mass)
{
    for (int i = 0; i < HH_JOINTS * HH_JOINTS; i++)
        mass[i] = 0.0;
    for (int f = 0; f < HH_FINGERS; f++) {
        double u[3][2], pts[4][2], block[3][3];
        hh_finger_frames(m->fingers[f], q + 3 * f, u, pts);
        hh_finger_mass_matrix(m->fingers[f], (const double(*)[2])u, block);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                mass[(3 * f + i) * HH_JOINTS + 3 * f + j] = block[i][j];
    }
}

void hh_bias(const hh_model *m, const double *q, const double *qd, double *bias)
{
    for (int f = 0; f < HH_FINGERS; f++) {
        double u[3][2], pts[4][2];
        hh_finger_frames(m->fingers[f], q + 3 * f, u, pts);
        hh_finger_bias(m->fingers[f], (const double(*)[2])u, qd + 3 * f, m->body[HH_B_GX], m->body[HH_B_GY],
                       bias + 3 * f);
    }
}
