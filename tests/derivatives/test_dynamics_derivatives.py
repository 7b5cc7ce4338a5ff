"""The derivative kernels of the chain dynamics (derivations/chain_dynamics_derivatives.py):
against central differences of inverse_dynamics and forward_dynamics, the identities between
them, C against NumPy, and the derivation's own steps in 40-digit arithmetic."""

from __future__ import annotations

import numpy as np
import pytest
from apair_test_helpers import evaluate_spec

import apair
from apair.kernels import call
from derivations.chain_dynamics_derivatives import specs_for_n

SIZES = (1, 2, 6, 7)
DESIGNS = ("revolute", "sinusoidal", "general", "special", "range_end", "framed", "lower")
QUARTER = np.pi / 2


def _link(rng) -> apair.Link:
    """A solid box of random size and mass, turned at random: a physically realisable inertia."""
    m = rng.uniform(0.5, 3.0)
    x, y, z = rng.uniform(0.05, 0.5, 3)
    principal = m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return apair.Link(m, rng.uniform(-0.3, 0.3, 3), Q @ np.diag(principal) @ Q.T)


def _general(rng, ratio, leg_mass) -> apair.APair:
    """A general pair with a = ratio · b (ratio < 1: a restricted range)."""
    r_b, r_p = rng.uniform(0.1, 0.3, 2)
    a = r_b * r_p * ratio
    return apair.APair(r_b, r_p, leg_length=np.sqrt(a + r_b**2 + r_p**2 / 4), leg_mass=leg_mass)


def design(name: str, n: int, seed: int = 0):
    """(chain, q, qd, qdd) of one design of n joints, at a state that design is about."""
    rng = np.random.default_rng(1000 * n + DESIGNS.index(name))
    q = rng.uniform(-2.5, 2.5, n)
    dh = [rng.uniform(-0.5, 0.5, n), rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.3, 0.3, n), rng.uniform(-1, 1, n)]
    frames: dict = {}
    if name == "lower":  # every kind: R-, P-, H-pairs and a sinusoidal A-pair with legs
        kinds = [
            apair.APair.prismatic(),
            apair.APair.helical(0.02),
            apair.APair.revolute(),
            apair.APair(0.2, 0.1, leg_mass=0.3),
        ]
        pairs = [kinds[i % 4] for i in range(n)]
        frames = {"limits": [(-0.4, 0.6) if p.kind == "prismatic" else None for p in pairs]}
        q = np.where([p.kind == "prismatic" for p in pairs], rng.uniform(-0.3, 0.5, n), q)
    elif name == "revolute":
        pairs = [apair.APair.revolute() for _ in range(n)]
        dh[1] = rng.choice([0.0, QUARTER, -QUARTER], n)
    elif name == "sinusoidal":
        pairs = [apair.APair(*rng.uniform(0.05, 0.3, 2), leg_mass=rng.uniform(0.1, 0.5)) for _ in range(n)]
    elif name == "general":
        pairs = [_general(rng, rng.uniform(1.2, 3.0), rng.uniform(0.1, 0.5)) for _ in range(n)]
    elif name == "special":  # zero lengths, twists 0 and ±90°, joints at 0 and ±π, every kind
        kinds = [
            apair.APair.revolute(),
            apair.APair(0.2, 0.15, leg_mass=0.3),
            _general(rng, 2.0, 0.2),
        ]
        pairs = [kinds[i % 3] for i in range(n)]
        dh = [np.zeros(n), np.resize([0.0, QUARTER, -QUARTER], n), np.zeros(n), np.zeros(n)]
        q = np.resize([0.0, np.pi, -np.pi, 0.0, np.pi], n)
    elif name == "range_end":  # general pairs with a < b, each joint at 97% of its range
        pairs = [_general(rng, rng.uniform(0.3, 0.8), rng.uniform(0.1, 0.5)) for _ in range(n)]
        q = np.array([p.theta_limit for p in pairs]) * 0.97 * rng.choice([-1.0, 1.0], n)
    else:  # base and tool frames: gravity is in the world
        pairs = [
            apair.APair(*rng.uniform(0.05, 0.3, 2), leg_mass=0.2) if i % 2 else apair.APair.revolute() for i in range(n)
        ]
        R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        base = np.eye(4)
        base[:3, :3], base[:3, 3] = R * np.sign(np.linalg.det(R)), rng.normal(size=3)
        tool = np.eye(4)
        tool[:3, 3] = rng.normal(size=3)
        frames = {"base": base, "tool": tool}
    chain = apair.AChain(pairs, *dh, links=[_link(rng) for _ in range(n)], gravity=rng.normal(size=3) * 5, **frames)
    return chain, q, rng.normal(size=n) * 2, rng.normal(size=n) * 3


