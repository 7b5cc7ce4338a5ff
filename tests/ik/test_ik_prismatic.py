"""All-solutions inverse kinematics of chains with P-pairs (apair.ik.homotopy, a P-pair's slide as
its unknown): the Stanford arm (RRPRRR) against its closed-form solutions, a SCARA (RRPR, 4 joints,
by the virtual joints) against its two elbows, both against a local search from many seeds, the C
tracker against the NumPy one on a P-pair problem, and the refusal of helical pairs."""

from __future__ import annotations

import numpy as np
import pytest

import apair
from apair.ik import homotopy

R, P = apair.APair.revolute, apair.APair.prismatic
STANFORD_OFFSETS = (0.412, 0.154, 0.0, 0.0, 0.0, 0.263)  # d1, d2, (d3 the slide), d4, d5, d6


def stanford() -> apair.AChain:
    """The Stanford arm: twists −90, 90, 0, −90, 90, 0°, no link lengths, the offset d2, joint 3 a
    P-pair (its range wide, so that a local search inside it reaches every solution)."""
    alpha = np.radians([-90, 90, 0, -90, 90, 0])
    limits = [None, None, (-2.0, 2.0), None, None, None]
    return apair.AChain([R(), R(), P(), R(), R(), R()], np.zeros(6), alpha, STANFORD_OFFSETS, limits=limits)


def scara() -> apair.AChain:
    """A SCARA arm: two R-pairs about vertical axes (a = 0.4, 0.3 m), a vertical slide and the
    tool's R-pair about it."""
    limits = [None, None, (-1.0, 1.0), None]
    return apair.AChain(
        [R(), R(), P(), R()], [0.4, 0.3, 0.0, 0.0], [0.0, np.pi, 0.0, 0.0], [0.3, 0.0, 0.0, 0.05], limits=limits
    )


