"""Ctrl-C inside FMU calls, the pieces on their own (through a running FMU: test_block)."""

from __future__ import annotations

import sys
from types import SimpleNamespace

import pytest

from blocks.fmu import interrupt


def test_an_interrupt_lost_in_a_callback_is_raised_after_the_call():
    """The pieces on their own: a KeyboardInterrupt inside a wrapped callback, or one that
    ctypes hands to sys.unraisablehook for it, is raised by the next check()."""
    @interrupt.callback
    def log(*args):
        raise KeyboardInterrupt

    log(1, 2)
    with pytest.raises(KeyboardInterrupt):
        interrupt.check()
    interrupt.check()                                       # noted once, raised once
    interrupt.arm()
    lost = KeyboardInterrupt()
    sys.unraisablehook(SimpleNamespace(exc_type=KeyboardInterrupt, exc_value=lost, object=log))
    with pytest.raises(KeyboardInterrupt) as raised:
        interrupt.check()
    assert raised.value is lost                             # the interrupt itself, e.g. a StopRequest
    seen = []
    before = sys.unraisablehook
    sys.unraisablehook = seen.append                        # others' hooks keep their messages
    interrupt.arm()
    other = SimpleNamespace(exc_type=KeyboardInterrupt, exc_value=KeyboardInterrupt(), object=print)
    sys.unraisablehook(other)
    assert seen == [other]
    interrupt.check()
    sys.unraisablehook = before
