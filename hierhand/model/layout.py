"""Flat-array layouts of the plant's C core, named for Python.

The slots are defined once, in ``hierhand/csrc/hand.h``; the extension reports them in
``hierhand._native.LAYOUT`` and this module gives them names Python code can import.
"""

from .._native import LAYOUT as _L

# -- per-finger parameter row: fingers[f, :] -------------------------------------------
F_BASE_X: int = _L["F_BASE_X"]
F_BASE_Y: int = _L["F_BASE_Y"]
F_BASE_ANGLE: int = _L["F_BASE_ANGLE"]
F_LINK0: int = _L["F_LINK0"]  # link i occupies F_LINK0 + F_LINK_STRIDE * i + (L_*)
F_LINK_STRIDE: int = _L["F_LINK_STRIDE"]
L_LENGTH: int = _L["L_LENGTH"]
L_MASS: int = _L["L_MASS"]
L_COM_ALONG: int = _L["L_COM_ALONG"]
L_COM_ACROSS: int = _L["L_COM_ACROSS"]
L_INERTIA: int = _L["L_INERTIA"]
F_DAMPING: int = _L["F_DAMPING"]  # three joints
F_ARMATURE: int = _L["F_ARMATURE"]  # three joints
F_TIP_RADIUS: int = _L["F_TIP_RADIUS"]
N_FINGER_PARAMS: int = _L["N_FINGER_PARAMS"]

# -- body parameters: gravity, object, contact law, step ------------------------------
B_GX: int = _L["B_GX"]
B_GY: int = _L["B_GY"]
B_MASS: int = _L["B_MASS"]
B_INERTIA: int = _L["B_INERTIA"]
B_HALF_A: int = _L["B_HALF_A"]
B_HALF_B: int = _L["B_HALF_B"]
B_K_N: int = _L["B_K_N"]
B_C_N: int = _L["B_C_N"]
B_K_T: int = _L["B_K_T"]
B_C_T: int = _L["B_C_T"]
B_MU_S: int = _L["B_MU_S"]
B_MU_D: int = _L["B_MU_D"]
B_DT: int = _L["B_DT"]
N_BODY_PARAMS: int = _L["N_BODY_PARAMS"]

# -- object edges, in the object frame: edges[e, :] -------------------------------------
# Point k of edge e (k = 0 .. count-1) sits at origin + k * spacing * direction; the
# edge's end corner is point 0 of the next edge. Points are numbered start + k.
E_OX: int = _L["E_OX"]
E_OY: int = _L["E_OY"]
E_DX: int = _L["E_DX"]
E_DY: int = _L["E_DY"]
E_NX: int = _L["E_NX"]  # outward normal
E_NY: int = _L["E_NY"]
E_SPACING: int = _L["E_SPACING"]
E_COUNT: int = _L["E_COUNT"]
E_START: int = _L["E_START"]
N_EDGE_COLS: int = _L["N_EDGE_COLS"]
N_EDGES: int = _L["EDGES"]

# -- state vector ----------------------------------------------------------------------
# q(9) qd(9) obj pose(3) obj velocity(3) contact windows(3 x 4 x 2: first and last point
# index per finger and edge that may hold an anchor) touching flags(3 x npts) anchors
# (3 x npts x 2, in the frame of link 3 relative to the tip centre).
S_Q: int = _L["S_Q"]
S_QD: int = _L["S_QD"]
S_OBJ: int = _L["S_OBJ"]
S_OBJ_VEL: int = _L["S_OBJ_VEL"]
S_WINDOW: int = _L["S_WINDOW"]
S_TOUCH: int = _L["S_TOUCH"]


def anchor_offset(npts: int) -> int:
    """Where the anchors start in the state, after the touching flags (its length: ``Model.state_size``)."""
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
O_Q: int = _L["O_Q"]
O_QD: int = _L["O_QD"]
O_TIP: int = _L["O_TIP"]
O_FN: int = _L["O_FN"]
O_FT: int = _L["O_FT"]
O_RATIO: int = _L["O_RATIO"]
O_CONTACT: int = _L["O_CONTACT"]
O_OBJ: int = _L["O_OBJ"]
O_OBJ_VEL: int = _L["O_OBJ_VEL"]
O_NORMAL: int = _L["O_NORMAL"]
N_OUTPUTS: int = _L["N_OUTPUTS"]

# -- per-finger contact summary (ContactWrenches) -----------------------------------------
W_OBJ_FX: int = _L["W_OBJ_FX"]  # force on the object
W_OBJ_FY: int = _L["W_OBJ_FY"]
W_OBJ_M: int = _L["W_OBJ_M"]  # its moment about the object's centre
W_TIP_M: int = _L["W_TIP_M"]  # moment of the force on the object about the tip centre
W_FN: int = _L["W_FN"]  # summed normal force
W_FT: int = _L["W_FT"]  # summed tangential force (signed, along t = z x n)
W_FN_PX: int = _L["W_FN_PX"]  # sum of f_n * p, for the force-weighted contact point
W_FN_PY: int = _L["W_FN_PY"]
N_WRENCH: int = _L["N_WRENCH"]

# -- status codes ------------------------------------------------------------------------
OK: int = _L["OK"]
ERR_Q: int = _L["ERR_Q"]
ERR_QD: int = _L["ERR_QD"]
ERR_OBJ: int = _L["ERR_OBJ"]
ERR_OBJ_VEL: int = _L["ERR_OBJ_VEL"]
ERR_PENETRATION: int = _L["ERR_PENETRATION"]
ERR_TAU: int = _L["ERR_TAU"]
ERR_F_EXT: int = _L["ERR_F_EXT"]

_ports_width = sum(width for _, width in OUTPUT_PORTS)
if _ports_width != N_OUTPUTS:
    raise ImportError(f"the output ports hold {_ports_width} values but the C core writes {N_OUTPUTS}")
