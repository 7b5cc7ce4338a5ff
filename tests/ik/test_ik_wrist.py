"""The closed-form inverse kinematics of six-joint R-chains with a spherical wrist (apair.ik.wrist,
issue 42): the same solution sets as EAIK on industrial-like arms, 2000 poses each, every solution
both ways; the same sets as the general solver; the special values (joints at 0 and π, the root
of ψ_3 at t = ∞), the singular configurations (wrist point on axis 1, axes 4 and 6 in line, the
arm stretched), unreachable poses and the chain's scale."""

from __future__ import annotations

import numpy as np
import pytest
from eaik.IK_DH import DhRobot

import apair
from apair.frames import frame
from apair.ik.solver import Solver

PI = np.pi
R = apair.APair.revolute()
SAME = 1e-6  # [rad] two solutions are one where every joint differs by less (mod 2π)

# standard DH (a, α, d) of arms with a spherical wrist, one per family of apair.ik.families
ARMS = {
    "PUMA560": ([0, 0.4318, 0.0203, 0, 0, 0], [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0], [0, 0, 0.15005, 0.4318, 0, 0]),
    "KUKA-KR6": ([0.025, 0.455, 0.035, 0, 0, 0], [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0], [0.4, 0, 0, 0.42, 0, 0.08]),
    "ABB-IRB6640": (
        [0.32, 1.075, 0.2, 0, 0, 0],
        [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0],
        [0.78, 0, 0, 1.1425, 0, 0.2],
    ),
    "Fanuc-M20": (
        [0.075, 0.84, 0.215, 0, 0, 0],
        [-PI / 2, PI, -PI / 2, PI / 2, -PI / 2, PI],
        [0.525, 0, 0, -0.89, 0, -0.09],
    ),
    "Staubli-TX90": (
        [0.05, 0.425, 0, 0, 0, 0],
        [-PI / 2, 0, PI / 2, -PI / 2, PI / 2, 0],
        [0.478, 0, 0.05, 0.425, 0, 0.1],
    ),
    "first-two-parallel": ([0.2, 0.4, 0.1, 0, 0, 0], [0, 1.0, -0.8, 1.1, -0.7, 0.3], [0.3, 0.1, 0.2, 0.4, 0, 0.1]),
    "first-two-intersecting": (
        [0, 0.4, 0.1, 0, 0, 0],
        [PI / 2, PI / 3, PI / 2, PI / 2, -PI / 2, 0],
        [0.3, 0.1, 0.2, 0.4, 0, 0.1],
    ),
    "second-two-intersecting": (
        [0.1, 0, 0.3, 0, 0, 0],
        [PI / 2, 0.9, PI / 2, 1.2, -PI / 2, 0],
        [0.3, 0.2, 0.1, 0.4, 0, 0.1],
    ),
    "no-parallel-no-intersecting": (
        [0.1, 0.4, 0.1, 0, 0, 0.05],
        [0.5, 1.0, -0.8, 1.1, -0.7, 0.3],
        [0.3, 0.1, 0.2, 0.4, 0, 0.1],
    ),
}
INDUSTRIAL = ["PUMA560", "KUKA-KR6", "ABB-IRB6640", "Fanuc-M20", "Staubli-TX90"]


def arm(name: str, scale: float = 1.0, theta_offset=None) -> apair.AChain:
    a, alpha, d = ARMS[name]
    return apair.AChain(
        [R] * 6, a=np.multiply(a, scale), alpha=alpha, offset=np.multiply(d, scale), theta_offset=theta_offset
    )


def among(q: np.ndarray, sols: np.ndarray) -> bool:
    d = np.abs((np.asarray(sols).reshape(-1, 6) - q + PI) % (2 * PI) - PI)
    return bool(np.any(np.all(d < SAME, axis=1)))


