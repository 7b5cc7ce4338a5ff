"""UR-like arms with sinusoidal A-pairs at joint 1 and/or joint 5 in closed form (apair.ik.parallel_slides,
issue 42 part 3): the same solution sets as the general solver (the homotopy, certified) on UR designs
and special ones (antiparallel axes, angle offsets, a_5 ≠ 0: the quartic, axes 5 and 6 parallel),
every solution a multi-start local search finds, the pairs' angles at 0, ±π (both twins) and beyond
±π with the other joints at 0, ±π/2 and π, the wrist singularity (a continuum: one member), scales,
the NumPy twin against C, and the designs it does not cover going to the general solver."""

from __future__ import annotations

import numpy as np
import pytest

import apair
from apair.ik.parallel_apair import one_per_multiple_root
from apair.ik.parallel_slides import ParallelSlides
from apair.ik.poses import refine
from apair.ik.solver import Solver

PI = np.pi
R = apair.APair.revolute()
A = apair.APair(0.06, 0.05)  # h = sqrt(2 r_b r_p) = 0.0775
SAME = 1e-6

UR5 = ([0, -0.425, -0.39225, 0, 0, 0], [PI / 2, 0, 0, PI / 2, -PI / 2, 0], [0.089159, 0, 0, 0.10915, 0.09465, 0.0823])
# (a, alpha, d, theta_offset, the A-pairs' joints from 1)
DESIGNS = {
    "UR5 A1": (*UR5, None, (1,)),
    "UR5 A5": (*UR5, None, (5,)),
    "UR5 A1 A5": (*UR5, None, (1, 5)),
    "UR10e A1 A5 offsets": (
        [0, -0.6127, -0.57155, 0, 0, 0],
        [-PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.1807, 0, 0, 0.17415, 0.11985, 0.11655],
        [0.3, -0.2, PI, 0.1, 2.0, 0.5],
        (1, 5),
    ),
    "antiparallel, a5 != 0 (quartic)": (
        [0.1, 0.4, 0.35, 0.02, 0.05, 0.03],
        [PI / 2, PI, 0, -PI / 2, 1.1, 0.4],
        [0.2, 0.05, -0.1, 0.12, 0.09, 0.08],
        None,
        (1, 5),
    ),
    "axes 5, 6 parallel": (
        [0.05, 0.4, 0.35, 0, 0.06, 0],
        [PI / 2, 0, 0, PI / 2, 0, 0],
        [0.15, 0, 0.02, 0.1, 0.09, 0.08],
        [0, 0, 0, 0.4, 0, 0],  # (at q = 0 axes 5 and 6 are not along axis 1: a curve of solutions there)
        (1, 5),
    ),
}


def chain_of(name: str, scale: float = 1.0) -> apair.AChain:
    a, alpha, d, phi, at = DESIGNS[name]
    pair = apair.APair(A.base_radius * scale, A.platform_radius * scale)
    return apair.AChain(
        [pair if i + 1 in at else R for i in range(6)],
        a=np.multiply(a, scale),
        alpha=alpha,
        offset=np.multiply(d, scale),
        theta_offset=phi,
    )


def periods(chain) -> np.ndarray:
    return np.array([2 * PI if p.kind == "revolute" else 4 * PI for p in chain.pairs])


def among(q, sols, per) -> bool:
    """q among sols: each joint within SAME, an A-pair's angle modulo 4π, the others modulo 2π."""
    sols = np.asarray(sols).reshape(-1, 6)
    d = np.abs((sols - q + per / 2) % per - per / 2)
    return bool(np.any(np.all(d < SAME, axis=1)))


def general_solver(chain) -> Solver:
    s = Solver(chain)
    s._closed = None
    return s


def random_q(rng, chain, k):
    return rng.uniform(-1, 1, (k, 6)) * periods(chain) / 2


def test_designs_go_to_the_closed_form():
    for name in DESIGNS:
        chain = chain_of(name)
        assert isinstance(Solver(chain)._closed, ParallelSlides), name
        q = np.array([0.3, -0.4, 2.5, 0.6, -0.7, 0.8])
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and sol.family == "three-inner-parallel", name
        assert sol.certified and among(q, sol.q, periods(chain)), name


@pytest.mark.parametrize("name", list(DESIGNS))
def test_same_sets_as_the_general_solver(name):
    """The homotopy (certified) on random poses of each design: the same solutions both ways."""
    chain = chain_of(name)
    general, per = general_solver(chain), periods(chain)
    rng = np.random.default_rng(5)
    for q in random_q(rng, chain, 4):
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and theirs.certified, (name, q)
        assert among(q, ours.q, per), (name, q)
        assert len(ours.q) == len(theirs.q), (name, q, ours.q, theirs.q)
        assert all(among(s, theirs.q, per) for s in ours.q), (name, q)
        assert np.all(ours.error <= 1e-9)


def test_every_solution_a_multi_start_search_finds():
    """An independent check: Levenberg-Marquardt from 300 random seeds per pose inside chain.limits
    (the pairs' collision-free ranges); every solution it converges to is among the closed form's."""
    chain = chain_of("UR5 A1 A5")
    lo, hi = np.array(chain.limits).T
    rng = np.random.default_rng(11)
    for _ in range(4):
        q = rng.uniform(lo, hi)
        T = chain.fk(q)
        ours = chain.ik(T)
        local = chain.ik_local(np.broadcast_to(T, (300, 4, 4)), rng.uniform(lo, hi, (300, 6)), tol=1e-11)
        found = local.q[local.converged]
        assert len(found) > 0
        for s in found:
            assert among(s, ours, periods(chain)), (q, s)


