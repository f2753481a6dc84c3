"""The hand file loader: defaults, strict validation with named fields, overrides."""

import copy

import numpy as np
import pytest
import yaml

from hierhand.model import Hand, HandFileError, HandPlant, load_hand
from hierhand.model.handfile import default_hand_dict


def full():
    return default_hand_dict()


def errors_of(data):
    with pytest.raises(HandFileError) as info:
        load_hand(data)
    return info.value.errors, str(info.value)


def test_default_hand_matches_documented_values():
    hand = Hand.default()
    p = hand.params
    assert hand.names == ("thumb", "fore", "middle")
    assert p.gravity == (0.0, -9.81)
    assert p.fingers[0].links[0].length == pytest.approx(0.046)
    assert p.fingers[1].tip_radius == pytest.approx(0.008)
    assert p.object.mass == pytest.approx(0.3)
    assert p.object.inertia == pytest.approx(0.3 * (0.05**2 + 0.05**2) / 12)
    assert p.contact.k_n == pytest.approx(3e3)
    assert hand.n_points == 200  # 50 mm sides at 1 mm spacing


def test_default_q0_puts_thumb_and_fore_at_the_faces_and_middle_clear():
    hand = Hand.default()
    tips = hand.tip_positions(hand.q0)
    r = hand.tip_radius
    half = 0.025
    thumb_gap = (-half) - (tips[0, 0] + r[0])
    fore_gap = (tips[1, 0] - r[1]) - half
    assert 0.0 <= thumb_gap <= 0.5e-3
    assert 0.0 <= fore_gap <= 0.5e-3
    # both touch the side faces within their span, at the same height (horizontal squeeze)
    assert abs(tips[0, 1] - 0.06) < half and abs(tips[1, 1] - 0.06) < half
    assert tips[0, 1] == pytest.approx(tips[1, 1], abs=1e-5)
    # middle finger: its tip circle is at least 10 mm from the square
    dx = max(abs(tips[2, 0]) - half, 0.0)
    dy = max(abs(tips[2, 1] - 0.06) - half, 0.0)
    assert np.hypot(dx, dy) - r[2] > 10e-3


def test_load_from_yaml_file_round_trip(tmp_path):
    data = Hand.default().params.to_dict()
    data["object"]["mass"] = 0.5
    path = tmp_path / "hand.yaml"
    path.write_text(yaml.safe_dump(data))
    hand = load_hand(path)
    assert hand.params.object.mass == 0.5
    assert hand.params.fingers == Hand.default().params.fingers


def test_yaml_exponent_without_dot_is_read_as_number(tmp_path):
    path = tmp_path / "hand.yaml"
    path.write_text("contact: {k_n: 5e3, c_n: 5, k_t: 5e3, c_t: 5, mu_s: 1, mu_d: 0.9}\n")
    assert load_hand(path).params.contact.k_n == 5000.0


def test_missing_sections_default_and_partial_object_recomputes_inertia():
    hand = load_hand({"object": {"mass": 0.6}})
    assert hand.params.object.mass == 0.6
    assert hand.params.object.inertia == pytest.approx(0.6 * (0.05**2 + 0.05**2) / 12)
    assert hand.params.contact == Hand.default().params.contact
    assert load_hand({"contact": {"mu_s": 0.8, "mu_d": 0.7}}).params.contact.k_n == 3e3


def test_link_mass_must_be_positive_and_the_field_is_named():
    data = full()
    data["fingers"][1]["links"][2]["mass"] = 0.0
    errors, message = errors_of(data)
    assert errors == ["fingers[1].links[2].mass must be > 0, got 0"]
    assert "fingers[1].links[2].mass must be > 0" in message


