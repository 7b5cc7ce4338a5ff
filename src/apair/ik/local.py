"""Local search: Levenberg-Marquardt on the pose error from many seeds at once over the batched fk
and Jacobian kernels (the fallback where the elimination degenerates, the nearest reachable pose
of `distance`), and `ik_local`, the same search in C from the user's seeds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

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


def distance(
    chain: ChainLike, T: ArrayLike, starts: int = 64, seed: int = SEED
) -> tuple[float, float, NDArray[np.float64]]:
    """How far a pose is from the chain's reach inside its joint limits (`chain.limits`):
    (position error [m], rotation error [rad], q) at the best of `starts` batched
    Levenberg-Marquardt fits of fk(q) to T (pose error weighted by the chain's length scale), a
    bounded amount of work (60 iterations of one batched fk and Jacobian call). An estimate for
    reporting unreachable poses, not part of the exact solver. A pose far out (beyond FAR_SEARCH
    reaches) is fitted at that distance in its direction, where the nearest pose is the same to
    the last digits, and the squares of its errors stay finite."""
    Tm = pose_of(T).matrix
    far = FAR_SEARCH * (reach_of(chain) + length_scale(chain))
    d = translation_norm(Tm)
    target = Tm
    if d > far:
        target = Tm.copy()
        u = Tm[:3, 3] / np.abs(Tm[:3, 3]).max()  # the direction, without overflow
        target[:3, 3] = u * (far / norm3(u))
    q = local_search(chain, target, seeds=starts, seed=seed, bounds=chain.limits)
    e, _ = pose_error(chain, q, target)
    best = q[int(np.argmin(np.sum(e * e, axis=1)))]
    F = chain.fk(best)
    dp = norm3(F[:3, 3] - Tm[:3, 3])
    if not np.isfinite(dp):
        raise ValueError("T: the translation's distance from the chain overflows a double")
    c = (np.trace(F[:3, :3].T @ Tm[:3, :3]) - 1) / 2
    return dp, float(np.arccos(np.clip(c, -1.0, 1.0))), best


@dataclass
class LocalSolution:
    """ik_local's result, one row per (pose, seed): q (..., n), the largest entry of |fk(q) − T|
    and whether it is within tol."""

    q: NDArray[np.float64]
    residual: NDArray[np.float64]
    converged: NDArray[np.bool_]


def ik_local(chain: ChainLike, T: ArrayLike, q0: ArrayLike, tol: float = 1e-10, max_iter: int = 100) -> LocalSolution:
    """Levenberg-Marquardt from the seeds q0 (n,) or (..., n) to the poses T (4, 4) or (..., 4, 4)
    (broadcast together), each step projected onto chain.limits, in C (apair_ik_local on the fk and
    Jacobian kernels)."""
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
    lim = chain.limits
    outside = (q0 < lim[:, 0]) | (q0 > lim[:, 1])
    if outside.any():
        j = int(np.argwhere(outside)[0][-1])
        raise ValueError(f"q0: joint {j + 1} lies outside chain.limits ({lim[j, 0]:.6g}, {lim[j, 1]:.6g}) rad")
    try:
        shape = np.broadcast_shapes(T.shape[:-2], q0.shape[:-1])
    except ValueError:
        raise ValueError(f"T, q0: batch shapes {T.shape[:-2]} and {q0.shape[:-1]} do not broadcast") from None
    n = chain.n
    Tb = np.ascontiguousarray(np.broadcast_to(T, shape + (4, 4)).reshape(-1, 4, 4))
    qb = np.ascontiguousarray(np.broadcast_to(q0, shape + (n,)).reshape(-1, n))
    kind = np.array([("revolute", "sinusoidal", "general").index(p.kind) for p in chain.pairs], np.int32)
    pair = np.zeros((n, 2))
    for i, p in enumerate(chain.pairs):
        params = p.law_kernel[1]
        pair[i, : len(params)] = params
    q, res, conv = native.ik_local(
        kind,
        pair,
        np.ascontiguousarray(chain._dh, float),
        np.ascontiguousarray(lim[:, 0]),
        np.ascontiguousarray(lim[:, 1]),
        length_scale(chain),
        Tb,
        qb,
        tol,
        max_iter,
    )
    return LocalSolution(q.reshape(shape + (n,)), res.reshape(shape), conv.reshape(shape).astype(bool))