def test_every_family_goes_to_the_closed_form():
    for name in ARMS:
        chain = arm(name)
        assert chain.kinematic_family().key.startswith("spherical-"), name
        sol = chain.ik(chain.fk(np.full(6, 0.3)), full=True)
        assert sol.method == "closed form" and sol.certified and among(np.full(6, 0.3), sol.q), name


@pytest.mark.parametrize("name", INDUSTRIAL)
def test_same_sets_as_eaik(name):
    """2000 random poses: every solution EAIK finds (verified by apair's fk) is apair's, and every
    one of apair's is EAIK's; and the joint vector the pose came from is among them."""
    a, alpha, d = ARMS[name]
    chain = arm(name)
    eaik = DhRobot(np.array(alpha, float), np.array(a, float), np.array(d, float))
    rng = np.random.default_rng(7)
    for _ in range(2000):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        ours = chain.ik(T)
        assert among(q, ours), (name, q)
        theirs = [s for s in np.asarray(eaik.IK(T).Q).reshape(-1, 6) if np.abs(chain.fk(s) - T).max() <= 1e-9]
        for s in theirs:
            assert among(s, ours), (name, q, s)
        for s in ours:
            assert among(s, np.array(theirs)), (name, q, s)


@pytest.mark.parametrize("name", sorted(ARMS))
def test_same_sets_as_the_general_solver(name):
    chain = arm(name)
    general = Solver(chain)
    general._closed = None  # the 6R elimination or the homotopy, as before the closed form
    rng = np.random.default_rng(3)
    for _ in range(15):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and theirs.certified
        assert len(ours.q) == len(theirs.q), (name, q, ours.q, theirs.q)
        assert all(among(s, theirs.q) for s in ours.q)


@pytest.mark.parametrize("name", ["PUMA560", "KUKA-KR6", "no-parallel-no-intersecting"])
def test_joint_values_at_zero_and_pi(name):
    """Joints at 0, ±π/2 and π, ψ_3 = π among them (the polynomial's root at t = ∞), with and
    without angle offsets φ; where θ_5 puts axes 4 and 6 in line, the member of the continuum
    through q is there."""
    for phi in (None, [0.3, -0.2, 0.5, 0.0, 1.0, -0.4]):
        chain = arm(name, theta_offset=phi)
        rng = np.random.default_rng(5)
        for _ in range(40):
            q = rng.choice([0.0, PI, -PI / 2, PI / 2], 6)
            if phi is not None and rng.random() < 0.5:
                q[2] = PI - phi[2]  # ψ_3 = π exactly
            sol = chain.ik(chain.fk(q), full=True)
            assert sol.method == "closed form" and len(sol.q) and np.all(sol.error <= 1e-9)
            if "axes 4 and 6 in line" in sol.note:  # the continuum through q is represented
                wrapped = lambda x: (x + PI) % (2 * PI) - PI
                close = np.abs(wrapped(sol.q[:, [0, 1, 2, 4]] - q[[0, 1, 2, 4]])) < SAME
                assert np.any(np.all(close, axis=1)), (name, q, sol.q)
            else:
                assert among(q, sol.q), (name, q, sol.q, sol.note)


def test_singular_wrist_is_one_member_of_a_continuum():
    """Axes 4 and 6 in line (θ_5 = 0 on a PUMA): ψ_4 + ψ_6 is fixed; one member (ψ_4 = 0) is given
    for each shoulder and elbow, and the note says so."""
    chain = arm("PUMA560")
    q = np.array([0.4, -0.7, 0.9, 1.1, 0.0, -0.5])
    sol = chain.ik(chain.fk(q), full=True)
    assert sol.method == "closed form" and "axes 4 and 6 in line" in sol.note, sol.note
    assert np.all(sol.error <= 1e-9) and len(sol.q) >= 2
    member = [s for s in sol.q if np.allclose(s[:3], q[:3], atol=1e-7) and abs(s[4]) < 1e-7]
    assert len(member) == 1 and abs(member[0][3]) < 1e-6
    assert abs((member[0][3] + member[0][5]) - (q[3] + q[5])) < 1e-7


