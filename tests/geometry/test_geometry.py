"""Layers 2-4: identities and geometry of pairs and chains, on random designs, for both backends."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import apair
from apair.study import from_matrix, to_matrix


def random_pair(rng: np.random.Generator, kind: str) -> apair.APair:
    r_b, r_p = rng.uniform(0.2, 2.0, 2)
    if kind == "revolute":
        return apair.APair.revolute()
    if kind == "sinusoidal":
        return apair.APair(r_b, r_p)
    # general: a = L1² − r_b² − r_p²/4 anywhere in (−b, 3b), both sides of a = b
    b = r_b * r_p
    a = b * rng.uniform(-0.9, 3.0)
    return apair.APair(r_b, r_p, leg_length=np.sqrt(a + r_b**2 + r_p**2 / 4))


def random_chain(rng: np.random.Generator, n: int, kinds=("sinusoidal", "general", "revolute")) -> apair.AChain:
    pairs = [random_pair(rng, rng.choice(kinds)) for _ in range(n)]
    return apair.AChain(
        pairs,
        rng.uniform(-1, 1, n),
        rng.uniform(-np.pi, np.pi, n),
        rng.uniform(-1, 1, n),
        rng.uniform(-np.pi, np.pi, n),
    )


def random_q(rng: np.random.Generator, chain: apair.AChain, count: int) -> np.ndarray:
    """Joint angles inside every pair's range (strictly, so that d' is finite)."""
    q = rng.uniform(-np.pi, np.pi, (count, chain.n))
    for i, p in enumerate(chain.pairs):
        if p.theta_limit is not None:
            q[:, i] = rng.uniform(-0.98, 0.98, count) * p.theta_limit
    return q


KINDS = ["sinusoidal", "general", "revolute"]


@pytest.mark.parametrize("kind", ["sinusoidal", "general"])
def test_leg_lengths_constant_along_the_motion(kind, backend):
    rng = np.random.default_rng(1)
    for _ in range(20):
        p = random_pair(rng, kind)
        lim = p.theta_limit or 2 * np.pi
        theta = np.linspace(-0.999 * lim, 0.999 * lim, 201)
        ends = p.leg_endpoints(theta)
        assert ends.shape == (201, 6, 2, 3)
        lengths = np.linalg.norm(ends[..., 1, :] - ends[..., 0, :], axis=-1)
        np.testing.assert_allclose(lengths, np.broadcast_to(p.leg_lengths, lengths.shape), rtol=0, atol=1e-12)
        # the base points do not move, and the platform point of leg k rises by d(θ)
        np.testing.assert_allclose(ends[:, :, 0, :], np.broadcast_to(ends[0, :, 0, :], (201, 6, 3)), atol=0)


def test_sinusoidal_pair_facts():
    """docs/conventions.md §2: congruent triangles give L1 = L2 = 3r/2, h = √2 r; d(θ) = h cos(θ/2)."""
    r = 0.7
    p = apair.APair(r, r)
    np.testing.assert_allclose(p.leg_lengths, 1.5 * r, rtol=1e-15)
    assert p.amplitude == pytest.approx(np.sqrt(2) * r, rel=1e-15)
    theta = np.linspace(-2 * np.pi, 2 * np.pi, 9)
    np.testing.assert_allclose(p.translation(theta), p.amplitude * np.cos(theta / 2), atol=1e-15)
    q = apair.APair(0.3, 0.5)
    assert q.amplitude == pytest.approx(np.sqrt(2 * 0.3 * 0.5), rel=1e-15)
    L1, L2 = q.leg_lengths[[0, 3]]
    assert L1**2 - L2**2 == pytest.approx(0.75 * (0.3**2 - 0.5**2), rel=1e-13)
    assert L1**2 == pytest.approx(0.3**2 + 0.5**2 / 4 + 0.3 * 0.5, rel=1e-15)
    # the same leg length given explicitly is the same (sinusoidal) pair
    assert apair.APair(0.3, 0.5, leg_length=L1).kind == "sinusoidal"


def test_general_pair_law():
    p = apair.APair(1.0, 1.0, leg_length=1.2)  # a = 0.19 < b = 1: a limited angle
    assert p.kind == "general" and p.theta_limit == pytest.approx(np.arccos(-p.a / p.b))
    theta = np.linspace(-0.99, 0.99, 50) * p.theta_limit
    law = p.law(theta)
    np.testing.assert_allclose(law[:, 0] ** 2, p.a + p.b * np.cos(theta), rtol=1e-13)
    # d' and d'' against central differences of d
    eps = 1e-6
    fd1 = (p.translation(theta + eps) - p.translation(theta - eps)) / (2 * eps)
    fd2 = (law[:, 1] - p.law(theta - eps)[:, 1]) / eps
    np.testing.assert_allclose(law[:, 1], fd1, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(law[:, 2], fd2, rtol=1e-4, atol=1e-4)


@pytest.mark.parametrize("n", range(1, 7))
def test_study_point_is_the_same_pose(n, backend):
    rng = np.random.default_rng(10 + n)
    for _ in range(5):
        chain = random_chain(rng, n)
        q = random_q(rng, chain, 40)
        T = chain.fk(q)
        S = chain.fk_study(q)
        np.testing.assert_allclose(np.linalg.norm(S[:, :4], axis=1), 1.0, atol=1e-14)
        np.testing.assert_allclose(np.sum(S[:, :4] * S[:, 4:], axis=1), 0.0, atol=1e-12)  # Study quadric
        np.testing.assert_allclose(to_matrix(S), T, atol=1e-12)
        back = from_matrix(T)
        sign = np.sign(np.sum(back[:, :4] * S[:, :4], axis=1))[:, None]
        np.testing.assert_allclose(sign * back, S, atol=1e-12)
        # one pose at a time (its own code path): the same point, the same sign
        np.testing.assert_allclose(np.array([from_matrix(t) for t in T]), back, rtol=0, atol=1e-15)


def test_single_pose_study_point_at_half_turns():
    """from_matrix of one pose and of a stack agree where Shepperd's branch changes: rotations by
    0 and π about each axis and about diagonals, where two diagonal candidates tie."""
    from scipy.spatial.transform import Rotation

    axes = np.vstack([np.eye(3), np.ones((1, 3)) / np.sqrt(3), [[1, -1, 0]] / np.sqrt(2)])
    T = np.tile(np.eye(4), (len(axes) * 4, 1, 1))
    for k, (axis, angle) in enumerate((a, t) for a in axes for t in (0.0, np.pi / 2, np.pi, -np.pi)):
        T[k, :3, :3] = Rotation.from_rotvec(angle * axis).as_matrix()
        T[k, :3, 3] = [0.3, -0.2, 1.5]
    stack = from_matrix(T)
    np.testing.assert_allclose(np.array([from_matrix(t) for t in T]), stack, rtol=0, atol=1e-15)
    np.testing.assert_allclose(to_matrix(stack), T, atol=1e-14)


@pytest.mark.parametrize("kind", ["sinusoidal", "general"])
def test_single_pair_study_point_satisfies_the_derived_equations(kind, backend):
    eqs = apair.polynomials.load("apair_motion")
    quadric = eqs["pair_quadric"]
    a, b = sp.symbols("a b", real=True)
    gens = sp.symbols("x0 x3 y0 y3", real=True)
    f = sp.lambdify((a, b) + gens, quadric)
    rng = np.random.default_rng(3)
    for _ in range(10):
        p = random_pair(rng, kind)
        chain = apair.AChain([p], [0.0], [0.0])  # frame 1 is the pair's platform frame
        q = random_q(rng, chain, 50)
        S = chain.fk_study(q)
        np.testing.assert_allclose(S[:, [1, 2, 5, 6]], 0.0, atol=1e-15)  # the 3-space of the pair
        x0, x3, y0, y3 = S[:, 0], S[:, 3], S[:, 4], S[:, 7]
        np.testing.assert_allclose(f(p.a, p.b, x0, x3, y0, y3), 0.0, atol=1e-12 * max(1, p.a + p.b))
    # and a point of the Study quadric off the curve does not satisfy it
    assert abs(f(p.a, p.b, 1.0, 0.0, 0.0, 0.0)) > 1e-3


def fk_numeric_jacobian(chain, q, eps=1e-6):
    J = np.zeros((6, chain.n))
    T = chain.fk(q)
    for i in range(chain.n):
        dq = np.zeros(chain.n)
        dq[i] = eps
        Tp, Tm = chain.fk(q + dq), chain.fk(q - dq)
        dT = (Tp - Tm) / (2 * eps)
        W = dT[:3, :3] @ T[:3, :3].T
        J[:3, i] = dT[:3, 3]
        J[3:, i] = [W[2, 1], W[0, 2], W[1, 0]]
    return J


@pytest.mark.parametrize("n", range(1, 7))
def test_jacobian_matches_finite_differences(n, backend):
    rng = np.random.default_rng(20 + n)
    for _ in range(8):
        chain = random_chain(rng, n)
        for q in random_q(rng, chain, 5):
            J = chain.jacobian(q)
            assert J.shape == (6, n)
            np.testing.assert_allclose(J, fk_numeric_jacobian(chain, q), atol=1e-7)
        qs = random_q(rng, chain, 7)
        np.testing.assert_allclose(chain.jacobian(qs), np.stack([chain.jacobian(x) for x in qs]), atol=1e-15)


def dh_reference(a, alpha, d, theta):
    """Textbook standard-DH transform, written independently of the derivations."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0.0, sa, ca, d], [0.0, 0.0, 0.0, 1.0]]
    )


