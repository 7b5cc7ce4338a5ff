"""Local search: Levenberg-Marquardt on the pose error from many seeds at once over the batched fk
and Jacobian kernels (`local_search`, the fallback where the elimination degenerates), the nearest
pose inside the joint limits to an unreachable one (`nearest`, `distance`: a multistart search in
a metric that weighs translation and rotation), and `ik_local`, the search in C from the user's
seeds (with `local_solver`, its native fast path for one pose at a time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _validate as V
from ..kernels import native_module
from .pencil import SEED
from .poses import (
    check_matrix,
    error_weights,
    jacobian_rank,
    joint_periods,
    length_scale,
    norm3,
    pose_error,
    pose_of,
    reach_of,
    translation_norm,
    wrap,
)

if TYPE_CHECKING:
    from .._typing import ChainLike


def on_continuum(chain: ChainLike, q: NDArray[np.float64], T: NDArray[np.float64], tol: float) -> bool:
    """Whether the solution q lies on a curve of solutions: where the Jacobian is rank-deficient,
    a step along its null space, corrected back onto the pose, lands on another solution."""
    if jacobian_rank(chain, q[None])[0] == chain.n:
        return False
    v = np.linalg.svd(chain.jacobian(q) * error_weights(chain))[2][-1]
    moved = local_search(chain, T, start=(q + 1e-2 * v)[None])
    _, err = pose_error(chain, moved, T)
    return bool(err[0] <= tol and np.abs(moved[0] - q).max() > 1e-3)


def local_search(
    chain: ChainLike,
    T: NDArray[np.float64],
    seeds: int = 64,
    iterations: int = 60,
    seed: int = SEED,
    bounds: NDArray[np.float64] | None = None,
    start: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Levenberg-Marquardt on the pose error from `seeds` joint vectors drawn uniformly (in
    `bounds` (n, 2), default each joint's period), all at once over the batched fk and Jacobian
    kernels (or from the rows of `start`); returns the end points, kept inside the bounds. Not
    complete: the fallback where the elimination degenerates, and the nearest-pose search."""
    periods = joint_periods(chain)
    if bounds is None:
        bounds = np.stack([-periods / 2, periods / 2], 1)
        for i, p in enumerate(chain.pairs):
            if p.theta_limit is not None:
                bounds[i] = -p.theta_limit, p.theta_limit
    lo, hi = bounds[:, 0], bounds[:, 1]
    rng = np.random.default_rng(seed)
    q = rng.uniform(lo, hi, (seeds, chain.n)) if start is None else np.clip(start, lo, hi)
    seeds = len(q)
    W = error_weights(chain)
    lam = np.full(seeds, 1e-3)
    e, _ = pose_error(chain, q, T)
    cost = np.sum(e * e, axis=1)
    for _ in range(iterations):
        J = chain.jacobian(q) * W
        JtJ = np.einsum("kia,kib->kab", J, J)
        g = np.einsum("kia,ki->ka", J, e)
        A = JtJ + lam[:, None, None] * (np.eye(chain.n) * (np.einsum("kaa->ka", JtJ)[:, :, None] + 1e-12))
        step = np.einsum("kab,kb->ka", np.linalg.pinv(A), g)
        q2 = np.clip(q + step, lo, hi)
        e2, _ = pose_error(chain, q2, T)
        cost2 = np.sum(e2 * e2, axis=1)
        better = cost2 < cost
        q, e, cost = np.where(better[:, None], q2, q), np.where(better[:, None], e2, e), np.where(better, cost2, cost)
        lam = np.where(better, lam / 3, lam * 4)
        if np.all(cost < 1e-28):
            break
    return q


FAR_SEARCH = 1e3  # a pose further than this many reaches is searched for along its direction
SCREEN = 16  # nearest: random joint vectors screened per start
FIT_ITERATIONS = 150  # nearest: Levenberg-Marquardt steps at most (one batched fk and Jacobian each)


