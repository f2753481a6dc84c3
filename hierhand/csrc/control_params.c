/* The controller blocks' parameters: their checks and the laws' parameter vectors packed
 * from them (control.h). The blocks (GraspReflex, ManipulationPD, Suppresser,
 * ObjectSupport) call these when they are made, and an exported FMU when it rebuilds
 * their kernels from its tunable parameters, so a value is refused by both in the same
 * words. Type checks (a number, not a string) stay with the Python blocks: an FMU's
 * parameters are always numbers. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "control.h"

void hh_number_text(double x, char *out, size_t size)
{
    if (isnan(x)) {
        snprintf(out, size, "nan");
        return;
    }
    if (isinf(x)) {
        snprintf(out, size, x > 0 ? "inf" : "-inf");
        return;
    }
    char text[40];
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, x);
        if (strtod(text, NULL) == x)
            break;
    }
    /* Python writes a whole number with ".0" and exponents from 1e16 with two digits */
    if (strpbrk(text, ".en") == NULL)
        strcat(text, ".0");
    snprintf(out, size, "%s", text);
}

static int refuse(char *message, size_t size, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(message, size, format, args);
    va_end(args);
    return 1;
}

/* Room for a number as hh_number_text writes it. */
#define NUMBER 40

static int not_finite(char *message, size_t size, const char *name, double x)
{
    char a[NUMBER];
    hh_number_text(x, a, sizeof a);
    return refuse(message, size, "parameter '%s' must be finite, got %s", name, a);
}

static double tip_radius(const double *hand, int f)
{
    return hand[HH_P_FINGER0 + f * HH_P_FINGER_STRIDE + HH_PF_TIP_RADIUS];
}

/* With friction_cap, a contact slides at |f_t| / f_n = mu_d: a safety ratio at or above it never
 * sees a sliding object, so the reflex keeps to at most this share of the hand's mu_d. */
#define HH_FRICTION_SHARE 0.9

static double reflex_safety_ratio(const double *g, const double *hand)
{
    double safety = g[HH_REFLEX_G_SAFETY_RATIO];
    if (g[HH_REFLEX_G_FRICTION_CAP] != 0.0 && HH_FRICTION_SHARE * hand[HH_P_MU_D] < safety)
        safety = HH_FRICTION_SHARE * hand[HH_P_MU_D];
    return safety;
}

/* With squeeze_from_weight, min_force is at least the normal force with which the fingers of
 * 'grasp' carry the object's weight by friction at the ratio target, m |g| / (k ratio_target)
 * (2.6 N for 0.3 kg in a two-finger pinch at 0.6 / 1.05), and at most max_force. */
static double reflex_min_force(const double *g, const double *hand, double ratio_target)
{
    double min_force = g[HH_REFLEX_G_MIN_FORCE];
    if (g[HH_REFLEX_G_SQUEEZE_FROM_WEIGHT] == 0.0)
        return min_force;
    int fingers = 0;
    for (int f = 0; f < HH_FINGERS; f++)
        fingers += g[HH_REFLEX_G_GRASP + f] != 0.0;
    double weight = hand[HH_P_OBJ_MASS] * hypot(hand[HH_P_GX], hand[HH_P_GY]);
    double share = weight / ((fingers > 0 ? fingers : 1) * ratio_target);
    if (share > min_force)
        min_force = share;
    return min_force < g[HH_REFLEX_G_MAX_FORCE] ? min_force : g[HH_REFLEX_G_MAX_FORCE];
}

