/* The hand vector: names of the hand-file numbers, their checks, and packing a hand into
 * the constant model the step reads.
 *
 * This is the one place where a hand's numbers are judged valid: HandPlant's hand-file
 * loader reports these problems under the file's field names, the FMU under its
 * parameter names.
 */
#include <math.h>
#include <stdio.h>

#include "hand.h"

enum { ANY = 0, POSITIVE = 1, NON_NEGATIVE = 2 };

typedef struct param_info {
    const char *name;
    const char *doc;
    int check;
} param_info;

#define LINK(f, l)                                                                                         \
    {"fingers[" #f "].links[" #l "].length", "link " #l " length: joint to the next joint or the tip centre [m]", \
     POSITIVE},                                                                                              \
    {"fingers[" #f "].links[" #l "].mass", "link " #l " mass [kg]", POSITIVE},                              \
    {"fingers[" #f "].links[" #l "].inertia", "link " #l " moment of inertia about its centre of mass [kg m^2]", \
     POSITIVE},                                                                                              \
    {"fingers[" #f "].links[" #l "].com[1]", "link " #l " centre of mass along the link [m]", ANY},        \
    {"fingers[" #f "].links[" #l "].com[2]", "link " #l " centre of mass across the link [m]", ANY}

#define FINGER(f)                                                                                    \
    {"fingers[" #f "].base[1]", "base joint x [m]", ANY},                                            \
    {"fingers[" #f "].base[2]", "base joint y [m]", ANY},                                            \
    {"fingers[" #f "].base_angle", "direction of link 1 at q1 = 0, counter-clockwise from +x [rad]", ANY}, \
    LINK(f, 1), LINK(f, 2), LINK(f, 3),                                                              \
    {"fingers[" #f "].damping[1]", "joint 1 viscous damping [N m s/rad]", NON_NEGATIVE},             \
    {"fingers[" #f "].damping[2]", "joint 2 viscous damping [N m s/rad]", NON_NEGATIVE},             \
    {"fingers[" #f "].damping[3]", "joint 3 viscous damping [N m s/rad]", NON_NEGATIVE},             \
    {"fingers[" #f "].armature[1]", "joint 1 reflected motor inertia [kg m^2]", NON_NEGATIVE},       \
    {"fingers[" #f "].armature[2]", "joint 2 reflected motor inertia [kg m^2]", NON_NEGATIVE},       \
    {"fingers[" #f "].armature[3]", "joint 3 reflected motor inertia [kg m^2]", NON_NEGATIVE},       \
    {"fingers[" #f "].tip_radius", "fingertip radius [m]", POSITIVE},                               \
    {"fingers[" #f "].q0[1]", "initial angle of joint 1 [rad]", ANY},                               \
    {"fingers[" #f "].q0[2]", "initial angle of joint 2, relative to link 1 [rad]", ANY},           \
    {"fingers[" #f "].q0[3]", "initial angle of joint 3, relative to link 2 [rad]", ANY}

static const param_info PARAMS[HH_HAND_PARAMS] = {
    {"gravity[1]", "gravity x [m/s^2]", ANY},
    {"gravity[2]", "gravity y [m/s^2]", ANY},
    {"object.mass", "object mass [kg]", POSITIVE},
    {"object.inertia", "object moment of inertia about its centre [kg m^2]", POSITIVE},
    {"object.size[1]", "object side length along its x axis [m]", POSITIVE},
    {"object.size[2]", "object side length along its y axis [m]", POSITIVE},
    {"object.pos[1]", "initial object x [m]", ANY},
    {"object.pos[2]", "initial object y [m]", ANY},
    {"object.angle", "initial object angle [rad]", ANY},
    {"object.surface_spacing", "spacing of the object's surface contact points [m]", POSITIVE},
    {"contact.k_n", "normal contact stiffness [N/m]", POSITIVE},
    {"contact.c_n", "normal contact damping [N s/m]", NON_NEGATIVE},
    {"contact.k_t", "tangential contact stiffness [N/m]", POSITIVE},
    {"contact.c_t", "tangential contact damping [N s/m]", NON_NEGATIVE},
    {"contact.mu_s", "static friction coefficient", NON_NEGATIVE},
    {"contact.mu_d", "dynamic (sliding) friction coefficient", NON_NEGATIVE},
    FINGER(1),
    FINGER(2),
    FINGER(3),
};

const char *hh_hand_param_name(int param)
{
    return param >= 0 && param < HH_HAND_PARAMS ? PARAMS[param].name : NULL;
}

const char *hh_hand_param_doc(int param)
{
    return param >= 0 && param < HH_HAND_PARAMS ? PARAMS[param].doc : NULL;
}

int hh_hand_param_at_least_zero(int param)
{
    return param >= 0 && param < HH_HAND_PARAMS && PARAMS[param].check != ANY;
}

static void report_problem(hh_report_fn report, void *context, int param, const char *text)
{
    if (report != NULL)
        report(context, param, text);
}

/* Per-number checks; returns the number of problems. */
static int check_numbers(const double *hand, hh_report_fn report, void *context)
{
    char text[160];
    int problems = 0;
    for (int i = 0; i < HH_HAND_PARAMS; i++) {
        double x = hand[i];
        const char *why = NULL;
        if (!isfinite(x))
            why = "must be finite, got %g";
        else if (PARAMS[i].check == POSITIVE && !(x > 0.0))
            why = "must be > 0, got %g";
        else if (PARAMS[i].check == NON_NEGATIVE && x < 0.0)
            why = "must be >= 0, got %g";
        if (why != NULL) {
            snprintf(text, sizeof text, why, x);
            report_problem(report, context, i, text);
            problems++;
        }
    }
    return problems;
}

/* Points per edge of length ``length``: round(length / spacing), at least 1, half to even. */
static double edge_points(double length, double spacing)
{
    double count = nearbyint(length / spacing);
    return count < 1.0 ? 1.0 : count;
}

/* Checks across numbers (only once each number is valid); returns the number of problems. */
static int check_together(const double *hand, hh_report_fn report, void *context)
{
    char text[200];
    int problems = 0;
    double a = hand[HH_P_OBJ_SIZE], b = hand[HH_P_OBJ_SIZE + 1], spacing = hand[HH_P_OBJ_SPACING];
    double smallest_side = a < b ? a : b;
    double smallest_tip = INFINITY;
    for (int f = 0; f < HH_FINGERS; f++) {
        double r = hand[HH_P_FINGER0 + f * HH_P_FINGER_STRIDE + HH_PF_TIP_RADIUS];
        if (r < smallest_tip)
            smallest_tip = r;
    }
    if (spacing > smallest_side / 4) {
        snprintf(text, sizeof text, "must be at most a quarter of the smallest side, got %g", spacing);
        report_problem(report, context, HH_P_OBJ_SPACING, text);
        problems++;
    } else if (spacing >= smallest_tip) {
        snprintf(text, sizeof text, "must be smaller than the smallest tip_radius (%g m), got %g", smallest_tip,
                 spacing);
        report_problem(report, context, HH_P_OBJ_SPACING, text);
        problems++;
    } else {
        double points = 2.0 * (edge_points(a, spacing) + edge_points(b, spacing));
        if (points > HH_MAX_POINTS) {
            snprintf(text, sizeof text, "gives %.0f surface points, more than the %d a model may have, got %g",
                     points, HH_MAX_POINTS, spacing);
            report_problem(report, context, HH_P_OBJ_SPACING, text);
            problems++;
        }
    }
    double mu_s = hand[HH_P_MU_S], mu_d = hand[HH_P_MU_D];
    if (mu_d > mu_s) {
        snprintf(text, sizeof text,
                 "must be <= contact.mu_s (a sliding contact cannot carry more), got %g > %g", mu_d, mu_s);
        report_problem(report, context, HH_P_MU_D, text);
        problems++;
    }
    return problems;
}

/* The square's four edges counter-clockwise from the bottom-left corner. Each edge of
 * length L gets round(L / surface_spacing) points, evenly spaced, so the spacing is as
 * close to the requested one as a whole number of points allows. */
static int pack_edges(hh_model *m, double a, double b, double spacing)
{
    const double corners[4][2] = {{-a / 2, -b / 2}, {a / 2, -b / 2}, {a / 2, b / 2}, {-a / 2, b / 2}};
    int start = 0;
    for (int e = 0; e < HH_EDGES; e++) {
        double x0 = corners[e][0], y0 = corners[e][1];
        double x1 = corners[(e + 1) % HH_EDGES][0], y1 = corners[(e + 1) % HH_EDGES][1];
        double length = hypot(x1 - x0, y1 - y0);
        double count = edge_points(length, spacing);
        double dx = (x1 - x0) / length, dy = (y1 - y0) / length;
        double *edge = m->edges[e];
        edge[HH_E_OX] = x0;
        edge[HH_E_OY] = y0;
        edge[HH_E_DX] = dx;
        edge[HH_E_DY] = dy;
        edge[HH_E_NX] = dy;
        edge[HH_E_NY] = -dx;
        edge[HH_E_SPACING] = length / count;
        edge[HH_E_COUNT] = count;
        edge[HH_E_START] = start;
        start += (int)count;
    }
    return start;
}

int hh_model_from_hand(hh_model *m, const double *hand, double dt, hh_report_fn report, void *context)
{
    int problems = check_numbers(hand, report, context);
    if (problems == 0)
        problems = check_together(hand, report, context);
    if (problems != 0)
        return problems;
    for (int f = 0; f < HH_FINGERS; f++) {
        const double *p = hand + HH_P_FINGER0 + f * HH_P_FINGER_STRIDE;
        double *row = m->fingers[f];
        for (int i = 0; i < HH_N_FINGER_PARAMS; i++)
            row[i] = 0.0;
        row[HH_F_BASE_X] = p[HH_PF_BASE];
        row[HH_F_BASE_Y] = p[HH_PF_BASE + 1];
        row[HH_F_BASE_ANGLE] = p[HH_PF_BASE_ANGLE];
        for (int i = 0; i < HH_LINKS; i++) {
            const double *link = p + HH_PF_LINK0 + HH_PF_LINK_STRIDE * i;
            double *out = row + HH_F_LINK0 + HH_F_LINK_STRIDE * i;
            out[HH_L_LENGTH] = link[HH_PL_LENGTH];
            out[HH_L_MASS] = link[HH_PL_MASS];
            out[HH_L_COM_ALONG] = link[HH_PL_COM_ALONG];
            out[HH_L_COM_ACROSS] = link[HH_PL_COM_ACROSS];
            out[HH_L_INERTIA] = link[HH_PL_INERTIA];
        }
        for (int j = 0; j < 3; j++) {
            row[HH_F_DAMPING + j] = p[HH_PF_DAMPING + j];
            row[HH_F_ARMATURE + j] = p[HH_PF_ARMATURE + j];
            m->q0[3 * f + j] = p[HH_PF_Q0 + j];
        }
        row[HH_F_TIP_RADIUS] = p[HH_PF_TIP_RADIUS];
    }
    double *body = m->body;
    body[HH_B_GX] = hand[HH_P_GX];
    body[HH_B_GY] = hand[HH_P_GY];
    body[HH_B_MASS] = hand[HH_P_OBJ_MASS];
    body[HH_B_INERTIA] = hand[HH_P_OBJ_INERTIA];
    body[HH_B_HALF_A] = hand[HH_P_OBJ_SIZE] / 2;
    body[HH_B_HALF_B] = hand[HH_P_OBJ_SIZE + 1] / 2;
    body[HH_B_K_N] = hand[HH_P_K_N];
    body[HH_B_C_N] = hand[HH_P_C_N];
    body[HH_B_K_T] = hand[HH_P_K_T];
    body[HH_B_C_T] = hand[HH_P_C_T];
    body[HH_B_MU_S] = hand[HH_P_MU_S];
    body[HH_B_MU_D] = hand[HH_P_MU_D];
    body[HH_B_DT] = dt;
    m->pose0[0] = hand[HH_P_OBJ_POS];
    m->pose0[1] = hand[HH_P_OBJ_POS + 1];
    m->pose0[2] = hand[HH_P_OBJ_ANGLE];
    m->npts = pack_edges(m, hand[HH_P_OBJ_SIZE], hand[HH_P_OBJ_SIZE + 1], hand[HH_P_OBJ_SPACING]);
    return 0;
}

double hh_plate_inertia(double mass, double a, double b)
{
    return mass * (pow(a, 2.0) + pow(b, 2.0)) / 12.0;
}

void hh_hand_of_segment(const double *segment, double *hand)
{
    for (int i = 0; i < HH_HAND_PARAMS; i++)
        hand[i] = segment[HH_SEG_HAND + i];
    if (segment[HH_SEG_FOLLOWS] != 0.0)
        hand[HH_P_OBJ_INERTIA] = hh_plate_inertia(hand[HH_P_OBJ_MASS], hand[HH_P_OBJ_SIZE], hand[HH_P_OBJ_SIZE + 1]);
}
