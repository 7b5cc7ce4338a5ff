"""Spherical-wrist arms with axes 2 and 3 parallel and a sinusoidal A-pair at joint 3 in closed form
(apair.ik.wrist_apair, issue 42 part 3): the same solution sets as the general solver (the homotopy,
certified) on the five industrial arms of test_ik_wrist (PUMA, KUKA, ABB, Fanuc with α_2 = π, Stäubli
with a_3 = 0) and a design with a general α_1 and φ_3 = π, every solution a multi-start local search
finds, the pair's angle at 0, ±π (both twins) and beyond ±π with the other joints at 0, ±π/2 and π,
the wrist's singularity (axes 4 and 6 in line: a continuum, one member), scales, the NumPy twin
against C, and the designs it does not cover going to the general solver."""

from __future__ import annotations

import numpy as np
import pytest
import test_ik_wrist as wrist_arms

import apair
from apair.ik.parallel_apair import one_per_multiple_root
from apair.ik.poses import refine
from apair.ik.solver import Solver
from apair.ik.wrist_apair import WristAPair

PI = np.pi
R = apair.APair.revolute()
A = apair.APair(0.06, 0.05)  # h = sqrt(2 r_b r_p) = 0.0775
SAME = 1e-6
PERIOD = np.array([2, 2, 4, 2, 2, 2]) * PI
DESIGNS = {name: (*wrist_arms.ARMS[name], None) for name in wrist_arms.INDUSTRIAL}
DESIGNS["general alpha1, phi3=pi"] = (
    [0.1, 0.4, 0.08, 0, 0, 0.02],
    [1.1, PI, PI / 2, -PI / 2, 1.2, 0.3],
    [0.3, 0.05, -0.04, 0.35, 0, 0.1],
    [0.2, -0.3, PI, 0.4, 0.1, -0.5],
)


def chain_of(name: str, scale: float = 1.0) -> apair.AChain:
    a, alpha, d, phi = DESIGNS[name]
    pair = apair.APair(A.base_radius * scale, A.platform_radius * scale)
    return apair.AChain(
        [R, R, pair, R, R, R], a=np.multiply(a, scale), alpha=alpha, offset=np.multiply(d, scale), theta_offset=phi
    )


def among(q, sols) -> bool:
    """q among sols: each joint within SAME, the A-pair's angle modulo 4π, the others modulo 2π."""
    d = np.abs((np.asarray(sols).reshape(-1, 6) - q + PERIOD / 2) % PERIOD - PERIOD / 2)
    return bool(np.any(np.all(d < SAME, axis=1)))


def general_solver(chain) -> Solver:
    s = Solver(chain)
    s._closed = None
    return s


def random_q(rng, k):
    return rng.uniform(-1, 1, (k, 6)) * PERIOD / 2


def test_designs_go_to_the_closed_form():
    for name in DESIGNS:
        chain = chain_of(name)
        assert isinstance(Solver(chain)._closed, WristAPair), name
        q = np.array([0.3, -0.4, 2.5, 0.6, -0.7, 0.8])
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and sol.family.startswith("spherical-"), name
        assert sol.certified and among(q, sol.q), name


@pytest.mark.parametrize("name", list(DESIGNS))
def test_same_sets_as_the_general_solver(name):
    """The homotopy (certified) on random poses of each design: the same solutions both ways. On the
    PUMA (a_1 = 0) the homotopy's start set for the pattern is incomplete and it does not certify its
    answer: there every solution it finds must be among ours, and the multi-start search below checks
    ours independently."""
    chain = chain_of(name)
    general = general_solver(chain)
    rng = np.random.default_rng(5)
    for q in random_q(rng, 4):
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and (theirs.certified or name == "PUMA560"), (name, q)
        assert among(q, ours.q), (name, q)
        assert len(ours.q) == len(theirs.q), (name, q, ours.q, theirs.q)
        assert all(among(s, theirs.q) for s in ours.q), (name, q)
        assert np.all(ours.error <= 1e-9)


@pytest.mark.parametrize("name", ["PUMA560", "KUKA-KR6"])
def test_every_solution_a_multi_start_search_finds(name):
    """An independent check: Levenberg-Marquardt from 300 random seeds per pose inside chain.limits
    (the pair's collision-free range); every solution it converges to is among the closed form's."""
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


