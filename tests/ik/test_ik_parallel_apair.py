"""UR-like arms with a sinusoidal A-pair at joint 3 in closed form (apair.ik.parallel_apair, issue
42 part 3): the same solution sets as the general solver (the homotopy, certified) on UR designs and
the special ones (antiparallel axes, φ_3 = π, c_5 = 0, a large amplitude), every solution a
multi-start local search finds, the pair's angle at 0, ±π (both twins) and beyond ±π, ψ_1 = π, the
wrist singularity, scales, and the designs it does not cover going to the general solver."""

from __future__ import annotations

import numpy as np
import pytest

import apair
from apair.ik.parallel_apair import ParallelAPair, one_per_multiple_root
from apair.ik.poses import refine
from apair.ik.solver import Solver

PI = np.pi
R = apair.APair.revolute()
A = apair.APair(0.06, 0.05)  # h = sqrt(2 r_b r_p) = 0.0775
SAME = 1e-6

# standard DH (a, alpha, d, theta_offset) with the A-pair at joint 3
DESIGNS = {
    "UR5": (
        [0, -0.425, -0.39225, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
        None,
    ),
    "UR10e phi3=pi": (
        [0, -0.6127, -0.57155, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.1807, 0, 0, 0.17415, 0.11985, 0.11655],
        [0.3, -0.2, PI, 0.1, 0, 0.5],
    ),
    "antiparallel": (
        [0.1, 0.4, 0.35, 0, 0, 0.03],
        [1.1, PI, 0, -PI / 2, PI / 2, 0.4],
        [0.2, 0.05, -0.1, 0.12, 0.09, 0.08],
        None,
    ),
    "c5=0": (
        [0.05, -0.425, -0.39225, 0, 0, 0],
        [PI / 2, 0, 0, -PI / 2, PI / 2, 0],
        [0.089, 0, 0, 0.109, 0, 0.082],
        None,
    ),
    "large amplitude": (
        [0, 0.2, 0.15, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.1, 0, 0, 0.1, 0.09, 0.08],
        None,
    ),
}


def chain_of(name: str, scale: float = 1.0, pair=A) -> apair.AChain:
    a, alpha, d, phi = DESIGNS[name]
    if name == "large amplitude":
        pair = apair.APair(0.12, 0.1)  # h = 0.155, about a_2
    pair = apair.APair(pair.base_radius * scale, pair.platform_radius * scale) if scale != 1.0 else pair
    return apair.AChain(
        [R, R, pair, R, R, R],
        a=np.multiply(a, scale),
        alpha=alpha,
        offset=np.multiply(d, scale),
        theta_offset=phi,
    )


def among(q, sols) -> bool:
    """q among sols: each joint within SAME, the A-pair's angle modulo 4π, the others modulo 2π."""
    sols = np.asarray(sols).reshape(-1, 6)
    period = np.array([2, 2, 4, 2, 2, 2]) * PI
    d = np.abs((sols - q + period / 2) % period - period / 2)
    return bool(np.any(np.all(d < SAME, axis=1)))


def general_solver(chain) -> Solver:
    s = Solver(chain)
    s._closed = None
    return s


def random_q(rng, k=None):
    q = rng.uniform(-PI, PI, 6 if k is None else (k, 6))
    q[..., 2] = rng.uniform(-2 * PI, 2 * PI, q[..., 2].shape)
    return q


def test_designs_go_to_the_closed_form():
    for name in DESIGNS:
        chain = chain_of(name)
        assert isinstance(Solver(chain)._closed, ParallelAPair), name
        q = np.array([0.3, -0.4, 2.5, 0.6, -0.7, 0.8])
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and sol.family == "three-inner-parallel", name
        assert sol.certified and among(q, sol.q), name


@pytest.mark.parametrize("name", list(DESIGNS))
def test_same_sets_as_the_general_solver(name):
    """The homotopy (certified) on random poses of each design: the same solutions both ways."""
    chain = chain_of(name)
    general = general_solver(chain)
    rng = np.random.default_rng(5)
    for q in random_q(rng, 6):
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and theirs.certified, (name, q)
        assert among(q, ours.q), (name, q)
        assert len(ours.q) == len(theirs.q), (name, q, ours.q, theirs.q)
        assert all(among(s, theirs.q) for s in ours.q), (name, q)
        assert np.all(ours.error <= 1e-9)


def test_every_solution_a_multi_start_search_finds():
    """An independent check: Levenberg-Marquardt from 300 random seeds per pose; every solution it
    converges to is among the closed form's (the search stays inside chain.limits: the pair's
    collision-free range, where the seeds and the poses are drawn)."""
    chain = chain_of("UR5")
    lo, hi = chain.limits[2]
    rng = np.random.default_rng(11)
    for q in random_q(rng, 4):
        q[2] = rng.uniform(lo, hi)
        T = chain.fk(q)
        ours = chain.ik(T)
        seeds = random_q(rng, 300)
        seeds[:, 2] = rng.uniform(lo, hi, 300)
        local = chain.ik_local(np.broadcast_to(T, (300, 4, 4)), seeds, tol=1e-11)
        found = local.q[local.converged]
        assert len(found) > 0
        for s in found:
            assert among(s, ours), (q, s)


@pytest.mark.parametrize("theta3", [0.0, PI, -PI, PI / 2, 1.5 * PI, -1.9 * PI, 2 * PI])
def test_pair_angle_special_values(theta3):
    """θ_3 at 0, beyond ±π and at ±π, where d_3 = 0 and both twins are solutions; the other joints
    at 0, ±π/2 and π, and ψ_1 = π (the root at t = ∞)."""
    chain = chain_of("UR5")
    for rest in ([0, 0, 0, 0, 0], [PI, -PI / 2, PI / 2, PI / 2, 0], [PI / 2, 0.3, -PI, 1.0, PI]):
        q = np.array([rest[0], rest[1], theta3, *rest[2:]], float)
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert among(q, sol.q), (q, sol.q, sol.note)
        if abs(abs(theta3) - PI) < 1e-12:
            twin = q.copy()
            twin[2] = -theta3
            assert among(twin, sol.q), (q, sol.q)
        assert np.all(np.abs(chain.fk(sol.q) - T) <= 1e-9)


@pytest.mark.parametrize("q", [[0.4, -0.9, 1.2, 0.3, 0.0, 0.5], [0.0] * 6, [1.0, 0.2, -3.0, -0.5, PI, 2.0]])
def test_wrist_singularity_is_pinned_by_the_slide(q):
    """ψ_5 = 0 or π: axis 6 parallel to axes 2-4, the R-arm's self-motion; the slide of joint 3 pins
    the elbow and so ψ_6: isolated solutions, the same as the general solver's, no continuum. At
    q = 0 the slide is at its top too (d_3' = 0): a singular pose, where the homotopy's paths meet
    (not certified, its answers 1e-4 off) and the closed form's are exact."""
    chain = chain_of("UR5")
    q = np.array(q)
    T = chain.fk(q)
    sol, ref = chain.ik(T, full=True), general_solver(chain).solve(T)
    assert among(q, sol.q) and not sol.note, (sol.q, sol.note)
    assert np.all(np.abs(chain.fk(sol.q) - T) <= 1e-12)
    if np.any(q):
        assert ref.certified and len(sol.q) == len(ref.q) and all(among(s, ref.q) for s in sol.q), (sol.q, ref.q)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_scales(scale):
    """A chain scaled by s has the solutions of the unscaled one at the scaled poses."""
    small, big = chain_of("UR5"), chain_of("UR5", scale)
    rng = np.random.default_rng(2)
    for q in random_q(rng, 5):
        T = big.fk(q)
        ours, ref = big.ik(T), small.ik(small.fk(q))
        assert len(ours) == len(ref) and all(among(s, ref) for s in ours), (scale, q)


def test_designs_not_covered_go_to_the_general_solver():
    """sin φ_3 ≠ 0, a wrist other than UR's, an A-pair at joint 2 or 4: no closed form."""
    a, alpha, d, _ = DESIGNS["UR5"]
    cases = [
        apair.AChain([R, R, A, R, R, R], a=a, alpha=alpha, offset=d, theta_offset=[0, 0, 0.3, 0, 0, 0]),
        apair.AChain([R, R, A, R, R, R], a=a, alpha=[PI / 2, 0, 0, 1.1, -PI / 2, 0], offset=d),
        apair.AChain([R, R, A, R, R, R], a=[0, -0.425, -0.39225, 0.05, 0, 0], alpha=alpha, offset=d),
        apair.AChain([R, A, R, R, R, R], a=a, alpha=alpha, offset=d),
        apair.AChain([R, R, R, A, R, R], a=a, alpha=alpha, offset=d),
    ]
    for chain in cases:
        assert Solver(chain)._closed is None
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    sol = cases[0].ik(cases[0].fk(q), full=True)
    assert sol.method != "closed form" and among(q, sol.q)


@pytest.mark.parametrize("name", list(DESIGNS))
def test_numpy_twin_gives_the_same_sets(name):
    """The NumPy steps (ParallelAPair.candidates, refined) and the C solver (apair_ik_parallel_apair,
    what ik calls) find the same solutions on random poses."""
    chain = chain_of(name)
    form = Solver(chain)._closed
    rng = np.random.default_rng(1)
    for q in random_q(rng, 30):
        T = chain.fk(q)
        cands, _ = form.candidates(T, 1e-9)
        twin, _ = one_per_multiple_root(chain, *refine(chain, cands, T, 1e-9, form.scale))
        ours = chain.ik(T)
        assert len(twin) == len(ours) and all(among(s, ours) for s in twin), (name, q)