@dataclass(frozen=True, eq=False)
class Nearest:
    """The nearest pose found to a target inside `chain.limits` (`nearest`): the joint vector q,
    the position error [m] and rotation error [rad] of fk(q), and `distance`, the dimensionless
    metric the search minimises,

        distance = sqrt((position / scale)² + (2 sin(rotation / 2))²)
                 = sqrt(|t_F − t_T|² / scale² + ½ ‖R_F − R_T‖²_F),

    with `scale` the chain's length scale L (apair.ik.poses.length_scale): one radian of rotation
    weighs like L metres of translation for small angles (2 sin(φ/2) ≈ φ), and the rotation term
    grows all the way to φ = π, so no pose turned half around looks near."""

    q: NDArray[np.float64]
    position: float
    rotation: float
    distance: float
    scale: float


def nearest(chain: ChainLike, T: ArrayLike, starts: int = 64, seed: int = SEED) -> Nearest:
    """The nearest pose to T (a 4×4 transform or a Study point) that a multistart local search
    finds inside the joint limits (`chain.limits`), in the metric of `Nearest`: projected
    Levenberg-Marquardt from `starts` seeds at once (half the best of SCREEN·starts random joint
    vectors, half random, from a fixed RNG `seed`), at most FIT_ITERATIONS batched fk and Jacobian
    calls. An estimate for reporting unreachable poses (`apair ik`), not part of the exact
    solver. A pose far out (beyond FAR_SEARCH reaches) is fitted at that distance in its
    direction, where the nearest pose is the same to the last digits, and the squares of its
    errors stay finite; its errors are then measured against T itself."""
    Tm = pose_of(T).matrix
    target = _within_search(chain, Tm)
    L = length_scale(chain)
    lo, hi = _search_box(chain)
    q = _fit(chain, target, L, _starts(chain, target, L, lo, hi, starts, seed), lo, hi)
    r = _residuals(chain, q, target, L)
    best = _wrap_free(chain, q[int(np.argmin(np.sum(r * r, axis=1)))])
    F = chain.fk(best)
    dp = norm3(F[:3, 3] - Tm[:3, 3])
    if not np.isfinite(dp):
        raise ValueError("T: the translation's distance from the chain overflows a double")
    chord = math.sqrt(0.5 * float(np.sum((F[:3, :3] - Tm[:3, :3]) ** 2)))  # 2 sin(φ/2), φ the rotation angle
    return Nearest(best, dp, 2 * math.asin(min(chord / 2, 1.0)), math.hypot(dp / L, chord), L)


def distance(
    chain: ChainLike, T: ArrayLike, starts: int = 64, seed: int = SEED
) -> tuple[float, float, NDArray[np.float64]]:
    """How far a pose is from the chain's reach inside its joint limits (`chain.limits`):
    (position error [m], rotation error [rad], q) of the nearest pose found (`nearest`, whose
    `distance` weighs the two)."""
    found = nearest(chain, T, starts=starts, seed=seed)
    return found.position, found.rotation, found.q


def _within_search(chain: ChainLike, Tm: NDArray[np.float64]) -> NDArray[np.float64]:
    """Tm, or beyond FAR_SEARCH reaches the same pose moved in to that distance."""
    far = FAR_SEARCH * (reach_of(chain) + length_scale(chain))
    if translation_norm(Tm) <= far:
        return Tm
    target = Tm.copy()
    u = Tm[:3, 3] / np.abs(Tm[:3, 3]).max()  # the direction, without overflow
    target[:3, 3] = u * (far / norm3(u))
    return target


