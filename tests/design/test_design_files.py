"""The files of a design search: target CSV files (points, poses) and the chain file writer, whose
text reads back through apair.io to the same chain, bit for bit."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import apair
from apair.design.chainfile import dumps
from apair.design.targets import read_targets
from apair.io import chain_from_dict, loads

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_point_targets_take_comments_a_header_and_blank_lines(tmp_path):
    (tmp_path / "t.csv").write_text("# made by hand\nx, y, z\n\n0.1, 0.2, 0.3  # first\n-1e-3,0,2.5\n")
    t = read_targets("targets", {"points": "t.csv", "tolerance": 0.001}, tmp_path)
    assert t.kind == "points" and t.tolerance == 0.001 and t.tolerance_deg is None
    assert t.values.tolist() == [[0.1, 0.2, 0.3], [-1e-3, 0.0, 2.5]]


def test_pose_targets_are_rotations_with_positions(tmp_path):
    R = apair.load(EXAMPLES / "4a_chain.toml").fk([0.1, 0.2, 0.3, 0.4])
    row = ",".join(repr(float(v)) for v in [*R[:3, :3].ravel(), *R[:3, 3]])
    (tmp_path / "p.csv").write_text(row + "\n")
    t = read_targets("targets", {"poses": "p.csv", "tolerance": 0.001, "tolerance_deg": 0.5}, tmp_path)
    assert t.values.shape == (1, 4, 4) and np.array_equal(t.values[0], R)
    bad = np.eye(3)
    bad[0, 0] = -1  # a reflection
    (tmp_path / "p.csv").write_text(",".join(map(str, [*bad.ravel(), 0, 0, 0])) + "\n")
    with pytest.raises(ValueError, match=r"targets\.poses: 'p\.csv' target 1: the rotation is a reflection"):
        read_targets("targets", {"poses": "p.csv", "tolerance": 0.001, "tolerance_deg": 0.5}, tmp_path)
    (tmp_path / "p.csv").write_text(",".join(map(str, [1, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0])) + "\n")
    with pytest.raises(ValueError, match=r"target 1: the rotation is not orthonormal"):
        read_targets("targets", {"poses": "p.csv", "tolerance": 0.001, "tolerance_deg": 0.5}, tmp_path)
    with pytest.raises(ValueError, match=r"targets\.tolerance_deg: missing"):
        read_targets("targets", {"poses": "p.csv", "tolerance": 0.001}, tmp_path)


@pytest.mark.parametrize(
    "table, pattern",
    [
        ({"tolerance": 0.1}, r'give points = "file\.csv" or poses = "file\.csv" \(exactly one\)'),
        ({"points": "t.csv", "poses": "t.csv", "tolerance": 0.1}, r"exactly one"),
        ({"points": "t.csv", "tolerance": 0.1, "tolerance_deg": 1}, r"unknown key 'tolerance_deg' \(rotations"),
        ({"points": "", "tolerance": 0.1}, r"targets\.points: expected a file name"),
        ({"points": "t.csv", "tolerance": True}, r"targets\.tolerance: expected a positive number"),
        ({"points": ".", "tolerance": 0.1}, r"targets\.points: '\.' is a folder"),
    ],
)
def test_a_targets_table_that_cannot_be_read_is_refused_naming_its_key(tmp_path, table, pattern):
    (tmp_path / "t.csv").write_text("1,2,3\n")
    with pytest.raises(ValueError, match=pattern):
        read_targets("targets", table, tmp_path)


def test_non_finite_and_non_utf8_targets_are_refused(tmp_path):
    (tmp_path / "t.csv").write_text("1,2,3\n1,nan,3\n")
    with pytest.raises(ValueError, match=r"line 2: 'nan' is not a finite number"):
        read_targets("targets", {"points": "t.csv", "tolerance": 0.1}, tmp_path)
    (tmp_path / "t.csv").write_bytes(b"1,2,3\n\xff\xfe,1,2\n")
    with pytest.raises(ValueError, match=r"'t\.csv' is not UTF-8 text"):
        read_targets("targets", {"points": "t.csv", "tolerance": 0.1}, tmp_path)


def _same_chain(a, b) -> None:
    for key in ("a", "alpha", "offset", "theta_offset", "gravity"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key
    assert [repr(p) for p in a.pairs] == [repr(p) for p in b.pairs]
    assert np.array_equal(a._links, b._links)
    assert a._explicit_limits == b._explicit_limits


@pytest.mark.parametrize("name", ["4a_chain.toml", "2a_chain.toml", "design/start.toml"])
def test_a_chain_file_written_reads_back_to_the_same_document_and_chain(name):
    doc = tomllib.loads((EXAMPLES / name).read_text())
    text = dumps(doc, ["a comment", "another"])
    assert text.startswith("# a comment\n# another\n")
    assert tomllib.loads(text) == doc
    _same_chain(loads(text), chain_from_dict(doc))


def test_floats_strings_and_limits_round_trip_bit_for_bit():
    rng = np.random.default_rng(4)
    a = [float(x) for x in rng.uniform(0.1, 0.5, 3)]
    doc = {
        "name": 'tricky "name" \\ with ünïcode',
        "description": "two\nlines\twith a tab",
        "gravity": [0.0, 0.0, -9.81],
        "joint": [
            {"pair": "revolute", "a": a[0], "alpha": math.pi / 3, "limits": [-1.0000000000000002, 2.5e-05]},
            {"pair": "sinusoidal", "base_radius": 1e-3 / 3, "platform_radius": 0.001, "a": a[1], "alpha_deg": 90},
            {
                "pair": "general",
                "base_radius": 0.05,
                "platform_radius": 0.04,
                "leg_length": 0.1,
                "a": a[2],
                "alpha": 0.0,
                "inertia": [[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]],
            },
        ],
    }
    text = dumps(doc)
    assert tomllib.loads(text) == doc
    chain = loads(text)
    assert chain.a.tolist() == a and chain.name == doc["name"]


def test_a_value_a_chain_file_cannot_hold_is_refused():
    with pytest.raises(ValueError, match=r"finite numbers only"):
        dumps({"joint": [{"pair": "revolute", "a": math.inf, "alpha": 0.0}]})
    with pytest.raises(ValueError, match=r"cannot write a dict value"):
        dumps({"joint": [{"pair": "revolute", "a": {"x": 1}, "alpha": 0.0}]})
