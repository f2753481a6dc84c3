"""The channel between a run and an FMU instance hosted in a process of its own.

Two pieces (the C side and the protocol: ``blocks/csrc/fmu_channel.h``):

- ``Region``, the shared memory both processes map: the request and reply counters, the
  step asked for, the input and output values (float64, port after port in the block's
  order), the name of the FMU function the host called last (so that a crash inside it
  can be named after the host is gone) and its last log messages;
- messages: length-prefixed pickles over a socket pair, for everything but the steady
  step (instantiate, initialise, read, terminate, free, and what a step that was not a
  plain success did). Exceptions travel as plain tuples (``encode`` / ``decode``) and
  are raised on the run's side as the in-process instance would raise them, so the
  block's messages are the same either way.

Both ends are ours (``hosted`` in the run's process, ``host`` in the FMU's), so pickles
are no risk here.
"""

from __future__ import annotations

import functools
import mmap
import os
import pickle
import socket
import struct
from collections.abc import Iterable
from typing import Any

import numpy as np

from blocks.block import BlockError
from blocks.fmu import native as compiled
from blocks.fmu.solvers import CallFailed, SolverError

_LENGTH = struct.Struct("<Q")
_ALIGN = 64


class ChannelClosed(EOFError):
    """The other end of the socket pair is gone (its process ended)."""


@functools.cache
def native() -> dict[str, Any]:
    """The channel's C functions, layout and codes (``blocks._native.fmu_kernel()["host"]``)."""
    found = compiled.native()
    if found is None:
        raise BlockError("running an FMU in a process of its own needs the compiled extension blocks._native, "
                         "which is not built (reinstall with 'pip install -e .')")
    return found["host"]


