"""One pose: the start system tracked to it, the endpoints pooled, and the solutions that failed,
jumped or diverged paths left missing looked for with new γ (`solve`); where that does not account
for every start solution (a singular pose: paths meet at a multiple root), the pose moved by NEAR,
solved there and its solutions carried back by Newton (`solve_near`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import tracker
from .problem import Index, Problem, canonical, far_of, own_rows
from .startsets import StartSystem
from .tracker import DIVERGED, ENDGAME_FAR, OK, RETRIES, SINGULAR, TOO_LONG, WIDE_POSE, unit_gamma

CONFIRM = 2  # failure-free rounds of new γ that must agree before paths to infinity count
MULTIPLE = 1e6  # an endpoint's condition number above which paths that meet there meet at a multiple root
NEAR = 1e-6  # solve_near's move of the pose: translation (units of the chain's scale) and rotation [rad]
REAL_SNAP = 1e-3  # |Im θ| under which such an endpoint, carried back to T, is taken as real
NEAR_REAL = 2.0  # |Im θ| under which every endpoint at the moved pose must be carried back by Newton
# Newton onto the pose (at a multiple root it converges linearly, at m-fold ones by (m - 1)/m per
# step): steps, tolerance, floor and stall ratio of tracker.newton, and the last step that counts
# as converged (the real solutions are then verified by fk, as every candidate is)
NEWTON = (100, 1e-14, 1e-8, 0.9, 1e-4)


@dataclass
class Endpoints:
    """The tracked solutions at one pose: finite endpoints θ (k, n) that satisfy all six
    equations, whether the set is complete, and the path counts behind it (diverged: the paths
    to infinity that were confirmed and counted; failed: the paths accounted for by neither)."""

    theta: np.ndarray
    complete: bool
    paths: int
    failed: int
    diverged: int
    singular: np.ndarray | None = None  # (k,) bool: no path's endpoint there was refined (far out, or singular)
    multiple: int = 0  # paths that ended at a multiple root another path had reached (not accounted for)
    near: float = 0.0  # solve_near: how far the pose was moved (0: the endpoints are the pose's own)


@dataclass
class _Pool:
    """The distinct endpoints found so far (`found`) and, for each, the start whose first-γ path
    ended there (`owner`; None: none, or two did)."""

    found: Index
    owner: dict[int, int | None] = field(default_factory=dict)
    cond: dict[int, float] = field(default_factory=dict)  # the condition number of each endpoint's first path
    multiple: int = 0  # paths that met another at a multiple root

    def first(self, ends: np.ndarray, status: np.ndarray, cond: np.ndarray) -> set[int]:
        """Places the first γ's endpoints: the starts whose solutions are missing (the set U).
        A path that failed or diverged leaves its start's solution missing; one that ended where
        another did jumped, and either may have, so both are, unless that endpoint is
        ill-conditioned (MULTIPLE): paths meet at a multiple root by nature, with every γ, so
        they are counted in `multiple` and not tracked again. A diverged path proves nothing: at
        a generic pose every solution is finite, and a path can jump off to infinity."""
        missing: set[int] = set()
        for j, (endpoint, st) in enumerate(zip(ends, status)):
            if st not in (OK, SINGULAR):  # SINGULAR: not refined to full accuracy (far out, a multiple root)
                missing.add(j)
                continue
            new, row = self.found.place(endpoint, is_canonical=True, loose=st == SINGULAR)
            if new:
                self.owner[row], self.cond[row] = j, cond[j]
            elif st == OK and max(cond[j], self.cond[row]) > MULTIPLE:
                self.multiple += 1
            elif st == OK and (other := self.owner[row]) is not None:
                missing |= {j, other}
                self.owner[row] = None
            elif st == OK:
                missing.add(j)
        return missing

    def retrack(
        self, problem: Problem, start: StartSystem, p1: np.ndarray, gamma: complex, missing: set[int]
    ) -> tuple[bool, int]:
        """One γ from every start of U, each followed by a chain of paths: where a path ends at the
        first γ's endpoint of another start, that start is tracked next. (failed, ends): whether a
        path failed or jumped, and how many chains ended at infinity or far (`_far`)."""
        failed, ends = False, 0
        tracked = set(missing)
        reached: set[int] = set()  # the endpoint rows paths of this γ reached
        wave = sorted(missing)
        while wave:
            e, s, _, _ = tracker.track(problem, start.p0, p1, gamma, start.solutions[wave], wide=WIDE_POSE)
            chain = []
            for endpoint, st in zip(canonical(problem, e), s):
                if st not in (OK, SINGULAR):
                    far = _far(problem, endpoint, st)
                    failed |= not far
                    ends += far
                    continue
                new, row = self.found.place(endpoint, is_canonical=True, loose=st == SINGULAR)
                if new:
                    self.owner[row] = None
                elif row in reached:  # two paths of this γ at one endpoint: one jumped
                    failed = True
                    continue
                reached.add(row)
                k = self.owner.get(row)
                if not new and k is not None and k not in tracked:
                    tracked.add(k)
                    chain.append(k)
            wave = chain
        return failed, ends

    def near(self, problem: Problem) -> int:
        """The distinct endpoints found within ENDGAME_FAR (the ones that can be real)."""
        return sum(bool(far_of(problem, t) <= ENDGAME_FAR) for t in self.found.rows)


def solve(problem: Problem, start: StartSystem, T: np.ndarray, seed: int = 0) -> Endpoints:
    """Tracks the start system to the pose T (4 × 4, in the chain's units).

    Every regular endpoint is a solution (Newton converged at it), so the endpoints of all paths
    are pooled. The first γ takes every path. Where paths failed or diverged, or two ended at one
    endpoint (one of them jumped), as many solutions are missing: the first γ's endpoints of
    those starts, the set U. Each further round takes a new γ and from every start of U a chain of
    paths (`_Pool.retrack`). The two γ permute the solutions differently, and the chain is that
    permutation's cycle, which leaves the known endpoints only at one of U's or at infinity: when
    no path fails, one round reaches all of them. Rounds go on until as many distinct endpoints
    as start solutions are found, or until CONFIRM rounds in a row without failures found no new
    endpoint within ENDGAME_FAR and as many chains at infinity or far (`_far`) as make up the
    count with the endpoints (those paths then count as diverging: a path that jumped to infinity
    would have to do so again with each γ), or RETRIES rounds are spent. The set is complete only
    when the endpoints add up so; paths that met at a multiple root (`_Pool.first`) leave it
    incomplete (`solve_near` completes it)."""
    pool, complete, infinite = _pooled(problem, start, problem.target(T), seed)
    theta = np.array(pool.found.rows).reshape(-1, problem.n)
    keep = own_rows(problem, theta)
    accounted = len(pool.found.rows) + infinite
    return Endpoints(
        theta[keep, : problem.joints],
        complete,
        start.count,
        max(start.count - accounted - pool.multiple, 0),
        infinite,
        np.array(pool.found.loose, bool)[keep],
        pool.multiple,
    )


def _pooled(problem: Problem, start: StartSystem, p1: np.ndarray, seed: int) -> tuple[_Pool, bool, int]:
    """`solve` at the pose coordinates p1: the pool of distinct endpoints, whether they and the
    confirmed paths to infinity account for every start solution, and how many paths those are."""
    rng = np.random.default_rng([seed, 5])
    pool = _Pool(Index(problem))
    e, s, _, cond = tracker.track(problem, start.p0, p1, unit_gamma(rng), start.solutions, wide=WIDE_POSE)
    missing = pool.first(canonical(problem, e), s, cond)
    # per failure-free round: (endpoints within ENDGAME_FAR, all endpoints + chains far, chains far)
    clean: list[tuple[int, int, int]] = []
    for _ in range(RETRIES):
        if not missing or len(pool.found.rows) >= start.count or _confirmed(clean, start.count):
            break
        failed, ends = pool.retrack(problem, start, p1, unit_gamma(rng), missing)
        if not failed:
            clean.append((pool.near(problem), len(pool.found.rows) + ends, ends))
    confirmed = _confirmed(clean, start.count)
    infinite = min(clean[-1][2], start.count - len(pool.found.rows)) if confirmed else 0
    complete = start.certified and (len(pool.found.rows) >= start.count or confirmed)
    return pool, complete, infinite


def solve_near(problem: Problem, start: StartSystem, T: np.ndarray, seed: int = 0) -> Endpoints:
    """The solutions at T (4 × 4, in the chain's units) from those at a pose T' moved from T by
    NEAR (a random translation and rotation): where `solve` cannot account for every start
    solution at T (a singular pose, such as the workspace's boundary, where paths meet at a
    multiple root or fail near it), T' is generic, and its set is complete where `solve` makes it
    so. Every isolated solution of T is a limit of solutions of T' (an m-fold one of m, within
    about NEAR^(1/m) times a constant), so every endpoint at T' within NEAR_REAL of the real
    ones (farther out lie the limits of T's solutions at infinity) is carried onto T by Newton's
    method (linear at a multiple root), the virtual joints (n < 6) back to 0 with it. The answer is
    complete where T' was and Newton converged from each of those endpoints (`near` says how far
    the pose was moved)."""
    rng = np.random.default_rng([seed, 11])
    pool, complete, infinite = _pooled(problem, start, problem.target(_moved(T, NEAR, rng)), seed)
    theta = np.array(pool.found.rows).reshape(-1, problem.n)
    theta = theta[np.all(np.abs(theta.imag) <= NEAR_REAL, axis=1) & (far_of(problem, theta) <= ENDGAME_FAR)]
    steps, tol, floor, stall, converged = NEWTON
    theta, size = tracker.newton(problem, theta, problem.target(T), steps, tol, floor, stall, 2 * NEAR_REAL)
    ok = size <= converged
    # at a multiple root Newton leaves about ε^(1/m) of it, in the imaginary parts too: a point that
    # close to the real ones is a real candidate (fk verifies it)
    near_real = np.all(np.abs(theta.imag) <= REAL_SNAP, axis=1)
    theta[near_real] = theta[near_real].real
    mine = merged(problem, theta[ok & own_rows(problem, theta), : problem.joints])
    accounted = len(pool.found.rows) + infinite
    unaccounted = max(start.count - accounted - pool.multiple, 0) + int(np.sum(~ok))
    return Endpoints(mine, complete and bool(ok.all()), start.count, unaccounted, infinite, None, pool.multiple, NEAR)


def merged(problem: Problem, *sets: np.ndarray) -> np.ndarray:
    """The distinct rows of the sets of the chain's own solutions (k, joints), in order (one
    solution within SAME in every angle, modulo the joint's period)."""
    n = problem.joints
    own = Index(Problem(problem.kind[:n], problem.pair[:n], problem.dh[:n], problem.scale, n))
    for rows in sets:
        for t in rows:
            own.add(t)
    return np.array(own.rows, complex).reshape(-1, n)


def _moved(T: np.ndarray, by: float, rng: np.random.Generator) -> np.ndarray:
    """T (4 × 4) translated by `by` and rotated by the angle `by`, each about a random direction."""
    u, w = rng.standard_normal((2, 3))
    u, w = u / np.linalg.norm(u), w / np.linalg.norm(w)
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    out = np.array(T, float)
    out[:3, :3] = T[:3, :3] @ (np.eye(3) + np.sin(by) * K + (1 - np.cos(by)) * K @ K)
    out[:3, 3] = T[:3, 3] + by * u
    return out


def _far(problem: Problem, endpoint: np.ndarray, status: int) -> bool:
    """Whether a path that did not end regularly ended "far": found going to infinity (DIVERGED),
    or given up crawling in extended precision (TOO_LONG) beyond ENDGAME_FAR, where the tracker may
    end a path found going to infinity. Such paths, and the endpoints beyond ENDGAME_FAR, are taken
    alike (see `_confirmed`): none of them is real, and double precision cannot tell a finite point
    that far out from infinity."""
    return status == DIVERGED or (status == TOO_LONG and bool(far_of(problem, endpoint) > ENDGAME_FAR))


def _confirmed(clean: list[tuple[int, int, int]], count: int) -> bool:
    """Whether the last CONFIRM failure-free rounds agree (no endpoint that can be real found in
    between) and in each, the endpoints and the chains that ended far make up the count. A path
    to a finite point beyond ENDGAME_FAR may end there with one γ and be found going to infinity
    with another (see `_far`), so such a point may count twice, never one within it."""
    last = clean[-CONFIRM:]
    return len(last) == CONFIRM and len({near for near, _, _ in last}) == 1 and all(t >= count for _, t, _ in last)
