"""The closed forms of families at the base end of a six-joint R-chain (a spherical wrist at joints
1-3, axes 3, 4, 5 parallel, axes 4, 5, 6 parallel with 1 and 2 meeting), solved as the reversed
chain's (apair.ik.reverse, issue 42): the reversed chain's fk and Jacobian; the same solution sets
as EAIK on industrial arms mounted wrist-first (and a design with axes 4∥5∥6, 1∩2), 2000 poses
each, every solution both ways; the same sets as the general solver; joints at 0, ±π/2 and π;
singular configurations named in the chain's own joint numbers; the NumPy twin, ik's fast path
and base and tool frames."""

from __future__ import annotations

import numpy as np
import pytest
import test_ik_parallel as parallel_arms
import test_ik_three_parallel as three_parallel_arms
import test_ik_wrist as wrist_arms
from eaik.IK_DH import DhRobot
from test_ik_parallel import among, general_solver

import apair
from apair.frames import dh_matrix, frame
from apair.ik.reverse import Reversed, ReversedView
from apair.ik.solver import Solver

PI = np.pi
R = apair.APair.revolute()


def upside_down(a, alpha, d, a6: float = 0.05, alpha6: float = 0.4):
    """DH (a, α, d) of a chain whose reversed chain has joints 1-5 of (a, α, d) (a'_6 = α'_6 = 0:
    its own a_6, α_6 are the reversed chain's base)."""
    a, alpha, d = (np.asarray(x, float) for x in (a, alpha, d))
    return np.append(-a[4::-1], a6), np.append(-alpha[4::-1], alpha6), -d[::-1]


SOURCES = {**wrist_arms.ARMS, **parallel_arms.ARMS, **three_parallel_arms.ARMS}
ARMS = {name: upside_down(*SOURCES[name]) for name in SOURCES}
ARMS["UR5 (a6 = α6 = 0)"] = upside_down(*SOURCES["UR5"], a6=0.0, alpha6=0.0)
INDUSTRIAL = ["PUMA560", "KUKA-KR6", "Fanuc-M20", "UR5", "UR10e", "general-twists"]


def arm(name: str, theta_offset=None, **frames) -> apair.AChain:
    a, alpha, d = ARMS[name]
    return apair.AChain([R] * 6, a=a, alpha=alpha, offset=d, theta_offset=theta_offset, **frames)


def test_view_is_the_reversed_chain():
    """front · fk(θ)⁻¹ is the product of the reversed chain's DH joints at θ' (θ_{7−k} = −θ'_k),
    and the view's Jacobian is its derivative (central differences)."""
    chain = arm("no-parallel-no-intersecting", theta_offset=[0.3, -0.2, 0.5, 0.1, 1.0, -0.4])
    view = ReversedView(chain)
    rng = np.random.default_rng(2)
    for qr in rng.uniform(-PI, PI, (5, 6)):
        T = np.eye(4)
        for k in range(6):
            T = T @ dh_matrix(view.a[k], view.alpha[k], view.offset[k], qr[k] + view.theta_offset[k])
        assert np.abs(view.fk(qr[None])[0] - T).max() < 1e-14
        J, h = view.jacobian(qr[None])[0], 1e-6
        for k in range(6):
            dq = np.zeros(6)
            dq[k] = h
            Fp, Fm = view.fk((qr + dq)[None])[0], view.fk((qr - dq)[None])[0]
            v = (Fp[:3, 3] - Fm[:3, 3]) / (2 * h)
            W = (Fp[:3, :3] - Fm[:3, :3]) / (2 * h) @ T[:3, :3].T
            w = np.array([W[2, 1], W[0, 2], W[1, 0]])
            assert np.abs(J[:, k] - np.concatenate([v, w])).max() < 1e-8, k
        assert np.allclose(view.pose(chain.fk(view.original(qr))), T, atol=1e-14)


def test_every_reversed_family_goes_to_the_closed_form():
    for name in ARMS:
        chain = arm(name)
        family = chain.kinematic_family().family
        assert family is not None and family.reversed, name
        assert isinstance(Solver(chain)._closed, Reversed), name
        q = np.full(6, 0.3)
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and sol.certified and among(q, sol.q), name
        assert sol.family == family.key


@pytest.mark.parametrize("name", INDUSTRIAL)
def test_same_sets_as_eaik(name):
    """2000 random poses of an arm mounted wrist-first: every solution EAIK finds (verified by
    apair's fk) is apair's and every one of apair's is EAIK's; q is among them."""
    a, alpha, d = ARMS[name]
    chain = arm(name)
    eaik = DhRobot(alpha, a, d)
    rng = np.random.default_rng(11)
    for _ in range(2000):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        ours = chain.ik(T)
        assert among(q, ours), (name, q)
        theirs = [s for s in np.asarray(eaik.IK(T).Q).reshape(-1, 6) if np.abs(chain.fk(s) - T).max() <= 1e-9]
        assert all(among(s, ours) for s in theirs), (name, q)
        assert all(among(s, np.array(theirs)) for s in ours), (name, q)


