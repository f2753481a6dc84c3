"""How a Diagram shows itself: a one-line repr, and its wiring graph in Jupyter."""

from __future__ import annotations

from pathlib import Path

import blocks

DIAGRAMS = Path(__file__).resolve().parents[3] / "diagrams"


def test_repr_names_the_diagram_its_file_and_its_size():
    d = blocks.load_diagram(DIAGRAMS / "toy.yaml")
    assert repr(d) == (f"<Diagram 'toy-multirate' ({DIAGRAMS / 'toy.yaml'}): 6 blocks, 7 connections, "
                       "logs plant.y; t_end 1 s>")


def test_repr_of_a_diagram_with_a_subsystem_counts_it_and_its_logged_signals():
    d = blocks.load_diagram(DIAGRAMS / "regrasp.yaml")
    assert repr(d).startswith("<Diagram 'regrasp' (")
    assert f"{len(d.blocks)} blocks (1 subsystem), {len(d.connections)} connections, logs 13 signals; t_end 1 s>" \
        in repr(d)


def test_jupyter_shows_the_wiring_graph_as_svg():
    svg = blocks.load_diagram(DIAGRAMS / "toy.yaml")._repr_svg_()
    assert svg.lstrip().startswith("<?xml") and "<svg" in svg
    assert 'id="block:plant"' in svg and 'id="wire:u.y -&gt; plant.u"' in svg