@pytest.mark.parametrize("theta3", [0.0, PI, -PI, PI / 2, 1.5 * PI, -1.9 * PI, 2 * PI])
def test_pair_angle_special_values(theta3):
    """θ_3 at 0, ±π (d_3 = 0: both twins are solutions), beyond ±π and at 2π; the other joints at 0,
    ±π/2 and π (ψ_1 = π among them: the root at t = ∞). Where ψ_5 = 0 (axes 4 and 6 in line) the
    wrist is a continuum: the member given reproduces the pose and the note says so."""
    chain = chain_of("PUMA560")
    for rest in ([0.3, -0.2, 0.5, 0.7, 0.1], [PI, -PI / 2, PI / 2, PI / 2, 0], [PI / 2, 0.3, -PI, 0.0, PI]):
        q = np.array([rest[0], rest[1], theta3, *rest[2:]], float)
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert len(sol.q) and np.all(np.abs(chain.fk(sol.q) - T) <= 1e-9), (q, sol.q)
        if abs(np.sin(q[4])) < 1e-12:
            assert "axes 4 and 6 in line" in sol.note, (q, sol.note)
            continue
        assert among(q, sol.q), (q, sol.q, sol.note)
        if abs(abs(theta3) - PI) < 1e-12:
            twin = q.copy()
            twin[2] = -theta3
            assert among(twin, sol.q), (q, sol.q)


def test_wrist_in_line_gives_the_member_with_psi4_zero():
    """ψ_5 = 0 on the PUMA: axes 4 and 6 in line, ψ_4 + ψ_6 fixed (the slide of joint 3 does not
    pin it); the closed form gives the member with ψ_4 = 0 (θ_4 = −φ_4) and says so."""
    chain = chain_of("PUMA560")
    q = np.array([0.4, -0.9, 1.2, 0.3, 0.0, 0.5])
    T = chain.fk(q)
    sol = chain.ik(T, full=True)
    assert "axes 4 and 6 in line" in sol.note
    member = q.copy()
    member[3], member[5] = 0.0, q[3] + q[5]
    assert among(member, sol.q), sol.q


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_scales(scale):
    """A chain scaled by s has the solutions of the unscaled one at the scaled poses."""
    small, big = chain_of("ABB-IRB6640"), chain_of("ABB-IRB6640", scale)
    rng = np.random.default_rng(2)
    for q in random_q(rng, 5):
        ours, ref = big.ik(big.fk(q)), small.ik(small.fk(q))
        assert len(ours) == len(ref) and all(among(s, ref) for s in ours), (scale, q)


def test_designs_not_covered_go_to_the_general_solver():
    """sin φ_3 ≠ 0, axes 2 and 3 not parallel, the forearm along the elbow's axis (sin α_3 = 0:
    E_s = 0), A-pairs at joints 3 and 5: no closed form of this kind."""
    a, alpha, d = wrist_arms.ARMS["PUMA560"]
    cases = [
        apair.AChain([R, R, A, R, R, R], a=a, alpha=alpha, offset=d, theta_offset=[0, 0, 0.3, 0, 0, 0]),
        apair.AChain([R, R, A, R, R, R], a=a, alpha=[-PI / 2, 0.4, -PI / 2, PI / 2, -PI / 2, 0], offset=d),
        apair.AChain(
            [R, R, A, R, R, R], a=[0, 0.4318, 0.3, 0, 0, 0], alpha=[-PI / 2, 0, 0, PI / 2, -PI / 2, 0], offset=d
        ),
        apair.AChain([R, R, A, R, A, R], a=a, alpha=alpha, offset=d),
    ]
    for chain in cases:
        assert not isinstance(Solver(chain)._closed, WristAPair)
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    sol = cases[0].ik(cases[0].fk(q), full=True)
    assert sol.method != "closed form" and among(q, sol.q)


@pytest.mark.parametrize("name", list(DESIGNS))
def test_numpy_twin_gives_the_same_sets(name):
    """The NumPy steps (WristAPair.candidates, refined) and the C solver (apair_ik_wrist_apair, what
    ik calls) find the same solutions on random poses."""
    chain = chain_of(name)
    form = Solver(chain)._closed
    rng = np.random.default_rng(1)
    for q in random_q(rng, 30):
        T = chain.fk(q)
        cands, _ = form.candidates(T)
        twin, _ = one_per_multiple_root(chain, *refine(chain, cands, T, 1e-9, form.scale))
        ours = chain.ik(T)
        assert len(twin) == len(ours) and all(among(s, ours) for s in twin), (name, q)
