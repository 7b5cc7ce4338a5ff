"""Dynamics of A-chains: against Pinocchio (R-chains, and A-pairs as coupled RZ+PZ joints),
against an independent finite-difference energy with legs, and the structural identities."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import apair

N_RANGE = range(1, 7)


def random_link(rng) -> apair.Link:
    """A solid box of random size and mass, turned at random: a physically realisable inertia."""
    m = rng.uniform(0.5, 3.0)
    x, y, z = rng.uniform(0.05, 0.5, 3)
    principal = m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return apair.Link(m, rng.uniform(-0.3, 0.3, 3), Q @ np.diag(principal) @ Q.T)


def random_chain(rng, n, kinds=("sinusoidal", "general", "revolute"), legs=False) -> apair.AChain:
    pairs = []
    for _ in range(n):
        kind = rng.choice(kinds)
        r_b, r_p = rng.uniform(0.05, 0.3, 2)
        ml = rng.uniform(0.05, 0.5) if legs else 0.0
        if kind == "revolute":
            pairs.append(apair.APair.revolute())
        elif kind == "sinusoidal":
            pairs.append(apair.APair(r_b, r_p, leg_mass=ml))
        else:
            b = r_b * r_p
            a = b * rng.uniform(1.2, 3.0)  # a > b: every angle is reachable
            pairs.append(apair.APair(r_b, r_p, leg_length=np.sqrt(a + r_b**2 + r_p**2 / 4), leg_mass=ml))
    return apair.AChain(
        pairs,
        rng.uniform(-0.5, 0.5, n),
        rng.uniform(-np.pi, np.pi, n),
        rng.uniform(-0.3, 0.3, n),
        rng.uniform(-np.pi, np.pi, n),
        links=[random_link(rng) for _ in range(n)],
        gravity=rng.normal(size=3) * 5,
    )


def pinocchio_model(chain: apair.AChain):
    """Each R-pair a revolute joint; each A-pair a revolute joint followed by a prismatic one along
    the same axis (d as a free coordinate); link i attached after them."""
    model = pin.Model()
    parent, placement = 0, pin.SE3.Identity()
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
    model.gravity = pin.Motion(chain.gravity, np.zeros(3))
    return model


def reduced(chain, q, qd, qdd):
    """Full coordinates of the Pinocchio model and the coupling S, Ṡθ' (d_i = d_i(θ_i))."""
    law = chain.law(q)
    qf = []
    nf = sum(1 if p.kind == "revolute" else 2 for p in chain.pairs)
    S = np.zeros((nf, chain.n))
    Sdqd = np.zeros(nf)
    r = 0
    for i, p in enumerate(chain.pairs):
        S[r, i] = 1.0
        qf.append(q[i])
        r += 1
        if p.kind != "revolute":
            S[r, i] = law[i, 1]
            Sdqd[r] = law[i, 2] * qd[i] ** 2
            qf.append(law[i, 0])
            r += 1
    return np.array(qf), S, Sdqd


@pytest.mark.parametrize("n", N_RANGE)
def test_revolute_chain_equals_pinocchio(n, backend):
    rng = np.random.default_rng(100 + n)
    for _ in range(4):
        chain = random_chain(rng, n, kinds=("revolute",))
        model = pinocchio_model(chain)
        data = model.createData()
        for _ in range(3):
            q, qd, qdd = rng.uniform(-3, 3, n), rng.normal(size=n), rng.normal(size=n)
            Mp = pin.crba(model, data, q)
            Mp = np.triu(Mp) + np.triu(Mp, 1).T
            np.testing.assert_allclose(chain.mass_matrix(q), Mp, atol=1e-9)
            np.testing.assert_allclose(chain.bias(q, qd), pin.rnea(model, data, q, qd, np.zeros(n)), atol=1e-9)
            np.testing.assert_allclose(chain.inverse_dynamics(q, qd, qdd), pin.rnea(model, data, q, qd, qdd), atol=1e-9)
            np.testing.assert_allclose(
                chain.gravity_torques(q), pin.computeGeneralizedGravity(model, data, q), atol=1e-9
            )


