"""Flat-array layouts shared by the Python side and the compiled kernels.

The kernels take a handful of float64 arrays rather than objects so that a call costs
little to dispatch and needs no allocation per step; these constants name the slots.
Numba freezes module-level integers as compile-time constants.
"""

# -- per-finger parameter row: fingers[f, :] -------------------------------------------
F_BASE_X = 0
F_BASE_Y = 1
F_BASE_ANGLE = 2
F_LINK0 = 3  # link i occupies F_LINK0 + F_LINK_STRIDE * i + (L_*)
F_LINK_STRIDE = 5
L_LENGTH = 0
L_MASS = 1
L_COM_ALONG = 2
L_COM_ACROSS = 3
L_INERTIA = 4
F_DAMPING = 18  # three joints
F_ARMATURE = 21  # three joints
F_TIP_RADIUS = 24
N_FINGER_PARAMS = 25

# -- body parameters: gravity, object, contact law, step ------------------------------
B_GX = 0
B_GY = 1
B_MASS = 2
B_INERTIA = 3
B_HALF_A = 4
B_HALF_B = 5
B_K_N = 6
B_C_N = 7
B_K_T = 8
B_C_T = 9
B_MU_S = 10
B_MU_D = 11
B_DT = 12
N_BODY_PARAMS = 13

# -- object edges, in the object frame: edges[e, :] -------------------------------------
# Point k of edge e (k = 0 .. count-1) sits at origin + k * spacing * direction; the
# edge's end corner is point 0 of the next edge. Points are numbered start + k.
E_OX = 0
E_OY = 1
E_DX = 2
E_DY = 3
E_NX = 4  # outward normal
E_NY = 5
E_SPACING = 6
E_COUNT = 7
E_START = 8
N_EDGE_COLS = 9
N_EDGES = 4

# -- state vector ----------------------------------------------------------------------
# q(9) qd(9) obj pose(3) obj velocity(3) contact windows(3 x 4 x 2: first and last point
# index per finger and edge that may hold an anchor) touching flags(3 x npts) anchors
# (3 x npts x 2, in the frame of link 3 relative to the tip centre).
S_Q = 0
S_QD = 9
S_OBJ = 18
S_OBJ_VEL = 21
S_WINDOW = 24
S_TOUCH = 48


def state_size(npts: int) -> int:
    return S_TOUCH + 9 * npts


def anchor_offset(npts: int) -> int:
    return S_TOUCH + 3 * npts


# -- output row ------------------------------------------------------------------------
OUTPUT_PORTS = (
    ("q", 9),
    ("qd", 9),
    ("tip", 9),
    ("fn", 3),
    ("ft", 3),
    ("ratio", 3),
    ("contact", 3),
    ("obj", 3),
    ("obj_vel", 3),
    ("normal", 6),
)
O_Q = 0
O_QD = 9
O_TIP = 18
O_FN = 27
O_FT = 30
O_RATIO = 33
O_CONTACT = 36
O_OBJ = 39
O_OBJ_VEL = 42
O_NORMAL = 45
N_OUTPUTS = 51

# -- kernel status codes ---------------------------------------------------------------
OK = 0
ERR_Q = 1
ERR_QD = 2
ERR_OBJ = 3
ERR_OBJ_VEL = 4
ERR_PENETRATION = 5
ERR_TAU = 6
ERR_F_EXT = 7
