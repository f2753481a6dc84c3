/* The paper's penalty contact with anchors and stick/slip (see contact.h). */
#include "contact.h"

#include <math.h>

int hh_finger_contact(const hh_model *m, hh_work *w, const double *state, int f, const hh_tip *tip,
                      const hh_object_motion *obj)
{
    const double *body = m->body;
    const int npts = m->npts;
    double *wrench = w->wrench[f];
    for (int i = 0; i < HH_N_WRENCH; i++)
        wrench[i] = 0.0;
    const double cx = tip->cx, cy = tip->cy, cphi = tip->cphi, sphi = tip->sphi;
    const double vcx = tip->vcx, vcy = tip->vcy, wphi = tip->wphi, radius = tip->radius;
    const double ox = obj->ox, oy = obj->oy, co = obj->co, so = obj->so;
    const double ovx = obj->ovx, ovy = obj->ovy, ow = obj->ow;
    double dx = cx - ox;
    double dy = cy - oy;
    double lx = co * dx + so * dy;
    double ly = -so * dx + co * dy;
    if (fabs(lx) < body[HH_B_HALF_A] && fabs(ly) < body[HH_B_HALF_B])
        return HH_ERR_PENETRATION;
    const double k_n = body[HH_B_K_N];
    const double c_n = body[HH_B_C_N];
    const double k_t = body[HH_B_K_T];
    const double c_t = body[HH_B_C_T];
    const double mu_s = body[HH_B_MU_S];
    const double mu_d = body[HH_B_MU_D];
    const double r2 = radius * radius;
    const double *touch = state + HH_S_TOUCH + (size_t)f * npts;
    const double *anchor = state + HH_S_TOUCH + 3 * (size_t)npts + 2 * (size_t)f * npts;
    double *pend_anchor = w->pend_anchor + 2 * (size_t)f * npts;
    unsigned char *pend_flag = w->pend_flag + (size_t)f * npts;
    long j = 0;
    for (int e = 0; e < HH_EDGES; e++) {
        const double *edge = m->edges[e];
        w->window[f][e][0] = 0;
        w->window[f][e][1] = -1;
        double ex = edge[HH_E_OX];
        double ey = edge[HH_E_OY];
        double edx = edge[HH_E_DX];
        double edy = edge[HH_E_DY];
        double rx = lx - ex;
        double ry = ly - ey;
        double dist = rx * edge[HH_E_NX] + ry * edge[HH_E_NY];
        if (dist >= radius || dist <= -radius)
            continue;
        double h = edge[HH_E_SPACING];
        double s = rx * edx + ry * edy;
        double half = sqrt(r2 - dist * dist);
        double first = ceil((s - half) / h);
        double final = floor((s + half) / h);
        double last = edge[HH_E_COUNT] - 1.0;
        if (first < 0.0)
            first = 0.0;
        if (final > last)
            final = last;
        if (!(first <= final))
            continue;
        long lo = (long)first;
        long hi = (long)final;
        w->window[f][e][0] = lo;
        w->window[f][e][1] = hi;
        long start = (long)edge[HH_E_START];
        for (long k = lo; k <= hi; k++) {
            long idx = start + k;
            double plx = ex + ((double)k * h) * edx;
            double ply = ey + ((double)k * h) * edy;
            double px = ox + co * plx - so * ply;
            double py = oy + so * plx + co * ply;
            double relx = px - cx;
            double rely = py - cy;
            double d2 = relx * relx + rely * rely;
            if (d2 >= r2) {
                pend_flag[j] = 0;
                j++;
                continue;
            }
            double rho = sqrt(d2);
            if (rho <= 1e-12 * radius)
                return HH_ERR_PENETRATION;
            double nx = relx / rho;
            double ny = rely / rho;
            double tx = -ny;
            double ty = nx;
            /* velocity of the object point relative to the fingertip material point at p */
            double vrx = (ovx - ow * (py - oy)) - (vcx - wphi * rely);
            double vry = (ovy + ow * (px - ox)) - (vcy + wphi * relx);
            double fn = k_n * (radius - rho) - c_n * (nx * vrx + ny * vry);
            if (fn < 0.0)
                fn = 0.0;
            int held = touch[idx] != 0.0;
            double alx, aly, awx, awy;
            if (held) {
                alx = anchor[2 * idx];
                aly = anchor[2 * idx + 1];
                awx = cx + cphi * alx - sphi * aly;
                awy = cy + sphi * alx + cphi * aly;
            } else {
                alx = 0.0;
                aly = 0.0;
                awx = px;
                awy = py;
            }
            double stretch = tx * (px - awx) + ty * (py - awy);
            double ft = -k_t * stretch - c_t * (tx * vrx + ty * vry);
            if (fabs(ft) < mu_s * fn) {
                if (!held) {
                    alx = cphi * relx + sphi * rely;
                    aly = -sphi * relx + cphi * rely;
                }
            } else {
                if (ft > 0.0)
                    ft = mu_d * fn;
                else if (ft < 0.0)
                    ft = -mu_d * fn;
                awx = px + (ft / k_t) * tx - cx;
                awy = py + (ft / k_t) * ty - cy;
                alx = cphi * awx + sphi * awy;
                aly = -sphi * awx + cphi * awy;
            }
            pend_anchor[2 * j] = alx;
            pend_anchor[2 * j + 1] = aly;
            pend_flag[j] = 1;
            j++;
            double fx = fn * nx + ft * tx;
            double fy = fn * ny + ft * ty;
            wrench[HH_W_OBJ_FX] += fx;
            wrench[HH_W_OBJ_FY] += fy;
            wrench[HH_W_OBJ_M] += (px - ox) * fy - (py - oy) * fx;
            wrench[HH_W_TIP_M] += relx * fy - rely * fx;
            wrench[HH_W_FN] += fn;
            wrench[HH_W_FT] += ft;
            wrench[HH_W_FN_PX] += fn * px;
            wrench[HH_W_FN_PY] += fn * py;
        }
    }
    return HH_OK;
}

