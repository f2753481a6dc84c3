/* Planar finger kinematics: link directions, joint points, point Jacobians.
 *
 * Joint angles are relative: link i of a finger points at base_angle + q1 + ... + qi
 * (counter-clockwise from +x). Link 3 ends at the fingertip-circle centre. Inline
 * functions, so the step, the controllers and the queries share one implementation.
 */
#ifndef HIERHAND_KINEMATICS_H
#define HIERHAND_KINEMATICS_H

#include <math.h>

#include "hand.h"

/* Fill the link directions u (3 x 2) and points pts (4 x 2: joints 1-3, tip centre) of
 * the finger with parameter row ``row`` at its joint angles q[0..2]; returns the
 * absolute angle of link 3. */
static inline double hh_finger_frames(const double *row, const double *q, double u[3][2], double pts[4][2])
{
    double th = row[HH_F_BASE_ANGLE];
    double x = row[HH_F_BASE_X];
    double y = row[HH_F_BASE_Y];
    for (int i = 0; i < 3; i++) {
        pts[i][0] = x;
        pts[i][1] = y;
        th += q[i];
        double c = cos(th);
        double s = sin(th);
        u[i][0] = c;
        u[i][1] = s;
        double length = row[HH_F_LINK0 + HH_F_LINK_STRIDE * i + HH_L_LENGTH];
        x += length * c;
        y += length * s;
    }
    pts[3][0] = x;
    pts[3][1] = y;
    return th;
}

/* Jacobian jac (2 x 3) of the link-3 point at (px, py): column j is z x (p - joint_j),
 * the velocity of the point per unit rate of joint j. */
static inline void hh_finger_point_jacobian(const double pts[4][2], double px, double py, double jac[2][3])
{
    for (int j = 0; j < 3; j++) {
        jac[0][j] = -(py - pts[j][1]);
        jac[1][j] = px - pts[j][0];
    }
}

#endif
