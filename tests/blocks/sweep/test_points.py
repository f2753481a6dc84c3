"""Point generation: grid products, seeded random samples, points files, hashes."""

from __future__ import annotations

import pytest

from blocks.sweep import SweepError
from blocks.sweep.points import (combine, csv_points, grid_points, origins, parse_grid, parse_random,
                                   point_hash, random_points, split_top_level, unique_points)


def test_grid_is_the_cartesian_product_with_yaml_values():
    axes = parse_grid(["a.k=1,2.5,1e-3", "b.v=[1, 2],[3, 4]", "c.on=true"])
    assert axes == {"a.k": [1, 2.5, 0.001], "b.v": [[1, 2], [3, 4]], "c.on": [True]}
    points = grid_points(axes)
    assert len(points) == 6
    assert points[0] == {"a.k": 1, "b.v": [1, 2], "c.on": True}
    assert points[1] == {"a.k": 1, "b.v": [3, 4], "c.on": True}
    assert {(p["a.k"], tuple(p["b.v"])) for p in points} == {(k, v) for k in (1, 2.5, 0.001)
                                                              for v in ((1, 2), (3, 4))}


def test_a_key_may_index_a_list_as_set_does():
    assert parse_grid(["plant.fingers.1.links.0.length=0.040,0.041"]) == {
        "plant.fingers.1.links.0.length": [0.040, 0.041]}


def test_split_keeps_brackets_and_quotes_together():
    assert split_top_level("1,[2,3],{a: 1, b: 2},'x,y'") == ["1", "[2,3]", "{a: 1, b: 2}", "'x,y'"]


@pytest.mark.parametrize("item, message", [
    ("k=1,2", "not BLOCK.PARAM"),
    ("a.0=1,2", "not BLOCK.PARAM"),
    ("a.k", "expected BLOCK.PARAM=V1,V2"),
    ("a.k=1,,2", "empty value"),
    ("a.k=[1,", "YAML syntax error"),
])
def test_bad_grid_items_are_refused(item, message):
    with pytest.raises(SweepError, match=message):
        parse_grid([item])


def test_random_points_are_reproducible_by_seed_and_in_range():
    dists = parse_random(["a.k=uniform(1, 2)", "b.x=normal(0, 0.5)"])
    assert dists == {"a.k": ("uniform", 1.0, 2.0), "b.x": ("normal", 0.0, 0.5)}
    first, again, other = (random_points(dists, 20, 7), random_points(dists, 20, 7), random_points(dists, 20, 8))
    assert first == again
    assert first != other
    assert all(1 <= p["a.k"] < 2 for p in first)
    assert len({p["b.x"] for p in first}) == 20


@pytest.mark.parametrize("item, message", [
    ("a.k=gamma(1,2)", "unknown distribution"),
    ("a.k=uniform(2,1)", "a < b"),
    ("a.k=normal(0,0)", "std > 0"),
    ("a.k=uniform(x,1)", "must be numbers"),
])
def test_bad_distributions_are_refused(item, message):
    with pytest.raises(SweepError, match=message):
        parse_random([item])


def test_grid_crossed_with_random_samples():
    points = combine(grid_points({"a.k": [1, 2]}), random_points(parse_random(["b.x=uniform(0,1)"]), 3, 0))
    assert len(points) == 6 and {p["a.k"] for p in points} == {1, 2}


def test_points_file(tmp_path):
    f = tmp_path / "points.csv"
    f.write_text('prop.k,plant.A\n1,"[[0.9]]"\n2.5,"[[0.5]]"\n\n')
    assert csv_points(f) == [{"prop.k": 1, "plant.A": [[0.9]]}, {"prop.k": 2.5, "plant.A": [[0.5]]}]
    f.write_text("prop.k,plant.A\n1\n")
    with pytest.raises(SweepError, match=":2: 1 values for 2 columns"):
        csv_points(f)
    f.write_text("k\n1\n")
    with pytest.raises(SweepError, match="not BLOCK.PARAM"):
        csv_points(f)
    with pytest.raises(SweepError, match="no such file"):
        csv_points(tmp_path / "missing.csv")


def test_hash_depends_on_diagram_values_and_end_time_not_key_order():
    h = point_hash("d1", {"a.k": 1, "b.x": 2})
    assert h == point_hash("d1", {"b.x": 2, "a.k": 1})
    assert len({h, point_hash("d2", {"a.k": 1, "b.x": 2}), point_hash("d1", {"a.k": 1, "b.x": 3}),
                point_hash("d1", {"a.k": 1, "b.x": 2}, "0.5")}) == 4
    assert len(unique_points([{"a.k": 1}, {"a.k": 1}, {"a.k": 2}], "d", None)) == 2


def test_origins_name_the_option_as_typed():
    assert origins(["a.k=1,2", " b.x =[1],[2]"], ["c.y=uniform(0, 1)"], None, []) == {
        "a.k": "--grid a.k=1,2", "b.x": "--grid  b.x =[1],[2]", "c.y": "--random c.y=uniform(0, 1)"}


def test_origins_of_a_points_file_are_its_header_columns(tmp_path):
    path = tmp_path / "p.csv"
    assert origins([], [], path, [{"a.k": 1, "b.x": 2}]) == {
        "a.k": f"--points {path}:1: column 'a.k'", "b.x": f"--points {path}:1: column 'b.x'"}