def central(f, x, h=1e-6) -> np.ndarray:
    """Columns k = (f(x + h e_k) − f(x − h e_k)) / 2h."""
    cols = []
    for k in range(len(x)):
        e = np.zeros(len(x))
        e[k] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(cols, axis=-1)


def rel(got, ref, floor=1e-12) -> float:
    """The largest error relative to the largest reference entry (at least `floor`)."""
    return float(np.max(np.abs(got - ref)) / max(np.max(np.abs(ref)), floor))


def rel_fd(got, f, x) -> float:
    """rel against central differences, whose rounding error is absolute: an all-zero block
    (a joint that does not feel another's velocity) is compared to 1e-3."""
    return rel(got, central(f, x), floor=1e-3)


CASES = [(d, n) for d in DESIGNS for n in SIZES]


@pytest.mark.parametrize(("name", "n"), CASES)
def test_inverse_dynamics_derivatives_equal_central_differences(name, n, backend):
    chain, q, qd, qdd = design(name, n)
    dq, dqd, M = chain.inverse_dynamics_derivatives(q, qd, qdd)
    assert dq.shape == dqd.shape == M.shape == (n, n)
    assert rel_fd(dq, lambda x: chain.inverse_dynamics(x, qd, qdd), q) < 1e-6
    assert rel_fd(dqd, lambda x: chain.inverse_dynamics(q, x, qdd), qd) < 1e-6
    assert np.array_equal(M, chain.mass_matrix(q))


@pytest.mark.parametrize(("name", "n"), CASES)
def test_forward_dynamics_derivatives_equal_central_differences(name, n, backend):
    chain, q, qd, _ = design(name, n)
    tau = np.random.default_rng(n).normal(size=n) * 5
    dq, dqd, Minv = chain.forward_dynamics_derivatives(q, qd, tau)
    assert rel_fd(dq, lambda x: chain.forward_dynamics(x, qd, tau), q) < 1e-6
    assert rel_fd(dqd, lambda x: chain.forward_dynamics(q, x, tau), qd) < 1e-6
    assert rel_fd(Minv, lambda x: chain.forward_dynamics(q, qd, x), tau) < 1e-6


@pytest.mark.parametrize(("name", "n"), CASES)
def test_forward_derivatives_are_minus_minv_times_inverse_ones(name, n, backend):
    chain, q, qd, _ = design(name, n)
    tau = np.random.default_rng(n + 7).normal(size=n) * 5
    dq, dqd, Minv = chain.forward_dynamics_derivatives(q, qd, tau)
    qdd = chain.forward_dynamics(q, qd, tau)
    idq, idqd, M = chain.inverse_dynamics_derivatives(q, qd, qdd)
    assert rel(Minv @ M, np.eye(n)) < 1e-10
    assert rel(dq, -Minv @ idq) < 1e-10
    assert rel(dqd, -Minv @ idqd) < 1e-10


def test_batches_broadcast_like_inverse_dynamics(backend):
    chain, q, qd, qdd = design("general", 3)
    Q = q + np.linspace(-0.3, 0.3, 8).reshape(2, 4, 1)
    dq, dqd, M = chain.inverse_dynamics_derivatives(Q, qd, qdd)
    assert dq.shape == dqd.shape == M.shape == (2, 4, 3, 3)
    one = chain.inverse_dynamics_derivatives(Q[1, 2], qd, qdd)
    for batched, single in zip((dq, dqd, M), one):
        assert np.allclose(batched[1, 2], single, rtol=1e-13, atol=1e-13)
    fq, fqd, Minv = chain.forward_dynamics_derivatives(Q, qd, np.ones(3))
    assert fq.shape == fqd.shape == Minv.shape == (2, 4, 3, 3)
    assert np.allclose(Minv[0, 3], chain.forward_dynamics_derivatives(Q[0, 3], qd, np.ones(3))[2], rtol=1e-13)


@pytest.mark.parametrize("n", SIZES)
def test_c_kernels_equal_numpy_kernels(n):
    if not apair.c_available():
        pytest.skip("the C kernels are not built")
    from apair.generated.numpy import KERNELS

    chain, q, qd, qdd = design("sinusoidal", n)
    law = chain._law(q)
    dddd = np.array(
        [call(f"{p.law_kernel[0]}_d3", [qi], *([x] for x in p.law_kernel[1]))[0][0] for p, qi in zip(chain.pairs, q)]
    )
    for name, state in (("inverse_dynamics_derivatives", qdd), ("forward_dynamics_derivatives", qdd * 4)):
        args = (law, dddd, qd, state, *chain._body)
        apair.set_backend("c")
        try:
            c_out = call(f"{name}{n}", *args)
        finally:
            apair.set_backend(None)
        for got, ref in zip(c_out, KERNELS[f"{name}{n}"](*args)):
            assert rel(got, ref) < 1e-12


