"""The kinematic family of a chain (apair.ik.families, issue 42 part 1) against EAIK's own classifier
on the industrial arms and on random designs built from the values arms use (twists of 0, ±90°,
180° and one generic, zero and non-zero lengths and offsets); its invariance under the chain's
scale; what A-pairs do to a family; and where it is said (Solution.family, `apair ik`,
`apair ik-prepare`)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from eaik.IK_DH import DhRobot

import apair
from apair.cli import main
from apair.ik.families import TOLERANCE, classify

PI = np.pi
R = apair.APair.revolute()

# standard DH (a, α, d) of industrial-like arms and EAIK's family for each
ARMS = {
    "UR5": (
        (
            [0, -0.425, -0.39225, 0, 0, 0],
            [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
            [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
        ),
        "three-inner-parallel",
    ),
    "PUMA560": (
        ([0, 0.4318, 0.0203, 0, 0, 0], [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0], [0, 0, 0.15005, 0.4318, 0, 0]),
        "spherical-second-two-parallel",
    ),
    "KUKA-KR": (
        ([0.025, 0.455, 0.035, 0, 0, 0], [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0], [0.4, 0, 0, 0.42, 0, 0.08]),
        "spherical-second-two-parallel",
    ),
    "ABB-IRB6640": (
        ([0.32, 1.075, 0.2, 0, 0, 0], [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0], [0.78, 0, 0, 1.1425, 0, 0.2]),
        "spherical-second-two-parallel",
    ),
    # a spherical wrist whose first two axes meet and no two of the first three are parallel
    "wrist-1∩2": (
        ([0, 0.4, 0.1, 0, 0, 0], [PI / 2, PI / 3, PI / 2, PI / 2, -PI / 2, 0], [0.3, 0.1, 0.2, 0.4, 0, 0.1]),
        "spherical-first-two-intersecting",
    ),
    # the wrist at the base (axes 1, 2, 3 meet): the reversed chain's family
    "base-wrist": (
        ([0, 0, 0.4, 0.3, 0.1, 0], [PI / 2, -PI / 2, 0, PI / 2, 0, 0], [0.3, 0, 0.2, 0.1, 0.1, 0.1]),
        "spherical-first-two-parallel",
    ),
    "general": (
        ([0.1, 0.4, 0.2, 0.1, 0.05, 0], [0.3, 1.1, -0.7, 0.9, -1.3, 0.4], [0.3, 0.1, 0.05, 0.3, 0.1, 0.1]),
        "general",
    ),
}


def _chain(a, alpha, d, pairs=None) -> apair.AChain:
    return apair.AChain(pairs or [R] * 6, a=a, alpha=alpha, offset=d)


def _eaik(a, alpha, d) -> str:
    return DhRobot(np.array(alpha, float), np.array(a, float), np.array(d, float)).getKinematicFamily()


@pytest.mark.parametrize("name", sorted(ARMS))
def test_industrial_arms_as_eaik(name):
    (a, alpha, d), key = ARMS[name]
    c = classify(_chain(a, alpha, d))
    assert c.key == key
    assert c.family is not None and c.family.eaik == _eaik(a, alpha, d)
    assert c.family.reversed == (name == "base-wrist")
    assert c.twin == c.family and c.broken_by == ()


def _designs(count: int, seed: int):
    """Random six-joint designs from the values arms use; coaxial neighbours set apart (EAIK calls
    some of them spherical, and crashes on others: two R-pairs about one line are a self-motion)."""
    rng = np.random.default_rng(seed)
    twists = [0.0, PI / 2, -PI / 2, PI, 0.7]
    for _ in range(count):
        alpha = rng.choice(twists, 6)
        a = np.where(rng.random(6) < 0.5, 0.0, rng.uniform(0.1, 0.5, 6))
        a[5] = 0.0
        d = np.where(rng.random(6) < 0.5, 0.0, rng.uniform(0.1, 0.5, 6))
        yield a, alpha, d, any(abs(np.sin(alpha[k])) < 1e-9 and a[k] == 0 for k in range(5))


def test_random_designs_as_eaik():
    """Every family occurs, and each design gets EAIK's name for it."""
    seen: dict[str, int] = {}
    coaxial = 0
    for a, alpha, d, same_line in _designs(1500, seed=1):
        c = classify(_chain(a, alpha, d))
        if same_line:
            assert c.key == "coaxial", (a, alpha, d)
            coaxial += 1
            continue
        assert c.family is not None
        theirs = _eaik(a, alpha, d)
        assert c.family.eaik == theirs, (a.tolist(), alpha.tolist(), d.tolist(), c.key, theirs)
        seen[c.key] = seen.get(c.key, 0) + 1
    assert coaxial > 0
    assert set(seen) == {
        "general",
        "three-inner-parallel",
        "three-parallel-two-intersecting",
        "spherical-first-two-parallel",
        "spherical-second-two-parallel",
        "spherical-first-two-intersecting",
        "spherical-second-two-intersecting",
        "spherical-no-parallel-no-intersecting",
    }, seen


@pytest.mark.parametrize("scale", [1e-6, 1e-3, 1.0, 1e3, 1e6])
def test_scale_invariant(scale):
    for name, ((a, alpha, d), key) in ARMS.items():
        assert classify(_chain(np.multiply(a, scale), alpha, np.multiply(d, scale))).key == key, (name, scale)


