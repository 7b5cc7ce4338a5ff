"""The spec of a design search: read in full and checked before any search, every refusal one line
naming the spec's key; candidates decoded into chain file documents."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from apair.design import design, load_spec
from apair.design.spec import Spec
from apair.io import chain_from_dict


def refused(spec_path, pattern: str) -> str:
    """The one-line message of load_spec's refusal, which must match `pattern`."""
    with pytest.raises(ValueError) as info:
        load_spec(spec_path)
    message = str(info.value)
    assert "\n" not in message, message
    assert re.search(pattern, message), message
    return message


def edit(spec_path, old: str, new: str):
    text = spec_path.read_text()
    assert old in text, (old, text)
    spec_path.write_text(text.replace(old, new))
    return spec_path


def test_a_spec_is_read_with_its_variables_start_and_targets(problem):
    spec = load_spec(problem())
    assert isinstance(spec, Spec)
    assert [v.name for v in spec.variables] == ["joint.1.offset", "joint.2.a", "joint.3.a"]
    assert spec.bounds == [(0.0, 0.3), (0.1, 0.5), (0.1, 0.5)]
    assert spec.x0.tolist() == [0.05, 0.15, 0.40]  # the start file's values
    assert spec.targets is not None and spec.targets.values.shape == (30, 3)
    assert [(o.name, o.sense) for o in spec.objectives] == [("coverage", "maximise")]
    assert load_spec(spec) is spec


def test_a_candidate_is_decoded_into_a_chain_file_document(problem):
    spec = load_spec(problem())
    doc = spec.decode(np.array([0.2, 0.33, 0.27]))
    chain = chain_from_dict(doc)
    assert chain.offset[0] == 0.2 and chain.a[1] == 0.33 and chain.a[2] == 0.27
    assert spec.decode(spec.x0) == spec.start  # the start design is the start file


def test_an_angle_replaces_its_other_unit(problem):
    spec = load_spec(problem(vary='"joint.2.alpha" = [-0.5, 0.5]'))
    assert spec.x0.tolist() == [0.0]  # the start's alpha_deg = 0, in radians
    doc = spec.decode(np.array([0.25]))
    assert doc["joint"][1]["alpha"] == 0.25 and "alpha_deg" not in doc["joint"][1]
    spec = load_spec(problem(vary='"joint.1.alpha_deg" = [45, 135]'))
    assert spec.x0.tolist() == [90.0]


def test_a_choice_of_pair_kinds_keeps_only_the_keys_a_kind_has(problem):
    spec = load_spec(problem(vary='"joint.2.pair" = ["sinusoidal", "revolute"]\n"joint.2.a" = [0.1, 0.5]'))
    assert spec.bounds[0] == (0.0, 2.0) and spec.x0[0] == 0.5
    revolute = spec.decode(np.array([1.7, 0.3]))["joint"][1]
    assert revolute["pair"] == "revolute" and "base_radius" not in revolute and revolute["a"] == 0.3
    assert spec.values(np.array([2.0, 0.3]))["joint.2.pair"] == "revolute"  # the upper bound picks the last
    assert spec.decode(np.array([0.2, 0.3]))["joint"][1]["base_radius"] == 0.04  # the start's


def test_a_general_pair_among_the_choices_needs_its_leg_length(problem):
    refused(
        problem(vary='"joint.2.pair" = ["sinusoidal", "general"]'),
        r'vary\."joint\.2\.pair": a general pair needs leg_length: vary "joint\.2\.leg_length" too',
    )
    spec = load_spec(problem(vary='"joint.2.pair" = ["sinusoidal", "general"]\n"joint.2.leg_length" = [0.08, 0.12]'))
    general = spec.decode(np.array([1.5, 0.1]))["joint"][1]
    assert general["pair"] == "general" and general["leg_length"] == 0.1
    assert "leg_length" not in spec.decode(np.array([0.5, 0.1]))["joint"][1]


