"""The closed-form inverse kinematics of six-joint R-chains with axes 1, 2 and 3 parallel and axes 5
and 6 meeting (apair.ik.three_parallel, issue 42): the same solution sets as EAIK, 2000 poses per
design, every solution both ways; the same sets as the general solver; joints at 0, ±π/2 and π;
the singular configurations (axis 5 or 6 parallel to axes 1-3, axes 1 and 3 on one line), refused
by the general solver; scales, frames, the NumPy twin and a design the closed form declines."""

from __future__ import annotations

import numpy as np
import pytest
from eaik.IK_DH import DhRobot
from test_ik_parallel import among, general_solver

import apair
from apair.frames import frame
from apair.ik.solver import Solver
from apair.ik.three_parallel import ThreeParallel

PI = np.pi
R = apair.APair.revolute()

# standard DH (a, α, d): axes 1∥2∥3 (α_1, α_2 ∈ {0, π}), a_5 = 0
ARMS = {
    "right-angles": (
        [0.3, 0.25, 0.1, 0.05, 0, 0.0],
        [0, 0, PI / 2, -PI / 2, PI / 2, 0],
        [0.2, 0.05, 0.1, 0.15, 0.08, 0.1],
    ),
    "general-twists": (
        [0.3, 0.25, 0.1, 0.05, 0, 0.02],
        [0, 0, 1.1, -0.7, 0.9, 0.3],
        [0.2, 0.05, 0.1, 0.15, 0.08, 0.1],
    ),
    "antiparallel": ([0.3, 0.25, 0.1, 0.05, 0, 0.0], [PI, 0, 1.1, -0.7, 0.9, 0], [0.2, -0.05, 0.1, 0.15, 0.08, 0.1]),
    "a4=0": ([0.3, 0.25, 0.1, 0.0, 0, 0.0], [0, PI, PI / 2, PI / 2, -PI / 2, 0], [0.2, 0.05, 0.1, 0.15, 0.08, 0.1]),
}


def arm(name: str, scale: float = 1.0, theta_offset=None, **frames) -> apair.AChain:
    a, alpha, d = ARMS[name]
    return apair.AChain(
        [R] * 6, a=np.multiply(a, scale), alpha=alpha, offset=np.multiply(d, scale), theta_offset=theta_offset, **frames
    )


def test_every_design_goes_to_the_closed_form():
    for name in ARMS:
        chain = arm(name)
        assert chain.kinematic_family().key == "three-parallel-two-intersecting", name
        assert isinstance(Solver(chain)._closed, ThreeParallel), name
        q = np.full(6, 0.3)
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and sol.certified and among(q, sol.q), name


@pytest.mark.parametrize("name", ["right-angles", "general-twists", "a4=0"])
def test_same_sets_as_eaik(name):
    """2000 random poses: every solution EAIK finds (verified by apair's fk) is apair's and every
    one of apair's is EAIK's; q is among them."""
    a, alpha, d = ARMS[name]
    chain = arm(name)
    eaik = DhRobot(np.array(alpha, float), np.array(a, float), np.array(d, float))
    assert eaik.getKinematicFamily() == "6R-THREE_PARALLEL_TWO_INTERSECTING"
    rng = np.random.default_rng(13)
    for _ in range(2000):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        ours = chain.ik(T)
        assert among(q, ours), (name, q)
        theirs = [s for s in np.asarray(eaik.IK(T).Q).reshape(-1, 6) if np.abs(chain.fk(s) - T).max() <= 1e-9]
        assert all(among(s, ours) for s in theirs), (name, q)
        assert all(among(s, np.array(theirs)) for s in ours), (name, q)


@pytest.mark.parametrize("name", sorted(ARMS))
def test_same_sets_as_the_general_solver(name):
    chain = arm(name)
    general = general_solver(chain)
    rng = np.random.default_rng(3)
    for _ in range(6):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and theirs.certified
        assert len(ours.q) == len(theirs.q) and all(among(s, theirs.q) for s in ours.q), (name, q)


