/* The slots of every flat array that the hand's C code shares with Python, declared once.
 *
 * An array's layout is a table of slots SLOT(P, NAME, WIDTH), in order: slot NAME holds WIDTH
 * doubles, and its offset is the sum of the widths before it. From each table the
 * preprocessor makes
 *   - the C enum (HH_LAYOUT_ENUM): P##NAME = its offset, and the array's size, so the C
 *     code indexes with HH_REFLEX_P_KI, HH_S_QD, ...;
 *   - the binding's table (python/py_layouts.c), which hierhand._native.LAYOUTS gives
 *     Python by the array's name: hierhand.layouts.REFLEX_PARAMS.KI is HH_REFLEX_P_KI.
 * Nothing else lists a slot, so the C names, the Python names and the sizes cannot
 * disagree. A slot of width 0 marks where a part of variable length starts (the plant
 * state's per-point arrays, a trajectory's waypoints).
 *
 * Codes are declared the same way (a code of width 3 takes three values: one per finger).
 * Each kernel type's record (the numbers its context is built from, kernel_types.h) is a
 * layout too, listed in HH_RECORDS with the table of its kernel type and the Python block
 * class that writes it; that list is also the list of the hand's kernel types and of its
 * block types. The input ports a kernel reads (inputs[i]) are lists too (HH_INPUT_PORTS),
 * from which the blocks take their inputs. So a new block type is its own .c file, its
 * Python block file and its lines here; docs/tutorials/c-kernel-block.md walks through one.
 */
#ifndef HIERHAND_LAYOUTS_H
#define HIERHAND_LAYOUTS_H

/* -- the generators ------------------------------------------------------------------------
 * HH_LAYOUT_ENUM(P, SLOTS, SIZE): the enum of a table, P##NAME for each slot and SIZE, the
 * array's length. Each slot also gets a helper P##NAME##_LAST_ (its last index), from
 * which the next slot's offset follows. */
#define HH_SLOT_ENUM(P, NAME, WIDTH) P##NAME, P##NAME##_LAST_ = P##NAME + (WIDTH)-1,
#define HH_LAYOUT_ENUM(P, SLOTS, SIZE) enum { SLOTS(HH_SLOT_ENUM, P) SIZE };
#define HH_LAYOUT_ENUM_OF(NAME, P, SLOTS, SIZE) HH_LAYOUT_ENUM(P, SLOTS, SIZE)
#define HH_RECORD_ENUM_OF(NAME, P, SLOTS, SIZE, TYPES, BLOCK) HH_LAYOUT_ENUM(P, SLOTS, SIZE)
/* HH_PORTS_ENUM_OF(NAME, P, PORTS, COUNT): the indices P##NAME of a list of ports, and COUNT. */
#define HH_PORT_ENUM(P, NAME, WIDTH) P##NAME,
#define HH_PORTS_ENUM_OF(NAME, P, PORTS, COUNT) enum { PORTS(HH_PORT_ENUM, P) COUNT };

/* -- sizes of the hand ---------------------------------------------------------------------- */
#define HH_DIMENSIONS(X)                                                                               \
    X(FINGERS, 3)                                                                                      \
    X(LINKS, 3) /* per finger */                                                                       \
    X(JOINTS, 9)                                                                                       \
    X(EDGES, 4) /* of the object */                                                                    \
    X(MAX_POINTS, 100000) /* surface points a model may have (state memory bound) */
#define HH_DIMENSION_ENUM(NAME, VALUE) HH_##NAME = (VALUE),
enum { HH_DIMENSIONS(HH_DIMENSION_ENUM) };

/* == the plant (hand.h) ======================================================================= */

/* A link's numbers in the packed finger row, model->fingers[f][HH_F_LINK0 + HH_F_LINK_STRIDE * i + HH_L_*] */
#define HH_LINK_SLOTS(SLOT, P)                                                                         \
    SLOT(P, LENGTH, 1)                                                                                 \
    SLOT(P, MASS, 1)                                                                                   \
    SLOT(P, COM_ALONG, 1)                                                                              \
    SLOT(P, COM_ACROSS, 1)                                                                             \
    SLOT(P, INERTIA, 1)