def test_tolerances():
    """Twists and lengths within TOLERANCE (relative to the chain's size) count as exact; beyond it not."""
    (a, alpha, d), _ = ARMS["UR5"]
    near = list(alpha)
    near[1] = near[2] = TOLERANCE / 10
    assert classify(_chain(a, near, d)).key == "three-inner-parallel"
    near[1] = 1e-6
    assert classify(_chain(a, near, d)).key != "three-inner-parallel"
    (a, alpha, d), _ = ARMS["PUMA560"]
    off = list(d)
    off[4] = 0.4318 * TOLERANCE / 10
    assert classify(_chain(a, alpha, off)).key == "spherical-second-two-parallel"
    off[4] = 1e-6
    assert classify(_chain(a, alpha, off)).key == "general"


def test_a_pairs_in_the_families():
    """A slide keeps parallel and meeting axes, but a sliding middle joint of a spherical triple
    moves where the axes meet: the twin's family is broken, by that joint."""
    A = apair.APair(0.06, 0.05)
    (a, alpha, d), _ = ARMS["UR5"]
    for k in range(6):  # three parallel axes survive an A-pair anywhere
        pairs = [R] * 6
        pairs[k] = A
        c = classify(_chain(a, alpha, d, pairs))
        assert c.key == "three-inner-parallel" and c.broken_by == ()
        assert c.sliding_joints() == [k + 1] and f"joint(s) {k + 1}" in c.describe()
    (a, alpha, d), _ = ARMS["PUMA560"]
    for k in range(6):
        pairs = [R] * 6
        pairs[k] = A
        c = classify(_chain(a, alpha, d, pairs))
        assert c.twin is not None and c.twin.key == "spherical-second-two-parallel"
        if k == 4:  # the wrist's middle joint
            assert c.key == "general" and c.broken_by == (5,), c.describe()
            assert "breaks" in c.describe()
        else:
            assert c.key == "spherical-second-two-parallel" and c.broken_by == ()
    (a, alpha, d), _ = ARMS["base-wrist"]
    c = classify(_chain(a, alpha, d, [R, A, R, R, R, R]))
    assert c.key == "general" and c.broken_by == (2,)
    # a P-pair slides too (the Stanford arm: RRPRRR with a spherical wrist)
    stanford = apair.AChain(
        [R, R, apair.APair.prismatic(), R, R, R],
        a=[0] * 6,
        alpha=[-PI / 2, PI / 2, 0, -PI / 2, PI / 2, 0],
        offset=[0.412, 0.154, 0, 0, 0, 0.263],
        limits=[(-PI, PI), (-PI, PI), (0.2, 0.9), (-PI, PI), (-PI, PI), (-PI, PI)],
    )
    c = stanford.kinematic_family()
    assert c.key == "spherical-first-two-intersecting" and c.sliding_joints() == [3]


def test_coaxial_and_other_lengths():
    (a, alpha, d), _ = ARMS["UR5"]
    same = list(alpha)
    same[0] = 0.0  # axes 1 and 2 parallel at a_1 = 0: one line
    c = classify(_chain(a, same, d))
    assert c.key == "coaxial" and c.family is not None and c.family.conditions == "1≡2"
    A = apair.APair(0.06, 0.05)
    c = classify(_chain(a, same, d, [A] + [R] * 5))
    assert c.key != "coaxial"  # an A-pair and an R-pair about one line: a cylindrical pair
    four = apair.AChain([R] * 4, a=[0.1, 0.2, 0.3, 0.1], alpha=[PI / 2, 0, 0, PI / 2], offset=[0.1, 0, 0, 0])
    c = four.kinematic_family()
    assert c.family is None and c.key == "unclassified" and c.facts.parallel == (False, True, True)


def test_said_in_the_answers(tmp_path, capsys):
    (a, alpha, d), _ = ARMS["UR5"]
    chain = _chain(a, alpha, d)
    T = chain.fk([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    sol = chain.ik(T, full=True)
    assert sol.family == "three-inner-parallel" and len(sol.q) == 8
    lines = ["name = 'ur5'"]
    for ai, al, di in zip(a, alpha, d):
        lines += ["[[joint]]", "pair = 'revolute'", f"a = {ai!r}", f"alpha = {al!r}", f"offset = {di!r}"]
    path = tmp_path / "ur5.toml"
    path.write_text("\n".join(lines) + "\n")
    pose = [str(x) for x in T.ravel()[:12]]
    assert main(["ik", str(path), *pose]) == 0
    assert "family three-inner-parallel" in capsys.readouterr().out
    assert main(["ik", str(path), *pose, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["family"] == "three-inner-parallel"
    assert main(["ik-prepare", str(path), "--quiet"]) == 0
    assert "kinematic family: three-inner-parallel (2∥3∥4)" in capsys.readouterr().out
    assert main(["ik-prepare", str(path), "--quiet", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)["family"]
    assert doc["key"] == "three-inner-parallel" and doc["eaik"] == "6R-THREE_INNER_PARALLEL"
    assert doc["parallel"] == [[2, 3], [3, 4]] and doc["meeting"] == [[1, 2], [4, 5], [5, 6]]