@pytest.mark.parametrize("n", range(1, 7))
def test_zero_amplitude_chain_is_the_revolute_dh_chain(n, backend):
    rng = np.random.default_rng(30 + n)
    for _ in range(10):
        chain = random_chain(rng, n, kinds=("revolute",))
        for q in random_q(rng, chain, 5):
            T = np.eye(4)
            for i in range(n):
                T = T @ dh_reference(chain.a[i], chain.alpha[i], chain.offset[i], q[i] + chain.theta_offset[i])
            np.testing.assert_allclose(chain.fk(q), T, atol=1e-13)


@pytest.mark.parametrize("n", [2, 4, 6])
def test_a_chain_equals_dh_chain_with_the_pair_translation(n, backend):
    """An A-chain is the DH chain whose offset is c_i + d_i(θ_i), d_i from the pair."""
    rng = np.random.default_rng(40 + n)
    chain = random_chain(rng, n)
    for q in random_q(rng, chain, 10):
        T = np.eye(4)
        for i, p in enumerate(chain.pairs):
            d = chain.offset[i] + p.translation(q[i])
            T = T @ dh_reference(chain.a[i], chain.alpha[i], d, q[i] + chain.theta_offset[i])
        np.testing.assert_allclose(chain.fk(q), T, atol=1e-13)


def test_backends_agree():
    rng = np.random.default_rng(5)
    chain = random_chain(rng, 5)
    q = random_q(rng, chain, 100)
    out = {}
    for b in ("c", "numpy"):
        apair.set_backend(b)
        out[b] = (chain.fk(q), chain.fk_study(q), chain.jacobian(q))
    apair.set_backend(None)
    for x, y in zip(out["c"], out["numpy"]):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-14)