@pytest.mark.parametrize("name", ["right-angles", "antiparallel", "a4=0"])
def test_joint_values_at_zero_and_pi(name):
    """Joints at 0, ±π/2 and π, with and without offsets φ: q is among the solutions, or the pose
    is singular, the note names the continuum and its member verifies."""
    for phi in (None, [0.3, -0.2, 0.5, 0.1, 1.0, -0.4]):
        chain = arm(name, theta_offset=phi)
        rng = np.random.default_rng(5)
        for _ in range(40):
            q = rng.choice([0.0, PI, -PI / 2, PI / 2], 6)
            sol = chain.ik(chain.fk(q), full=True)
            assert sol.method == "closed form" and len(sol.q) and np.all(sol.error <= 1e-9), (name, q)
            assert among(q, sol.q) or "continuum" in sol.note, (name, q, sol.q)


def test_singular_configurations():
    """θ_4 = 0 on the right-angled design puts axis 5 parallel to axes 1-3 (four parallel joints),
    and a_1 = a_2 with θ_2 = π puts axis 3 on axis 1: one member of each continuum, named; the
    general solver refuses both poses."""
    chain = arm("right-angles")
    q = np.array([0.4, -0.7, 0.9, 0.0, 0.6, -0.5])
    sol = chain.ik(chain.fk(q), full=True)
    assert "axis 5 parallel to axes 1, 2 and 3" in sol.note and np.all(sol.error <= 1e-9), sol.note
    with pytest.raises(ValueError, match="not isolated"):
        general_solver(chain).solve(chain.fk(q))
    a, alpha, d = ARMS["general-twists"]
    folded = apair.AChain([R] * 6, a=[0.3, 0.3, *a[2:]], alpha=alpha, offset=d)
    q = np.array([0.4, PI, 0.9, 0.3, 0.6, -0.5])
    sol = folded.ik(folded.fk(q), full=True)
    assert "axes 1 and 3 on one line" in sol.note and np.all(sol.error <= 1e-9), sol.note
    assert any(abs(s[0]) < 1e-9 and abs(abs(s[1]) - PI) < 1e-6 for s in sol.q)
    with pytest.raises(ValueError, match="not isolated"):
        general_solver(folded).solve(folded.fk(q))


def test_numpy_twin_gives_the_same_sets():
    for name in ARMS:
        rng = np.random.default_rng(29)
        Ts = arm(name).fk(rng.uniform(-PI, PI, (30, 6)))
        ours = [arm(name).ik(T) for T in Ts]
        apair.set_backend("numpy")
        try:
            twin = [arm(name).ik(T) for T in Ts]
        finally:
            apair.set_backend(None)
        for x, y in zip(ours, twin):
            assert x.shape == y.shape and np.allclose(x, y, atol=1e-9), name


def test_scales_frames_and_a_declined_design():
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    for scale in (1e-3, 1e3):
        chain = arm("general-twists", scale)
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and among(q, sol.q) and np.all(sol.error <= 1e-9)
    framed = arm("general-twists", base=frame([0.1, 0.2, 0.3], [0.1, 0.2, 0.3]), tool=frame([0, 0, 0.1], [0, 0.5, 0]))
    sol = framed.ik(framed.fk(q), full=True)
    assert sol.method == "closed form" and among(q, sol.q)
    # a_4 = c_5 = 0: axes 4, 5, 6 meet too, in a point whose height along axes 1-3 no joint moves (five
    # degrees of freedom at most): the closed form declines, and ik says the solutions are not isolated
    a, alpha, d = ARMS["a4=0"]
    flat = apair.AChain([R] * 6, a=a, alpha=alpha, offset=[*d[:4], 0.0, d[5]])
    assert flat.kinematic_family().key == "three-parallel-two-intersecting" and Solver(flat)._closed is None
    with pytest.raises(ValueError, match="no isolated solutions"):
        flat.ik(flat.fk(q))
