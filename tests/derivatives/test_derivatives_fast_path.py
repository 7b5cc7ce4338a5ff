"""The native single-call path of AChain.inverse_dynamics_derivatives, forward_dynamics_derivatives
and jacobian_dot (apair.kernels.native_chain: the law kernels, the d3 kernels and the chain kernels
in one C call) against the validating path (apair.derivatives with no fast path: the inputs checked
and converted, the law values and d3 by the law kernels' own calls, the generic kernels through
apair.kernels.call) and against the NumPy kernels; and the validating path's refusals, whatever
the fast path is handed."""

from __future__ import annotations

import re

import numpy as np
import pytest

import apair
from apair import derivatives as D
from apair.chain import METHODS

INDEX = {family: i for i, (family, _) in enumerate(METHODS)}
# the fast path's outputs are those of the same kernels (single items through their core, batches
# through their batch form): equal up to the last bits of a reassociated sum
TOL = 1e-15


def _link(rng) -> apair.Link:
    m = rng.uniform(0.5, 3.0)
    x, y, z = rng.uniform(0.05, 0.5, 3)
    principal = m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return apair.Link(m, rng.uniform(-0.3, 0.3, 3), Q @ np.diag(principal) @ Q.T)


def _frame(rng, scale: float) -> np.ndarray:
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    T = np.eye(4)
    T[:3, :3] = Q * np.sign(np.linalg.det(Q))
    T[:3, 3] = rng.uniform(-scale, scale, 3)
    return T


def chain6(framed: bool, seed: int = 39) -> apair.AChain:
    """Six joints: sinusoidal and general A-pairs with legs (the general one with a restricted
    range, a < b), a prismatic pair, an R-pair, an H-pair; with
    base and tool frames (translations and rotations) or without."""
    rng = np.random.default_rng(seed)
    pairs = [
        apair.APair(0.15, 0.1, leg_mass=0.2),
        apair.APair(0.12, 0.2, leg_length=np.sqrt(0.5 * 0.12 * 0.2 + 0.12**2 + 0.2**2 / 4), leg_mass=0.1),
        apair.APair.prismatic(),
        apair.APair.revolute(),
        apair.APair(0.2, 0.08, leg_mass=0.3),
        apair.APair.helical(0.02),
    ]
    frames = {"base": _frame(rng, 0.5), "tool": _frame(rng, 0.2)} if framed else {}
    return apair.AChain(
        pairs,
        rng.uniform(-0.5, 0.5, 6),
        rng.uniform(-np.pi, np.pi, 6),
        rng.uniform(-0.3, 0.3, 6),
        rng.uniform(-1, 1, 6),
        links=[_link(rng) for _ in range(6)],
        gravity=rng.normal(size=3) * 5,
        limits=[None, None, (-0.3, 0.4), None, None, None],
        **frames,
    )


def states(chain, count, rng):
    lim = chain.limits
    mid, half = lim.mean(axis=1), (lim[:, 1] - lim[:, 0]) / 2
    q = mid + 0.9 * half * rng.uniform(-1, 1, (count, chain.n))
    return q, rng.normal(size=(count, chain.n)), rng.normal(size=(count, chain.n))


def same(got, want, tol=TOL):
    """Every output of got equals want's to tol relative to the largest entry (at least 1)."""
    got = got if isinstance(got, tuple) else (got,)
    want = want if isinstance(want, tuple) else (want,)
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert type(g) is np.ndarray and g.shape == w.shape, (type(g), np.shape(g), w.shape)
        scale = max(1.0, float(np.abs(w).max()))
        assert np.abs(g - w).max() <= tol * scale, np.abs(g - w).max() / scale


def validating(chain, method, *args):
    """The method on the validating path alone (no fast path anywhere)."""
    return getattr(D, method)(chain, *args)


DERIVED = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives", "jacobian_dot")


def args_of(method, q, qd, x):
    return (q, qd) if method == "jacobian_dot" else (q, qd, x)


@pytest.mark.parametrize("framed", [False, True])
def test_single_calls_take_the_fast_path_and_equal_the_validating_path(framed):
    chain = chain6(framed)
    q, qd, x = states(chain, 8, np.random.default_rng(1))
    for method in DERIVED:
        for k in range(len(q)):
            args = args_of(method, q[k], qd[k], x[k])
            fast = chain._fast.call(INDEX[method], *args)
            assert fast is not None  # the single call is native
            want = validating(chain, method, *args)
            same(getattr(chain, method)(*args), want)
            if method != "jacobian_dot":  # frame 0's kernels are the world's for the dynamics
                same(fast, want)
        # a batch on the fast path equals the validating path's batch, and each item its single call
        args = args_of(method, q, qd, x)
        batch = getattr(chain, method)(*args)
        same(batch, validating(chain, method, *args))
        single = getattr(chain, method)(*(a[3] for a in args))
        same(single, tuple(b[3] for b in batch) if isinstance(batch, tuple) else batch[3])


