/* Penalty contact between a fingertip circle and the object's surface points.
 *
 * The paper's law, per object surface point inside a fingertip circle:
 *
 * - normal n: from the tip centre through the point; penetration d = r - |p - c| (the
 *   anchor's normal coordinate is the circle itself, which is rigid);
 *   f_n = k_n d + c_n d', clipped at 0 (no adhesion);
 * - tangent t = z x n; the anchor is the fingertip material point the surface point first
 *   touched, kept in the frame of link 3 so that it moves (and rolls) with the fingertip;
 *   f_t = -k_t e - c_t v_t with e = t . (p - anchor) and v_t the tangential velocity of the
 *   object point relative to the fingertip;
 * - stick while |f_t| < mu_s f_n; otherwise slip with f_t = mu_d f_n sign(f_t) and the
 *   anchor moved so the spring alone gives that slip force;
 * - a point that leaves the circle loses its anchor.
 *
 * f_n n + f_t t acts on the object at the point and its opposite on link 3 at the same
 * point, so every pair is equal and opposite with a common line of action.
 *
 * Only points that can lie in the circle are visited: per edge of the square, the tip
 * centre is projected on the edge line and only the points within the chord
 * |s_k - s| <= sqrt(r^2 - dist^2) are tested. The visited index range per edge (the
 * "window") is kept in the state, so that at the next commit the points of the previous
 * window that are no longer visited are released; points outside every window never hold
 * an anchor. Contact evaluation is a pure function of the state: anchor changes go to a
 * pending buffer and only hh_commit_anchors (part of an update) applies them, so the
 * forces reported at a hit and the forces that drive the step from it are identical.
 */
#ifndef HIERHAND_CONTACT_H
#define HIERHAND_CONTACT_H

#include "hand.h"

/* The fingertip of one finger and the object, as hh_finger_contact needs them. */
typedef struct hh_tip {
    double cx, cy; /* tip centre */
    double cphi, sphi; /* link-3 direction */
    double vcx, vcy; /* tip-centre velocity */
    double wphi; /* angular rate of link 3 */
    double radius;
} hh_tip;

typedef struct hh_object_motion {
    double ox, oy, co, so; /* pose: position, cos and sin of the angle */
    double ovx, ovy, ow; /* velocity */
} hh_object_motion;

/* Contact forces between finger f's tip and the object, from the state alone. Fills the
 * finger's new window (w->window[f]), the pending anchors and flags of the visited points
 * in window order, and w->wrench[f]. Returns HH_ERR_PENETRATION if the tip centre lies
 * inside the object (penetration deeper than the radius), else HH_OK. */
int hh_finger_contact(const hh_model *m, hh_work *w, const double *state, int f, const hh_tip *tip,
                      const hh_object_motion *obj);

/* Apply finger f's pending anchors: release its old window, write the new one. */
void hh_commit_anchors(const hh_model *m, const hh_work *w, double *state, int f);

#endif