@pytest.mark.parametrize(
    "mutate, expected",
    [
        (lambda d: d["fingers"][0].update(tip_radius=-0.01), "fingers[0].tip_radius must be > 0"),
        (lambda d: d["fingers"][2].update(damping=[1e-3, -1e-3, 0.0]), "fingers[2].damping[1] must be >= 0"),
        (lambda d: d["fingers"][0].update(q0=[0.1, 0.2]), "fingers[0].q0 must be a list of 3 numbers"),
        (lambda d: d["fingers"][1].update(base=[0.0, "left"]), "fingers[1].base[1] must be a number"),
        (lambda d: d["fingers"][1]["links"][0].update(length=float("nan")), "fingers[1].links[0].length must be finite"),
        (lambda d: d["fingers"][1]["links"][0].update(colour="red"), "fingers[1].links[0].colour is not a known key"),
        (lambda d: d["fingers"][2]["links"][1].pop("inertia"), "fingers[2].links[1].inertia is missing"),
        (lambda d: d["fingers"][0].update(armature=True), "fingers[0].armature must be a list of 3 numbers"),
        (lambda d: d["fingers"].pop(), "fingers must be a list of exactly 3 fingers"),
        (lambda d: d["fingers"][1].update(name="thumb"), "fingers[1].name 'thumb' is used by another finger"),
        (lambda d: d["object"].update(size=[0.05, 0.0]), "object.size[1] must be > 0"),
        (lambda d: d["object"].update(surface_spacing=0.01), "object.surface_spacing must be smaller than the smallest tip_radius"),
        (lambda d: d["contact"].update(mu_d=1.2), "contact.mu_d must be <= contact.mu_s"),
        (lambda d: d["contact"].update(k_t=0), "contact.k_t must be > 0"),
        (lambda d: d.update(gravity=[0.0]), "gravity must be a list of 2 numbers"),
        (lambda d: d.update(friction=1.0), "friction is not a known key"),
    ],
)
def test_bad_fields_are_rejected_with_the_field_named(mutate, expected):
    data = full()
    mutate(data)
    errors, _ = errors_of(data)
    assert any(e.startswith(expected) for e in errors), errors


def test_all_errors_of_a_file_are_reported_at_once():
    data = full()
    data["fingers"][0]["links"][0]["mass"] = -1.0
    data["fingers"][2]["tip_radius"] = 0.0
    data["contact"]["c_n"] = -5.0
    errors, _ = errors_of(data)
    assert len(errors) == 3


def test_file_errors_name_the_file(tmp_path):
    data = full()
    data["object"]["mass"] = -0.3
    path = tmp_path / "bad_hand.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(HandFileError, match=r"bad_hand\.yaml(.|\n)*object\.mass must be > 0"):
        load_hand(path)


def test_plant_parameters_are_validated_like_a_hand_file():
    fingers = copy.deepcopy(full()["fingers"])
    fingers[1]["links"][2]["mass"] = -0.001
    with pytest.raises(ValueError, match=r"fingers\[1\]\.links\[2\]\.mass must be > 0"):
        HandPlant(fingers=fingers)
    plant = HandPlant(contact={"mu_s": 0.5, "mu_d": 0.4})
    assert plant.hand.params.contact.mu_s == 0.5
    assert plant.hand.params.contact.k_n == 3e3


def test_com_given_as_pair_is_used():
    data = full()
    data["fingers"][0]["links"][1]["com"] = [0.01, 0.002]
    link = load_hand(data).params.fingers[0].links[1]
    assert (link.com_along, link.com_across) == (0.01, 0.002)


def test_field_path():
    from hierhand.model.handfile import field_path

    assert field_path("fingers[1].links[2].mass") == ("fingers", 1, "links", 2, "mass")
    assert field_path("object.bogus") == ("object", "bogus")
    assert field_path("") == ()


def test_file_errors_carry_the_line_of_each_field(tmp_path):
    path = tmp_path / "hand.yaml"
    path.write_text("gravity: [0.0, -9.81]\nobject:\n  mass: 0.3\n  bogus: 1\ncontact:\n  k_n: 3.0e3\n  mu: 2\n")
    with pytest.raises(HandFileError) as info:
        load_hand(path)
    err = info.value
    assert err.fields == ["object.bogus", "contact.mu"] and err.lines == [4, 7]
    assert [str(i) for i in err.issues()] == [f"{path}:4: {err.errors[0]}", f"{path}:7: {err.errors[1]}"]


def test_value_errors_of_the_c_core_carry_the_line_of_the_field(tmp_path):
    path = tmp_path / "hand.yaml"
    path.write_text("contact:\n  mu_s: 0.5\n  k_n: -1\nobject:\n  mass: -2\n")
    with pytest.raises(HandFileError) as info:
        load_hand(path)
    assert dict(zip(info.value.fields, info.value.lines)) == {"object.mass": 5, "contact.k_n": 3}


@pytest.mark.parametrize("text, line, message", [
    ("gravity: [0.0, -9.81]\nobject: mass: 1\n", 2, "YAML syntax error"),
    ("- 1\n- 2\n", 1, "the file must be a mapping"),
    ("gravity: " + "[" * 500, 1, "nested deeper than"),
])
def test_unreadable_hand_files_are_one_error_at_a_line(tmp_path, text, line, message):
    path = tmp_path / "hand.yaml"
    path.write_text(text)
    with pytest.raises(HandFileError) as info:
        load_hand(path)
    assert info.value.lines == [line] and message in info.value.errors[0]


def test_plant_parameter_errors_name_their_fields():
    with pytest.raises(HandFileError) as info:
        HandPlant(object={"mass": -1.0, "bogus": 2})
    assert info.value.problems == [(("object", "bogus"), info.value.errors[0])]