def test_the_outputs_are_those_of_the_kernels_asked_for():
    """∂ID returns (∂τ/∂θ, ∂τ/∂θ', M) with M the mass matrix's; ∂FD's M⁻¹ inverts it; J̇ is the
    generic kernel's."""
    chain = chain6(False)
    q, qd, x = states(chain, 1, np.random.default_rng(2))
    q, qd, x = q[0], qd[0], x[0]
    dq, dqd, M = chain.inverse_dynamics_derivatives(q, qd, x)
    np.testing.assert_array_equal(M, chain.mass_matrix(q))
    _, _, Minv = chain.forward_dynamics_derivatives(q, qd, x)
    np.testing.assert_allclose(Minv @ M, np.eye(6), atol=1e-12)
    # ∂FD = −M⁻¹ ∂ID at θ'' = FD(θ, θ', τ)
    qdd = chain.forward_dynamics(q, qd, x)
    fq, fqd, _ = chain.forward_dynamics_derivatives(q, qd, x)
    iq, iqd, _ = chain.inverse_dynamics_derivatives(q, qd, qdd)
    np.testing.assert_allclose(fq, -Minv @ iq, rtol=0, atol=1e-10 * max(1.0, np.abs(fq).max()))
    np.testing.assert_allclose(fqd, -Minv @ iqd, rtol=0, atol=1e-10 * max(1.0, np.abs(fqd).max()))


@pytest.mark.parametrize("framed", [False, True])
def test_fast_path_equals_the_numpy_kernels(framed):
    chain = chain6(framed)
    q, qd, x = states(chain, 3, np.random.default_rng(3))
    got = {m: getattr(chain, m)(*args_of(m, q[1], qd[1], x[1])) for m in DERIVED}
    apair.set_backend("numpy")
    try:
        assert chain._fast.call(INDEX["jacobian_dot"], q[1], qd[1]) is None  # off with NumPy
        want = {m: getattr(chain, m)(*args_of(m, q[1], qd[1], x[1])) for m in DERIVED}
    finally:
        apair.set_backend(None)
    for m in DERIVED:
        same(got[m], want[m], 1e-12)


def test_inputs_the_fast_path_passes_on_give_the_same_numbers():
    """Lists, float32, big-endian, strided, integer and broadcast inputs go through the validating
    path and give what the canonical float64 input gives."""
    chain = chain6(True)
    q, qd, x = states(chain, 2, np.random.default_rng(4))
    q[0, 2] = 0.25
    for method in DERIVED:
        want = getattr(chain, method)(*args_of(method, q[0], qd[0], x[0]))
        for variant in (
            lambda a: a.tolist(),
            lambda a: a.astype(">f8"),
            lambda a: np.stack([a, a], axis=1)[:, 0],
        ):
            same(getattr(chain, method)(*(variant(a) for a in args_of(method, q[0], qd[0], x[0]))), want)
        rounded = np.round(q[0], 1)
        same(
            getattr(chain, method)(*args_of(method, rounded.astype(np.float32), qd[0], x[0])),
            getattr(chain, method)(*args_of(method, rounded.astype(np.float32).astype(np.float64), qd[0], x[0])),
        )
        # one q for a batch of velocities broadcasts
        got = getattr(chain, method)(*args_of(method, q[0], qd, x))
        want = getattr(chain, method)(*args_of(method, np.broadcast_to(q[0], q.shape).copy(), qd, x))
        same(got, want)


def _one_line(exc: pytest.ExceptionInfo) -> None:
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("method", DERIVED)
def test_bad_inputs_are_refused_with_the_argument_named(method):
    chain = chain6(False)
    n = chain.n
    ok = np.zeros(n)
    lim = chain.pairs[1].theta_limit  # the general pair's range end
    assert lim is not None
    nan = np.array([np.nan] + [0.0] * (n - 1))
    cases = [
        ("q", args_of(method, nan, ok, ok), "NaN"),
        ("q", args_of(method, np.full(n, np.inf), ok, ok), "NaN or infinite"),
        ("q", args_of(method, np.zeros(n + 1), ok, ok), "shape"),
        ("q", args_of(method, np.zeros(n, dtype=complex), ok, ok), "real numbers"),
        ("qd", args_of(method, ok, nan, ok), "NaN"),
        ("qd", args_of(method, np.zeros((3, n)), np.zeros((2, n)), np.zeros((3, n))), "batch shape"),
        ("q", args_of(method, np.array([0.0, lim] + [0.0] * (n - 2)), ok, ok), "limit"),
        ("q[..., 1] (joint 2)", args_of(method, np.array([0.0, lim + 0.1] + [0.0] * (n - 2)), ok, ok), "outside"),
    ]
    if method != "jacobian_dot":
        third = "qdd" if method == "inverse_dynamics_derivatives" else "tau"
        cases += [
            (third, (ok, ok, np.array([np.nan] * n)), "NaN"),
            (third, (ok, ok, np.zeros((2, n + 1))), "shape"),
        ]
    for name, args, what in cases:
        with pytest.raises(ValueError, match=rf"^{re.escape(name)}: .*{what}") as exc:
            getattr(chain, method)(*args)
        _one_line(exc)


def test_forward_dynamics_derivatives_of_a_massless_chain_are_refused():
    """M is not positive definite: NaN from the kernel, so the fast path hands over and the
    validating path refuses, single calls and batches alike."""
    chain = apair.AChain([apair.APair.revolute()] * 2, [0.3, 0.2], [0.0, 0.0])
    z = np.zeros(2)
    assert chain._fast.call(INDEX["forward_dynamics_derivatives"], z, z, z) is None
    for args in ((z, z, z), (np.zeros((3, 2)), np.zeros((3, 2)), np.zeros((3, 2))), ([0.0, 0.0], z, z)):
        with pytest.raises(ValueError, match="^links: the mass matrix is not positive definite") as exc:
            chain.forward_dynamics_derivatives(*args)
        _one_line(exc)
    dq, dqd, M = chain.inverse_dynamics_derivatives(z, z, z)  # ∂ID is defined all the same
    assert np.all(M == 0) and np.all(dq == 0) and np.all(dqd == 0)
