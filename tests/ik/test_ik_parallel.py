"""The closed-form inverse kinematics of six-joint R-chains with axes 2, 3 and 4 parallel
(apair.ik.parallel, issue 42; the UR arms): the same solution sets as EAIK on UR arms, 2000 poses
each, every solution both ways; the same sets as the general solver on every case of the
polynomial (a quartic; L_2's quadratic where a_5 = 0; L_1's where axes 5 and 6 are parallel) and
with antiparallel axes (α = π); joints at 0, ±π/2 and π; the singular configurations (axis 6
parallel to axes 2-4, the elbow stretched); unreachable poses; scales; the NumPy twin."""

from __future__ import annotations

import numpy as np
import pytest
from eaik.IK_DH import DhRobot

import apair
from apair.ik.parallel import Parallel
from apair.ik.poses import refine
from apair.ik.solver import Solver

PI = np.pi
R = apair.APair.revolute()
SAME = 1e-6  # [rad] two solutions are one where every joint differs by less (mod 2π)

# standard DH (a, α, d): Universal Robots' published parameters, and designs for each case
ARMS = {
    "UR3": (
        [0, -0.24365, -0.21325, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.1519, 0, 0, 0.11235, 0.08535, 0.0819],
    ),
    "UR5": (
        [0, -0.425, -0.39225, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
    ),
    "UR10": (
        [0, -0.612, -0.5723, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.1273, 0, 0, 0.163941, 0.1157, 0.0922],
    ),
    "UR5e": ([0, -0.425, -0.3922, 0, 0, 0], [PI / 2, 0, 0, PI / 2, -PI / 2, 0], [0.1625, 0, 0, 0.1333, 0.0997, 0.0996]),
    "UR10e": (
        [0, -0.6127, -0.57155, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.1807, 0, 0, 0.17415, 0.11985, 0.11655],
    ),
    "quartic": ([0.1, 0.4, 0.35, 0.05, 0.07, 0.03], [1.1, 0, 0, -0.9, 0.7, 0.4], [0.2, 0.05, -0.1, 0.12, 0.09, 0.08]),
    "a5=0": ([0.1, 0.4, 0.35, 0.05, 0, 0.03], [1.1, 0, 0, -0.9, 0.7, 0.4], [0.2, 0.05, -0.1, 0.12, 0.09, 0.08]),
    "5∥6": ([0.1, 0.4, 0.35, 0.05, 0.07, 0.03], [1.1, 0, 0, -0.9, 0, 0.4], [0.2, 0.05, -0.1, 0.12, 0.09, 0.08]),
    "antiparallel": (
        [0.1, 0.4, 0.35, 0.05, 0.07, 0.03],
        [1.1, PI, 0, -0.9, 0.7, 0.4],
        [0.2, 0.05, -0.1, 0.12, 0.09, 0.08],
    ),
    "antiparallel-UR": (
        [0, -0.425, -0.39225, 0, 0, 0],
        [PI / 2, 0, PI, PI / 2, -PI / 2, 0],
        [0.089, 0, 0, 0.109, 0.095, 0.082],
    ),
}
UR = ["UR3", "UR5", "UR10", "UR5e", "UR10e"]


def arm(name: str, scale: float = 1.0, theta_offset=None) -> apair.AChain:
    a, alpha, d = ARMS[name]
    return apair.AChain(
        [R] * 6, a=np.multiply(a, scale), alpha=alpha, offset=np.multiply(d, scale), theta_offset=theta_offset
    )


def among(q: np.ndarray, sols: np.ndarray) -> bool:
    d = np.abs((np.asarray(sols).reshape(-1, 6) - q + PI) % (2 * PI) - PI)
    return bool(np.any(np.all(d < SAME, axis=1)))


def general_solver(chain) -> Solver:
    """The 6R elimination or the homotopy, as before the closed form."""
    s = Solver(chain)
    s._closed = None
    return s


def test_every_case_goes_to_the_closed_form():
    for name in ARMS:
        chain = arm(name)
        assert chain.kinematic_family().key == "three-inner-parallel", name
        sol = chain.ik(chain.fk(np.full(6, 0.3)), full=True)
        assert sol.method == "closed form" and sol.certified and among(np.full(6, 0.3), sol.q), name


@pytest.mark.parametrize("name", UR)
def test_same_sets_as_eaik(name):
    """2000 random poses: every solution EAIK finds (verified by apair's fk) is apair's, and every
    one of apair's is EAIK's; and the joint vector the pose came from is among them."""
    a, alpha, d = ARMS[name]
    chain = arm(name)
    eaik = DhRobot(np.array(alpha, float), np.array(a, float), np.array(d, float))
    rng = np.random.default_rng(17)
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


@pytest.mark.parametrize("name", ["UR5", "quartic", "a5=0", "5∥6", "antiparallel", "antiparallel-UR"])
def test_same_sets_as_the_general_solver(name):
    """Every case of the polynomial, and axes 2, 3, 4 antiparallel (α = π, where EAIK's answers do
    not verify): the same sets as the 6R elimination or the homotopy, both certified."""
    chain = arm(name)
    general = general_solver(chain)
    rng = np.random.default_rng(3)
    for _ in range(8):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and theirs.certified and ours.certified
        assert among(q, ours.q)
        assert len(ours.q) == len(theirs.q), (name, q, ours.q, theirs.q)
        assert all(among(s, theirs.q) for s in ours.q)


@pytest.mark.parametrize("name", ["UR5", "quartic", "5∥6"])
def test_random_poses_reachable_or_not(name):
    """Poses of random position within the reach bound and random rotation (many unreachable):
    the same number of solutions as the general solver."""
    from scipy.spatial.transform import Rotation

    chain = arm(name)
    general = general_solver(chain)
    rng = np.random.default_rng(23)
    reach = float(np.sum(np.abs(ARMS[name][0])) + np.sum(np.abs(ARMS[name][2])))
    empty = 0
    for k in range(12):
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=200 + k).as_matrix()
        T[:3, 3] = rng.uniform(-reach, reach, 3) / np.sqrt(3)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert ours.method == "closed form" and ours.certified and theirs.certified
        assert len(ours.q) == len(theirs.q), (name, k, ours.q, theirs.q)
        empty += len(ours.q) == 0
    assert 0 < empty < 12