/* The packed finger row, model->fingers[f][HH_F_*] */
#define HH_FINGER_ROW_SLOTS(SLOT, P)                                                                   \
    SLOT(P, BASE_X, 1)                                                                                 \
    SLOT(P, BASE_Y, 1)                                                                                 \
    SLOT(P, BASE_ANGLE, 1)                                                                             \
    SLOT(P, LINK0, HH_LINKS * HH_F_LINK_STRIDE) /* link i from HH_F_LINK0 + HH_F_LINK_STRIDE * i */    \
    SLOT(P, DAMPING, HH_LINKS) /* per joint */                                                         \
    SLOT(P, ARMATURE, HH_LINKS)                                                                        \
    SLOT(P, TIP_RADIUS, 1)

/* Body parameters: gravity, the object, the contact law, the step, model->body[HH_B_*] */
#define HH_BODY_SLOTS(SLOT, P)                                                                         \
    SLOT(P, GX, 1)                                                                                     \
    SLOT(P, GY, 1)                                                                                     \
    SLOT(P, MASS, 1)                                                                                   \
    SLOT(P, INERTIA, 1)                                                                                \
    SLOT(P, HALF_A, 1)                                                                                 \
    SLOT(P, HALF_B, 1)                                                                                 \
    SLOT(P, K_N, 1)                                                                                    \
    SLOT(P, C_N, 1)                                                                                    \
    SLOT(P, K_T, 1)                                                                                    \
    SLOT(P, C_T, 1)                                                                                    \
    SLOT(P, MU_S, 1)                                                                                   \
    SLOT(P, MU_D, 1)                                                                                   \
    SLOT(P, DT, 1)

/* An object edge in the object frame, model->edges[e][HH_E_*]. Point k of edge e (k = 0 ..
 * count-1) sits at origin + k * spacing * direction; the edge's end corner is point 0 of the
 * next edge. Points are numbered start + k. */
#define HH_EDGE_SLOTS(SLOT, P)                                                                         \
    SLOT(P, OX, 1)                                                                                     \
    SLOT(P, OY, 1)                                                                                     \
    SLOT(P, DX, 1)                                                                                     \
    SLOT(P, DY, 1)                                                                                     \
    SLOT(P, NX, 1) /* outward normal */                                                                \
    SLOT(P, NY, 1)                                                                                     \
    SLOT(P, SPACING, 1)                                                                                \
    SLOT(P, COUNT, 1)                                                                                  \
    SLOT(P, START, 1)

/* The state vector. After the fixed part, per finger and surface point a touching flag
 * (3 x npts, from HH_S_TOUCH), then the anchors (3 x npts x 2, in the frame of link 3
 * relative to the tip centre). WINDOW: per finger and edge the first and last point that
 * may hold an anchor. */
#define HH_STATE_SLOTS(SLOT, P)                                                                        \
    SLOT(P, Q, HH_JOINTS)                                                                              \
    SLOT(P, QD, HH_JOINTS)                                                                             \
    SLOT(P, OBJ, 3) /* x, y, theta */                                                                  \
    SLOT(P, OBJ_VEL, 3)                                                                                \
    SLOT(P, WINDOW, HH_FINGERS * HH_EDGES * 2)                                                         \
    SLOT(P, TOUCH, 0)

/* The output row: the plant block's output ports in order, each named as its slot in
 * lower case. */
#define HH_OUTPUT_SLOTS(SLOT, P)                                                                       \
    SLOT(P, Q, HH_JOINTS)                                                                              \
    SLOT(P, QD, HH_JOINTS)                                                                             \
    SLOT(P, TIP, 3 * HH_FINGERS) /* per finger: tip centre x, y, absolute angle of link 3 */           \
    SLOT(P, FN, HH_FINGERS)                                                                            \
    SLOT(P, FT, HH_FINGERS)                                                                            \
    SLOT(P, RATIO, HH_FINGERS)                                                                         \
    SLOT(P, CONTACT, HH_FINGERS)                                                                       \
    SLOT(P, OBJ, 3)                                                                                    \
    SLOT(P, OBJ_VEL, 3)                                                                                \
    SLOT(P, NORMAL, 2 * HH_FINGERS)

/* A finger's contact summary, work->wrench[f][HH_W_*] */
#define HH_WRENCH_SLOTS(SLOT, P)                                                                       \
    SLOT(P, OBJ_FX, 1) /* force on the object */                                                       \
    SLOT(P, OBJ_FY, 1)                                                                                 \
    SLOT(P, OBJ_M, 1) /* its moment about the object's centre */                                       \
    SLOT(P, TIP_M, 1) /* moment of the force on the object about the tip centre */                     \
    SLOT(P, FN, 1) /* summed normal force */                                                           \
    SLOT(P, FT, 1) /* summed tangential force, signed along t = z x n */                               \
    SLOT(P, FN_PX, 1) /* sum of f_n * p, for the force-weighted contact point */                       \
    SLOT(P, FN_PY, 1)