@pytest.mark.parametrize("theta", [0.0, PI, -PI, PI / 2, 1.5 * PI, -1.9 * PI, 2 * PI])
def test_pair_angle_special_values(theta):
    """θ_1 and θ_5 at 0, ±π (d = 0: both twins are solutions), beyond ±π and at 2π; the other joints
    at 0, ±π/2 and π, ψ_1 = π among them (the root at t = ∞). Where ψ_5 is 0 or π (axis 6 parallel to
    axes 2-4) ψ_6 and the elbow are a continuum: the member given reproduces the pose."""
    chain, per = chain_of("UR5 A1 A5"), periods(chain_of("UR5 A1 A5"))
    for rest in ([0, 0, 0, 0], [-PI / 2, PI / 2, PI / 2, 0], [0.3, -PI, 1.0, PI]):
        for joint in (0, 4):
            q = np.array([0.7, *rest[:3], -1.2, rest[3]], float)
            q[joint] = theta
            T = chain.fk(q)
            sol = chain.ik(T, full=True)
            assert np.all(np.abs(chain.fk(sol.q) - T) <= 1e-9)
            if np.isclose(abs(np.sin(q[4])), 0.0, atol=1e-12):  # the wrist singularity
                assert "continuum" in sol.note and len(sol.q), (q, sol.note)
                continue
            assert among(q, sol.q, per), (q, sol.q, sol.note)
            if abs(abs(theta) - PI) < 1e-12:
                twin = q.copy()
                twin[joint] = -theta
                assert among(twin, sol.q, per), (q, sol.q)


def test_wrist_singularity_is_a_continuum_with_the_slides_fixed():
    """ψ_5 = 0: axis 6 parallel to axes 2-4; joints 1 and 5 (and so their slides) stay fixed and ψ_6
    turns with the elbow, a continuum: the R-arm's member (the elbow mid-range), noted."""
    chain = chain_of("UR5 A1 A5")
    q = np.array([0.4, -0.9, 1.2, 0.3, 0.0, 0.5])
    T = chain.fk(q)
    sol = chain.ik(T, full=True)
    assert "continuum" in sol.note and "axis 6 parallel" in sol.note
    assert len(sol.q) and np.all(np.abs(chain.fk(sol.q) - T) <= 1e-9)
    for theta1 in (q[0], q[0] - 2 * PI):  # each slide of the pose's ψ_1 and ψ_5: the two elbows' members
        for theta5 in (0.0, 2 * PI):
            member = (np.abs(sol.q[:, 0] - theta1) < SAME) & (np.abs(sol.q[:, 4] - theta5) < SAME)
            assert member.sum() == 2, (theta1, theta5, sol.q)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_scales(scale):
    """A chain scaled by s has the solutions of the unscaled one at the scaled poses."""
    small, big = chain_of("UR5 A1 A5"), chain_of("UR5 A1 A5", scale)
    rng = np.random.default_rng(2)
    for q in random_q(rng, small, 5):
        ours, ref = big.ik(big.fk(q)), small.ik(small.fk(q))
        assert len(ours) == len(ref) and all(among(s, ref, periods(small)) for s in ours), (scale, q)


def test_designs_not_covered_go_to_the_general_solver():
    """A slide with a component along the parallel axes (cos α_1 ≠ 0 with an A-pair at joint 1,
    cos α_4 ≠ 0 at joint 5), A-pairs at joints 1 and 3 together: no closed form."""
    a, alpha, d = UR5
    cases = [
        apair.AChain([A, R, R, R, R, R], a=a, alpha=[1.2, 0, 0, PI / 2, -PI / 2, 0], offset=d),
        apair.AChain([R, R, R, R, A, R], a=a, alpha=[PI / 2, 0, 0, 1.1, -PI / 2, 0], offset=d),
        apair.AChain([A, R, A, R, R, R], a=a, alpha=alpha, offset=d),
    ]
    for chain in cases:
        assert Solver(chain)._closed is None
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    sol = cases[0].ik(cases[0].fk(q), full=True)
    assert sol.method != "closed form" and among(q, sol.q, periods(cases[0]))


@pytest.mark.parametrize("name", list(DESIGNS))
def test_numpy_twin_gives_the_same_sets(name):
    """The NumPy steps (ParallelSlides.candidates, refined) and the C solver (apair_ik_parallel_apair,
    what ik calls) find the same solutions on random poses."""
    chain = chain_of(name)
    form = Solver(chain)._closed
    rng = np.random.default_rng(1)
    for q in random_q(rng, chain, 30):
        T = chain.fk(q)
        cands, _ = form.candidates(T, 1e-9)
        twin, _ = one_per_multiple_root(chain, *refine(chain, cands, T, 1e-9, form.scale))
        ours = chain.ik(T)
        assert len(twin) == len(ours) and all(among(s, ours, periods(chain)) for s in twin), (name, q)