def dh(theta, d, alpha) -> np.ndarray:
    """Rz(θ)·Tz(d)·Rx(α) (no link lengths), for the closed forms."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, 0], [st, ct * ca, -ct * sa, 0], [0, sa, ca, d], [0, 0, 0, 1.0]])


def stanford_closed_form(T: np.ndarray) -> np.ndarray:
    """The Stanford arm's solutions in closed form (8 at a generic pose, the slide of either sign):
    the wrist centre p − d6·z fixes θ1 (y cos θ1 − x sin θ1 = d2, two roots), then θ2 and d3
    (d3 sin θ2 = x cos θ1 + y sin θ1, d3 cos θ2 = z − d1: d3 of either sign), and the wrist
    Rz(θ4)·Ry(θ5)·Rz(θ6) = R03ᵀ·R two triples."""
    d1, d2, _, _, _, d6 = STANFORD_OFFSETS
    x, y, z = T[:3, 3] - d6 * T[:3, 2]
    rho, phi = np.hypot(x, y), np.arctan2(y, x)
    out = []
    for t1 in (phi - np.arcsin(d2 / rho), phi - np.pi + np.arcsin(d2 / rho)):
        u, w = x * np.cos(t1) + y * np.sin(t1), z - d1
        for d3 in (np.hypot(u, w), -np.hypot(u, w)):
            t2 = np.arctan2(u / d3, w / d3)
            R03 = (dh(t1, d1, -np.pi / 2) @ dh(t2, d2, np.pi / 2) @ dh(0.0, d3, 0.0))[:3, :3]
            W = R03.T @ T[:3, :3]
            for s in (1.0, -1.0):
                t5 = np.arctan2(s * np.hypot(W[0, 2], W[1, 2]), W[2, 2])
                t4 = np.arctan2(s * W[1, 2], s * W[0, 2])
                t6 = np.arctan2(s * W[2, 1], -s * W[2, 0])
                out.append([t1, t2, d3, t4, t5, t6])
    q = np.array(out)
    q[:, [0, 1, 3, 4, 5]] = (q[:, [0, 1, 3, 4, 5]] + np.pi) % (2 * np.pi) - np.pi
    return q


def same(a: np.ndarray, b: np.ndarray, slides: np.ndarray, tol: float = 1e-7) -> bool:
    """Whether joint vectors a and b are one (angles modulo 2π, slides as they are)."""
    d = np.where(slides, np.abs(a - b), np.abs((a - b + np.pi) % (2 * np.pi) - np.pi))
    return bool(np.all(d <= tol))


def members(sols: np.ndarray, qs: np.ndarray, slides: np.ndarray, tol: float = 1e-7) -> np.ndarray:
    return np.array([any(same(s, q, slides, tol) for s in sols) for q in qs], bool)


def slides_of(chain) -> np.ndarray:
    return np.array([p.kind == "prismatic" for p in chain.pairs])


def test_stanford_arm_all_solutions_against_its_closed_form():
    """At fk of random joint vectors: 8 verified solutions, certified, exactly the closed form's
    (the generating q among them), and the slide in metres."""
    chain = stanford()
    slides = slides_of(chain)
    rng = np.random.default_rng(38)
    for _ in range(5):
        q = np.concatenate([rng.uniform(-np.pi, np.pi, 2), rng.uniform(0.3, 1.2, 1), rng.uniform(-np.pi, np.pi, 3)])
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert sol.method == "homotopy" and sol.certified, sol.note
        assert len(sol.q) == 8 and np.all(sol.error <= 1e-9)
        assert np.abs(chain.fk(sol.q) - T).max() <= 1e-9
        closed = stanford_closed_form(T)
        assert np.abs(chain.fk(closed) - T).max() <= 1e-9  # the closed form is right
        assert members(sol.q, closed, slides).all() and members(closed, sol.q, slides).all()
        assert members(sol.q, q[None], slides).all()
        assert sol.complex_count == 8  # the design's start set holds 8 (the generic RRPRRR count is more)


def test_stanford_arm_local_search_finds_nothing_else():
    """A Levenberg-Marquardt search from 200 random seeds: every pose it converges to lies in the set."""
    chain = stanford()
    slides = slides_of(chain)
    rng = np.random.default_rng(7)
    q = np.array([0.4, -1.1, 0.7, 0.3, 1.2, -2.0])
    T = chain.fk(q)
    sols = chain.ik(T)
    seeds = np.concatenate(
        [rng.uniform(-np.pi, np.pi, (200, 2)), rng.uniform(-2, 2, (200, 1)), rng.uniform(-np.pi, np.pi, (200, 3))],
        axis=1,
    )
    local = chain.ik_local(np.broadcast_to(T, (200, 4, 4)), seeds)
    found = local.q[local.converged]
    assert len(found) >= 50
    assert members(sols, found, slides, 1e-6).all()
    assert members(found, sols, slides, 1e-6).sum() >= 6  # the search reaches most of the 8


def test_scara_has_its_two_elbows():
    """A SCARA (4 joints: its poses a 4-dimensional set) at poses on it: two solutions, elbow left
    and right (θ2 of opposite sign, the same slide), certified, the generating one among them; a
    pose off the set (a tilted tool) has none."""
    chain = scara()
    slides = slides_of(chain)
    rng = np.random.default_rng(4)
    for _ in range(4):
        q = np.array(
            [
                rng.uniform(-3, 3),
                rng.uniform(0.3, 2.5) * rng.choice([-1, 1]),
                rng.uniform(-0.5, 0.5),
                rng.uniform(-3, 3),
            ]
        )
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert sol.method == "homotopy" and sol.certified, sol.note
        assert len(sol.q) == 2 and np.abs(chain.fk(sol.q) - T).max() <= 1e-9
        assert members(sol.q, q[None], slides).all()
        a, b = sol.q
        assert abs(a[1] + b[1]) <= 1e-7 and abs(a[2] - b[2]) <= 1e-9
        local = chain.ik_local(
            np.broadcast_to(T, (64, 4, 4)),
            np.concatenate(
                [rng.uniform(-3, 3, (64, 2)), rng.uniform(-1, 1, (64, 1)), rng.uniform(-3, 3, (64, 1))], axis=1
            ),
        )
        assert members(sol.q, local.q[local.converged], slides, 1e-6).all()
    tilt = chain.fk(np.array([0.3, 1.0, 0.2, 0.5]))
    c, s = np.cos(0.2), np.sin(0.2)
    tilt[:3, :3] = tilt[:3, :3] @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    sol = chain.ik(tilt, full=True)
    assert len(sol.q) == 0 and sol.certified


def test_slides_beyond_the_limits_are_solutions_too():
    """A P-pair's value is any real: a pose reached with the slide outside its range is solved, the
    solution marked outside the limits (the reach bound, which counts the range, does not cut it)."""
    chain = scara()
    q = np.array([0.5, 1.2, 1.6, -0.4])  # the slide beyond its range (−1, 1)
    sol = chain.ik(chain.fk(q), full=True)
    assert len(sol.q) == 2 and members(sol.q, q[None], slides_of(chain)).all()
    assert not sol.inside.any()


def test_numpy_tracker_agrees_with_the_c_tracker_on_slides():
    """apair_ik_track (C) and track_numpy on the Stanford arm's paths: the same endpoints."""
    if homotopy.tracker.native_in_use() is None:
        pytest.skip("the compiled C kernels are not installed")
    chain = stanford()
    problem = homotopy.Problem.of(chain)
    start = chain.prepare_ik()
    p1 = problem.target(chain.fk(np.array([0.3, -0.2, 0.5, 1.0, -0.7, 0.4])))
    ends = {e: homotopy.track(problem, start.p0, p1, np.exp(0.4j), start.solutions, engine=e) for e in ("c", "numpy")}
    (ec, sc, _, _), (en, sn, _, _) = ends["c"], ends["numpy"]
    both = (sc == homotopy.OK) & (sn == homotopy.OK)
    assert both.sum() == start.count
    assert np.abs(homotopy.canonical(problem, ec[both]) - homotopy.canonical(problem, en[both])).max() < 1e-8


def test_helical_pairs_are_refused():
    chain = apair.AChain(
        [R(), apair.APair.helical(0.01), R()], [0.2, 0.2, 0.1], [0.5, 0.7, 0.2], limits=[None, (-3, 3), None]
    )
    with pytest.raises(ValueError, match=r"pairs\[1\]: a helical pair"):
        chain.ik(np.eye(4))
