"""Base and tool frames (issue 38): fk, fk_study, the Jacobian and the dynamics of a chain with a
base and a tool, against numpy composition, finite differences and Pinocchio (the base as the
first joint's placement, the tool as a frame on the last body, gravity in the world)."""

from __future__ import annotations

import pickle

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

import apair
from apair.frames import frame, rpy_matrix
from apair.study import from_matrix, to_matrix


def random_frame(rng, scale=0.5):
    return frame(rng.uniform(-scale, scale, 3), rng.uniform(-np.pi, np.pi, 3))


def random_link(rng) -> apair.Link:
    m = rng.uniform(0.5, 3.0)
    x, y, z = rng.uniform(0.05, 0.5, 3)
    principal = m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return apair.Link(m, rng.uniform(-0.3, 0.3, 3), Q @ np.diag(principal) @ Q.T)


def random_design(rng, n, kinds=("sinusoidal", "general", "revolute")):
    """(pairs, a, alpha, offset, theta_offset, links, gravity) of a random chain, legs massless."""
    pairs = []
    for _ in range(n):
        kind = rng.choice(kinds)
        r_b, r_p = rng.uniform(0.05, 0.3, 2)
        if kind == "revolute":
            pairs.append(apair.APair.revolute())
        elif kind == "sinusoidal":
            pairs.append(apair.APair(r_b, r_p))
        else:
            b = r_b * r_p
            pairs.append(apair.APair(r_b, r_p, leg_length=np.sqrt(b * rng.uniform(1.2, 3.0) + r_b**2 + r_p**2 / 4)))
    return dict(
        pairs=pairs,
        a=rng.uniform(-0.5, 0.5, n),
        alpha=rng.uniform(-np.pi, np.pi, n),
        offset=rng.uniform(-0.3, 0.3, n),
        theta_offset=rng.uniform(-np.pi, np.pi, n),
        links=[random_link(rng) for _ in range(n)],
        gravity=rng.normal(size=3) * 5,
    )


def pair_of_chains(rng, n, kinds=("sinusoidal", "general", "revolute")):
    """(framed, plain, B, T): the same design with random base and tool frames and without."""
    d = random_design(rng, n, kinds)
    B, T = random_frame(rng), random_frame(rng, 0.2)
    return apair.AChain(**d, base=B, tool=T), apair.AChain(**d), B, T


def random_q(rng, chain, shape=()):
    lim = chain.limits
    return rng.uniform(lim[:, 0] * 0.9, lim[:, 1] * 0.9, shape + (chain.n,))


def test_rpy_is_urdfs_fixed_axis_convention():
    """R = Rz(yaw)·Ry(pitch)·Rx(roll): scipy's extrinsic x-y-z Euler angles."""
    rng = np.random.default_rng(1)
    for rpy in rng.uniform(-np.pi, np.pi, (20, 3)):
        np.testing.assert_allclose(rpy_matrix(rpy), Rotation.from_euler("xyz", rpy).as_matrix(), atol=1e-15)
    r, p, y = 0.3, -0.4, 1.1
    Rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    Ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    Rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    np.testing.assert_allclose(rpy_matrix([r, p, y]), Rz @ Ry @ Rx, atol=1e-15)


@pytest.mark.parametrize("n", [1, 3, 6])
def test_fk_is_base_fk_tool(n):
    rng = np.random.default_rng(10 + n)
    for _ in range(3):
        framed, plain, B, T = pair_of_chains(rng, n)
        q = random_q(rng, plain, (5,))
        want = B @ plain.fk(q) @ T
        np.testing.assert_allclose(framed.fk(q), want, atol=1e-14)
        np.testing.assert_allclose(framed.fk(q[0]), want[0], atol=1e-14)
        np.testing.assert_allclose(framed.fk(q[0].tolist()), want[0], atol=1e-14)  # the validating path
        # fk_study: the Study point of the same pose, |x| = 1
        S = framed.fk_study(q)
        np.testing.assert_allclose(np.linalg.norm(S[..., :4], axis=-1), 1.0, atol=1e-14)
        np.testing.assert_allclose(to_matrix(S), want, atol=1e-13)
        same = np.sign(np.sum(S[..., :4] * from_matrix(want)[..., :4], axis=-1))[..., None]
        np.testing.assert_allclose(S * same, from_matrix(want), atol=1e-13)
        np.testing.assert_allclose(framed.fk_study(q[1].tolist()), framed.fk_study(q[1]), atol=1e-15)