/* The plant's status codes; ``which`` then says which element or finger */
#define HH_PLANT_STATUS_SLOTS(SLOT, P)                                                                 \
    SLOT(P, OK, 1)                                                                                     \
    SLOT(P, ERR_Q, 1) /* non-finite joint angle q[which] */                                            \
    SLOT(P, ERR_QD, 1) /* non-finite joint rate qd[which] */                                           \
    SLOT(P, ERR_OBJ, 1) /* non-finite object pose obj[which] */                                        \
    SLOT(P, ERR_OBJ_VEL, 1) /* non-finite object velocity obj_vel[which] */                            \
    SLOT(P, ERR_PENETRATION, 1) /* finger ``which``'s tip centre is inside the object */               \
    SLOT(P, ERR_TAU, 1) /* non-finite input tau[which] */                                              \
    SLOT(P, ERR_F_EXT, 1) /* non-finite input f_ext[which] */

/* A link's numbers in the hand vector, offsets in a finger's block */
#define HH_HAND_LINK_SLOTS(SLOT, P)                                                                    \
    SLOT(P, LENGTH, 1)                                                                                 \
    SLOT(P, MASS, 1)                                                                                   \
    SLOT(P, INERTIA, 1)                                                                                \
    SLOT(P, COM_ALONG, 1)                                                                              \
    SLOT(P, COM_ACROSS, 1)

/* A finger's block of the hand vector */
#define HH_HAND_FINGER_SLOTS(SLOT, P)                                                                  \
    SLOT(P, BASE, 2)                                                                                   \
    SLOT(P, BASE_ANGLE, 1)                                                                             \
    SLOT(P, LINK0, HH_LINKS * HH_PF_LINK_STRIDE) /* link i from HH_PF_LINK0 + HH_PF_LINK_STRIDE * i */ \
    SLOT(P, DAMPING, HH_LINKS)                                                                         \
    SLOT(P, ARMATURE, HH_LINKS)                                                                        \
    SLOT(P, TIP_RADIUS, 1)                                                                             \
    SLOT(P, Q0, HH_LINKS)

/* The hand vector: every number of a hand file, in sections gravity, object, contact,
 * fingers (finger f from HH_P_FINGER0 + f * HH_P_FINGER_STRIDE). hand_params.c names each
 * number ("object.mass", "fingers[2].links[3].com[1]"). */
#define HH_HAND_SLOTS(SLOT, P)                                                                         \
    SLOT(P, GX, 1)                                                                                     \
    SLOT(P, GY, 1)                                                                                     \
    SLOT(P, OBJ_MASS, 1)                                                                               \
    SLOT(P, OBJ_INERTIA, 1)                                                                            \
    SLOT(P, OBJ_SIZE, 2)                                                                               \
    SLOT(P, OBJ_POS, 2)                                                                                \
    SLOT(P, OBJ_ANGLE, 1)                                                                              \
    SLOT(P, OBJ_SPACING, 1)                                                                            \
    SLOT(P, K_N, 1)                                                                                    \
    SLOT(P, C_N, 1)                                                                                    \
    SLOT(P, K_T, 1)                                                                                    \
    SLOT(P, C_T, 1)                                                                                    \
    SLOT(P, MU_S, 1)                                                                                   \
    SLOT(P, MU_D, 1)                                                                                   \
    SLOT(P, FINGER0, HH_FINGERS * HH_P_FINGER_STRIDE)

/* A hand as a record carries it: FOLLOWS non-zero when the object's inertia is the plate
 * inertia of its mass and size (hh_hand_of_segment computes it), then the hand vector. */
#define HH_SEGMENT_SLOTS(SLOT, P) SLOT(P, FOLLOWS, 1) SLOT(P, HAND, HH_HAND_PARAMS)

/* == the controllers (control.h) ============================================================= */