def test_wrist_point_on_axis_1():
    """A PUMA without shoulder offset with its wrist point on axis 1: joint 1 is free; the member
    with θ_1 = 0 is given, and the note says so."""
    from scipy.optimize import brentq

    a, alpha, _ = ARMS["PUMA560"]
    chain = apair.AChain([R] * 6, a=a, alpha=alpha, offset=[0, 0, 0, 0.4318, 0, 0])
    q = np.array([0.0, 0.0, 0.6, 0.3, 0.8, -0.2])

    def wx(q2: float) -> float:
        q[1] = q2
        return float(chain.fk(q)[0, 3])

    q[1] = brentq(wx, -PI, 0.0, xtol=1e-15)
    T = chain.fk(q)
    assert abs(T[0, 3]) < 1e-12 and abs(T[1, 3]) < 1e-12
    sol = chain.ik(T, full=True)
    assert sol.method == "closed form" and "axis 1" in sol.note, sol.note
    assert among(q, sol.q) and np.all(sol.error <= 1e-9)


def test_stretched_elbow_double_root():
    """The elbow at its stretched angle (|p| largest: ψ_3 a double root of the position
    polynomial) and a hair off it: the pose's own joint vector is found."""
    chain = arm("KUKA-KR6")
    a3, c4 = 0.035, 0.42
    stretched = -np.arctan2(-np.sin(-PI / 2) * c4, a3)  # m_x = cos ψ a_3 − sin ψ (−sin α_3 c_4) largest
    for q3 in (stretched, stretched + 1e-7, stretched - 1e-7):
        q = np.array([0.2, -0.6, q3, 0.3, 0.5, 0.1])
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and np.all(sol.error <= 1e-9)
        assert among(q, sol.q), (q3, sol.q)


@pytest.mark.parametrize("name", ["PUMA560", "Fanuc-M20", "no-parallel-no-intersecting"])
def test_random_poses_reachable_or_not(name):
    """Poses of random position within the reach bound and random rotation (most unreachable):
    the same number of solutions as the general solver, both certified."""
    from scipy.spatial.transform import Rotation

    chain = arm(name)
    general = Solver(chain)
    general._closed = None
    rng = np.random.default_rng(13)
    reach = float(np.sum(np.abs(ARMS[name][0])) + np.sum(np.abs(ARMS[name][2])))
    empty = 0
    for k in range(20):
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=100 + k).as_matrix()
        T[:3, 3] = rng.uniform(-reach, reach, 3) / np.sqrt(3)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert ours.method == "closed form" and ours.certified and theirs.certified
        assert len(ours.q) == len(theirs.q), (name, k, ours.q, theirs.q)
        empty += len(ours.q) == 0
    assert 0 < empty < 20


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_scales(scale):
    chain = arm("ABB-IRB6640", scale)
    rng = np.random.default_rng(11)
    for _ in range(30):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert sol.method == "closed form" and among(q, sol.q)
        assert np.all(sol.error <= 1e-9)


def test_a_pairs_and_frames():
    """A chain with an A-pair in the wrist is not a spherical wrist: the general solver answers;
    base and tool frames keep the closed form."""
    a, alpha, d = ARMS["PUMA560"]
    wrist_a = apair.AChain([R, R, R, R, apair.APair(0.06, 0.05), R], a=a, alpha=alpha, offset=d)
    assert Solver(wrist_a)._closed is None
    framed = apair.AChain(
        [R] * 6,
        a=a,
        alpha=alpha,
        offset=d,
        base=frame([0.1, 0.2, 0.3], [0.1, 0.2, 0.3]),
        tool=frame([0.0, 0.0, 0.12], [0.0, PI / 2, 0.0]),
    )
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    sol = framed.ik(framed.fk(q), full=True)
    assert sol.method == "closed form" and among(q, sol.q)
