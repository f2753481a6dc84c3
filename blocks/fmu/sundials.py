"""CVode as fmpy ships it (SUNDIALS 7, ``fmpy.sundials``), declared for the model-exchange solver.

fmpy loads the SUNDIALS libraries of its platform and checks their major version when
``fmpy.sundials`` is imported. ``functions()`` declares, on function objects of its own
(so that fmpy's declarations stay as they are), the calls ``solvers.CVode`` makes: a
context, serial vectors over the solver's own numpy buffers, a BDF integrator with a dense
linear solver and root finding, and their freeing. Pointers are plain ``c_void_p``; the
right-hand side and the root function are C functions of ``blocks._native`` (fmu_me_integration.c),
passed by address. Imported when a run first integrates with CVode, never at load time.
"""

from __future__ import annotations

import ctypes
import functools
from ctypes import POINTER, c_char_p, c_double, c_int, c_int64, c_long, c_void_p
from types import SimpleNamespace

CV_BDF = 2
CV_NORMAL = 1
CV_SUCCESS = 0
CV_ROOT_RETURN = 2
SUN_COMM_NULL = 0

ErrorHandler = ctypes.CFUNCTYPE(None, c_int, c_char_p, c_char_p, c_char_p, c_int, c_void_p, c_void_p)
"""SUNErrHandlerFn: (line, function, file, message, error code, user data, context)."""

_SIGNATURES = {
    "core": {
        "SUNContext_Create": (c_int, [c_int, POINTER(c_void_p)]),
        "SUNContext_Free": (c_int, [POINTER(c_void_p)]),
        "SUNContext_ClearErrHandlers": (c_int, [c_void_p]),
        "SUNContext_PushErrHandler": (c_int, [c_void_p, ErrorHandler, c_void_p]),
        "N_VDestroy": (None, [c_void_p]),
        "SUNMatDestroy": (None, [c_void_p]),
        "SUNLinSolFree": (c_int, [c_void_p]),
    },
    "nvecserial": {
        "N_VMake_Serial": (c_void_p, [c_int64, c_void_p, c_void_p]),
    },
    "sunmatrixdense": {
        "SUNDenseMatrix": (c_void_p, [c_int64, c_int64, c_void_p]),
    },
    "sunlinsoldense": {
        "SUNLinSol_Dense": (c_void_p, [c_void_p, c_void_p, c_void_p]),
    },
    "cvode": {
        "CVodeCreate": (c_void_p, [c_int, c_void_p]),
        "CVodeInit": (c_int, [c_void_p, c_void_p, c_double, c_void_p]),
        "CVodeReInit": (c_int, [c_void_p, c_double, c_void_p]),
        "CVodeSVtolerances": (c_int, [c_void_p, c_double, c_void_p]),
        "CVodeRootInit": (c_int, [c_void_p, c_int, c_void_p]),
        "CVodeSetLinearSolver": (c_int, [c_void_p, c_void_p, c_void_p]),
        "CVodeSetMaxStep": (c_int, [c_void_p, c_double]),
        "CVodeSetMaxNumSteps": (c_int, [c_void_p, c_long]),
        "CVodeSetNoInactiveRootWarn": (c_int, [c_void_p]),
        "CVodeSetUserData": (c_int, [c_void_p, c_void_p]),
        "CVode": (c_int, [c_void_p, c_double, c_void_p, POINTER(c_double), c_int]),
        "CVodeGetRootInfo": (c_int, [c_void_p, POINTER(c_int)]),
        "CVodeFree": (None, [POINTER(c_void_p)]),
    },
}


@functools.cache
def functions() -> SimpleNamespace:
    """The SUNDIALS functions the CVode solver calls, and ``array``, the address of
    ``N_VGetArrayPointer_Serial`` (for the C callbacks). RuntimeError if fmpy's SUNDIALS
    cannot be loaded here."""
    try:
        from fmpy.sundials import libraries
    except Exception as exc:
        raise RuntimeError(f"CVode (the SUNDIALS libraries fmpy ships) cannot be loaded here: {exc}; "
                           "use 'solver: euler'") from None
    found = {}
    for library, signatures in _SIGNATURES.items():
        cdll = getattr(libraries, f"sundials_{library}")
        for name, (restype, argtypes) in signatures.items():
            function = cdll[name]  # a function object of our own, not fmpy's
            function.restype, function.argtypes = restype, argtypes
            found[name] = function
    array = ctypes.cast(libraries.sundials_nvecserial["N_VGetArrayPointer_Serial"], c_void_p).value
    return SimpleNamespace(array=array, **found)