/* The grasping reflex's packed parameters, params[HH_REFLEX_P_*] */
#define HH_REFLEX_PARAM_SLOTS(SLOT, P)                                                                 \
    SLOT(P, THRESHOLD, 1) /* normal force, N, above which a finger is in contact */                    \
    SLOT(P, APPROACH, 1) /* force, N, of a finger approaching the others */                            \
    SLOT(P, KI, 1) /* integral gain, 1/s */                                                            \
    SLOT(P, DT, 1) /* period, s (not > 0: unbound, update refuses) */                                  \
    SLOT(P, MIN_FORCE, 1) /* smallest normal force per contact, N */                                   \
    SLOT(P, RATIO, 1) /* |f_t| / f_n the loop aims at: safety_ratio / (1 + margin) */                  \
    SLOT(P, MAX_FORCE, 1) /* largest force scale, N */                                                 \
    SLOT(P, INITIAL, HH_FINGERS) /* non-zero for the fingers listed in 'grasp' */                      \
    SLOT(P, COINCIDENT_RTOL, 1) /* points this close, relative to their size, coincide */              \
    SLOT(P, RELEASE_SHARE, 1) /* a finger that loses contact while the suppresser lets through less    \
                              than this share of its grasping torque is not pushed back */             \
    SLOT(P, TIP_RADIUS, HH_FINGERS) /* the fingertip radii; a touching finger's contact point is its   \
                                    tip centre plus this along the contact normal */                   \
    SLOT(P, FOLLOW, 1) /* non-zero: the reflex's hold of a finger follows its share (hand-over) */     \
    SLOT(P, HOLD_SHARE, 1) /* a third finger is held whole down to this share, not at all at           \
                           release_share */                                                             \
    SLOT(P, CATCH_UP, 1) /* share of a positive shortfall closed at once, besides the integral */

/* The reflex's state: the force scale, per finger 1 where the reflex was letting go of it
 * when it last touched, per finger how much the reflex holds it */
#define HH_REFLEX_STATE_SLOTS(SLOT, P) SLOT(P, SCALE, 1) SLOT(P, HANDED, HH_FINGERS) SLOT(P, HOLD, HH_FINGERS)

/* hh_reflex_output's out: tau_g, |f_i|, in the grasp (0 or 1) */
#define HH_REFLEX_OUT_SLOTS(SLOT, P) SLOT(P, TAU_G, HH_JOINTS) SLOT(P, FORCE, HH_FINGERS) SLOT(P, ACTIVE, HH_FINGERS)

#define HH_REFLEX_STATUS_SLOTS(SLOT, P)                                                                \
    SLOT(P, OK, 1)                                                                                     \
    SLOT(P, COINCIDENT, 1) /* the squeeze is undefined: all grasp points coincide */                   \
    SLOT(P, NO_PERIOD, 1) /* update without a period (params[HH_REFLEX_P_DT] not > 0) */

/* GraspReflex's parameters as the block is given them, given[HH_REFLEX_G_*] */
#define HH_REFLEX_GIVEN_SLOTS(SLOT, P)                                                                 \
    SLOT(P, KI, 1)                                                                                     \
    SLOT(P, SAFETY_RATIO, 1)                                                                           \
    SLOT(P, MARGIN, 1)                                                                                 \
    SLOT(P, MIN_FORCE, 1)                                                                              \
    SLOT(P, MAX_FORCE, 1)                                                                              \
    SLOT(P, APPROACH, 1)                                                                               \
    SLOT(P, THRESHOLD, 1)                                                                              \
    SLOT(P, RELEASE_SHARE, 1)                                                                          \
    SLOT(P, HOLD_SHARE, 1)                                                                             \
    SLOT(P, FOLLOW, 1) /* follow_suppression, 0 or 1 */                                                \
    SLOT(P, GRASP, HH_FINGERS) /* 1 for the fingers listed in 'grasp' */                               \
    SLOT(P, COINCIDENT_RTOL, 1) /* Python's internal_forces._COINCIDENT_RTOL */                         \
    SLOT(P, CATCH_UP, 1)                                                                               \
    SLOT(P, SQUEEZE_FROM_WEIGHT, 1) /* non-zero: min_force at least the weight's share (reflex pack) */  \
    SLOT(P, FRICTION_CAP, 1) /* non-zero: the safety ratio at most HH_FRICTION_SHARE mu_d */