def test_attributes_are_read_only_copies():
    rng = np.random.default_rng(2)
    framed, plain, B, T = pair_of_chains(rng, 2)
    assert framed.base.dtype == np.float64 and framed.base.shape == (4, 4)
    np.testing.assert_array_equal(framed.base, B)
    np.testing.assert_array_equal(framed.tool, T)
    framed.base[0, 3] = 99.0
    framed.tool[0, 3] = 99.0
    np.testing.assert_array_equal(framed.base, B)
    np.testing.assert_array_equal(framed.tool, T)
    with pytest.raises(AttributeError):
        framed.base = np.eye(4)  # type: ignore[misc]
    np.testing.assert_array_equal(plain.base, np.eye(4))
    np.testing.assert_array_equal(plain.tool, np.eye(4))
    np.testing.assert_array_equal(framed.gravity, plain.gravity)  # as given: in the world


def _vee(S):
    return np.array([S[2, 1] - S[1, 2], S[0, 2] - S[2, 0], S[1, 0] - S[0, 1]]) / 2


@pytest.mark.parametrize("n", [1, 2, 4, 6])
def test_jacobian_is_the_tool_origins_in_the_world(n):
    """Rows v by central differences of the tool's origin, ω from the rotation's (Ṙ Rᵀ)^∨."""
    rng = np.random.default_rng(20 + n)
    h = 1e-6
    for _ in range(3):
        framed, plain, B, T = pair_of_chains(rng, n)
        q = random_q(rng, plain)
        J = framed.jacobian(q)
        F = framed.fk(q)
        for k in range(n):
            e = np.zeros(n)
            e[k] = h
            Fp, Fm = framed.fk(q + e), framed.fk(q - e)
            v = (Fp[:3, 3] - Fm[:3, 3]) / (2 * h)
            w = _vee((Fp[:3, :3] - Fm[:3, :3]) / (2 * h) @ F[:3, :3].T)
            np.testing.assert_allclose(J[:3, k], v, atol=1e-7)
            np.testing.assert_allclose(J[3:, k], w, atol=1e-7)
        # batches and the validating path agree with single calls
        qs = random_q(rng, plain, (2, 3))
        Js = framed.jacobian(qs)
        np.testing.assert_allclose(Js[1, 2], framed.jacobian(qs[1, 2]), atol=1e-15)
        np.testing.assert_allclose(framed.jacobian(q.tolist()), J, atol=1e-15)


def pinocchio_model(chain, base, tool, gravity):
    """Each R-pair a revolute joint, each A-pair a revolute and a prismatic joint along the same
    axis; the base is the first joint's placement, the tool a frame "tool" on the last body."""
    model = pin.Model()
    parent, placement = 0, pin.SE3(base[:3, :3], base[:3, 3])
    for i, p in enumerate(chain.pairs):
        parent = model.addJoint(parent, pin.JointModelRZ(), placement, f"r{i}")
        if p.kind != "revolute":
            parent = model.addJoint(parent, pin.JointModelPZ(), pin.SE3.Identity(), f"p{i}")
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
    model.addFrame(pin.Frame("tool", parent, 0, placement * pin.SE3(tool[:3, :3], tool[:3, 3]), pin.FrameType.OP_FRAME))
    model.gravity = pin.Motion(np.asarray(gravity, float), np.zeros(3))
    return model


def reduced(chain, q, qd):
    """Pinocchio's coordinates (θ, d(θ)), the coupling S and Ṡθ'."""
    law = chain.law(q)
    nf = sum(1 if p.kind == "revolute" else 2 for p in chain.pairs)
    qf, S, Sdqd, r = [], np.zeros((nf, chain.n)), np.zeros(nf), 0
    for i, p in enumerate(chain.pairs):
        S[r, i] = 1.0
        qf.append(q[i])
        r += 1
        if p.kind != "revolute":
            S[r, i], Sdqd[r] = law[i, 1], law[i, 2] * qd[i] ** 2
            qf.append(law[i, 0])
            r += 1
    return np.array(qf), S, Sdqd


def close(a, b, rel=1e-10):
    scale = max(1.0, float(np.abs(b).max()))
    assert np.abs(np.asarray(a) - b).max() <= rel * scale, (a, b)