@pytest.mark.parametrize("name", ["UR5", "quartic", "5∥6"])
def test_joint_values_at_zero_and_pi(name):
    """Joints at 0, ±π/2 and π (ψ_1 = π: the polynomial's root at t = ∞), with and without angle
    offsets φ; where θ_5 puts axis 6 parallel to axes 2-4 the note names the continuum and its
    member keeps θ_1, θ_5."""
    for phi in (None, [0.3, -0.2, 0.5, 0.0, 1.0, -0.4]):
        chain = arm(name, theta_offset=phi)
        rng = np.random.default_rng(5)
        for _ in range(30):
            q = rng.choice([0.0, PI, -PI / 2, PI / 2], 6)
            if phi is not None and rng.random() < 0.5:
                q[0] = PI - phi[0]  # ψ_1 = π exactly
            sol = chain.ik(chain.fk(q), full=True)
            assert sol.method == "closed form" and len(sol.q) and np.all(sol.error <= 1e-9), (name, q)
            if "axis 6 parallel" in sol.note:
                wrapped = lambda x: (x + PI) % (2 * PI) - PI
                close = np.abs(wrapped(sol.q[:, [0, 4]] - q[[0, 4]])) < SAME
                assert np.any(np.all(close, axis=1)), (name, q, sol.q)
            else:
                assert among(q, sol.q), (name, q, sol.q, sol.note)


def test_wrist_singularity_is_one_member_of_a_continuum():
    """θ_5 = 0 on a UR5: axis 6 parallel to axes 2-4, a curve of solutions; one member per
    shoulder is given (verified), the note says so; the general solver refuses the pose."""
    chain = arm("UR5")
    q = np.array([0.4, -0.7, 0.9, 1.1, 0.0, -0.5])
    T = chain.fk(q)
    sol = chain.ik(T, full=True)
    assert sol.method == "closed form" and "axis 6 parallel to axes 2, 3 and 4" in sol.note, sol.note
    assert np.all(sol.error <= 1e-9) and len(sol.q) >= 2
    assert any(abs(s[0] - q[0]) < 1e-7 and abs(s[4]) < 1e-6 for s in sol.q)
    with pytest.raises(ValueError, match="not isolated"):
        general_solver(chain).solve(T)


def test_stretched_elbow():
    """θ_3 = 0 (a double root of cos ψ_3's two elbows) and a hair off it: q is found."""
    chain = arm("UR10")
    for q3 in (0.0, 1e-7, -1e-7, PI):
        q = np.array([0.2, -0.6, q3, 0.3, 0.5, 0.1])
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and np.all(sol.error <= 1e-9)
        assert among(q, sol.q), (q3, sol.q)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_scales(scale):
    for name in ("UR5", "quartic"):
        chain = arm(name, scale)
        rng = np.random.default_rng(11)
        for _ in range(30):
            q = rng.uniform(-PI, PI, 6)
            sol = chain.ik(chain.fk(q), full=True)
            assert sol.method == "closed form" and among(q, sol.q) and np.all(sol.error <= 1e-9)


@pytest.mark.parametrize("name", ["UR5", "quartic", "5∥6", "antiparallel"])
def test_numpy_twin_gives_the_same_sets(name):
    """The NumPy steps (apair.ik.parallel.Parallel.candidates, run where the C backend is not)
    find what apair_ik_parallel finds."""
    chain = arm(name)
    p = Parallel(chain, Solver(chain).scale)
    rng = np.random.default_rng(29)
    for _ in range(40):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        cands, _ = p.candidates(T, 1e-9)
        twin, _ = refine(chain, cands, T, 1e-9, p.scale)
        ours = chain.ik(T)
        assert len(twin) == len(ours) and all(among(s, ours) for s in twin), (name, q)


def test_a_pairs_frames_and_line_5_6():
    """An A-pair at joint 2 keeps the family but not the closed form (the general solver answers);
    base and tool frames keep it; axes 5 and 6 one line is refused by the closed form."""
    a, alpha, d = ARMS["UR5"]
    with_a = apair.AChain([R, apair.APair(0.06, 0.05), R, R, R, R], a=a, alpha=alpha, offset=d)
    assert Solver(with_a)._closed is None
    framed = apair.AChain(
        [R] * 6,
        a=a,
        alpha=alpha,
        offset=d,
        base=apair.frames.frame([0.1, 0.2, 0.3], [0.1, 0.2, 0.3]),
        tool=apair.frames.frame([0.0, 0.0, 0.12], [0.0, PI / 2, 0.0]),
    )
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    sol = framed.ik(framed.fk(q), full=True)
    assert sol.method == "closed form" and among(q, sol.q)
    line = apair.AChain([R] * 6, a=[0.1, 0.4, 0.35, 0.05, 0, 0.03], alpha=[1.1, 0, 0, -0.9, 0, 0.4], offset=[0.2] * 6)
    with pytest.raises(ValueError, match="one line"):
        Parallel(line, 1.0)