int hh_reflex_pack(const double *g, const double *hand, double dt, double *p, char *message, size_t size)
{
    static const struct {
        int slot;
        const char *name;
    } positive[] = {{HH_REFLEX_G_KI, "ki"},
                    {HH_REFLEX_G_SAFETY_RATIO, "safety_ratio"},
                    {HH_REFLEX_G_MIN_FORCE, "min_force"},
                    {HH_REFLEX_G_MAX_FORCE, "max_force"},
                    {HH_REFLEX_G_THRESHOLD, "contact_threshold"}};
    for (size_t i = 0; i < sizeof positive / sizeof positive[0]; i++) {
        double x = g[positive[i].slot];
        if (!(isfinite(x) && x > 0)) {
            char a[NUMBER];
            hh_number_text(x, a, sizeof a);
            return refuse(message, size, "parameter '%s' must be a positive number, got %s", positive[i].name, a);
        }
    }
    double release = g[HH_REFLEX_G_RELEASE_SHARE], hold = g[HH_REFLEX_G_HOLD_SHARE];
    if (!(0 <= release && release < hold && hold <= 1)) {
        char a[NUMBER], b[NUMBER];
        hh_number_text(release, a, sizeof a);
        hh_number_text(hold, b, sizeof b);
        return refuse(message, size,
                      "parameters 'release_share' and 'hold_share' must satisfy 0 <= release_share < hold_share <= 1, "
                      "got %s and %s", a, b);
    }
    double margin = g[HH_REFLEX_G_MARGIN], max_force = g[HH_REFLEX_G_MAX_FORCE];
    if (!(0 <= margin && margin < 1)) {
        char a[NUMBER];
        hh_number_text(margin, a, sizeof a);
        return refuse(message, size, "parameter 'margin' must be in [0, 1), got %s", a);
    }
    if (!(0 <= g[HH_REFLEX_G_APPROACH] && g[HH_REFLEX_G_APPROACH] <= max_force))
        return refuse(message, size, "parameter 'approach_force' must be in [0, max_force]");
    if (g[HH_REFLEX_G_MIN_FORCE] > max_force)
        return refuse(message, size, "parameter 'min_force' must not exceed 'max_force'");
    if (!(0 <= g[HH_REFLEX_G_CATCH_UP] && g[HH_REFLEX_G_CATCH_UP] <= 1))
        return refuse(message, size, "parameter 'catch_up' must be in [0, 1]");
    p[HH_REFLEX_P_THRESHOLD] = g[HH_REFLEX_G_THRESHOLD];
    p[HH_REFLEX_P_APPROACH] = g[HH_REFLEX_G_APPROACH];
    p[HH_REFLEX_P_KI] = g[HH_REFLEX_G_KI];
    p[HH_REFLEX_P_DT] = dt;
    p[HH_REFLEX_P_RATIO] = reflex_safety_ratio(g, hand) / (1.0 + margin);
    p[HH_REFLEX_P_MIN_FORCE] = reflex_min_force(g, hand, p[HH_REFLEX_P_RATIO]);
    p[HH_REFLEX_P_MAX_FORCE] = max_force;
    for (int f = 0; f < HH_FINGERS; f++) {
        p[HH_REFLEX_P_INITIAL + f] = g[HH_REFLEX_G_GRASP + f] != 0.0 ? 1.0 : 0.0;
        p[HH_REFLEX_P_TIP_RADIUS + f] = tip_radius(hand, f);
    }
    p[HH_REFLEX_P_COINCIDENT_RTOL] = g[HH_REFLEX_G_COINCIDENT_RTOL];
    p[HH_REFLEX_P_RELEASE_SHARE] = release;
    p[HH_REFLEX_P_FOLLOW] = g[HH_REFLEX_G_FOLLOW] != 0.0 ? 1.0 : 0.0;
    p[HH_REFLEX_P_HOLD_SHARE] = hold;
    p[HH_REFLEX_P_CATCH_UP] = g[HH_REFLEX_G_CATCH_UP];
    return 0;
}

static double flag(double x)
{
    return x != 0.0 ? 1.0 : 0.0;
}

