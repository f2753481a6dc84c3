"""hierhand: hierarchical grasping/manipulation control of a three-fingered hand, as blocks.

The application is built only on the public API of the ``blocks`` framework; this
package also provides the ``hierhand`` command line. Its physics and control laws are
compiled C (``hierhand/csrc``), built by ``pip install`` into ``hierhand._native``.
"""

import os as _os

__version__ = "0.1.0"
"""The distribution's version (pyproject.toml reads it from here)."""


def _check_native() -> None:
    """Fail early, with the fix, when the C core is missing or older than its sources."""
    try:
        from . import _native
    except ImportError as exc:
        raise ImportError(f"hierhand's C core is not built ({exc}); install hierhand with "
                          "'pip install -e .' or 'pip install .' (needs a C compiler and the Python headers)") from None
    from .native_sources import CSRC, sources_digest

    root = _os.path.dirname(_os.path.dirname(_os.path.realpath(__file__)))
    if _os.path.isdir(_os.path.join(root, CSRC)) and _native.SOURCES_DIGEST != sources_digest(root):
        raise ImportError(f"hierhand's C core was built from other sources than those in {_os.path.join(root, CSRC)}; "
                          "rebuild it with 'pip install -e .'")


_check_native()