def test_third_derivative_of_the_laws():
    """law_<kind>_d3 against central differences of d'' (the law kernels')."""
    rng = np.random.default_rng(3)
    lower = (apair.APair.helical(0.03), apair.APair.prismatic())
    for pair in (
        apair.APair.revolute(),
        apair.APair(0.2, 0.1),
        _general(rng, 2.0, 0.0),
        _general(rng, 0.5, 0.0),
    ) + lower:
        kernel, params = pair.law_kernel
        th = np.linspace(-0.9, 0.9, 7) * (pair.theta_limit or np.pi)
        d3 = call(f"{kernel}_d3", th[:, None], *([x] for x in params))[0][:, 0]
        ref = (pair.law(th + 1e-5)[:, 2] - pair.law(th - 1e-5)[:, 2]) / 2e-5
        assert np.allclose(d3, ref, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("name", ["general", "special", "range_end", "lower"])
def test_kernels_equal_the_derivation_in_40_digits(name, backend):
    """At one point, both kernels against the derivation's own steps evaluated in 40 digits."""
    n = 2
    chain, q, qd, qdd = design(name, n)
    law = chain._law(q)[None]
    dddd = apair.derivatives.third_derivatives(chain, q)[None]
    body = [x[None] for x in chain._body]
    for spec, state in zip(specs_for_n(n), (qdd, qdd * 4)):
        inputs = [law, dddd, qd[None], state[None], *body]
        for got, ref in zip(call(spec.name, *inputs), evaluate_spec(spec, inputs)):
            assert rel(got, ref) < 1e-12, spec.name


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((np.zeros(3), np.zeros(2), np.zeros(2)), "q: "),
        ((np.zeros(2), np.zeros(3), np.zeros(2)), "qd: "),
        ((np.zeros(2), np.zeros(2), [np.nan, 0.0]), None),
    ],
)
def test_bad_input_is_refused_naming_the_argument(args, message):
    chain, *_ = design("sinusoidal", 2)
    for method, last in (
        (chain.inverse_dynamics_derivatives, "qdd: "),
        (chain.forward_dynamics_derivatives, "tau: "),
    ):
        with pytest.raises(ValueError, match=message or last) as info:
            method(*args)
        assert "\n" not in str(info.value)


def test_a_joint_at_its_range_end_is_refused():
    chain, *_ = design("range_end", 1)
    q = np.array([chain.pairs[0].theta_limit])
    with pytest.raises(ValueError, match="q: a joint is at its pair's limit"):
        chain.inverse_dynamics_derivatives(q, [0.0], [0.0])
    with pytest.raises(ValueError, match="q: a joint is at its pair's limit"):
        chain.forward_dynamics_derivatives(q, [0.0], [0.0])


def test_massless_links_are_refused_by_forward_derivatives():
    chain = apair.AChain([apair.APair.revolute()] * 2, [0.3, 0.2], [0.0, 0.0])
    with pytest.raises(ValueError, match="links: the mass matrix is not positive definite"):
        chain.forward_dynamics_derivatives([0.1, 0.2], [0.0, 0.0], [0.0, 0.0])


@pytest.mark.parametrize(("name", "n"), CASES)
def test_jacobian_dot_equals_central_differences_along_the_motion(name, n, backend):
    """J̇ = dJ/dt at (q, q') against (J(q + h q') − J(q − h q')) / 2h, base and tool frames and
    every pair kind included; broadcast over a batch of q."""
    chain, q, qd, _ = design(name, n)
    h = 1e-6 / max(1.0, float(np.abs(qd).max()))
    if name == "range_end":  # stay inside the range
        h = min(h, 1e-3 * float(np.min(np.abs(np.array([p.theta_limit for p in chain.pairs]) - np.abs(q)))))
    ref = (chain.jacobian(q + h * qd) - chain.jacobian(q - h * qd)) / (2 * h)
    got = chain.jacobian_dot(q, qd)
    assert got.shape == (6, n)
    assert rel(got, ref, floor=1e-3) < 1e-6, (name, n)
    assert rel(chain.jacobian_dot(np.stack([q, q]), qd)[1], got) < 1e-15