@pytest.mark.parametrize("n", [1, 2, 3, 5, 6])
@pytest.mark.parametrize("kinds", [("revolute",), ("sinusoidal", "general", "revolute")])
def test_against_pinocchio(n, kinds):
    """fk, the Jacobian (LOCAL_WORLD_ALIGNED at the tool), M, g, τ and θ'' with a base, a tool
    and gravity in the world: R-chains directly, A-chains through the (θ, d) coupling."""
    rng = np.random.default_rng(30 + n + 10 * len(kinds))
    for _ in range(3):
        framed, _, B, T = pair_of_chains(rng, n, kinds)
        model = pinocchio_model(framed, B, T, framed.gravity)
        data = model.createData()
        fid = model.getFrameId("tool")
        for _ in range(3):
            q, qd, qdd = random_q(rng, framed), rng.normal(size=n), rng.normal(size=n)
            qf, S, Sdqd = reduced(framed, q, qd)
            pin.framesForwardKinematics(model, data, qf)
            close(framed.fk(q), data.oMf[fid].homogeneous)
            Jf = pin.computeFrameJacobian(model, data, qf, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            close(framed.jacobian(q), Jf.reshape(6, -1) @ S)
            Mf = np.atleast_2d(pin.crba(model, data, qf))
            M = S.T @ (np.triu(Mf) + np.triu(Mf, 1).T) @ S
            g = S.T @ pin.computeGeneralizedGravity(model, data, qf)
            bias = S.T @ pin.rnea(model, data, qf, S @ qd, Sdqd)
            close(framed.mass_matrix(q), M)
            close(framed.gravity_torques(q), g)
            close(framed.bias(q, qd), bias)
            tau = M @ qdd + bias
            close(framed.inverse_dynamics(q, qd, qdd), tau)
            close(framed.forward_dynamics(q, qd, tau), qdd, 1e-8)  # through M⁻¹: its condition
            if kinds == ("revolute",):
                close(framed.forward_dynamics(q, qd, tau), pin.aba(model, data, q, qd, tau), 1e-8)


def test_energy_potential_is_of_world_gravity():
    """dV/dθ = g(θ) with the base's rotation: V uses the same (world) gravity as the torques."""
    rng = np.random.default_rng(4)
    framed, _, _, _ = pair_of_chains(rng, 4)
    q, h = random_q(rng, framed), 1e-6
    for k in range(4):
        e = np.zeros(4)
        e[k] = h
        dV = (framed.energy(q + e, np.zeros(4))[1] - framed.energy(q - e, np.zeros(4))[1]) / (2 * h)
        assert abs(dV - framed.gravity_torques(q)[k]) < 1e-6 * max(1.0, abs(dV))


def test_identity_frames_are_bit_identical():
    """base = tool = identity (or None) gives today's numbers exactly, through the same path."""
    rng = np.random.default_rng(5)
    d = random_design(rng, 4)
    plain = apair.AChain(**d)
    ident = apair.AChain(**d, base=np.eye(4), tool=np.eye(4).tolist())
    assert not ident._framed and ident._call == ident._fast.call  # no composition on the way
    q, qd, qdd = random_q(rng, plain, (3,)), rng.normal(size=(3, 4)), rng.normal(size=(3, 4))
    for method, args in [
        ("fk", (q,)),
        ("fk_study", (q,)),
        ("jacobian", (q,)),
        ("mass_matrix", (q,)),
        ("gravity_torques", (q,)),
        ("bias", (q, qd)),
        ("inverse_dynamics", (q, qd, qdd)),
        ("forward_dynamics", (q, qd, qdd)),
        ("energy", (q, qd)),
    ]:
        np.testing.assert_array_equal(getattr(ident, method)(*args), getattr(plain, method)(*args))
        np.testing.assert_array_equal(
            getattr(ident, method)(*(a[0].tolist() for a in args)), getattr(plain, method)(*(a[0] for a in args))
        )
    assert repr(ident) == repr(plain)


def test_pickle_keeps_the_frames():
    rng = np.random.default_rng(6)
    framed, _, B, T = pair_of_chains(rng, 3)
    q = random_q(rng, framed)
    framed.ik_local(framed.fk(q), q)  # sets up the fast path (dropped when pickled)
    back = pickle.loads(pickle.dumps(framed))
    np.testing.assert_array_equal(back.base, B)
    np.testing.assert_array_equal(back.fk(q), framed.fk(q))
    np.testing.assert_array_equal(back.jacobian(q), framed.jacobian(q))
    np.testing.assert_array_equal(back.gravity_torques(q), framed.gravity_torques(q))


@pytest.mark.parametrize(
    "value, words",
    [
        (np.full((4, 4), np.nan), "base: contains NaN"),
        (np.eye(3), "base: expected a 4x4 rigid transform, got shape (3, 3)"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), "base: the rotation part is a reflection"),
        (np.diag([1.0, 1.0, 1.001, 1.0]), "base: the rotation part is not orthonormal"),
        (np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0.1, 1.0]]), "base: last row must be"),
        (frame([1e41, 0, 0]), "base translation[0]: 1e+41 m is outside the range"),
        ("eye", "base: expected real numbers"),
    ],
)
def test_bad_frames_are_refused(value, words):
    d = random_design(np.random.default_rng(7), 2)
    with pytest.raises(ValueError) as exc:
        apair.AChain(**d, base=value)
    assert words in str(exc.value) and "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="^tool[: ]"):
        apair.AChain(**d, tool=value)
