"""Plug-ins through entry points: what loads is registered, what does not is named with its reason."""

from __future__ import annotations

from importlib.metadata import EntryPoint

import pytest

from blocks import plugins, registry
from blocks.library.math_blocks import Gain
from blocks.registry import RegistryError, resolve_type


@pytest.fixture
def fake_types(monkeypatch):
    """Three ``blocks.types`` plug-ins: a block, something that is not one, a missing module."""
    group = registry.ENTRY_POINT_GROUP
    points = [EntryPoint("Doubler", "blocks.library.math_blocks:Gain", group),
              EntryPoint("NotABlock", "blocks.plugins:load_group", group),
              EntryPoint("Gone", "no_such_module_anywhere:Block", group)]
    monkeypatch.setattr(plugins, "entry_points", lambda group: points if group == registry.ENTRY_POINT_GROUP else [])
    monkeypatch.setattr(registry, "_cache", None)
    monkeypatch.setattr(registry, "_load_errors", {})


def test_load_group_keeps_what_loads_and_says_why_the_rest_does_not(fake_types):
    found, errors = plugins.load_group(registry.ENTRY_POINT_GROUP, lambda obj: None if obj is Gain else "is wrong")
    assert found == {"Doubler": Gain}
    assert errors["NotABlock"] == "blocks.plugins:load_group is wrong"
    assert errors["Gone"].startswith("no_such_module_anywhere:Block: No module named")


def test_a_broken_block_plugin_is_named_when_a_diagram_asks_for_it(fake_types):
    assert resolve_type("Doubler") is Gain and resolve_type("Gain") is Gain
    with pytest.raises(RegistryError, match="'NotABlock' is registered but failed to load: .* is not a Block subclass"):
        resolve_type("NotABlock")
    with pytest.raises(RegistryError, match="'Gone' is registered but failed to load"):
        resolve_type("Gone")