void hh_commit_anchors(const hh_model *m, const hh_work *w, double *state, int f)
{
    const int npts = m->npts;
    double *touch = state + HH_S_TOUCH + (size_t)f * npts;
    double *anchor = state + HH_S_TOUCH + 3 * (size_t)npts + 2 * (size_t)f * npts;
    const double *pend_anchor = w->pend_anchor + 2 * (size_t)f * npts;
    const unsigned char *pend_flag = w->pend_flag + (size_t)f * npts;
    for (int e = 0; e < HH_EDGES; e++) {
        const double *win = state + HH_S_WINDOW + 8 * f + 2 * e;
        long start = (long)m->edges[e][HH_E_START];
        double last = m->edges[e][HH_E_COUNT] - 1.0;
        /* clamped, so that a state that was not made by the step cannot write elsewhere */
        long lo = win[0] > 0.0 ? (long)(win[0] < last ? win[0] : last) : 0;
        long hi = win[1] >= 0.0 ? (long)(win[1] < last ? win[1] : last) : -1;
        for (long k = lo; k <= hi; k++)
            touch[start + k] = 0.0;
    }
    long j = 0;
    for (int e = 0; e < HH_EDGES; e++) {
        double *win = state + HH_S_WINDOW + 8 * f + 2 * e;
        long start = (long)m->edges[e][HH_E_START];
        long lo = w->window[f][e][0];
        long hi = w->window[f][e][1];
        win[0] = (double)lo;
        win[1] = (double)hi;
        for (long k = lo; k <= hi; k++) {
            long idx = start + k;
            if (pend_flag[j] != 0) {
                touch[idx] = 1.0;
                anchor[2 * idx] = pend_anchor[2 * j];
                anchor[2 * idx + 1] = pend_anchor[2 * j + 1];
            }
            j++;
        }
    }
}