def _search_box(chain: ChainLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(lower, upper) of the search: `chain.limits`, but a freely turning R-pair unbounded (its
    angle is wrapped into (−π, π] at the end: the same pose) and a range that ends where d' is
    unbounded (a general pair at its theta_limit) kept a relative 1e-9 inside, where the
    Jacobian is finite."""
    lim = chain.limits
    lo, hi = lim[:, 0].copy(), lim[:, 1].copy()
    hard = chain.hard_limits()
    for i, p in enumerate(chain.pairs):
        if p.kind == "revolute" and not np.isfinite(hard[i]).any():
            lo[i], hi[i] = -np.inf, np.inf
        elif p.theta_limit is not None:
            end = p.theta_limit * (1 - 1e-9)
            lo[i], hi[i] = max(lo[i], -end), min(hi[i], end)
    return lo, hi


def _wrap_free(chain: ChainLike, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """q with each unbounded (free R-pair) angle of the search wrapped into (−π, π]."""
    lim = chain.limits
    return np.where((q < lim[:, 0]) | (q > lim[:, 1]), wrap(q, 2 * np.pi), q)


def _starts(
    chain: ChainLike,
    target: NDArray[np.float64],
    L: float,
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    starts: int,
    seed: int,
) -> NDArray[np.float64]:
    """`starts` seeds: the best half of SCREEN·starts random joint vectors inside the box (one
    batched fk), and the rest random (free angles drawn in (−π, π))."""
    rng = np.random.default_rng(seed)
    lo_, hi_ = np.where(np.isfinite(lo), lo, -np.pi), np.where(np.isfinite(hi), hi, np.pi)
    pool = rng.uniform(lo_, hi_, (SCREEN * starts, chain.n))
    r = _residuals(chain, pool, target, L)
    best = pool[np.argsort(np.sum(r * r, axis=1), kind="stable")[: (starts + 1) // 2]]
    return np.concatenate([best, rng.uniform(lo_, hi_, (starts - len(best), chain.n))])


def _residuals(chain: ChainLike, q: NDArray[np.float64], target: NDArray[np.float64], L: float) -> NDArray[np.float64]:
    """(k, 12): ((t_F − t_T) / L, (R_F − R_T) / √2 row by row) of F = fk(q): their squares sum to
    Nearest's distance²."""
    F = chain.fk(q)
    dp = (F[:, :3, 3] - target[:3, 3]) / L
    dR = (F[:, :3, :3] - target[:3, :3]).reshape(len(q), 9) / math.sqrt(2)
    return np.concatenate([dp, dR], axis=1)


def _residual_jacobian(chain: ChainLike, q: NDArray[np.float64], L: float) -> NDArray[np.float64]:
    """(k, 12, n): the derivatives of `_residuals` (the target drops out): J_v / L, and
    ∂R/∂q_a = [ω_a]× R, column by column, / √2."""
    R, J = chain.fk(q)[:, :3, :3], chain.jacobian(q)
    w = np.swapaxes(J[:, 3:], 1, 2)[:, :, None, :]  # (k, n, 1, 3): ω_a
    cols = np.swapaxes(R, 1, 2)[:, None]  # (k, 1, 3, 3): R e_j
    dR = np.cross(w, cols)  # (k, n, j, i): (ω_a × R e_j)_i = ∂R_ij/∂q_a
    return np.concatenate([J[:, :3] / L, dR.transpose(0, 3, 2, 1).reshape(len(q), 9, -1) / math.sqrt(2)], axis=1)


def _fit(
    chain: ChainLike,
    target: NDArray[np.float64],
    L: float,
    q: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Levenberg-Marquardt on `_residuals` from every row of q at once, in the box (lo, hi): a
    joint at a bound that the gradient pushes outward is held there (the step solved for the
    others), the rest of the step clipped to the box; a step is kept where it lowers the sum of
    squares. Stops after FIT_ITERATIONS or when no row can improve."""
    n = chain.n
    r, J = _residuals(chain, q, target, L), _residual_jacobian(chain, q, L)
    cost = np.sum(r * r, axis=1)
    lam = np.full(len(q), 1e-3)
    eye = np.eye(n, dtype=bool)
    for _ in range(FIT_ITERATIONS):
        g = np.einsum("kia,ki->ka", J, r)
        A = np.einsum("kia,kib->kab", J, J)
        held = ((q <= lo) & (g > 0)) | ((q >= hi) & (g < 0))
        free = ~held[:, :, None] & ~held[:, None, :]
        diag = np.einsum("kaa->ka", A)
        damping = lam[:, None] * (diag + 1e-12 * diag.max(axis=1, keepdims=True) + 1e-300)
        M = np.where(free, A, 0.0) + np.where(eye, np.where(held, 1.0, damping)[:, :, None], 0.0)
        step = np.linalg.solve(M, np.where(held, 0.0, -g)[..., None])[..., 0]
        q2 = np.clip(q + step, lo, hi)
        r2 = _residuals(chain, q2, target, L)
        cost2 = np.sum(r2 * r2, axis=1)
        better = cost2 < cost
        if better.any():
            J[better] = _residual_jacobian(chain, q2[better], L)
            q[better], r[better], cost[better] = q2[better], r2[better], cost2[better]
        lam = np.where(better, np.maximum(lam / 3, 1e-12), lam * 4)
        if np.all(lam > 1e10):
            break
    return q


@dataclass
class LocalSolution:
    """ik_local's result, one row per (pose, seed): q (..., n), the largest entry of |fk(q) − T|
    and whether it is within tol."""

    q: NDArray[np.float64]
    residual: NDArray[np.float64]
    converged: NDArray[np.bool_]


# apair_ik_local's chain: kind, pair, dh, lower, upper, scale
Design = tuple[
    NDArray[np.int32], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], float
]


def _design(chain: ChainLike) -> Design:
    """apair_ik_local's chain: kind (0 revolute, 1 sinusoidal, 2 general, 3 helical, 4 prismatic) and law parameters (n, 2)
    of each pair, the DH rows, the lower and upper limits (chain.limits) and the length scale."""
    n = chain.n
    kinds = ("revolute", "sinusoidal", "general", "helical", "prismatic")
    kind = np.array([kinds.index(p.kind) for p in chain.pairs], np.int32)
    pair = np.zeros((n, 2))
    for i, p in enumerate(chain.pairs):
        params = p.law_kernel[1]
        pair[i, : len(params)] = params
    lim = chain.limits
    dh = np.ascontiguousarray(chain._dh, float)
    return kind, pair, dh, np.ascontiguousarray(lim[:, 0]), np.ascontiguousarray(lim[:, 1]), length_scale(chain)


def local_solver(chain: ChainLike, max_iter: int) -> Any:
    """The single-pose fast path of `ik_local` (apair._native.LocalIK, or None without the C
    kernels): the chain's design and limits held in C; its call(T, q0, tol, max_iter) gives this
    module's ik_local(chain, T, q0, tol, max_iter) for a float64 4x4 T and (n,) q0, a float tol and
    an int max_iter up to `max_iter`, and None for any input that needs validating or converting."""
    native, _ = native_module()
    return None if native is None else native.LocalIK(*_design(chain), max_iter, LocalSolution)


def ik_local(chain: ChainLike, T: ArrayLike, q0: ArrayLike, tol: float = 1e-10, max_iter: int = 100) -> LocalSolution:
    """Levenberg-Marquardt from the seeds q0 (n,) or (..., n) to the poses T (4, 4) or (..., 4, 4)
    (broadcast together), each step projected onto chain.limits, in C (apair_ik_local on the fk and
    Jacobian kernels). The validating path: `local_solver` is the fast path of single poses."""
    native, why = native_module()
    if native is None:
        raise RuntimeError(f"ik_local needs the compiled C kernels: {why}")
    T = V.real_array("T", T)
    if T.shape[-2:] != (4, 4):
        raise ValueError(f"T: expected a 4x4 transform or an array of them (..., 4, 4), got shape {T.shape}")
    check_matrix(T)
    q0 = chain._q(q0, "q0")
    if not isinstance(max_iter, int) or isinstance(max_iter, bool) or max_iter < 1:
        raise ValueError(f"max_iter: expected a positive integer, got {max_iter!r}")
    tol = V.scalar("tol", tol, positive=True)
    kind, pair, dh, lower, upper, scale = _design(chain)
    outside = (q0 < lower) | (q0 > upper)
    if outside.any():
        j = int(np.argwhere(outside)[0][-1])
        raise ValueError(f"q0: joint {j + 1} lies outside chain.limits ({lower[j]:.6g}, {upper[j]:.6g}) rad")
    try:
        shape = np.broadcast_shapes(T.shape[:-2], q0.shape[:-1])
    except ValueError:
        raise ValueError(f"T, q0: batch shapes {T.shape[:-2]} and {q0.shape[:-1]} do not broadcast") from None
    n = chain.n
    Tb = np.ascontiguousarray(np.broadcast_to(T, shape + (4, 4)).reshape(-1, 4, 4))
    qb = np.ascontiguousarray(np.broadcast_to(q0, shape + (n,)).reshape(-1, n))
    q, res, conv = native.ik_local(kind, pair, dh, lower, upper, scale, Tb, qb, tol, max_iter)
    return LocalSolution(q.reshape(shape + (n,)), res.reshape(shape), conv.reshape(shape).astype(bool))