class Region:
    """The shared memory of one channel, mapped from the file descriptor ``fd``: the
    header of fmu_channel.h, then ``n_in`` input values and the output values."""

    def __init__(self, fd: int, n_in: int | None = None, n_out: int | None = None):
        layout = native()["layout"]
        self.at = layout
        self.fd = fd
        header = -(-layout["size"] // _ALIGN) * _ALIGN
        if n_in is not None:  # the run's side makes the region
            os.ftruncate(fd, header + 8 * (n_in + n_out))
        self.map = mmap.mmap(fd, os.fstat(fd).st_size)
        self.bytes = np.frombuffer(self.map, dtype=np.uint8)
        self.address = self.bytes.__array_interface__["data"][0]
        if n_in is not None:
            self._put("q", "inputs", header)
            self._put("q", "outputs", header + 8 * n_in)
        start, end = self._get("q", "inputs"), self._get("q", "outputs")
        self.inputs = np.frombuffer(self.map, dtype=np.float64, offset=start, count=(end - start) // 8)
        self.outputs = np.frombuffer(self.map, dtype=np.float64, offset=end,
                                     count=(len(self.map) - end) // 8)
        self.inputs_address = self.address + start
        self.outputs_address = self.address + end
        self.call_address = self.address + layout["call"]
        self._marks: dict[str, bytes] = {}
        self._words = np.frombuffer(self.map, dtype=np.int32, count=layout["t"] // 4)
        """The header's 32-bit words (the counters, command and answer), for reading and writing them fast."""
        self._step = np.frombuffer(self.map, dtype=np.float64, count=2, offset=layout["t"])
        """The step asked for, (t, h): adjacent in the header."""
        self._step_code = native()["codes"]["step"]

    @classmethod
    def create(cls, n_in: int, n_out: int) -> Region:
        """A new region (an anonymous memory file) for ``n_in`` input and ``n_out`` output values."""
        return cls(os.memfd_create("blocks-fmu-channel", os.MFD_CLOEXEC), n_in, n_out)

    def _get(self, code: str, field: str) -> Any:
        return struct.unpack_from(code, self.map, self.at[field])[0]

    def _put(self, code: str, field: str, value: Any) -> None:
        struct.pack_into(code, self.map, self.at[field], value)

    @property
    def pending(self) -> bool:
        """Whether a request has not been answered (a call the run stopped waiting for)."""
        words, at = self._words, self.at
        return words[at["request"] // 4] != words[at["reply"] // 4]

    @property
    def command(self) -> int:
        return int(self._words[self.at["command"] // 4])

    @command.setter
    def command(self, value: int) -> None:
        self._words[self.at["command"] // 4] = value

    @property
    def answer(self) -> int:
        return int(self._words[self.at["answer"] // 4])

    def step(self, t: float, h: float) -> None:
        """Ask for the step from ``t`` over ``h`` (the inputs already in place)."""
        self._words[self.at["command"] // 4] = self._step_code
        self._step[0] = t
        self._step[1] = h

    @property
    def asked(self) -> tuple[float, float]:
        """The step asked for: (t, h)."""
        t, h = self._step
        return float(t), float(h)

    # -- the call traced and the log --------------------------------------------------

    def mark(self, name: str) -> None:
        """The FMU function the host is about to call is ``name``."""
        encoded = self._marks.get(name)
        if encoded is None:
            encoded = self._marks[name] = name.encode()[:self.at["call_bytes"] - 1] + b"\0"
        start = self.at["call"]
        self.map[start:start + len(encoded)] = encoded

    @property
    def call(self) -> str:
        """The FMU function the host called last ('' before its first)."""
        start = self.at["call"]
        raw = self.map[start:start + self.at["call_bytes"]]
        return raw.split(b"\0", 1)[0].decode(errors="replace")

    def log(self, line: str) -> None:
        """Keep one of the FMU's log messages (the last ``log_lines`` are kept)."""
        count = self._get("I", "logged")
        size = self.at["log_bytes"]
        start = self.at["log"] + (count % self.at["log_lines"]) * size
        data = line.encode(errors="replace")[:size - 1]
        self.map[start:start + len(data) + 1] = data + b"\0"
        self._put("I", "logged", count + 1)

    def clear_log(self) -> None:
        self._put("I", "logged", 0)

    def log_lines(self) -> list[str]:
        """The FMU's last log messages, oldest first."""
        count, lines, size = self._get("I", "logged"), self.at["log_lines"], self.at["log_bytes"]
        out = []
        for i in range(max(0, count - lines), count):
            start = self.at["log"] + (i % lines) * size
            out.append(self.map[start:start + size].split(b"\0", 1)[0].decode(errors="replace"))
        return out

    def close(self) -> None:
        """Unmap the region and close its file (views of it must be gone)."""
        self.inputs = self.outputs = self.bytes = self._words = self._step = None
        try:
            self.map.close()
        except BufferError:  # a view of it is still alive somewhere: the map goes with it
            pass
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1


def ports_of(values: np.ndarray, ports: Iterable[tuple[str, int]]) -> dict[str, np.ndarray]:
    """``values`` cut into the ports ``(name, width)``, in that order (views)."""
    out, first = {}, 0
    for name, width in ports:
        out[name] = values[first:first + width]
        first += width
    return out


def put_ports(values: np.ndarray, ports: Iterable[tuple[str, int]], given: dict[str, Any]) -> None:
    """Write the ports ``given`` into ``values``, laid out as ``ports_of`` reads them."""
    first = 0
    for name, width in ports:
        values[first:first + width] = given[name]
        first += width


# -- messages ---------------------------------------------------------------------------

def send(sock: socket.socket, message: Any) -> None:
    """One message: its length, then its pickle."""
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    sock.sendall(_LENGTH.pack(len(data)))
    sock.sendall(data)


def receive(sock: socket.socket) -> Any:
    """The next message; ChannelClosed if the other end has closed."""
    (length,) = _LENGTH.unpack(_exactly(sock, _LENGTH.size))
    return pickle.loads(_exactly(sock, length))


def _exactly(sock: socket.socket, n: int) -> bytes:
    data = bytearray(n)
    view, got = memoryview(data), 0
    while got < n:
        count = sock.recv_into(view[got:], n - got)
        if count == 0:
            raise ChannelClosed("the other end of the FMU's channel closed")
        got += count
    return bytes(data)


# -- exceptions across ------------------------------------------------------------------

def encode(exc: BaseException) -> tuple:
    """An exception of the FMU's calls as plain data."""
    if isinstance(exc, BlockError):
        return ("BlockError", str(exc), exc.port)
    if isinstance(exc, CallFailed):
        return ("CallFailed", exc.function, exc.status, exc.time)
    if isinstance(exc, SolverError):
        return ("SolverError", str(exc))
    function = getattr(exc, "function", None)
    if function is not None:  # fmpy's FMICallException
        return ("FMICall", function, getattr(exc, "status", None))
    return ("Exception", type(exc).__name__, str(exc))


def decode(data: tuple) -> Exception:
    """The exception ``encode`` made plain, as it was raised."""
    kind, *args = data
    if kind == "BlockError":
        return BlockError(args[0], port=args[1])
    if kind == "CallFailed":
        return CallFailed(*args)
    if kind == "SolverError":
        return SolverError(args[0])
    if kind == "FMICall":
        from blocks.fmu.instance import call_failed

        return call_failed(*args)
    return _named(args[0])(args[1])


@functools.cache
def _named(name: str) -> type:
    """An exception class of the name of one raised in the host (its message says what it was)."""
    return type(name, (Exception,), {"__module__": "blocks.fmu.isolation.server"})
