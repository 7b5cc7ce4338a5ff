"""Inverse kinematics of 7-joint chains: ik(T) refused in one line (a continuum of solutions),
ik(T, fix={k: value}) exact on the chain folded to 6 joints (every k, on the Panda, round trip and
the original q found), fix on chains of up to 6 joints, the fold itself against the 4x4 product,
and ik_local on the Panda."""

from __future__ import annotations

import math

import numpy as np
import pytest
from chain7_robots import panda

import apair
from apair.frames import dh_matrix as _dh_matrix
from apair.hold import _as_dh, hold


@pytest.fixture(scope="module")
def chain() -> apair.AChain:
    return panda().chain


def _pose(chain: apair.AChain, seed: int) -> tuple[np.ndarray, np.ndarray]:
    lim = chain.limits
    q = np.random.default_rng(seed).uniform(lim[:, 0] + 0.1, lim[:, 1] - 0.1)
    return q, chain.fk(q)


def test_seven_joint_ik_without_fix_is_refused_in_one_line(chain: apair.AChain) -> None:
    _, T = _pose(chain, 0)
    with pytest.raises(ValueError, match=r"^fix: a 7-joint chain .*fix=\{k: value\}.*ik_local") as exc:
        chain.ik(T)
    assert "\n" not in str(exc.value)


@pytest.mark.slow
@pytest.mark.parametrize("k", range(1, 8))
def test_seven_joint_ik_with_one_joint_held(chain: apair.AChain, k: int) -> None:
    for seed in (2, 3):
        q, T = _pose(chain, seed)
        sol = chain.ik(T, fix={k: q[k - 1]}, full=True)
        assert sol.q.shape[1] == 7 and len(sol.q) >= 1
        assert np.all(sol.q[:, k - 1] == q[k - 1])
        assert np.abs(sol.q - q).max(axis=1).min() < 1e-8  # the original joint vector is among them
        for x, err in zip(sol.q, sol.error):
            gap = float(np.abs(chain.fk(x) - T).max())
            assert gap < 1e-9 and err < 1e-9, (k, gap, err)
        assert sol.inside is not None and np.array_equal(sol.inside, chain.within_limits(sol.q))
        inside = chain.ik(T, fix={k: q[k - 1]}, within_limits=True)
        assert np.array_equal(inside, sol.q[sol.inside])


def test_seven_joint_ik_joint_4_held_at_seed_1(chain: apair.AChain) -> None:
    """The Panda folded at joint 4 has axes 1, 2, 3 meeting (a spherical wrist at the base end): the
    closed form of the reversed chain answers, with the pose's own q among its 8. (The homotopy's
    start set of this folded design has 4 solutions where the pose has at least 5 real ones; the
    issue 38 part 3 report.)"""
    q, T = _pose(chain, 1)
    sol = chain.ik(T, fix={4: q[3]}, full=True)
    assert sol.method == "closed form" and sol.family.startswith("spherical-") and len(sol.q) == 8
    assert np.abs(sol.q - q).max(axis=1).min() < 1e-8
    assert max(float(np.abs(chain.fk(x) - T).max()) for x in sol.q) < 1e-9


def test_seven_joint_ik_with_an_interior_joint_held(chain: apair.AChain) -> None:
    q, T = _pose(chain, 3)
    got = chain.ik(T, fix={3: q[2]})  # an interior joint: folded into joints 2 and 4
    assert np.abs(got - q).max(axis=1).min() < 1e-8
    assert max(float(np.abs(chain.fk(x) - T).max()) for x in got) < 1e-9


def test_fold_is_the_same_chain() -> None:
    """The folded chain's fk equals the original's with the held joints inserted, on a random
    7-joint chain of R- and A-pairs with base and tool frames, for every held joint (and pairs)."""
    rng = np.random.default_rng(11)
    pairs = [apair.APair.revolute() for _ in range(7)]
    pairs[2] = apair.APair(base_radius=0.06, platform_radius=0.05)  # sinusoidal
    base = apair.frame((0.1, -0.2, 0.3), (0.2, -0.1, 0.4))
    tool = apair.frame((0.0, 0.05, 0.12), (0.3, 0.2, -0.1))
    c = apair.AChain(
        pairs,
        a=rng.uniform(-0.3, 0.3, 7),
        alpha=rng.uniform(-2, 2, 7),
        offset=rng.uniform(-0.2, 0.2, 7),
        theta_offset=rng.uniform(-2, 2, 7),
        base=base,
        tool=tool,
    )
    lim = c.limits
    for fix_at in ([1], [4], [7], [3], [2, 6], [1, 7]):
        q = rng.uniform(lim[:, 0], lim[:, 1], (5, 7))
        held = {k: float(q[0, k - 1]) for k in fix_at}
        sub, index, _ = hold(c, held, apair.AChain)
        assert sub.n == 7 - len(fix_at) and index == [i for i in range(7) if i + 1 not in fix_at]
        full = q.copy()
        for k, v in held.items():
            full[:, k - 1] = v
        assert np.abs(sub.fk(full[:, index]) - c.fk(full)).max() < 1e-13


