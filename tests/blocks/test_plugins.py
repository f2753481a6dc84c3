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
    with pytest.raises(RegistryError, match="'NotABlock' is registered but failed to load: blocks.plugins:load_group"):
        resolve_type("NotABlock")
    with pytest.raises(RegistryError, match="'Gone' is registered but failed to load"):
        resolve_type("Gone")


class Doubler(Gain):
    """A block type of a test collection."""


class Halver(Gain):
    """Another block type of a test collection; ``type_name`` is the name it registers as."""

    type_name = "Half"


PAIR = (Doubler, f"{__name__}:Halver")
"""A collection: a class and a reference to one."""

BROKEN = [Doubler, 42, f"{__name__}:NoSuchBlock", "blocks.plugins:load_group"]
"""A collection holding one type, something that is not a type, a missing class and a non-Block."""

OTHER_DOUBLER = [type("Doubler", (Gain,), {"__doc__": "A different class named as the first."})]
"""Another plug-in's collection that claims the name 'Doubler'."""


def _installed(monkeypatch, *points):
    """The ``blocks.types`` entry points are ``points`` (name, value), and the registry is reloaded."""
    group = registry.ENTRY_POINT_GROUP
    eps = [EntryPoint(name, value, group) for name, value in points]
    monkeypatch.setattr(plugins, "entry_points", lambda group: eps if group == registry.ENTRY_POINT_GROUP else [])
    monkeypatch.setattr(registry, "_cache", None)
    monkeypatch.setattr(registry, "_load_errors", {})


def test_a_collection_registers_each_type_under_its_own_name(monkeypatch):
    _installed(monkeypatch, ("mine", f"{__name__}:PAIR"))
    assert resolve_type("Doubler") is Doubler
    assert resolve_type("Half") is Halver
    assert "mine" not in registry.block_types() and registry._load_errors == {}


def test_what_a_collection_cannot_register_is_left_out_with_its_reason(monkeypatch):
    _installed(monkeypatch, ("mine", f"{__name__}:BROKEN"), ("gone", "no_such_module_anywhere:TYPES"),
               ("text", f"{__name__}:__doc__"))
    assert resolve_type("Doubler") is Doubler
    errors = registry._load_errors
    assert "42" in errors["mine"]
    with pytest.raises(RegistryError, match="'NoSuchBlock' is registered but failed to load: .*NoSuchBlock"):
        resolve_type("NoSuchBlock")
    with pytest.raises(RegistryError, match="'load_group' is registered but failed to load: .* not a Block"):
        resolve_type("load_group")
    assert errors["gone"].startswith("no_such_module_anywhere:TYPES: No module named")
    assert "text" in errors and "text" not in registry.block_types()


def test_a_type_of_a_collection_that_failed_to_load_is_unknown_with_the_failure_in_the_hint(monkeypatch):
    _installed(monkeypatch, ("gone", "no_such_module_anywhere:TYPES"))
    with pytest.raises(RegistryError) as raised:
        resolve_type("HandPlant")
    assert "'gone'" in raised.value.hint and "no_such_module_anywhere" in raised.value.hint


@pytest.mark.parametrize("order", [1, -1])
def test_a_name_two_plugins_give_to_different_classes_is_left_out_whatever_their_order(monkeypatch, order):
    _installed(monkeypatch, *[("mine", f"{__name__}:PAIR"), ("theirs", f"{__name__}:OTHER_DOUBLER")][::order])
    assert "Doubler" not in registry.block_types()
    assert resolve_type("Half") is Halver
    with pytest.raises(RegistryError, match="'Doubler' is registered but failed to load: .* all register it"):
        resolve_type("Doubler")


def test_the_same_class_registered_twice_is_no_conflict_and_a_library_type_is_not_replaced(monkeypatch):
    _installed(monkeypatch, ("mine", f"{__name__}:PAIR"), ("Doubler", f"{__name__}:Doubler"),
               ("Gain", f"{__name__}:Doubler"), ("Sum", "blocks.library.math_blocks:Sum"))
    types = registry.block_types()
    assert types["Doubler"] is Doubler and types["Gain"] is Gain
    assert list(registry._load_errors) == ["Gain"]
