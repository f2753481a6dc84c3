/* Finger dynamics: recursive Newton-Euler for M(q) and h(q, qd).
 *
 * Each finger is a planar serial chain on a fixed base, so the hand's 9 x 9 mass matrix is
 * block-diagonal. hh_rnea returns the joint torques that produce given joint
 * accelerations; the mass matrix comes from it column by column (zero velocity and
 * gravity, unit acceleration), the bias from zero acceleration. Gravity enters as an
 * upward acceleration of the base. Armature (reflected motor inertia) adds to M's
 * diagonal, joint viscous damping to h, so that tau = M qdd + h for a finger without
 * contact.
 */
#ifndef HIERHAND_DYNAMICS_H
#define HIERHAND_DYNAMICS_H

#include "hand.h"

/* Vector from joint i to the COM of link i; returns the link's length. */
static inline double hh_com_offset(const double *row, const double u[3][2], int i, double *rcx, double *rcy)
{
    int k = HH_F_LINK0 + HH_F_LINK_STRIDE * i;
    double ux = u[i][0];
    double uy = u[i][1];
    double along = row[k + HH_L_COM_ALONG];
    double across = row[k + HH_L_COM_ACROSS];
    *rcx = along * ux - across * uy;
    *rcy = along * uy + across * ux;
    return row[k + HH_L_LENGTH];
}

/* Acceleration of link i's COM (ac) and of the next joint (a, updated in place), given
 * joint i's acceleration a, the link's angular rate w and angular acceleration al. */
static inline void hh_rnea_forward(const double *row, const double u[3][2], int i, double *ax, double *ay,
                                   double w, double al, double *acx, double *acy)
{
    double rcx, rcy;
    double length = hh_com_offset(row, u, i, &rcx, &rcy);
    double w2 = w * w;
    double lx = length * u[i][0];
    double ly = length * u[i][1];
    *acx = *ax - al * rcy - w2 * rcx;
    *acy = *ay + al * rcx - w2 * rcy;
    double nx = *ax - al * ly - w2 * lx;
    double ny = *ay + al * lx - w2 * ly;
    *ax = nx;
    *ay = ny;
}

/* Force (fx, fy, updated in place) and moment about joint i (returned) that link i
 * receives from its parent, given what it passes to its child (fx, fy, n). */
static inline double hh_rnea_backward(const double *row, const double u[3][2], int i, double acx, double acy,
                                      double al, double *fx, double *fy, double n)
{
    double rcx, rcy;
    double length = hh_com_offset(row, u, i, &rcx, &rcy);
    int k = HH_F_LINK0 + HH_F_LINK_STRIDE * i;
    double m = row[k + HH_L_MASS];
    double mx = m * acx;
    double my = m * acy;
    double lx = length * u[i][0];
    double ly = length * u[i][1];
    n = row[k + HH_L_INERTIA] * al + (rcx * my - rcy * mx) + (lx * *fy - ly * *fx) + n;
    *fx = mx + *fx;
    *fy = my + *fy;
    return n;
}

/* Joint torques tau (3) of one finger's rigid links, without armature or damping, at
 * joint rates qd and accelerations qdd, gravity (gx, gy). Angular rates and accelerations
 * of link i are the sums over joints 1..i. */
static inline void hh_rnea(const double *row, const double u[3][2], const double qd[3], const double qdd[3],
                           double gx, double gy, double tau[3])
{
    double w0 = qd[0];
    double w1 = w0 + qd[1];
    double w2 = w1 + qd[2];
    double al0 = qdd[0];
    double al1 = al0 + qdd[1];
    double al2 = al1 + qdd[2];
    double ax = -gx, ay = -gy;
    double acx0, acy0, acx1, acy1, acx2, acy2;
    hh_rnea_forward(row, u, 0, &ax, &ay, w0, al0, &acx0, &acy0);
    hh_rnea_forward(row, u, 1, &ax, &ay, w1, al1, &acx1, &acy1);
    hh_rnea_forward(row, u, 2, &ax, &ay, w2, al2, &acx2, &acy2);
    double fx = 0.0, fy = 0.0;
    double n2 = hh_rnea_backward(row, u, 2, acx2, acy2, al2, &fx, &fy, 0.0);
    double n1 = hh_rnea_backward(row, u, 1, acx1, acy1, al1, &fx, &fy, n2);
    double n0 = hh_rnea_backward(row, u, 0, acx0, acy0, al0, &fx, &fy, n1);
    tau[0] = n0;
    tau[1] = n1;
    tau[2] = n2;
}

/* The finger's mass matrix m (3 x 3) including armature. */
static inline void hh_finger_mass_matrix(const double *row, const double u[3][2], double m[3][3])
{
    static const double zero[3] = {0.0, 0.0, 0.0};
    for (int j = 0; j < 3; j++) {
        double a[3] = {0.0, 0.0, 0.0};
        double c[3];
        a[j] = 1.0;
        hh_rnea(row, u, zero, a, 0.0, 0.0, c);
        m[0][j] = c[0];
        m[1][j] = c[1];
        m[2][j] = c[2];
    }
    for (int j = 0; j < 3; j++)
        m[j][j] += row[HH_F_ARMATURE + j];
}

/* Coriolis/centrifugal + gravity + joint viscous damping torques h (3). */
static inline void hh_finger_bias(const double *row, const double u[3][2], const double qd[3], double gx,
                                  double gy, double h[3])
{
    static const double zero[3] = {0.0, 0.0, 0.0};
    hh_rnea(row, u, qd, zero, gx, gy, h);
    for (int j = 0; j < 3; j++)
        h[j] = h[j] + row[HH_F_DAMPING + j] * qd[j];
}

/* Solve m x = b for a symmetric positive definite 3 x 3 m (lower part read): adjugate
 * over determinant, one division, no square roots. The finger mass matrices are well
 * conditioned (the armature bounds their smallest eigenvalue from below). */
static inline void hh_solve_spd3(const double m[3][3], const double b[3], double x[3])
{
    double a = m[0][0];
    double bb = m[1][0];
    double c = m[2][0];
    double d = m[1][1];
    double e = m[2][1];
    double f = m[2][2];
    double ca = d * f - e * e;
    double cb = c * e - bb * f;
    double cc = bb * e - c * d;
    double cd = a * f - c * c;
    double ce = bb * c - a * e;
    double cf = a * d - bb * bb;
    double inv = 1.0 / (a * ca + bb * cb + c * cc);
    x[0] = (ca * b[0] + cb * b[1] + cc * b[2]) * inv;
    x[1] = (cb * b[0] + cd * b[1] + ce * b[2]) * inv;
    x[2] = (cc * b[0] + ce * b[1] + cf * b[2]) * inv;
}

#endif