int hh_manip_pack(const double *g, const double *hand, double dt, double *p, char *message, size_t size)
{
    for (int i = 0; i < 2 * HH_JOINTS; i++)
        if (!isfinite(g[HH_MANIP_G_KP + i]))
            return not_finite(message, size, i < HH_JOINTS ? "kp" : "kd", g[HH_MANIP_G_KP + i]);
    for (int i = 0; i < 2 * HH_JOINTS; i++)
        if (g[HH_MANIP_G_KP + i] < 0)
            return refuse(message, size, "kp and kd must be non-negative");
    if (!isfinite(g[HH_MANIP_G_CONTACT_AIM]) || g[HH_MANIP_G_CONTACT_AIM] < 0)
        return refuse(message, size, "contact_aim must be a finite number >= 0 (0: aim fn / k_n deep)");
    for (int f = 0; f < HH_FINGERS; f++)
        for (int j = 0; j < 3; j++)
            p[HH_MANIP_P_Q0 + 3 * f + j] = hand[HH_P_FINGER0 + f * HH_P_FINGER_STRIDE + HH_PF_Q0 + j];
    for (int i = 0; i < HH_JOINTS; i++) {
        p[HH_MANIP_P_KP + i] = g[HH_MANIP_G_KP + i];
        p[HH_MANIP_P_KD + i] = g[HH_MANIP_G_KD + i];
    }
    double mass = hand[HH_P_OBJ_MASS];
    p[HH_MANIP_P_GX] = hand[HH_P_GX];
    p[HH_MANIP_P_GY] = hand[HH_P_GY];
    p[HH_MANIP_P_WX] = mass * hand[HH_P_GX];
    p[HH_MANIP_P_WY] = mass * hand[HH_P_GY];
    p[HH_MANIP_P_THRESHOLD] = g[HH_MANIP_G_THRESHOLD];
    p[HH_MANIP_P_GRAVITY_COMP] = flag(g[HH_MANIP_G_GRAVITY_COMP]);
    p[HH_MANIP_P_LOAD_COMP] = flag(g[HH_MANIP_G_LOAD_COMP]);
    p[HH_MANIP_P_STEP] = g[HH_MANIP_G_STEP];
    p[HH_MANIP_P_REACH_RTOL] = g[HH_MANIP_G_REACH_RTOL];
    p[HH_MANIP_P_DT] = dt;
    p[HH_MANIP_P_MATCHED] = flag(g[HH_MANIP_G_MATCHED]);
    p[HH_MANIP_P_CONTACT_COMP] = flag(g[HH_MANIP_G_CONTACT_COMP]);
    p[HH_MANIP_P_CONTACT_AIM] = g[HH_MANIP_G_CONTACT_AIM];
    return 0;
}

int hh_suppress_pack(const double *g, double period, double *p, char *message, size_t size)
{
    for (int i = 0; i < 2 * HH_JOINTS; i++)
        if (!isfinite(g[HH_SUPPRESS_G_S_A + i]))
            return not_finite(message, size, i < HH_JOINTS ? "S_a" : "S_b", g[HH_SUPPRESS_G_S_A + i]);
    for (int i = 0; i < HH_JOINTS; i++)
        if (g[HH_SUPPRESS_G_S_A + i] < 0) {
            char a[NUMBER];
            hh_number_text(g[HH_SUPPRESS_G_S_A + i], a, sizeof a);
            return refuse(message, size, "S_a must be >= 0, got %s (joint %d)", a, i + 1);
        }
    double mode = g[HH_SUPPRESS_G_MODE], tc = g[HH_SUPPRESS_G_TIME_CONSTANT];
    if (mode != HH_SUPPRESS_MAGNITUDE && mode != HH_SUPPRESS_SIGNED)
        return refuse(message, size, "mode must be magnitude (%d) or signed (%d), got code %g", HH_SUPPRESS_MAGNITUDE,
                      HH_SUPPRESS_SIGNED, mode);
    if (!(isfinite(tc) && tc >= 0)) {
        char a[NUMBER];
        hh_number_text(tc, a, sizeof a);
        return refuse(message, size, "parameter 'time_constant' must be a time >= 0 in seconds, got %s", a);
    }
    for (int i = 0; i < HH_JOINTS; i++) {
        p[HH_SUPPRESS_P_S_A + i] = g[HH_SUPPRESS_G_S_A + i];
        p[HH_SUPPRESS_P_S_B + i] = g[HH_SUPPRESS_G_S_B + i];
    }
    p[HH_SUPPRESS_P_MODE] = g[HH_SUPPRESS_G_ENABLED] != 0.0 ? mode : (double)HH_SUPPRESS_PASS;
    p[HH_SUPPRESS_P_ALPHA] = tc > 0 && period > 0 ? -expm1(-period / tc) : 1.0;
    return 0;
}

int hh_support_pack(double until, const double *hand, double *c, char *message, size_t size)
{
    if (!isfinite(until))
        return not_finite(message, size, "until", until);
    double mass = hand[HH_P_OBJ_MASS];
    c[HH_SUPPORT_C_FORCE] = 0.0 - mass * hand[HH_P_GX];
    c[HH_SUPPORT_C_FORCE + 1] = 0.0 - mass * hand[HH_P_GY];
    c[HH_SUPPORT_C_FORCE + 2] = 0.0;
    c[HH_SUPPORT_C_UNTIL] = until;
    return 0;
}
