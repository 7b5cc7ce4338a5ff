"""Reachability of targets inside the joint ranges: targets a chain makes itself are found (the
false-negative rate is measured), a target reported reached is reached for certain (the joint
vectors returned are inside the limits and within the tolerance), targets out of reach never are."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import apair
from apair.design.reach import has_exact_ik, reach
from apair.design.targets import Targets

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TOL = 0.002


def own_points(chain, count, seed):
    lim = chain.limits
    q = np.random.default_rng(seed).uniform(lim[:, 0], lim[:, 1], (count, chain.n))
    return q, chain.fk(q)


def check_found(chain, targets, found):
    """Every joint vector returned is inside the limits; those of reached targets are within the
    tolerance of their target."""
    for k, q in enumerate(found.q):
        assert len(q) >= 1
        assert chain.within_limits(q).all()
        if found.reached[k]:
            F = chain.fk(q)
            if targets.kind == "points":
                assert np.linalg.norm(F[:, :3, 3] - targets.values[k], axis=1).max() <= targets.tolerance
            else:
                assert np.linalg.norm(F[:, :3, 3] - targets.values[k][:3, 3], axis=1).max() <= targets.tolerance


@pytest.mark.parametrize("name", ["4a_chain.toml", "2a_chain.toml"])
def test_points_a_chain_reaches_are_found_and_verified(name):
    chain = apair.load(EXAMPLES / name)
    _, T = own_points(chain, 200, seed=11)
    targets = Targets("points", T[:, :3, 3], TOL, None, "own")
    found = reach(chain, targets, scale=0.5, seed=3)
    assert found.reached.mean() >= 0.99, np.flatnonzero(~found.reached)  # the false-negative rate, measured
    assert np.all(found.excess[found.reached] == 0)
    check_found(chain, targets, found)


def test_points_out_of_reach_are_never_reached_and_their_excess_grows_with_the_distance():
    chain = apair.load(EXAMPLES / "4a_chain.toml")
    _, T = own_points(chain, 10, seed=2)
    p = T[:, :3, 3]
    far = p + 2.0 * p / np.linalg.norm(p, axis=1, keepdims=True)  # 2 m further out than a reached point
    farther = p + 3.0 * p / np.linalg.norm(p, axis=1, keepdims=True)
    a = reach(chain, Targets("points", far, TOL, None, "far"), scale=1.0, seed=3)
    b = reach(chain, Targets("points", farther, TOL, None, "far"), scale=1.0, seed=3)
    assert not a.reached.any() and not b.reached.any()
    assert np.all(a.excess > 1.0) and np.all(b.excess > a.excess + 0.9)


def test_narrower_limits_leave_out_what_only_the_wider_range_reaches():
    wide = apair.load(EXAMPLES / "2a_chain.toml")
    narrow = apair.AChain(wide.pairs, wide.a, wide.alpha, wide.offset, wide.theta_offset, limits=[(-0.3, 0.3)] * 2)
    q, T = own_points(wide, 60, seed=5)
    targets = Targets("points", T[:, :3, 3], TOL, None, "own")
    inside = np.all(np.abs(q) <= 0.3, axis=1)
    found = reach(narrow, targets, scale=0.5, seed=3)
    check_found(narrow, targets, found)
    assert found.reached[inside].all()  # what the narrow range reaches itself is found
    assert found.reached.sum() < len(T)  # and something only the wide one reaches is not
    assert reach(wide, targets, scale=0.5, seed=3).reached.all()


def test_poses_are_found_by_the_all_solutions_ik_or_within_the_tolerances():
    chain = apair.load(EXAMPLES / "4a_chain.toml")
    assert has_exact_ik(chain)
    _, T = own_points(chain, 8, seed=9)
    exact = reach(chain, Targets("poses", T, TOL, 0.5, "own"), scale=0.5, seed=3)
    assert exact.reached.all()
    turned = T.copy()
    c, s = math.cos(math.radians(0.2)), math.sin(math.radians(0.2))
    turned[:, :3, :3] = T[:, :3, :3] @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])  # 0.2 deg off the chain's own
    near = reach(chain, Targets("poses", turned, TOL, 0.5, "turned"), scale=0.5, seed=3)
    assert near.reached.all()
    check_found(chain, Targets("poses", turned, TOL, 0.5, "turned"), near)
    moved = T.copy()
    moved[:, :3, 3] *= 5.0
    assert not reach(chain, Targets("poses", moved, TOL, 0.5, "far"), scale=0.5, seed=3).reached.any()


def test_a_chain_without_an_all_solutions_ik_reaches_its_own_poses_by_the_local_solver():
    general = apair.APair(0.05, 0.05, leg_length=0.09)
    chain = apair.AChain([general, apair.APair(0.04, 0.04)], [0.3, 0.2], [0.0, math.pi / 2])
    assert not has_exact_ik(chain)
    _, T = own_points(chain, 20, seed=4)
    found = reach(chain, Targets("poses", T, TOL, 0.5, "own"), scale=0.5, seed=3)
    assert found.reached.mean() >= 0.95
    check_found(chain, Targets("poses", T, TOL, 0.5, "own"), found)


def test_reach_is_deterministic_for_a_seed():
    chain = apair.load(EXAMPLES / "4a_chain.toml")
    _, T = own_points(chain, 30, seed=1)
    targets = Targets("points", T[:, :3, 3] * 1.1, TOL, None, "own")
    a, b = reach(chain, targets, 0.5, 3), reach(chain, targets, 0.5, 3)
    assert np.array_equal(a.reached, b.reached) and np.array_equal(a.excess, b.excess)
    assert all(np.array_equal(x, y) for x, y in zip(a.q, b.q))