def special_chain(rng, n) -> apair.AChain:
    """The constants real robots use: twists 0 and ±90°, lengths, offsets and angle offsets 0 or
    round values (intersecting and parallel axes), sinusoidal A-pairs with massive legs and R-pairs."""
    pairs = [apair.APair.revolute() if rng.random() < 0.4 else apair.APair(0.05, 0.04, leg_mass=0.1) for _ in range(n)]
    pick = lambda values: rng.choice(values, n)
    return apair.AChain(
        pairs,
        pick([0.0, 0.1, 0.3]),
        pick([0.0, np.pi / 2, -np.pi / 2]),
        pick([0.0, 0.1]),
        pick([0.0, np.pi / 2]),
        links=[random_link(rng) for _ in range(n)],
        gravity=(0.0, 0.0, -9.81),
    )


@pytest.mark.parametrize("n", [2, 4, 6])
def test_special_designs_equal_reduced_pinocchio(n, backend):
    """Twists 0 and ±90°, zero lengths and offsets, joint values 0 and π (d = 0 for an A-pair),
    legs with mass set to zero for Pinocchio's model: M, bias, τ and θ'' agree."""
    rng = np.random.default_rng(300 + n)
    for _ in range(6):
        chain = special_chain(rng, n)
        plain = apair.AChain(
            [apair.APair(0.05, 0.04) if p.kind != "revolute" else p for p in chain.pairs],
            chain.a,
            chain.alpha,
            chain.offset,
            chain.theta_offset,
            links=chain.links,
            gravity=chain.gravity,
        )
        model = pinocchio_model(plain)
        data = model.createData()
        for _ in range(3):
            q = rng.choice([0.0, np.pi, -np.pi, 0.5, -2.0], n)
            qd, qdd = rng.normal(size=n), rng.normal(size=n)
            qf, S, Sdqd = reduced(plain, q, qd, qdd)
            Mf = pin.crba(model, data, qf)
            M = S.T @ (np.triu(Mf) + np.triu(Mf, 1).T) @ S
            bias = S.T @ pin.rnea(model, data, qf, S @ qd, Sdqd)
            np.testing.assert_allclose(plain.mass_matrix(q), M, atol=1e-9)
            np.testing.assert_allclose(plain.bias(q, qd), bias, atol=1e-9)
            np.testing.assert_allclose(plain.inverse_dynamics(q, qd, qdd), M @ qdd + bias, atol=1e-9)
            np.testing.assert_allclose(plain.forward_dynamics(q, qd, M @ qdd + bias), qdd, atol=1e-7)
            # the legs only add: their mass matrix is the plain one plus a positive semidefinite part
            extra = np.linalg.eigvalsh(chain.mass_matrix(q) - plain.mass_matrix(q))
            assert extra.min() > -1e-12
            np.testing.assert_allclose(
                chain.forward_dynamics(q, qd, chain.inverse_dynamics(q, qd, qdd)), qdd, atol=1e-7
            )


@pytest.mark.parametrize("n", N_RANGE)
def test_apair_chain_equals_reduced_pinocchio(n, backend):
    rng = np.random.default_rng(200 + n)
    for _ in range(4):
        chain = random_chain(rng, n, kinds=("sinusoidal", "general", "sinusoidal", "revolute"))
        model = pinocchio_model(chain)
        data = model.createData()
        for _ in range(3):
            q, qd, qdd = rng.uniform(-3, 3, n), rng.normal(size=n), rng.normal(size=n)
            qf, S, Sdqd = reduced(chain, q, qd, qdd)
            Mf = pin.crba(model, data, qf)
            Mf = np.triu(Mf) + np.triu(Mf, 1).T
            np.testing.assert_allclose(chain.mass_matrix(q), S.T @ Mf @ S, atol=1e-9)
            bias = S.T @ pin.rnea(model, data, qf, S @ qd, Sdqd)
            np.testing.assert_allclose(chain.bias(q, qd), bias, atol=1e-9)
            tau = S.T @ pin.rnea(model, data, qf, S @ qd, S @ qdd + Sdqd)
            np.testing.assert_allclose(chain.inverse_dynamics(q, qd, qdd), tau, atol=1e-9)


