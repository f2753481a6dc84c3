"""The instances of one FMU, pooled across the runs of the block that loaded it.

Instantiating an FMU (loading its binary, allocating its memory) costs far more than
resetting one, and an FMU may allow only one instance per process, so a block keeps the
instances its runs gave back and hands them to the next runs. ``PooledModel`` is the
block's ``Model`` with that pool: a run takes an idle instance (reset when it starts) or a
new one (in this process, or for ``isolation: process`` in a process of its own,
``hosted``), extracting the archive the first time a run needs one; giving it back
terminates the FMU's simulation and pools the instance (an isolated one is freed in its
process, which is pooled and instantiates the FMU again for the next run), or frees it if
it failed. A
process forked from this one drops the isolated instances it inherited (their hosts
belong to the parent) and makes its own, and an isolated instance whose process ended
while it was idle is dropped too. Closing the block,
or its going away, frees the idle instances and, once no run holds one, the extracted
files.
"""

from __future__ import annotations

import shutil
import threading
import weakref
import zipfile
from pathlib import Path

from blocks.process import scratch
from ..block import BlockError
from .archive import ArchiveError, extract_archive
from .description import MODEL_DESCRIPTION
from .cosimulation import CoSimulation2, CoSimulation3
from .exchange import ModelExchange2, ModelExchange3
from .scheduled import ScheduledExecution3
from blocks.fmu.isolation.client import HostedInstance
from .instance import Binary, Instance
from .model import Model


class PooledModel(Model):
    """What an FMU's modelDescription says (``Model``), and the pool of its instances.

    Reading the model touches only the archive's member list and modelDescription.xml;
    the archive is extracted (and the binary loaded, by ``Instance``) when the first
    instance is acquired, that is when a run starts.
    """

    def __init__(self, path: Path, shown: str, interface: str | None = None):
        self.lock = threading.Lock()
        self.extract_lock = threading.Lock()
        self.idle: list[Instance] = []
        self.live = 0
        self.closed = False
        self.dir: Path | None = None
        self.binary: Binary | None = None
        self._dirs: list[str] = []
        self._cleanup = weakref.finalize(self, _remove_model, self.idle, self._dirs)
        self.integration = None
        """How the block integrates a model-exchange FMU (``solvers.Integration``), set when
        the block is bound to its period."""
        self.isolation = "none"
        self.timeout = 0.0
        """Where the block's instances run ('none': here, 'process': each in a process of its
        own) and how long one call may take there (seconds), set by the block."""
        super().__init__(path, shown, interface)

    def acquire(self) -> Instance:
        with self.lock:
            if self.closed:
                raise BlockError(f"{self.shown}: the FMU block was closed")
            unusable = [inst for inst in self.idle if not inst.usable]
            self.idle[:] = [inst for inst in self.idle if inst not in unusable]
            inst = self.idle.pop() if self.idle else None
            if inst is None and self.once_per_process and self.live and self.isolation == "none":
                raise BlockError(f"{self.shown} can be instantiated only once per process, and its "
                                 "instance is in use by another run")
            self.live += 1
        for gone in unusable:  # copies of another process's hosted instances, or ones whose host ended
            gone.free()
        if inst is None:
            try:
                inst = new_instance(self._extracted())
            except BaseException:
                with self.lock:
                    self.live -= 1
                raise
        return inst

    def _extracted(self) -> Binary:
        """What an instance needs, extracting the archive the first time (a run starts)."""
        with self.extract_lock:
            if self.binary is None:
                folder = scratch.folder("fmu-")
                self._dirs.append(str(folder))
                try:
                    extract_archive(self.path, folder)
                    xml = (folder / MODEL_DESCRIPTION).read_bytes()
                except (ArchiveError, OSError, zipfile.BadZipFile, EOFError) as exc:
                    shutil.rmtree(folder, ignore_errors=True)
                    raise BlockError(f"{self.shown}: extracting the FMU failed: {exc}") from None
                if xml != self.description.xml:
                    shutil.rmtree(folder, ignore_errors=True)
                    raise BlockError(f"{self.shown} has changed since the diagram was loaded; load it again")
                self.dir = folder
                self.binary = Binary(self.shown, self.major, self.identifier, self.guid, folder,
                                     folder / self.library, self.in_groups, self.out_groups, self.exchange,
                                     self.integration, self.states, self.indicators, self.completed_step,
                                     [(p.name, p.width) for p in self.inputs.values()],
                                     [(p.name, p.width) for p in self.outputs.values()], self.isolation,
                                     self.timeout, self.scheduled)
        return self.binary

    def release(self, inst: Instance, report: bool = False) -> None:
        """Take an instance back from a run: terminate and pool it, or free it if it failed.
        An instance in a process of its own is also freed there (freeInstance; its process,
        the binary loaded, is what the pool keeps). With ``report`` (the run's end) a crash
        in either call raises its HostFailure, to fail the run; an instance in this process
        is freed when the block is closed."""
        try:
            inst.stop(report=report)
        finally:
            with self.lock:
                self.live -= 1
                keep = not inst.broken and not self.closed
                if keep:
                    self.idle.append(inst)
            if not keep:
                inst.free()

    def close(self) -> None:
        with self.lock:
            self.closed = True
            idle, self.idle[:] = list(self.idle), []
            live = self.live
        for inst in idle:
            inst.free()
        if not live:
            self._cleanup()


def instance_class(model: Binary) -> type[Instance]:
    """The class of an instance of the FMU ``model`` in this process, for its interface and FMI version."""
    if model.scheduled:
        return ScheduledExecution3
    kinds = {(False, 2): CoSimulation2, (False, 3): CoSimulation3, (True, 2): ModelExchange2,
             (True, 3): ModelExchange3}
    return kinds[model.exchange, model.major]


def new_instance(model: Binary) -> Instance | HostedInstance:
    """An instance of the FMU ``model``: in this process, or (isolation 'process') in a
    process of its own (BlockError if its binary does not load or instantiate)."""
    if model.isolation == "process":
        return HostedInstance(model)
    return instance_class(model)(model)


def _remove_model(idle: list, directories: list[str]) -> None:
    for inst in list(idle):
        inst.free()
    idle.clear()
    for directory in directories:
        shutil.rmtree(directory, ignore_errors=True)