@pytest.mark.parametrize("seed", range(40))
def test_as_dh_rebuilds_the_transform(seed: int) -> None:
    rng = np.random.default_rng(seed)
    angles = rng.uniform(-math.pi, math.pi, 4)
    G = _dh_matrix(rng.uniform(-1, 1), angles[0], rng.uniform(-1, 1), angles[1])
    G = G @ _dh_matrix(rng.uniform(-1, 1), angles[2], rng.uniform(-1, 1), angles[3])
    if seed % 4 == 0:  # parallel axes, then coincident ones
        G = _dh_matrix(rng.uniform(-1, 1) * (seed % 8 == 0), 0.0, rng.uniform(-1, 1), angles[0])
    delta, e, a, alpha, delta2, e2 = _as_dh(G)
    screw = _dh_matrix(0.0, 0.0, e2, delta2)
    assert np.abs(_dh_matrix(a, alpha, e, delta) @ screw - G).max() < 1e-14


def test_fix_reduces_a_six_joint_chain() -> None:
    rng = np.random.default_rng(5)
    R = apair.APair.revolute()
    c = apair.AChain([R] * 6, a=rng.uniform(0.1, 0.5, 6), alpha=rng.uniform(-1.5, 1.5, 6))
    q = rng.uniform(-2, 2, 6)
    T = c.fk(q)
    for fix in ({3: q[2]}, {1: q[0]}, {2: q[1], 5: q[4]}):
        got = c.ik(T, fix=fix)
        assert got.shape[1] == 6 and np.abs(got - q).max(axis=1).min() < 1e-8
        assert max(float(np.abs(c.fk(x) - T).max()) for x in got) < 1e-9


@pytest.mark.parametrize(
    ("fix", "match"),
    [
        ({0: 0.1}, r"^fix: must be >= 1, got 0$"),
        ({8: 0.1}, r"^fix: must be <= 7, got 8$"),
        ({1.5: 0.1}, r"^fix: expected an integer"),
        ({2: math.nan}, r"^fix\[2\]: "),
        ({2: 2.5}, r"^fix\[2\]: 2\.5 rad lies outside joint 2's range"),
        ({}, r"^fix: expected at least one joint"),
        ([0.1], r"^fix: expected a mapping"),
        ("all", r"^fix: holds all 7 joints"),
    ],
)
def test_fix_refusals(chain: apair.AChain, fix: object, match: str) -> None:
    _, T = _pose(chain, 0)
    if fix == "all":
        fix = {k: float(np.mean(chain.limits[k - 1])) for k in range(1, 8)}
    with pytest.raises(ValueError, match=match) as exc:
        chain.ik(T, fix=fix)  # type: ignore[arg-type]
    assert "\n" not in str(exc.value)


def test_fix_where_the_rest_has_no_isolated_solutions(chain: apair.AChain) -> None:
    q, T = _pose(chain, 4)
    q[1] = 0.0  # joint 2 straight: joints 1 and 3 on one axis
    with pytest.raises(ValueError, match=r"^fix: with joint\(s\) 2 held there, the inverse kinematics has no isolated"):
        chain.ik(chain.fk(q), fix={2: 0.0})


def test_ik_local_converges_on_the_panda(chain: apair.AChain) -> None:
    rng = np.random.default_rng(9)
    lim = chain.limits
    q = rng.uniform(lim[:, 0] + 0.2, lim[:, 1] - 0.2, (20, 7))
    T = chain.fk(q)
    seeds = np.clip(q + rng.normal(scale=0.1, size=q.shape), lim[:, 0], lim[:, 1])
    sol = chain.ik_local(T, seeds)
    assert np.all(sol.converged)
    assert np.abs(chain.fk(sol.q) - T).max() < 1e-9
    assert np.all(chain.within_limits(sol.q))
    one = chain.ik_local(T[0], seeds[0])  # the single-pose fast path
    assert one.converged and np.abs(chain.fk(one.q) - T[0]).max() < 1e-9


def test_prepare_ik_refuses_seven_joints(chain: apair.AChain) -> None:
    with pytest.raises(ValueError, match=r"^chain: start systems are for 5 and 6 joints \(this chain has 7; .*fix="):
        chain.prepare_ik()


@pytest.mark.slow
def test_cli_ik_with_fix(chain: apair.AChain, tmp_path, capsys) -> None:
    """apair ik FILE POSE --fix K=VALUE: the Panda's chain file (apair import urdf) solved with
    joint 7 held (degrees with --deg); the original q among the JSON solutions; a malformed --fix
    is one line naming --fix."""
    import json

    from chain7_robots import panda_path

    from apair.cli import main

    out = tmp_path / "panda.toml"
    assert main(["import", "urdf", str(panda_path()), "--tip", "panda_link8", "--out", str(out)]) == 0
    capsys.readouterr()
    q, T = _pose(apair.load(out), 2)
    pose = [repr(float(x)) for x in T.ravel()]
    assert main(["ik", str(out), *pose, "--fix", f"7={math.degrees(q[6])!r}", "--deg", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    found = np.array([s["q"] for s in doc["solutions"]])
    assert np.abs(found - q).max(axis=1).min() < 1e-7
    for bad in ("7", "x=1", "0=1", "8=0.1", "7=nan"):
        assert main(["ik", str(out), *pose, "--fix", bad]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--fix" in err, err
