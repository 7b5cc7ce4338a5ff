"""apair._native.LocalIK, the single-pose fast path of AChain.ik_local: one chain's design and limits
held in C, call(T, q0, tol, max_iter) runs apair_ik_local on one canonical pose and seed (the
numbers of the batched entry point ik_local), and returns None for anything the validating path
must look at first (so it never raises for the user's input, and never accepts what that path
refuses)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from apair import kernels

native = kernels._native()[0]
pytestmark = pytest.mark.skipif(native is None, reason="the C kernels are not installed")

MAX_ITER = 1000


def design(rng: np.random.Generator, n: int) -> tuple:
    """kind, pair, dh, lower, upper, scale of an n-joint chain: R-pairs and sinusoidal A-pairs."""
    kind = rng.integers(0, 2, n).astype(np.int32)
    pair = np.where(kind[:, None] == 1, rng.uniform(0.05, 0.1, (n, 2)), 0.0)
    lim = rng.uniform(1.0, 3.0, n)
    return kind, pair, rng.uniform(-1, 1, (n, 4)), -lim, lim, 0.7


def solver(args: tuple) -> object:
    return native.LocalIK(*args, MAX_ITER, lambda *out: out)


def rigid(rng: np.random.Generator) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    if np.linalg.det(T[:3, :3]) < 0:
        T[:3, 0] *= -1
    T[:3, 3] = rng.uniform(-1, 1, 3)
    return T


@pytest.mark.parametrize("n", range(1, 7))
def test_call_equals_the_batched_entry_point(n):
    rng = np.random.default_rng(n)
    args = design(rng, n)
    local = solver(args)
    for _ in range(5):
        T, q0 = rigid(rng), rng.uniform(args[3], args[4])
        for tol, max_iter in ((1e-10, 100), (1e-3, 2)):
            q, res, conv = local.call(T, q0, tol, max_iter)
            want = native.ik_local(*args, T[None], q0[None], tol, max_iter)
            assert q.shape == (n,) and res.shape == () and conv.shape == () and conv.dtype == np.bool_
            assert np.array_equal(q, want[0][0]) and np.array_equal(res, want[1][0]) and conv == bool(want[2][0])


def test_the_result_type_is_called_with_the_outputs():
    class Result:
        def __init__(self, q, residual, converged):
            self.q, self.residual, self.converged = q, residual, converged

    args = design(np.random.default_rng(0), 3)
    got = native.LocalIK(*args, MAX_ITER, Result).call(np.eye(4), np.zeros(3), 1e-10, 10)
    assert isinstance(got, Result) and got.q.shape == (3,)


def test_inputs_are_not_changed():
    rng = np.random.default_rng(1)
    args = design(rng, 4)
    T, q0 = rigid(rng), np.zeros(4)
    T0, q00 = T.copy(), q0.copy()
    solver(args).call(T, q0, 1e-10, 50)
    assert np.array_equal(T, T0) and np.array_equal(q0, q00)


def non_canonical(T: np.ndarray, q0: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> list[tuple]:
    """(T, q0, tol, max_iter) that the validating path must see first."""
    nan_T, inf_T, row, row3, scaled, reflected = (T.copy() for _ in range(6))
    nan_T[0, 1] = np.nan
    inf_T[2, 3] = np.inf
    row[3, 1] = 1e-9
    row3[3, 3] = 1 + 2e-5
    scaled[:3, :3] *= 1 + 1e-6
    reflected[:3, 1] *= -1
    borderline = T.copy()
    borderline[:3, :3] *= 1 + 4e-10  # orthonormal to 8e-10: a pose, but the validating path decides
    below, above, nan_q = q0.copy(), q0.copy(), q0.copy()
    below[0] = np.nextafter(lower[0], -np.inf)
    above[-1] = np.nextafter(upper[-1], np.inf)
    nan_q[1] = np.nan
    return [
        (T.tolist(), q0, 1e-10, 10),
        (T.astype(np.float32), q0, 1e-10, 10),
        (T.astype(">f8"), q0, 1e-10, 10),
        (np.asfortranarray(T), q0, 1e-10, 10),
        (np.ma.masked_array(T), q0, 1e-10, 10),
        (T[None], q0, 1e-10, 10),
        (T[:3], q0, 1e-10, 10),
        (np.zeros((4, 8))[:, ::2], q0, 1e-10, 10),
        (nan_T, q0, 1e-10, 10),
        (inf_T, q0, 1e-10, 10),
        (row, q0, 1e-10, 10),
        (row3, q0, 1e-10, 10),
        (scaled, q0, 1e-10, 10),
        (reflected, q0, 1e-10, 10),
        (borderline, q0, 1e-10, 10),
        (T, q0.tolist(), 1e-10, 10),
        (T, q0[None], 1e-10, 10),
        (T, q0[:-1], 1e-10, 10),
        (T, np.append(q0, 0.0), 1e-10, 10),
        (T, q0.astype(np.float32), 1e-10, 10),
        (T, np.ma.masked_array(q0), 1e-10, 10),
        (T, nan_q, 1e-10, 10),
        (T, below, 1e-10, 10),
        (T, above, 1e-10, 10),
        (T, q0, 0.0, 10),
        (T, q0, -1e-10, 10),
        (T, q0, math.nan, 10),
        (T, q0, math.inf, 10),
        (T, q0, 1, 10),
        (T, q0, True, 10),
        (T, q0, "1e-10", 10),
        (T, q0, 1e-10, 0),
        (T, q0, 1e-10, -5),
        (T, q0, 1e-10, MAX_ITER + 1),
        (T, q0, 1e-10, 2**80),
        (T, q0, 1e-10, True),
        (T, q0, 1e-10, 10.0),
        (T, q0, 1e-10, np.int64(10)),
        (T, q0, 1e-10, None),
    ]


def test_anything_not_canonical_returns_none():
    rng = np.random.default_rng(2)
    args = design(rng, 3)
    local = solver(args)
    T, q0 = rigid(rng), np.zeros(3)
    assert local.call(T, q0, 1e-10, 10) is not None
    assert local.call(T, args[3].copy(), 1e-10, 10) is not None  # on the limits: inside
    assert local.call(T, args[4].copy(), np.float64(1e-10), MAX_ITER) is not None
    for k, case in enumerate(non_canonical(T, q0, args[3], args[4])):
        assert local.call(*case) is None, k


@pytest.mark.parametrize(
    "change, error",
    [
        (
            {0: np.zeros(0, np.int32), 1: np.zeros((0, 2)), 2: np.zeros((0, 4)), 3: np.zeros(0), 4: np.zeros(0)},
            ValueError,
        ),
        ({0: np.zeros(7, np.int32)}, ValueError),
        ({0: np.array([0, 5, 0], np.int32)}, ValueError),
        ({1: np.zeros((3, 3))}, ValueError),
        ({2: np.zeros((2, 4))}, ValueError),
        ({3: np.zeros(2)}, ValueError),
        ({3: np.full(3, 4.0)}, ValueError),  # lower above upper
        ({4: np.full(3, np.nan)}, ValueError),
        ({5: 0.0}, ValueError),
        ({5: math.inf}, ValueError),
        ({6: 0}, ValueError),
        ({7: None}, TypeError),
    ],
)
def test_a_malformed_design_is_refused(change, error):
    args = [*design(np.random.default_rng(3), 3), MAX_ITER, lambda *out: out]
    for k, v in change.items():
        args[k] = v
    with pytest.raises(error):
        native.LocalIK(*args)


def test_the_design_is_set_once():
    """call() reads the design without the GIL: initialising the object again is refused."""
    args = design(np.random.default_rng(5), 2)
    local = solver(args)
    with pytest.raises(TypeError, match="already initialised"):
        local.__init__(*args, MAX_ITER, lambda *out: out)


def test_call_takes_four_arguments():
    local = solver(design(np.random.default_rng(4), 2))
    with pytest.raises(TypeError):
        local.call(np.eye(4), np.zeros(2), 1e-10)