/* The manipulation PD's packed parameters, params[HH_MANIP_P_*] */
#define HH_MANIP_PARAM_SLOTS(SLOT, P)                                                                  \
    SLOT(P, Q0, HH_JOINTS) /* held by fingers without a trajectory; the IK's reference */              \
    SLOT(P, KP, HH_JOINTS) /* joint stiffnesses */                                                     \
    SLOT(P, KD, HH_JOINTS) /* joint dampings */                                                        \
    SLOT(P, GX, 1) /* gravity */                                                                       \
    SLOT(P, GY, 1)                                                                                     \
    SLOT(P, WX, 1) /* the object's weight m g */                                                       \
    SLOT(P, WY, 1)                                                                                     \
    SLOT(P, THRESHOLD, 1) /* normal force above which a finger carries the object */                   \
    SLOT(P, GRAVITY_COMP, 1) /* non-zero: feed the fingers' gravity torques forward */                 \
    SLOT(P, LOAD_COMP, 1) /* non-zero: feed J^T of the shared weight forward */                        \
    SLOT(P, STEP, 1) /* seconds either side of t for the velocity target */                            \
    SLOT(P, REACH_RTOL, 1) /* wrist distances this close (relative to l1 + l2) outside the reachable   \
                           annulus count as on it */                                                   \
    SLOT(P, DT, 1) /* the controller's period T, s (> 0 where the gains are matched) */                \
    SLOT(P, MATCHED, 1) /* non-zero: realise kp, kd for the period (hh_matched_gains); zero: apply     \
                        them as they are, held for the period */                                       \
    SLOT(P, CONTACT_COMP, 1) /* non-zero: aim a finger in contact as deep into the object as its       \
                             measured normal force presses it */                                       \
    SLOT(P, CONTACT_AIM, 1) /* > 0: that many times the tip's own depth (hh contact_depth); 0: fn / k_n */

/* A waypoint row (t, x, y, phi) of a trajectory */
#define HH_MANIP_WAYPOINT_SLOTS(SLOT, P) SLOT(P, T, 1) SLOT(P, X, 1) SLOT(P, Y, 1) SLOT(P, PHI, 1)

/* A finger's meta row: its waypoint count (0: no trajectory, it holds q0), its interpolation */
#define HH_MANIP_META_SLOTS(SLOT, P) SLOT(P, COUNT, 1) SLOT(P, INTERP, 1)

/* Interpolation codes */
#define HH_MANIP_INTERP_SLOTS(SLOT, P) SLOT(P, LINEAR, 1) SLOT(P, MINJERK, 1)

/* hh_manipulation_output's out: rows tau_m, tau_ff, q_ref */
#define HH_MANIP_OUT_SLOTS(SLOT, P) SLOT(P, TAU_M, HH_JOINTS) SLOT(P, TAU_FF, HH_JOINTS) SLOT(P, Q_REF, HH_JOINTS)

/* HH_MANIP_UNREACHABLE + f: a target of finger f is out of its reach; NO_PERIOD: matched gains
 * have no period to be matched to */
#define HH_MANIP_STATUS_SLOTS(SLOT, P) SLOT(P, OK, 1) SLOT(P, UNREACHABLE, HH_FINGERS) SLOT(P, NO_PERIOD, 1)

/* ManipulationPD's parameters as given, given[HH_MANIP_G_*] */
#define HH_MANIP_GIVEN_SLOTS(SLOT, P)                                                                  \
    SLOT(P, KP, HH_JOINTS)                                                                             \
    SLOT(P, KD, HH_JOINTS)                                                                             \
    SLOT(P, THRESHOLD, 1)                                                                              \
    SLOT(P, GRAVITY_COMP, 1)                                                                           \
    SLOT(P, LOAD_COMP, 1)                                                                              \
    SLOT(P, MATCHED, 1) /* discretization 'matched' */                                                 \
    SLOT(P, CONTACT_COMP, 1)                                                                           \
    SLOT(P, STEP, 1) /* Python's manipulation_pd.DERIVATIVE_STEP */                                    \
    SLOT(P, REACH_RTOL, 1) /* Python's inverse_kinematics._REACH_RTOL */                               \
    SLOT(P, CONTACT_AIM, 1) /* contact_aim, 0 for none (fn / k_n) */

/* The suppresser's packed parameters, params[HH_SUPPRESS_P_*] */
#define HH_SUPPRESS_PARAM_SLOTS(SLOT, P)                                                               \
    SLOT(P, S_A, HH_JOINTS) /* sigmoid steepnesses, 1/(N m) */                                         \
    SLOT(P, S_B, HH_JOINTS) /* suppression inputs, N m, at which the grasping torque is halved */      \
    SLOT(P, MODE, 1) /* HH_SUPPRESS_PASS, _MAGNITUDE or _SIGNED */                                     \
    SLOT(P, ALPHA, 1) /* the low-pass step of hh_suppress_update: 1 - exp(-T / time constant) */

/* Mode codes, params[HH_SUPPRESS_P_MODE] */
#define HH_SUPPRESS_MODE_SLOTS(SLOT, P) SLOT(P, PASS, 1) SLOT(P, MAGNITUDE, 1) SLOT(P, SIGNED, 1)