def frames(chain, q):
    """Frames 0..n of the chain at q, from the forward kinematics of its sub-chains."""
    out = [np.eye(4)]
    for i in range(1, chain.n + 1):
        sub = apair.AChain(chain.pairs[:i], chain.a[:i], chain.alpha[:i], chain.offset[:i], chain.theta_offset[:i])
        out.append(sub.fk(q[:i]))
    return out


def points_and_bodies(chain, q):
    """World positions: link centres of mass, link rotations, and each leg's two end points."""
    F = frames(chain, q)
    coms = [F[i + 1][:3, :3] @ chain.links[i].com + F[i + 1][:3, 3] for i in range(chain.n)]
    rots = [F[i + 1][:3, :3] for i in range(chain.n)]
    legs = []
    for i, p in enumerate(chain.pairs):
        if p.kind == "revolute":
            continue
        ends = p.leg_endpoints(q[i])  # pair's base frame = frame i-1
        world = ends @ F[i][:3, :3].T + F[i][:3, 3]
        legs.append((p.leg_mass, world[:, 0], world[:, 1]))
    return coms, rots, legs


def numeric_energy(chain, q, qd, eps=1e-6):
    """T and V from positions alone: velocities by central differences along θ'."""
    cp, rp, lp = points_and_bodies(chain, q + eps * qd)
    cm, rm, lm = points_and_bodies(chain, q - eps * qd)
    c0, r0, l0 = points_and_bodies(chain, q)
    T = 0.0
    for i, link in enumerate(chain.links):
        v = (cp[i] - cm[i]) / (2 * eps)
        W = (rp[i] - rm[i]) / (2 * eps) @ r0[i].T
        w = np.array([W[2, 1], W[0, 2], W[1, 0]])
        Iw = r0[i] @ link.inertia @ r0[i].T
        T += 0.5 * link.mass * v @ v + 0.5 * w @ Iw @ w
    for (m, ap, bp), (_, am, bm) in zip(lp, lm):
        va, vb = (ap - am) / (2 * eps), (bp - bm) / (2 * eps)
        T += m / 6 * np.sum(va * va + va * vb + vb * vb)
    V = -chain.gravity @ sum(link.mass * c for link, c in zip(chain.links, c0))
    for m, a, b in l0:
        V -= chain.gravity @ (m * np.sum(a + b, axis=0) / 2)
    return T, V


@pytest.mark.parametrize("n", N_RANGE)
def test_energy_with_legs_equals_the_rod_model(n, backend):
    """T = ½θ'ᵀMθ' and V of the kernels against the rods' (m/6)(|v_a|²+v_a·v_b+|v_b|²) and
    weights, computed from leg end points and frames by finite differences."""
    rng = np.random.default_rng(300 + n)
    chain = random_chain(rng, n, legs=True)
    for _ in range(3):
        q, qd = rng.uniform(-2, 2, n), rng.normal(size=n)
        T, V = numeric_energy(chain, q, qd)
        E = chain.energy(q, qd)
        assert E[0] == pytest.approx(T, rel=1e-7, abs=1e-9)
        assert E[1] == pytest.approx(V, rel=1e-12, abs=1e-12)
        assert E[0] == pytest.approx(0.5 * qd @ chain.mass_matrix(q) @ qd, rel=1e-12)


@pytest.mark.parametrize("n", N_RANGE)
def test_structure_with_legs(n, backend):
    rng = np.random.default_rng(400 + n)
    chain = random_chain(rng, n, legs=True)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, n), rng.normal(size=n), rng.normal(size=n)
        M = chain.mass_matrix(q)
        np.testing.assert_allclose(M, M.T, atol=1e-13)
        assert np.linalg.eigvalsh(M)[0] > 0
        # Ṁ − 2C is skew-symmetric (Ṁ by central differences along θ')
        eps = 1e-6
        Mdot = (chain.mass_matrix(q + eps * qd) - chain.mass_matrix(q - eps * qd)) / (2 * eps)
        N = Mdot - 2 * chain.coriolis_matrix(q, qd)
        np.testing.assert_allclose(N + N.T, 0, atol=1e-6 * max(1, np.abs(Mdot).max()))
        # C θ' + g is the bias; ∂τ/∂θ'' is M (τ is affine in θ'')
        np.testing.assert_allclose(
            chain.coriolis_matrix(q, qd) @ qd + chain.gravity_torques(q), chain.bias(q, qd), atol=1e-10
        )
        tau0 = chain.inverse_dynamics(q, qd, qdd)
        J = np.stack([chain.inverse_dynamics(q, qd, qdd + e) - tau0 for e in np.eye(n)], axis=1)
        np.testing.assert_allclose(J, M, atol=1e-9)
        # forward dynamics inverts inverse dynamics, batched too
        np.testing.assert_allclose(chain.forward_dynamics(q, qd, tau0), qdd, atol=1e-9)
    qs, qds = rng.uniform(-2, 2, (5, n)), rng.normal(size=(5, n))
    taus = rng.normal(size=(5, n))
    batch = chain.forward_dynamics(qs, qds, taus)
    np.testing.assert_allclose(batch, np.stack([chain.forward_dynamics(*x) for x in zip(qs, qds, taus)]), atol=1e-12)


