"""A test's readiness sign inside the process under test: a signal sent at a chosen point.

Put this folder first on PYTHONPATH and set ``SIGNAL_AT`` to where the process should
signal itself, and ``SIGNAL_SEND`` to the signals (``SIGTERM,SIGINT``; default SIGINT):

- ``import:numpy``: when the process starts to import ``numpy`` (its start-up);
- ``blocks.diagram_file.reader:read_builder`` or ``blocks.results.signals:Results.write_files``: at the first
  call of that function or method, before it runs (``SIGNAL_CALL=N``: at its N-th call).

The signals are sent by the process to itself at exactly that point, so a test of what a
signal does in each phase (imports, loading, simulating, saving, plotting) needs no sleep
and does not depend on the machine's speed. With ``SIGNAL_TO=main`` a process forked by
the one under test (the plotter of ``run --plot``) sends them to that one instead, as a
Ctrl-C or ``kill`` reaches the program while its helper works; with ``SIGNAL_TO=group`` the
process sends them to its whole process group, as a terminal's Ctrl-C reaches a program
and every process it started. With ``SIGNAL_RECORD=FILE``
the process sends nothing there but appends to FILE the signals it blocks then (its
``SigBlk`` line of /proc/self/status), for a test of what a helper process starts with.
"""

import importlib.abc
import os
import signal
import sys

_AT = os.environ.get("SIGNAL_AT", "")
_SEND = [getattr(signal, name) for name in os.environ.get("SIGNAL_SEND", "SIGINT").split(",")]
_CALL = int(os.environ.get("SIGNAL_CALL", "1"))
_TO = os.getpid() if os.environ.get("SIGNAL_TO") == "main" else None
_GROUP = os.environ.get("SIGNAL_TO") == "group"
_RECORD = os.environ.get("SIGNAL_RECORD")
_calls = 0


def _fire() -> None:
    global _calls
    _calls += 1
    if _calls == _CALL and _RECORD:
        with open("/proc/self/status") as status, open(_RECORD, "a") as record:
            record.writelines(line for line in status if line.startswith("SigBlk:"))
    elif _calls == _CALL:
        for signum in _SEND:
            if _GROUP:
                os.killpg(0, signum)
            else:
                os.kill(os.getpid() if _TO is None else _TO, signum)


class _Watch(importlib.abc.MetaPathFinder):
    """Fires when the module named in SIGNAL_AT is imported (``import:NAME``), or wraps the
    function it names once its module has been imported."""

    def __init__(self, module: str, attr: str | None):
        self.module, self.attr = module, attr

    def find_spec(self, name, path=None, target=None):
        if name != self.module:
            return None
        if self.attr is None:
            _fire()
            return None
        sys.meta_path.remove(self)
        try:
            spec = importlib.util.find_spec(name)
        finally:
            sys.meta_path.insert(0, self)
        loader = spec.loader
        attr = self.attr

        class _Loader(importlib.abc.Loader):
            def create_module(self, spec):
                return loader.create_module(spec)

            def exec_module(self, module):
                loader.exec_module(module)
                owner_name, _, method = attr.rpartition(".")
                owner = getattr(module, owner_name) if owner_name else module
                real = getattr(owner, method)

                def signalling(*args, **kwargs):
                    _fire()
                    return real(*args, **kwargs)

                setattr(owner, method, signalling)

        spec.loader = _Loader()
        return spec


if _AT:
    import importlib.util

    where, _, what = _AT.partition(":")
    sys.meta_path.insert(0, _Watch(what, None) if where == "import" else _Watch(where, what))