/* hh_suppress's out: tau, tau_g_eff, share */
#define HH_SUPPRESS_OUT_SLOTS(SLOT, P) SLOT(P, TAU, HH_JOINTS) SLOT(P, TAU_G_EFF, HH_JOINTS) SLOT(P, SHARE, HH_FINGERS)

/* Suppresser's parameters as given, given[HH_SUPPRESS_G_*] */
#define HH_SUPPRESS_GIVEN_SLOTS(SLOT, P)                                                               \
    SLOT(P, S_A, HH_JOINTS)                                                                            \
    SLOT(P, S_B, HH_JOINTS)                                                                            \
    SLOT(P, MODE, 1) /* HH_SUPPRESS_MAGNITUDE or _SIGNED */                                            \
    SLOT(P, ENABLED, 1)                                                                                \
    SLOT(P, TIME_CONSTANT, 1) /* s; > 0: the block low-passes (a state), 0: the static law */

/* ObjectSupport's context: the force (fx, fy, torque on the object) while t < until */
#define HH_SUPPORT_CONTEXT_SLOTS(SLOT, P) SLOT(P, FORCE, 3) SLOT(P, UNTIL, 1)

/* == the layouts =============================================================================
 * X(NAME, P, SLOTS, SIZE): NAME is the layout's name in Python (hierhand.layouts.NAME), P the
 * prefix of its C names, SIZE the C name of its size. In order: a table may use the sizes of
 * those before it. */
#define HH_LAYOUTS(X)                                                                                  \
    X(LINK, HH_L_, HH_LINK_SLOTS, HH_F_LINK_STRIDE)                                                    \
    X(FINGER_ROW, HH_F_, HH_FINGER_ROW_SLOTS, HH_N_FINGER_PARAMS)                                      \
    X(BODY, HH_B_, HH_BODY_SLOTS, HH_N_BODY_PARAMS)                                                    \
    X(EDGE, HH_E_, HH_EDGE_SLOTS, HH_N_EDGE_COLS)                                                      \
    X(STATE, HH_S_, HH_STATE_SLOTS, HH_N_STATE_FIXED)                                                  \
    X(OUTPUT, HH_O_, HH_OUTPUT_SLOTS, HH_N_OUTPUTS)                                                    \
    X(WRENCH, HH_W_, HH_WRENCH_SLOTS, HH_N_WRENCH)                                                     \
    X(PLANT_STATUS, HH_, HH_PLANT_STATUS_SLOTS, HH_N_STATUS)                                           \
    X(HAND_LINK, HH_PL_, HH_HAND_LINK_SLOTS, HH_PF_LINK_STRIDE)                                        \
    X(HAND_FINGER, HH_PF_, HH_HAND_FINGER_SLOTS, HH_P_FINGER_STRIDE)                                   \
    X(HAND, HH_P_, HH_HAND_SLOTS, HH_HAND_PARAMS)                                                      \
    X(SEGMENT, HH_SEG_, HH_SEGMENT_SLOTS, HH_SEGMENT)                                                  \
    X(REFLEX_PARAMS, HH_REFLEX_P_, HH_REFLEX_PARAM_SLOTS, HH_REFLEX_N_PARAMS)                          \
    X(REFLEX_STATE, HH_REFLEX_S_, HH_REFLEX_STATE_SLOTS, HH_REFLEX_N_STATE)                            \
    X(REFLEX_OUT, HH_REFLEX_O_, HH_REFLEX_OUT_SLOTS, HH_REFLEX_N_OUT)                                  \
    X(REFLEX_STATUS, HH_REFLEX_, HH_REFLEX_STATUS_SLOTS, HH_REFLEX_N_STATUS)                           \
    X(REFLEX_GIVEN, HH_REFLEX_G_, HH_REFLEX_GIVEN_SLOTS, HH_REFLEX_N_GIVEN)                            \
    X(MANIP_PARAMS, HH_MANIP_P_, HH_MANIP_PARAM_SLOTS, HH_MANIP_N_PARAMS)                              \
    X(MANIP_WAYPOINT, HH_MANIP_W_, HH_MANIP_WAYPOINT_SLOTS, HH_MANIP_W_COLS)                           \
    X(MANIP_META, HH_MANIP_M_, HH_MANIP_META_SLOTS, HH_MANIP_N_META)                                   \
    X(MANIP_INTERP, HH_MANIP_INTERP_, HH_MANIP_INTERP_SLOTS, HH_MANIP_N_INTERP)                        \
    X(MANIP_OUT, HH_MANIP_O_, HH_MANIP_OUT_SLOTS, HH_MANIP_N_OUT)                                      \
    X(MANIP_STATUS, HH_MANIP_, HH_MANIP_STATUS_SLOTS, HH_MANIP_N_STATUS)                               \
    X(MANIP_GIVEN, HH_MANIP_G_, HH_MANIP_GIVEN_SLOTS, HH_MANIP_N_GIVEN)                                \
    X(SUPPRESS_PARAMS, HH_SUPPRESS_P_, HH_SUPPRESS_PARAM_SLOTS, HH_SUPPRESS_N_PARAMS)                  \
    X(SUPPRESS_MODE, HH_SUPPRESS_, HH_SUPPRESS_MODE_SLOTS, HH_SUPPRESS_N_MODES)                        \
    X(SUPPRESS_OUT, HH_SUPPRESS_O_, HH_SUPPRESS_OUT_SLOTS, HH_SUPPRESS_N_OUT)                          \
    X(SUPPRESS_GIVEN, HH_SUPPRESS_G_, HH_SUPPRESS_GIVEN_SLOTS, HH_SUPPRESS_N_GIVEN)                    \
    X(SUPPORT_CONTEXT, HH_SUPPORT_C_, HH_SUPPORT_CONTEXT_SLOTS, HH_SUPPORT_N_CONTEXT)

