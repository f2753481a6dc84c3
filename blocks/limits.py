"""The limits on what the loader reads, in one place.

A diagram, a params file or a hand file may come from someone else, so every input stops
at one of these limits with a one-line message instead of exhausting memory, the C stack
or the user's patience. Each limit is far above what a real file needs (the shipped
diagrams and hand are a few KB, nest at most 8 levels deep and use no aliases) and far
below what would hurt.
"""

from __future__ import annotations

MAX_YAML_BYTES = 4 * 1024 * 1024
"""Largest diagram, params file or hand file, in bytes (4 MiB). Checked on the open file
before it is read, and no more than this is ever read (a file that grows, or a /proc file
that reports size 0, stops here too). 4 MiB holds a 400 000-entry matrix; loading it takes
a few seconds."""

MAX_YAML_DEPTH = 100
"""Deepest nesting of YAML lists and mappings. libyaml's composer recurses once per level
on the C stack, so 50 000 nested brackets crash the process; the depth is measured from
the parser's events, which need no recursion, before anything is composed. A diagram
nests about 8 levels deep."""

MAX_ALIAS_VALUES = 100_000
"""Most values YAML aliases (``*name``) and merge keys (``<<: *name``) may add by repeating
an anchored value. An alias repeats its anchor's whole value, so ten levels of ten aliases
make 10^10 values from 1 KB of text (the 'billion laughs'); a diagram that shares a
matrix or a block's settings repeats a few hundred."""

MAX_NUMBER_CHARS = 100
"""Longest number a YAML value may write, in characters (digits, sign, point, exponent).
A float64 holds 17 significant digits and the largest integer a parameter takes (a
seed below 2^64) has 20; Python refuses to read integers of over 4300 digits at all, and a
5000-digit integer in a file would otherwise surface as an error deep inside a block."""

MAX_SWEEP_POINTS = 1_000_000
"""Most points one sweep may have, counted before any is made: a grid's axes multiply
(three axes of 1000 values are 10^9 points, gigabytes before the first run), and each
point is held with its hash while the sweep runs. A million re-grasp points take about
2.5 hours of one core; a bigger study is several sweeps (a points file each)."""

MAX_RESULTS_BYTES = 64 * 1024**3
"""Largest ``signals.npz`` a results folder may hold (64 GiB): a run writes what it logs,
so this is only a bound against a file that is not one; what bounds a hostile file is
that its arrays may hold at most 200 times its size once decompressed, checked from each
array's header before anything is allocated (``blocks.results.npzfile``)."""

MAX_PLOT_AXES = 120
"""Most axes one ``plot`` (or ``run --plot``) draws: 20 pages of six. A run that logs more
is plotted a selection at a time (``-s``); drawing 100 000 axes would take hours."""

MAX_PLOT_LINES = 5_000
"""Most lines (signal elements) one plot draws in all: a legend stops naming them at 24
per axis, and a port of a million elements drawn line by line would not finish."""

MAX_PORT_WIDTH = 1_000_000
"""Widest port a block may declare: a signal is copied at every hit, so a width beyond
this is a mistake in a block's parameters rather than a signal anyone logs."""

MAX_FOLDER_NAME = 100
"""Longest folder name made from a diagram's ``name:`` (the default ``runs/<name>``), in
bytes of UTF-8: file systems refuse names beyond 255 bytes, and a results path must leave
room for the folder it is in."""

MAX_SUBSYSTEM_DEPTH = 32
"""Deepest nesting of subsystems (a subsystem inside a subsystem ...): a real diagram nests
a few levels; a chain of files that each include the next is refused past this."""

MAX_SUBSYSTEM_BLOCKS = 200_000
"""Most blocks a diagram's subsystems may add in all. A file that includes another twice,
which includes another twice, ... doubles the blocks per level: 30 small files would make
10^9 blocks. A flat diagram of this size loads and plans in about 40 s."""

MAX_DATA_BYTES = 64 * 1024 * 1024
"""Largest NPZ data file a block reads (FromFile), in bytes, and the most its arrays may
hold once decompressed (64 MiB, 8 million samples): an archive's members are checked
before anything is decompressed, so a small file that inflates to gigabytes is refused.
CSV data files are text and read under MAX_YAML_BYTES, as points files are."""

MAX_DECIMATE = 10**12
"""Largest ``decimate`` of a log entry (and of ``run --decimate`` times an entry's own): a
count of sample hits, kept in the executor's 64-bit integers; a trillion hits of a 1 ps
period is a second, so a larger one logs only the first sample anyway."""

MAX_BLOCK_VALUES = 16 * 1024**2
"""Most numbers one block may hold beyond its ports (state, windows, tables, matrices), 16 Mi
float64 values (128 MiB): products of bounded parameters (a window of 10^6 on an input of
width 1000, a transfer function of degree 10^5) are counted before anything is allocated,
by ``check_block_size``. The shipped blocks hold a few hundred."""


def check_block_size(*factors: tuple[str, int], limit: int = MAX_BLOCK_VALUES,
                     what: str = "values to hold") -> int:
    """The product of ``factors`` (each ``(parameter, value)``: what sizes a block's memory,
    ``("window", 10**6), ("width", 1000)``), or ValueError naming them when it exceeds
    ``limit``: the one check of a block's size, made before its arrays are allocated."""
    total = 1
    for _, value in factors:
        total *= value
    if total > limit:
        shown = " x ".join(f"{name} {value}" for name, value in factors)
        raise ValueError(f"{shown} make {total:.3g} {what}, more than the limit of {limit}")
    return total
