"""Spherical-wrist arms with axes 2 and 3 parallel and a sinusoidal A-pair at joint 1 in closed form
(apair.ik.wrist_slide1, issue 42 part 3): the same solution sets as the general solver (the homotopy,
certified) on the five industrial arms of test_ik_wrist and one with angle offsets,
every solution a multi-start local search finds, the pair's angle at 0, ±π (both twins) and beyond ±π
with the other joints at 0, ±π/2 and π, scales, the NumPy twin against C, and the designs it does not
cover going to the general solver."""

from __future__ import annotations

import numpy as np
import pytest
import test_ik_wrist as wrist_arms

import apair
from apair.ik.parallel_apair import one_per_multiple_root
from apair.ik.poses import refine
from apair.ik.solver import Solver
from apair.ik.wrist_slide1 import WristSlide1

PI = np.pi
R = apair.APair.revolute()
A = apair.APair(0.06, 0.05)  # h = sqrt(2 r_b r_p) = 0.0775
SAME = 1e-6
PERIOD = np.array([4, 2, 2, 2, 2, 2]) * PI
DESIGNS = {name: (*wrist_arms.ARMS[name], None) for name in wrist_arms.INDUSTRIAL}
DESIGNS["KUKA-KR6 offsets"] = (*wrist_arms.ARMS["KUKA-KR6"], [0.3, -PI / 2, 0.2, PI, -0.4, 1.0])


def chain_of(name: str, scale: float = 1.0) -> apair.AChain:
    a, alpha, d, phi = DESIGNS[name]
    pair = apair.APair(A.base_radius * scale, A.platform_radius * scale)
    return apair.AChain(
        [pair, R, R, R, R, R], a=np.multiply(a, scale), alpha=alpha, offset=np.multiply(d, scale), theta_offset=phi
    )


def among(q, sols) -> bool:
    """q among sols: each joint within SAME, the A-pair's angle modulo 4π, the others modulo 2π."""
    d = np.abs((np.asarray(sols).reshape(-1, 6) - q + PERIOD / 2) % PERIOD - PERIOD / 2)
    return bool(np.any(np.all(d < SAME, axis=1)))


def random_q(rng, k):
    return rng.uniform(-1, 1, (k, 6)) * PERIOD / 2


def test_designs_go_to_the_closed_form():
    for name in DESIGNS:
        chain = chain_of(name)
        assert isinstance(Solver(chain)._closed, WristSlide1), name
        q = np.array([2.5, -0.4, 0.3, 0.6, -0.7, 0.8])
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and sol.family.startswith("spherical-"), name
        assert sol.certified and among(q, sol.q), name


@pytest.mark.parametrize("name", list(DESIGNS))
def test_same_sets_as_the_general_solver(name):
    """The homotopy (certified) on random poses of each design: the same solutions both ways."""
    chain = chain_of(name)
    general = Solver(chain)
    general._closed = None
    rng = np.random.default_rng(5)
    for q in random_q(rng, 4):
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and theirs.certified and among(q, ours.q), (name, q)
        assert len(ours.q) == len(theirs.q), (name, q, ours.q, theirs.q)
        assert all(among(s, ours.q) for s in theirs.q), (name, q, ours.q, theirs.q)
        assert np.all(ours.error <= 1e-9)


@pytest.mark.parametrize("name", ["PUMA560", "ABB-IRB6640"])
def test_every_solution_a_multi_start_search_finds(name):
    """An independent check: Levenberg-Marquardt from 300 random seeds per pose inside chain.limits;
    every solution it converges to is among the closed form's."""
    chain = chain_of(name)
    lo, hi = np.array(chain.limits).T
    rng = np.random.default_rng(11)
    for _ in range(3):
        q = rng.uniform(lo, hi)
        T = chain.fk(q)
        ours = chain.ik(T)
        local = chain.ik_local(np.broadcast_to(T, (300, 4, 4)), rng.uniform(lo, hi, (300, 6)), tol=1e-11)
        found = local.q[local.converged]
        assert len(found) > 0
        for s in found:
            assert among(s, ours), (q, s)


@pytest.mark.parametrize("theta1", [0.0, PI, -PI, PI / 2, 1.5 * PI, -1.9 * PI, 2 * PI])
def test_pair_angle_special_values(theta1):
    """θ_1 at 0, ±π (d_1 = 0: both twins are solutions), beyond ±π and at 2π; the other joints at 0,
    ±π/2 and π, the elbow stretched among them. Where ψ_5 = 0 (axes 4 and 6 in line) the member
    given reproduces the pose and the note says so."""
    chain = chain_of("KUKA-KR6")
    for rest in ([0.3, -0.2, 0.5, 0.7, 0.1], [-PI / 2, PI / 2, PI / 2, 0, PI], [0.3, 0.0, -PI, PI, 0.4]):
        q = np.array([theta1, *rest], float)
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert len(sol.q) and np.all(np.abs(chain.fk(sol.q) - T) <= 1e-9), (q, sol.q)
        if abs(np.sin(q[4])) < 1e-12:
            assert "axes 4 and 6 in line" in sol.note, (q, sol.note)
            continue
        assert among(q, sol.q), (q, sol.q, sol.note)
        if abs(abs(theta1) - PI) < 1e-12:
            twin = q.copy()
            twin[0] = -theta1
            assert among(twin, sol.q), (q, sol.q)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_scales(scale):
    """A chain scaled by s has the solutions of the unscaled one at the scaled poses."""
    small, big = chain_of("Fanuc-M20"), chain_of("Fanuc-M20", scale)
    rng = np.random.default_rng(2)
    for q in random_q(rng, 5):
        ours, ref = big.ik(big.fk(q)), small.ik(small.fk(q))
        assert len(ours) == len(ref) and all(among(s, ref) for s in ours), (scale, q)


def test_designs_not_covered_go_to_the_general_solver():
    """cos α_1 ≠ 0 (the slide moves the wrist point along axis 2), axes 2 and 3 not parallel, A-pairs
    at joints 1 and 3 together: no closed form of this kind."""
    a, alpha, d = wrist_arms.ARMS["PUMA560"]
    cases = [
        apair.AChain([A, R, R, R, R, R], a=a, alpha=[-1.2, 0, -PI / 2, PI / 2, -PI / 2, 0], offset=d),
        apair.AChain([A, R, R, R, R, R], a=a, alpha=[-PI / 2, 0.4, -PI / 2, PI / 2, -PI / 2, 0], offset=d),
        apair.AChain([A, R, A, R, R, R], a=a, alpha=alpha, offset=d),
    ]
    for chain in cases:
        assert not isinstance(Solver(chain)._closed, WristSlide1)
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    sol = cases[0].ik(cases[0].fk(q), full=True)
    assert sol.method != "closed form" and among(q, sol.q)


@pytest.mark.parametrize("name", list(DESIGNS))
def test_numpy_twin_gives_the_same_sets(name):
    """The NumPy steps (WristSlide1.candidates, refined) and the C solver (what ik calls) find the
    same solutions on random poses."""
    chain = chain_of(name)
    form = Solver(chain)._closed
    rng = np.random.default_rng(1)
    for q in random_q(rng, 30):
        T = chain.fk(q)
        cands, _ = form.candidates(T)
        twin, _ = one_per_multiple_root(chain, *refine(chain, cands, T, 1e-9, form.scale))
        ours = chain.ik(T)
        assert len(twin) == len(ours) and all(among(s, ours) for s in twin), (name, q)
