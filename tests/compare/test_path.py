"""The common path: followed where it is reachable (the end effector on the path's points at their
quintic times, checked by fk), the motion's work equal to the change of its energy, refused or
reported as not followed where it is not, and its input checked."""

from __future__ import annotations

import math

import numpy as np
import pytest
from compare_designs import SHOULDER, arm3a

from apair.compare import path, twin


@pytest.fixture(scope="module")
def runs():
    """The 3A arm and its twin along a line in front of the shoulder."""
    chain = arm3a()
    corners = np.array([[0.45, -0.2, SHOULDER + 0.1], [0.35, 0.25, SHOULDER - 0.15]])
    t, pts = path.timing(corners)
    out = {}
    for c in (chain, twin.build(chain)):
        ws = c.workspace(samples=8000, seed=1)
        out[c] = path.follow(c, ws, t, pts, 0.4)
    return t, pts, out


def test_quintic_timing_along_the_polyline():
    corners = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [3.0, 4.0, 0.0]])
    t, pts = path.timing(corners)
    u = t / path.DURATION
    s = 7.0 * (10 * u**3 - 15 * u**4 + 6 * u**5)  # the arc length run, 7 m in all
    expected = np.where(s[:, None] <= 3, np.stack([s, 0 * s, 0 * s], 1), np.stack([0 * s + 3, s - 3, 0 * s], 1))
    assert np.allclose(pts, expected, atol=1e-12)
    assert t[0] == 0 and t[-1] == path.DURATION and len(t) == path.STEPS


def test_both_follow_the_path_through_fk(runs):
    t, pts, out = runs
    for chain, run in out.items():
        assert run.followed, run.reason
        assert np.allclose(chain.fk(run.q)[:, :3, 3], pts, atol=1e-8)
        hard = chain.hard_limits()  # ±inf where a joint turns fully
        assert np.all((run.q >= hard[:, 0]) & (run.q <= hard[:, 1]))
        assert run.max_step < path.MAX_STEP


def test_the_work_is_the_change_of_energy(runs):
    """At rest at both ends, ∫ τ·θ' dt = V(end) − V(start): the finite differences and the inverse
    dynamics agree with the energy kernel (to the time step's second order)."""
    t, _, out = runs
    for chain, run in out.items():
        E = chain.energy(run.q[[0, -1]], np.zeros((2, chain.n))).sum(axis=1)
        assert run.work == pytest.approx(E[1] - E[0], rel=1e-4, abs=1e-6)
        assert run.energy >= abs(run.work) - 1e-12
        assert np.allclose(run.peak_torque, np.abs(run.tau).max(axis=0))
        assert np.allclose(run.qd[[0, -1]], 0, atol=2e-3)  # at rest at both ends (quintic)


def test_a_path_out_of_reach_is_not_followed():
    chain = arm3a()
    ws = chain.workspace(samples=8000, seed=1)
    t, pts = path.timing(np.array([[0.45, -0.2, SHOULDER], [2.0, 0.0, SHOULDER]]))
    run = path.follow(chain, ws, t, pts, 0.4)
    assert not run.followed and "no solution within the joint limits" in run.reason
    assert run.peak_torque is None and run.energy is None and len(run.q) < len(pts)


def test_two_joints_follow_no_path():
    import apair

    chain = apair.AChain([apair.APair(0.05, 0.04)] * 2, [0.3, 0.2], [math.pi / 2, 0])
    run = path.follow(chain, None, *path.timing(np.eye(3)[:2]), 0.3)  # type: ignore[arg-type]
    assert not run.followed and "2 joints" in run.reason


@pytest.mark.parametrize(
    ("value", "words"),
    [
        ([[0, 0, 0]], "expected 2 to"),
        ([[0, 0], [1, 1]], "shape (k, 3)"),
        ([[0, 0, 0], [0, 0, 0]], "two consecutive points are the same"),
        ([[0, 0, 0], [np.nan, 0, 0]], "NaN"),
        ("abc", "real numbers"),
    ],
)
def test_bad_points_are_refused_in_one_line(value, words):
    with pytest.raises(ValueError) as exc:
        path.points(value)
    assert str(exc.value).startswith("path: ") and words in str(exc.value) and "\n" not in str(exc.value)


def test_csv_points(tmp_path):
    f = tmp_path / "p.csv"
    f.write_text("# x, y, z [m]\n0.4, 0, 0.3\n\n0.3, 0.2, 0.2  # the end\n")
    assert path.read_csv(str(f)).tolist() == [[0.4, 0, 0.3], [0.3, 0.2, 0.2]]


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("0.4, 0, 0.3\n0.3, 0.2\n", "line 2 of"),
        ("0.4, 0, 0.3\n0.3, x, 0.2\n", "is not numbers"),
        ("0.4, 0, 0.3\n", "expected 2 to"),
        ("0.4, 0, 0.3\n0.3, 0.2, 0.2\n" * 101, "more than 200 points"),
    ],
)
def test_bad_csv_is_refused_in_one_line(tmp_path, text, words):
    f = tmp_path / "p.csv"
    f.write_text(text)
    with pytest.raises(ValueError) as exc:
        path.read_csv(str(f))
    assert str(exc.value).startswith("path: ") and words in str(exc.value) and "\n" not in str(exc.value)


def test_missing_csv_is_refused(tmp_path):
    with pytest.raises(ValueError, match="^path: cannot read"):
        path.read_csv(str(tmp_path / "none.csv"))
