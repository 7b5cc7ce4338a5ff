"""Which targets a chain reaches inside its joint ranges (`chain.limits`: explicit, or where legs or
plates touch), and with which joint vectors.

Points (position only): a multistart, box-projected Levenberg-Marquardt on |p(q) − t|², all targets
and seeds in one batch over the fk and Jacobian kernels (one call each per step), in ROUNDS: first
from the joint vectors nearest to each target, by their end-effector position, among POOL fixed
ones spread over the ranges (drawn once from the spec's seed, the same for every candidate design:
a fair comparison and a deterministic answer), then from more, nearest and random, for the targets
still missed. A target beyond the chain's reach bound (`reach_bound`) is missed without a search. A
target is reached when some end point lies within the tolerance; the end points never leave the
ranges, so a reached target is reached for certain. The risk is the other way: a target whose every
seed ends in a local minimum (at a range end, or where an A-pair's d'(θ) = 0 makes the Jacobian lose
rank) is counted as missed, a false negative: measured on targets the chains make themselves (the
tests), about 1 in 500 for the 4A example, none for the 2A one.

Poses: the all-solutions inverse kinematics (`AChain.ik`) where the chain has one that needs no
prepared start system (1 to 4 joints of sinusoidal A-pairs and R-pairs): every exact solution is
found, so a pose that the chain reaches exactly is never missed. A pose it reaches only within the
tolerances, and every pose of other chains, goes to the local solver (`AChain.ik_local`, in C)
from the SEEDS nearest pool vectors, and counts as reached when the end point is within
`tolerance` [m] and `tolerance_deg` of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from ..chain import AChain
from .targets import Targets

POOL = 1024  # joint vectors screened for seeds
# rounds of local searches, each for the targets still missed: (seeds nearest in the pool, next
# in rank after the previous rounds', and seeds drawn at random from the pool)
ROUNDS = ((4, 0), (4, 4), (8, 16), (0, 64))
SEEDS = 4  # local searches per pose target
STALL = 1e-3  # a search stops when a step gains less than this fraction of the tolerance
ITERATIONS = 60  # Levenberg-Marquardt steps at most
EXACT_JOINTS = 4  # the all-solutions IK is used up to this many joints (elimination, no start system)
END_MARGIN = 1e-9  # a range that ends where d' is unbounded is kept this far (relative) inside


@dataclass
class Reach:
    """Per target: `reached`, `excess` (how far the nearest end point is beyond the tolerance,
    dimensionless: metres over the targets' size, plus rotation over π for poses) and `q`, the
    joint vectors that reach it (or the nearest one found when none does)."""

    reached: NDArray[np.bool_]
    excess: NDArray[np.float64]
    q: list[NDArray[np.float64]]


@lru_cache(maxsize=16)
def unit_pool(n: int, seed: int) -> NDArray[np.float64]:
    """(POOL, n) fixed points in the unit cube, the same for every candidate of a search."""
    return np.random.default_rng((seed, n, 7)).random((POOL, n))


def search_box(chain: AChain) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(lower, upper) of the local search: `chain.limits`, a freely turning joint unbounded (its
    angle need not be wrapped: a position is periodic in it) and a range that ends where d' is
    unbounded (a general pair's range end) kept END_MARGIN inside."""
    lim = chain.limits
    lo, hi = lim[:, 0].copy(), lim[:, 1].copy()
    hard = chain.hard_limits()
    for i, p in enumerate(chain.pairs):
        if not np.isfinite(hard[i]).any():
            lo[i], hi[i] = -np.inf, np.inf
        elif p.theta_limit is not None:
            end = p.theta_limit * (1 - END_MARGIN)
            lo[i], hi[i] = max(lo[i], -end), min(hi[i], end)
    return lo, hi


def pool(chain: AChain, seed: int) -> NDArray[np.float64]:
    """The pool's joint vectors inside the chain's ranges (free joints over one turn)."""
    lo, hi = search_box(chain)
    lo_, hi_ = np.where(np.isfinite(lo), lo, -math.pi), np.where(np.isfinite(hi), hi, math.pi)
    return lo_ + unit_pool(chain.n, seed) * (hi_ - lo_)


def _nearest(distance: NDArray[np.float64], qs: NDArray[np.float64]) -> NDArray[np.float64]:
    """(m, SEEDS, n): for each row of distance (m, POOL), the pool vectors nearest."""
    k = min(SEEDS, qs.shape[0])
    idx = np.argsort(distance, axis=1, kind="stable")[:, :k]
    return qs[idx]


def reach_points(chain: AChain, targets: Targets, scale: float, seed: int) -> Reach:
    """Reachability of point targets (module docstring) in ROUNDS of local searches, each round
    for the targets still missed; `scale` [m] makes `excess` dimensionless."""
    t, tol = targets.values, targets.tolerance
    m, n = len(t), chain.n
    qs = pool(chain, seed)
    P = chain.fk(qs)[:, :3, 3]
    order = np.argsort(np.sum((t[:, None, :] - P[None, :, :]) ** 2, axis=2), axis=1, kind="stable")
    draws = np.random.default_rng((seed, n, 11)).integers(0, len(qs), (m, sum(r for _, r in ROUNDS)))
    lo, hi = search_box(chain)
    gap = np.linalg.norm(t, axis=1) - reach_bound(chain)
    beyond = gap > tol  # no joint vector comes nearer than gap: not searched
    best = np.where(beyond, gap, np.inf)
    found = [qs[order[k, :1]] for k in range(m)]  # the nearest pool vector, until a search finds better
    ranked = drawn = 0
    for near, rand in ROUNDS:
        todo = np.flatnonzero(~beyond & (best > tol))
        if not len(todo):
            break
        cols = np.concatenate([order[todo, ranked : ranked + near], draws[todo, drawn : drawn + rand]], axis=1)
        ranked, drawn, s = ranked + near, drawn + rand, cols.shape[1]
        q, r = fit_points(chain, qs[cols].reshape(-1, n), np.repeat(t[todo], s, axis=0), lo, hi, tol)
        q, r = q.reshape(len(todo), s, n), r.reshape(len(todo), s)
        for i, k in enumerate(todo):
            if r[i].min() < best[k]:
                best[k] = r[i].min()
                found[k] = q[i][r[i] <= tol] if best[k] <= tol else q[i][[int(np.argmin(r[i]))]]
    return Reach(best <= tol, np.maximum(best - tol, 0.0) / scale, found)


def reach_bound(chain: AChain) -> float:
    """A bound on the distance of the end-effector origin from the base: Σ |a| + |c| + max |d|
    (each joint's translation, a + (c + d) z, by the triangle inequality; |d| ≤ d(0), the pair's
    translation at θ = 0, the largest of d² = a + b cos θ)."""
    return float(sum(abs(a) + abs(c) + abs(p.translation(0.0)) for a, c, p in zip(chain.a, chain.offset, chain.pairs)))


def _solutions(q: NDArray[np.float64], ok: NDArray[np.bool_], err: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """Per target the joint vectors that reach it, else the single nearest one."""
    return [q[k][ok[k]] if ok[k].any() else q[k][[int(np.argmin(err[k]))]] for k in range(len(q))]


def fit_points(
    chain: AChain,
    q: NDArray[np.float64],
    t: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    tol: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Levenberg-Marquardt on |p(q) − t|² from every row of q at once, inside (lo, hi): a joint
    at a bound that the gradient pushes outward is held there, the rest of the step clipped; a
    row stops once within tol/2 or when its damping shows no step lowers the error. Returns the
    end points and their distances |p(q) − t| [m]."""
    q = np.clip(q, lo, hi)
    r = chain.fk(q)[:, :3, 3] - t
    cost = np.sum(r * r, axis=1)
    lam = np.full(len(q), 1e-3)
    n = q.shape[1]
    eye = np.eye(n, dtype=bool)
    active = np.flatnonzero(cost > (0.5 * tol) ** 2)
    for _ in range(ITERATIONS):
        if not len(active):
            break
        qa, ra = q[active], r[active]
        J = chain.jacobian(qa)[:, :3, :]
        g = np.einsum("kia,ki->ka", J, ra)
        A = np.einsum("kia,kib->kab", J, J)
        held = ((qa <= lo) & (g > 0)) | ((qa >= hi) & (g < 0))
        free = ~held[:, :, None] & ~held[:, None, :]
        diag = np.einsum("kaa->ka", A)
        damping = lam[active, None] * (diag + 1e-12 * diag.max(axis=1, keepdims=True) + 1e-300)
        M = np.where(free, A, 0.0) + np.where(eye, np.where(held, 1.0, damping)[:, :, None], 0.0)
        step = np.linalg.solve(M, np.where(held, 0.0, -g)[..., None])[..., 0]
        q2 = np.clip(qa + step, lo, hi)
        r2 = chain.fk(q2)[:, :3, 3] - t[active]
        cost2 = np.sum(r2 * r2, axis=1)
        better = cost2 < cost[active]
        gain = np.sqrt(cost[active]) - np.sqrt(np.minimum(cost2, cost[active]))
        rows = active[better]
        q[rows], r[rows], cost[rows] = q2[better], r2[better], cost2[better]
        lam[active] = np.where(better, np.maximum(lam[active] / 3, 1e-12), lam[active] * 4)
        going = (cost[active] > (0.5 * tol) ** 2) & (lam[active] < 1e10) & (~better | (gain > STALL * tol))
        active = active[going]
    return q, np.sqrt(cost)


def has_exact_ik(chain: AChain) -> bool:
    """Whether `AChain.ik` finds every solution without a prepared start system."""
    return chain.n <= EXACT_JOINTS and all(p.kind != "general" for p in chain.pairs)


def _pose_errors(chain: AChain, q: NDArray[np.float64], T: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """Position [m] and rotation [rad] errors of fk(q) against T, broadcast."""
    F = chain.fk(q)
    dp = np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1)
    c = (np.einsum("...ij,...ij->...", F[..., :3, :3], T[..., :3, :3]) - 1) / 2
    return dp, np.arccos(np.clip(c, -1.0, 1.0))


def reach_poses(chain: AChain, targets: Targets, scale: float, seed: int) -> Reach:
    """Reachability of pose targets (module docstring)."""
    T = targets.values
    m, n = len(T), chain.n
    tol, tol_r = targets.tolerance, math.radians(targets.tolerance_deg or 0.0)
    reached, excess = np.zeros(m, bool), np.zeros(m)
    found: list[NDArray[np.float64]] = [np.zeros((0, n))] * m
    if has_exact_ik(chain):
        for k in range(m):
            try:
                found[k] = chain.ik(T[k], within_limits=True)
            except ValueError:  # solutions on a curve (no isolated set): the local search decides
                continue
            reached[k] = len(found[k]) > 0
    rest = np.flatnonzero(~reached)
    if len(rest):
        qs = pool(chain, seed)
        F = chain.fk(qs)
        d2 = np.sum((T[rest, None, :3, 3] - F[None, :, :3, 3]) ** 2, axis=2) / scale**2
        d2 += 0.5 * np.sum((T[rest, None, :3, :3] - F[None, :, :3, :3]) ** 2, axis=(2, 3))
        q0 = _nearest(d2, qs)
        Tb = np.broadcast_to(T[rest, None], q0.shape[:2] + (4, 4))
        q = chain.ik_local(np.ascontiguousarray(Tb), q0, tol=1e-12, max_iter=200).q
        dp, dr = _pose_errors(chain, q, Tb)
        ok = (dp <= tol) & (dr <= tol_r)
        err = np.maximum(dp - tol, 0.0) / scale + np.maximum(dr - tol_r, 0.0) / math.pi
        sols = _solutions(q, ok, err)
        for i, k in enumerate(rest.tolist()):
            reached[k], excess[k], found[k] = ok[i].any(), err[i].min(), sols[i]
    return Reach(reached, excess, found)


def reach(chain: AChain, targets: Targets, scale: float, seed: int) -> Reach:
    """Reachability of the targets, points or poses."""
    if targets.kind == "points":
        return reach_points(chain, targets, scale, seed)
    return reach_poses(chain, targets, scale, seed)