/* == the records of the kernel types (kernel_types.h) ========================================
 * A record is what a block's kernel() writes and its kernel type's constructor builds the
 * context from (an exported FMU rebuilds it from the same record). TIME_CONSTANT, DT and
 * PERIOD are seconds, NaN while the block has no period. */

#define HH_PLANT_RECORD_SLOTS(SLOT, P) SLOT(P, DT, 1) SLOT(P, SEGMENT, HH_SEGMENT)
#define HH_REFLEX_RECORD_SLOTS(SLOT, P) SLOT(P, SEGMENT, HH_SEGMENT) SLOT(P, DT, 1) SLOT(P, GIVEN, HH_REFLEX_N_GIVEN)
/* then waypoints (HH_FINGERS x CAPACITY x HH_MANIP_W_COLS) and meta (HH_FINGERS x HH_MANIP_N_META) */
#define HH_MANIP_RECORD_SLOTS(SLOT, P)                                                                 \
    SLOT(P, SEGMENT, HH_SEGMENT)                                                                       \
    SLOT(P, DT, 1)                                                                                     \
    SLOT(P, GIVEN, HH_MANIP_N_GIVEN)                                                                   \
    SLOT(P, CAPACITY, 1)                                                                               \
    SLOT(P, WAYPOINTS, 0)
#define HH_SUPPRESS_RECORD_SLOTS(SLOT, P) SLOT(P, GIVEN, HH_SUPPRESS_N_GIVEN) SLOT(P, PERIOD, 1)
#define HH_SUPPORT_RECORD_SLOTS(SLOT, P) SLOT(P, SEGMENT, HH_SEGMENT) SLOT(P, UNTIL, 1)
#define HH_JOINT_LOW_PASS_RECORD_SLOTS(SLOT, P) SLOT(P, TIME_CONSTANT, 1) SLOT(P, PERIOD, 1)

/* X(NAME, P, SLOTS, SIZE, TYPES, BLOCK): as HH_LAYOUTS, TYPES the table (ending with a NULL
 * name) that defines the kernel type of the record, and BLOCK the Python block class that
 * writes the record ("module:Class"). These lines are the hand's kernel types, which the
 * extension and the FMU binaries hold, and its block types, which hierhand registers
 * (hierhand.layouts.BLOCK_CLASSES, its blocks.types entry point): no other list names them. */
