"""Prismatic (P) and helical (H) pairs in chains, against Pinocchio's JointModelPZ and
JointModelHelicalUnaligned (and RZ for R-pairs) on the same chain: fk, the Jacobian, M, inverse and
forward dynamics and gravity, on random and on special designs (twists 0 and ±90°, zero lengths)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import apair
from apair import APair

SLIDE = (-0.4, 0.6)  # the P-pairs' range [m]


def random_link(rng) -> apair.Link:
    m = rng.uniform(0.5, 3.0)
    x, y, z = rng.uniform(0.05, 0.5, 3)
    principal = m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return apair.Link(m, rng.uniform(-0.3, 0.3, 3), Q @ np.diag(principal) @ Q.T)


def make_pair(kind: str, rng) -> APair:
    if kind == "P":
        return APair.prismatic()
    if kind == "H":
        return APair.helical(rng.choice([-1, 1]) * rng.uniform(0.001, 0.05))
    return APair.revolute()


def chain_of(pattern: str, rng, special: bool = False) -> apair.AChain:
    n = len(pattern)
    if special:
        pick = lambda values: rng.choice(values, n)
        dh = pick([0.0, 0.1, 0.3]), pick([0.0, np.pi / 2, -np.pi / 2]), pick([0.0, 0.1]), pick([0.0, np.pi / 2])
    else:
        dh = rng.uniform(-0.5, 0.5, n), rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.3, 0.3, n), rng.uniform(-3, 3, n)
    return apair.AChain(
        [make_pair(k, rng) for k in pattern],
        *dh,
        links=[random_link(rng) for _ in range(n)],
        gravity=rng.normal(size=3) * 5,
        limits=[SLIDE if k == "P" else None for k in pattern],
    )


def pinocchio_model(chain: apair.AChain):
    """Joint i as Pinocchio's RZ, PZ or helical joint about z, then the constant Rz(φ)Tz(c)Tx(a)Rx(α)
    to frame i (it commutes with the joint's motion along z); link i after it; a frame "tip" at frame n."""
    model = pin.Model()
    parent, placement = 0, pin.SE3.Identity()
    for i, p in enumerate(chain.pairs):
        joint = {
            "revolute": lambda: pin.JointModelRZ(),
            "prismatic": lambda: pin.JointModelPZ(),
            "helical": lambda: pin.JointModelHelicalUnaligned(np.array([0.0, 0.0, 1.0]), p.pitch),
        }[p.kind]()
        parent = model.addJoint(parent, joint, placement, f"j{i}")
        a, alpha, c, phi = chain.a[i], chain.alpha[i], chain.offset[i], chain.theta_offset[i]
        D = (
            pin.SE3(pin.utils.rotate("z", phi), np.zeros(3))
            * pin.SE3(np.eye(3), np.array([0, 0, c]))
            * pin.SE3(np.eye(3), np.array([a, 0, 0]))
            * pin.SE3(pin.utils.rotate("x", alpha), np.zeros(3))
        )
        L = chain.links[i]
        model.appendBodyToJoint(parent, D.act(pin.Inertia(L.mass, L.com, L.inertia)), pin.SE3.Identity())
        placement = D
    model.addFrame(pin.Frame("tip", parent, parent, placement, pin.FrameType.OP_FRAME))
    model.gravity = pin.Motion(chain.gravity, np.zeros(3))
    return model


def states(chain, rng, count):
    """Joint values inside the ranges (with 0 and π for the angles, the range ends for slides)."""
    lim = chain.limits
    for k in range(count):
        q = rng.uniform(lim[:, 0], lim[:, 1])
        if k == 0:
            q = np.where([p.kind == "prismatic" for p in chain.pairs], lim[:, 1], np.pi)
        elif k == 1:
            q = np.where([p.kind == "prismatic" for p in chain.pairs], lim[:, 0], 0.0)
        yield q, rng.normal(size=chain.n), rng.normal(size=chain.n)


def compare(chain, rng, count=4):
    model = pinocchio_model(chain)
    data = model.createData()
    tip = model.getFrameId("tip")
    for q, qd, qdd in states(chain, rng, count):
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(chain.fk(q), data.oMf[tip].homogeneous, atol=1e-12)
        Jp = pin.computeFrameJacobian(model, data, q, tip, pin.LOCAL_WORLD_ALIGNED).reshape(6, -1)
        np.testing.assert_allclose(chain.jacobian(q), Jp, atol=1e-12)
        M = np.atleast_2d(pin.crba(model, data, q))
        M = np.triu(M) + np.triu(M, 1).T
        scale = np.abs(M).max()
        np.testing.assert_allclose(chain.mass_matrix(q), M, atol=1e-10 * scale)
        tau = pin.rnea(model, data, q, qd, qdd)
        np.testing.assert_allclose(chain.inverse_dynamics(q, qd, qdd), tau, atol=1e-10 * np.abs(tau).max())
        np.testing.assert_allclose(
            chain.gravity_torques(q), pin.computeGeneralizedGravity(model, data, q), atol=1e-10 * scale * 10
        )
        np.testing.assert_allclose(chain.forward_dynamics(q, qd, tau), qdd, atol=1e-8)
        np.testing.assert_allclose(pin.aba(model, data, q, qd, tau), qdd, atol=1e-8)


@pytest.mark.parametrize("pattern", ["P", "H", "RP", "PR", "RRPRRR", "PPP", "RHPHR", "HRPRRRP", "RRPR"])
def test_lower_pairs_equal_pinocchio(pattern):
    rng = np.random.default_rng(sum(map(ord, pattern)))
    for _ in range(3):
        compare(chain_of(pattern, rng), rng)


@pytest.mark.parametrize("pattern", ["RRPR", "RRPRRR", "PRHRP", "RPRPRPR"])
def test_lower_pairs_special_designs_equal_pinocchio(pattern):
    rng = np.random.default_rng(7 + len(pattern))
    for _ in range(3):
        compare(chain_of(pattern, rng, special=True), rng)