@pytest.mark.parametrize(
    "name", ["no-parallel-no-intersecting", "first-two-intersecting", "quartic", "5∥6", "a5=0", "right-angles"]
)
def test_same_sets_as_the_general_solver(name):
    chain = arm(name)
    general = general_solver(chain)
    rng = np.random.default_rng(3)
    for _ in range(8):
        q = rng.uniform(-PI, PI, 6)
        T = chain.fk(q)
        ours, theirs = chain.ik(T, full=True), general.solve(T)
        assert theirs.method != "closed form" and theirs.certified
        assert len(ours.q) == len(theirs.q) and all(among(s, theirs.q) for s in ours.q), (name, q)


@pytest.mark.parametrize("name", ["PUMA560", "UR5", "quartic"])
def test_joint_values_at_zero_and_pi(name):
    """Joints at 0, ±π/2 and π, with and without offsets φ: q is among the solutions, or (where
    the pose is singular) the note names the continuum in the chain's joint numbers."""
    for phi in (None, [0.3, -0.2, 0.5, 0.0, 1.0, -0.4]):
        chain = arm(name, theta_offset=phi)
        rng = np.random.default_rng(5)
        for _ in range(30):
            q = rng.choice([0.0, PI, -PI / 2, PI / 2], 6)
            sol = chain.ik(chain.fk(q), full=True)
            assert sol.method == "closed form" and len(sol.q) and np.all(sol.error <= 1e-9), (name, q)
            if "continuum" not in sol.note:
                assert among(q, sol.q), (name, q, sol.q)


def test_singular_configurations_in_the_chains_numbers():
    """A UR5 mounted wrist-first with θ_2 = 0 (axis 1 parallel to axes 3-5) and a PUMA mounted so
    with θ_2 = 0 (axes 1 and 3 in line): one member of each continuum, the note in the chain's
    joint numbers; the general solver refuses both poses."""
    ur = arm("UR5")
    q = np.array([-0.5, 0.0, 1.1, 0.9, -0.7, 0.4])
    sol = ur.ik(ur.fk(q), full=True)
    assert "joints 1, 3, 4 and 5: axis 1 parallel to axes 3, 4 and 5" in sol.note, sol.note
    assert np.all(sol.error <= 1e-9) and any(abs(s[5] - q[5]) < 1e-7 and abs(s[1]) < 1e-6 for s in sol.q)
    puma = arm("PUMA560")
    sol = puma.ik(puma.fk(q), full=True)
    assert "joints 1 and 3: axes 1 and 3 in line" in sol.note, sol.note
    assert np.all(sol.error <= 1e-9)
    for chain in (ur, puma):
        with pytest.raises(ValueError, match="not isolated"):
            general_solver(chain).solve(chain.fk(q))


@pytest.mark.parametrize("name", ["PUMA560", "UR5", "quartic", "no-parallel-no-intersecting"])
def test_numpy_twin_gives_the_same_sets(name):
    chain = arm(name)
    rng = np.random.default_rng(29)
    Ts = chain.fk(rng.uniform(-PI, PI, (30, 6)))
    ours = [chain.ik(T) for T in Ts]
    apair.set_backend("numpy")
    try:
        twin = [arm(name).ik(T) for T in Ts]
    finally:
        apair.set_backend(None)
    for a, b in zip(ours, twin):
        assert a.shape == b.shape and np.allclose(a, b, atol=1e-9), name


@pytest.mark.skipif(not apair.c_available(), reason="the compiled C kernels are not installed")
def test_fast_path_gives_the_validating_paths_numbers():
    for name in ["PUMA560", "UR10e", "quartic"]:
        chain = arm(name)
        rng = np.random.default_rng(4)
        chain.ik(chain.fk(np.zeros(6)))
        assert chain._ik_fast is not None, name
        for _ in range(50):
            T = chain.fk(rng.uniform(-PI, PI, 6))
            fast, full = chain.ik(T), chain._ik.solve(T)
            assert np.array_equal(fast, full.q), name


def test_base_and_tool_frames_and_scales():
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    framed = arm(
        "UR10e", base=frame([0.1, 0.2, 0.3], [0.1, 0.2, 0.3]), tool=frame([0.0, 0.0, 0.12], [0.0, PI / 2, 0.0])
    )
    sol = framed.ik(framed.fk(q), full=True)
    assert sol.method == "closed form" and among(q, sol.q)
    for scale in (1e-3, 1e3):
        a, alpha, d = ARMS["PUMA560"]
        chain = apair.AChain([R] * 6, a=a * scale, alpha=alpha, offset=d * scale)
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "closed form" and among(q, sol.q) and np.all(sol.error <= 1e-9)