#define HH_RECORDS(X)                                                                                  \
    X(PLANT_RECORD, HH_PLANT_R_, HH_PLANT_RECORD_SLOTS, HH_PLANT_RECORD, hh_plant_kernel_type,         \
      "hierhand.model.plant:HandPlant")                                                                \
    X(REFLEX_RECORD, HH_REFLEX_R_, HH_REFLEX_RECORD_SLOTS, HH_REFLEX_RECORD, hh_reflex_kernel_type,    \
      "hierhand.control.grasp_reflex:GraspReflex")                                                     \
    X(MANIP_RECORD, HH_MANIP_R_, HH_MANIP_RECORD_SLOTS, HH_MANIP_RECORD_HEAD, hh_manip_kernel_type,    \
      "hierhand.control.manipulation_pd:ManipulationPD")                                               \
    X(SUPPRESS_RECORD, HH_SUPPRESS_R_, HH_SUPPRESS_RECORD_SLOTS, HH_SUPPRESS_RECORD,                   \
      hh_suppress_kernel_type, "hierhand.control.suppresser:Suppresser")                               \
    X(SUPPORT_RECORD, HH_SUPPORT_R_, HH_SUPPORT_RECORD_SLOTS, HH_SUPPORT_RECORD, hh_support_kernel_type, \
      "hierhand.model.support:ObjectSupport")                                                          \
    X(JOINT_LOW_PASS_RECORD, HH_JOINT_LOW_PASS_R_, HH_JOINT_LOW_PASS_RECORD_SLOTS,                     \
      HH_JOINT_LOW_PASS_RECORD, hh_joint_low_pass_kernel_type, "hierhand.control.joint_low_pass:JointLowPass")

/* == the input ports of the kernel types =====================================================
 * A kernel reads input port i at inputs[i], in the order of its block's inputs
 * (blocks_kernel.h), and writes its output ports as one row: the slots of its output layout
 * (OUTPUT, REFLEX_OUT, MANIP_OUT, SUPPRESS_OUT), each port named as its slot in lower case.
 * A list PORT(P, NAME, WIDTH) gives a kernel type's input ports in order: inputs[P##NAME]
 * is port NAME (in lower case), of WIDTH values; the block takes its inputs from the list. */
#define HH_PLANT_INPUT_PORTS(PORT, P) PORT(P, TAU, HH_JOINTS) PORT(P, F_EXT, 3) /* fx, fy, torque on the object */
#define HH_REFLEX_INPUT_PORTS(PORT, P)                                                                 \
    PORT(P, Q, HH_JOINTS)                                                                              \
    PORT(P, TIP, 3 * HH_FINGERS)                                                                       \
    PORT(P, FN, HH_FINGERS)                                                                            \
    PORT(P, FT, HH_FINGERS)                                                                            \
    PORT(P, NORMAL, 2 * HH_FINGERS)                                                                    \
    PORT(P, SHARE, HH_FINGERS)
#define HH_MANIP_INPUT_PORTS(PORT, P)                                                                  \
    PORT(P, Q, HH_JOINTS)                                                                              \
    PORT(P, QD, HH_JOINTS)                                                                             \
    PORT(P, FN, HH_FINGERS)                                                                            \
    PORT(P, SUPPORT, 3)                                                                                \
    PORT(P, NORMAL, 2 * HH_FINGERS)                                                                    \
    PORT(P, OBJ, 3)
#define HH_SUPPRESS_INPUT_PORTS(PORT, P) PORT(P, TAU_G, HH_JOINTS) PORT(P, TAU_M, HH_JOINTS) PORT(P, TAU_FF, HH_JOINTS)
#define HH_JOINT_LOW_PASS_INPUT_PORTS(PORT, P) PORT(P, U, HH_JOINTS)

/* X(NAME, P, PORTS, COUNT): NAME the list's name in Python (hierhand.layouts.NAME, a mapping
 * of port to width), P the prefix of the ports' C indices, COUNT the C name of their number. */
#define HH_INPUT_PORTS(X)                                                                              \
    X(PLANT_INPUTS, HH_PLANT_I_, HH_PLANT_INPUT_PORTS, HH_PLANT_N_INPUTS)                              \
    X(REFLEX_INPUTS, HH_REFLEX_I_, HH_REFLEX_INPUT_PORTS, HH_REFLEX_N_INPUTS)                          \
    X(MANIP_INPUTS, HH_MANIP_I_, HH_MANIP_INPUT_PORTS, HH_MANIP_N_INPUTS)                              \
    X(SUPPRESS_INPUTS, HH_SUPPRESS_I_, HH_SUPPRESS_INPUT_PORTS, HH_SUPPRESS_N_INPUTS)                  \
    X(JOINT_LOW_PASS_INPUTS, HH_JOINT_LOW_PASS_I_, HH_JOINT_LOW_PASS_INPUT_PORTS, HH_JOINT_LOW_PASS_N_INPUTS)

/* -- the enums ------------------------------------------------------------------------------- */
HH_LAYOUTS(HH_LAYOUT_ENUM_OF)
HH_RECORDS(HH_RECORD_ENUM_OF)
HH_INPUT_PORTS(HH_PORTS_ENUM_OF)

#endif
