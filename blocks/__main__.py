"""``python -m blocks``: the framework's generic commands (run, validate, graph, plot, fmu
info, sweep, sweep-plot, blocks) on any diagram."""

from blocks.cli import PROGRAM, entry

if __name__ == "__main__":
    entry(PROGRAM)