@pytest.mark.parametrize(
    "old, new, pattern",
    [
        ('start = "start.toml"', 'start = "nowhere.toml"', r"start: 'nowhere.toml' does not exist"),
        ("budget = 200", "budgett = 200", r"unknown key 'budgett'; did you mean budget\?"),
        ("budget = 200", "budget = 0", r"budget: must be >= 1, got 0"),
        ("seed = 1", "seed = -3", r"seed: must be >= 0"),
        ('"joint.2.a" = [0.1, 0.5]', '"joint.2.a" = [0.5, 0.1]', r'vary\."joint\.2\.a": expected low < high'),
        ('"joint.2.a" = [0.1, 0.5]', '"joint.2.a" = 0.3', r'vary\."joint\.2\.a": expected \[low, high\]'),
        ('"joint.2.a" = [0.1, 0.5]', '"joint.7.a" = [0.1, 0.5]', r"the start chain has joints 1 to 3, not 7"),
        ('"joint.2.a" = [0.1, 0.5]', '"joint2.a" = [0.1, 0.5]', r'expected a key "joint\.K\.key"'),
        ('"joint.2.a" = [0.1, 0.5]', '"joint.2.com" = [0.1, 0.5]', r"com cannot be varied"),
        ('"joint.2.a" = [0.1, 0.5]', '"joint.2.base_radus" = [0.01, 0.1]', r"did you mean base_radius\?"),
        (
            '"joint.2.a" = [0.1, 0.5]',
            '"joint.1.base_radius" = [0.01, 0.1]',
            r"joint 1 is a revolute pair, which has no base_radius",
        ),
        (
            '"joint.2.a" = [0.1, 0.5]',
            '"joint.2.a" = [0.2, 0.5]',
            r"start design's value 0\.15 lies outside \[0\.2, 0\.5\]",
        ),
        (
            '"joint.2.a" = [0.1, 0.5]',
            '"joint.2.alpha" = [0, 90]',
            r"more than a turn in radians; did you mean \"joint\.2\.alpha_deg\"",
        ),
        (
            '"joint.2.a" = [0.1, 0.5]',
            '"joint.2.base_radius" = [0.0, 0.1]',
            r'vary\."joint\.2\.base_radius": 0 \(its low end\) gives an invalid chain: .*base_radius',
        ),
        (
            '"joint.2.a" = [0.1, 0.5]',
            '"joint.2.leg_radius" = [0.0, 0.5]',
            r'vary\."joint\.2\.leg_radius": 0\.5 \(its high end\) gives an invalid chain: .*overlap',
        ),
        ('points = "targets.csv"', 'points = "missing.csv"', r"targets\.points: 'missing\.csv' does not exist"),
        ("tolerance = 0.002", "tolerance = -1", r"targets\.tolerance: expected a positive number"),
        ("tolerance = 0.002", "", r"targets\.tolerance: missing"),
        ('maximise = "coverage"', 'maximise = "coverag"', r"unknown objective 'coverag'; did you mean coverage\?"),
        ('maximise = "coverage"', 'minimise = "coverage"', r"objective\.minimise: coverage is to be maximised"),
        ('maximise = "coverage"', "", r'no objective \(e\.g\. maximise = "coverage"\)'),
        ('maximise = "coverage"', 'maximize = "coverage"', r"unknown key 'maximize'; did you mean maximise\?"),
    ],
)
def test_a_spec_that_cannot_run_is_refused_in_one_line_naming_its_key(problem, old, new, pattern):
    spec_path = edit(problem(), old, new)
    message = refused(spec_path, pattern)
    assert message.startswith(str(spec_path))  # every message names the spec file first


def test_targets_that_do_not_parse_or_are_none_are_refused_before_any_search(problem):
    path = problem()
    (path.parent / "targets.csv").write_text("x,y,z\n0.1,0.2,0.3\n0.1,zz,0.3\n")
    refused(path, r"targets\.points: 'targets\.csv' line 3: 'zz' is not a finite number")
    (path.parent / "targets.csv").write_text("0.1,0.2\n")
    refused(path, r"line 1: expected 3 numbers \(x, y, z\), got 2")
    (path.parent / "targets.csv").write_text("# nothing here\n\nx,y,z\n")
    refused(path, r"targets\.points: 'targets\.csv' holds no targets")


def test_objectives_that_need_targets_refuse_a_spec_without_them(problem):
    path = problem()
    text = path.read_text()
    path.write_text(text[: text.index("[targets]")] + text[text.index("[objective]") :])
    refused(path, r"targets: missing; the objective coverage needs targets")
    path.write_text(path.read_text().replace('maximise = "coverage"', 'maximise = "volume"'))
    assert load_spec(path).targets is None  # the volume needs none


def test_constraints_are_read_and_checked(problem):
    spec = load_spec(problem(extra="[constraints]\nmin_clearance = 0.004\nleg_length = [0.05, 0.3]\n"))
    assert spec.constraints.min_clearance == 0.004 and spec.constraints.leg_length == (0.05, 0.3)
    refused(problem(extra="[constraints]\nmin_clearence = 0.004\n"), r"did you mean min_clearance\?")
    refused(problem(extra="[constraints]\nleg_length = [0.3, 0.05]\n"), r"constraints\.leg_length: expected low < high")
    refused(problem(extra="[constraints]\nmin_clearance = -1\n"), r"constraints\.min_clearance: must be >= 0")


def test_a_budget_below_one_population_is_refused_before_the_search(problem):
    with pytest.raises(ValueError, match=r"budget: 5 is less than one population of the search \(9 candidates for 3"):
        design(problem(budget=5), workers=0)


def test_a_spec_may_be_a_mapping_with_paths_from_the_working_folder(problem, monkeypatch):
    import tomllib

    path = problem()
    monkeypatch.chdir(path.parent)
    spec = load_spec(tomllib.loads(path.read_text()))
    assert spec.where == "spec" and spec.x0.tolist() == [0.05, 0.15, 0.40]
    with pytest.raises(ValueError, match=r"spec: expected a spec file's name, a mapping or a Spec"):
        load_spec(3)
    with pytest.raises(ValueError, match=r"spec: 'nope.toml' does not exist"):
        load_spec("nope.toml")


def test_the_fingerprint_changes_with_whatever_decides_the_search(problem):
    import dataclasses

    spec = load_spec(problem())
    same = load_spec(problem())
    assert spec.fingerprint() == same.fingerprint()
    for changed in (dataclasses.replace(spec, seed=2), dataclasses.replace(spec, budget=201)):
        assert changed.fingerprint() != spec.fingerprint()
    assert load_spec(problem(true=(0.15, 0.31, 0.22, 0.06))).fingerprint() != spec.fingerprint()  # other targets
    assert math.isfinite(spec.x0.sum())