@pytest.mark.parametrize("n", [1, 2, 3])
def test_energy_is_conserved_in_free_motion(n):
    rng = np.random.default_rng(500 + n)
    chain = random_chain(rng, n, legs=True)
    q0, qd0 = rng.uniform(-1, 1, n), rng.normal(size=n)
    traj = chain.simulate(q0, qd0, np.linspace(0, 2, 41), rtol=1e-12, atol=1e-12, limits="ignore")
    E = traj.energy
    scale = np.max(np.abs(traj.kinetic)) + np.max(np.abs(traj.potential))
    assert np.max(np.abs(E - E[0])) <= 1e-8 * scale
    assert traj.q.shape == (41, n) and np.ptp(traj.q[:, 0]) > 1e-3  # it did move


def test_simulate_with_torque_does_work():
    rng = np.random.default_rng(7)
    chain = random_chain(rng, 2, legs=True)
    chain.gravity[:] = 0
    t = np.linspace(0, 1, 11)
    traj = chain.simulate(np.zeros(2), np.zeros(2), t, tau=lambda tt, q, qd: np.array([1.0, 0.0]))
    # the work of a constant torque on joint 1 equals the energy gained
    assert traj.energy[-1] == pytest.approx(1.0 * (traj.q[-1, 0] - traj.q[0, 0]), rel=1e-7)
    const = chain.simulate(np.zeros(2), np.zeros(2), t, tau=[1.0, 0.0])
    np.testing.assert_allclose(const.q, traj.q, atol=1e-9)


@pytest.mark.parametrize("kind", ["sinusoidal", "general"])
def test_single_pair_closed_form_equals_the_chain(kind, backend):
    """The Lagrange closed form of one pair (derivations/apair_dynamics.py) and the chain recursion
    for n = 1, with legs."""
    rng = np.random.default_rng(600)
    for _ in range(5):
        r_b, r_p = rng.uniform(0.05, 0.3, 2)
        ml = rng.uniform(0.05, 0.5)
        if kind == "sinusoidal":
            p = apair.APair(r_b, r_p, leg_mass=ml)
        else:
            b = r_b * r_p
            p = apair.APair(r_b, r_p, leg_length=np.sqrt(b * rng.uniform(0.2, 3.0) + r_b**2 + r_p**2 / 4), leg_mass=ml)
        link = random_link(rng)
        g = rng.uniform(1, 20)
        chain = apair.AChain([p], [0.0], [0.0], links=[link], gravity=[0, 0, -g])
        lim = p.theta_limit or np.pi
        theta = rng.uniform(-0.95, 0.95, 20) * lim
        qd, qdd = rng.normal(size=20), rng.normal(size=20)
        terms = p.dynamics(theta, qd, qdd, platform=link, g=g)
        tau = chain.inverse_dynamics(theta[:, None], qd[:, None], qdd[:, None])[:, 0]
        np.testing.assert_allclose(terms[:, 0], tau, rtol=1e-11, atol=1e-12)
        np.testing.assert_allclose(terms[:, 1], chain.mass_matrix(theta[:, None])[:, 0, 0], rtol=1e-11)
        np.testing.assert_allclose(terms[:, 3], chain.gravity_torques(theta[:, None])[:, 0], rtol=1e-11, atol=1e-12)
