"""One pose: the start system tracked to it, the endpoints pooled, and the solutions that failed,
jumped or diverged paths left missing looked for with new γ (`solve`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import tracker
from .problem import Index, Problem, canonical, own_rows
from .startsets import StartSystem
from .tracker import DIVERGED, OK, RETRIES, SINGULAR, WIDE_POSE, unit_gamma

CONFIRM = 2  # failure-free rounds of new γ that must agree before paths to infinity count


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


@dataclass
class _Pool:
    """The distinct endpoints found so far (`found`) and, for each, the start whose first-γ path
    ended there (`owner`; None: none, or two did)."""

    found: Index
    owner: dict[int, int | None] = field(default_factory=dict)

    def first(self, ends: np.ndarray, status: np.ndarray) -> set[int]:
        """Places the first γ's endpoints: the starts whose solutions are missing (the set U).
        A path that failed or diverged leaves its start's solution missing; one that ended where
        another did jumped, and either may have, so both are. A diverged path proves nothing:
        at a generic pose every solution is finite, and a path can jump off to infinity."""
        missing: set[int] = set()
        for j, (endpoint, st) in enumerate(zip(ends, status)):
            if st not in (OK, SINGULAR):  # SINGULAR: not refined to full accuracy (far out, a multiple root)
                missing.add(j)
                continue
            new, row = self.found.place(endpoint, is_canonical=True, loose=st == SINGULAR)
            if new:
                self.owner[row] = j
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
        path failed or jumped, and how many chains ended at infinity."""
        failed, ends = False, 0
        tracked = set(missing)
        reached: set[int] = set()  # the endpoint rows paths of this γ reached
        wave = sorted(missing)
        while wave:
            e, s, _, _ = tracker.track(problem, start.p0, p1, gamma, start.solutions[wave], wide=WIDE_POSE)
            chain = []
            for endpoint, st in zip(canonical(problem, e), s):
                if st not in (OK, SINGULAR):
                    failed |= st != DIVERGED
                    ends += st == DIVERGED
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
    endpoint and as many chains at infinity as make up the count (those paths then count as
    diverging: a path that jumped to infinity would have to do so again with each γ), or RETRIES
    rounds are spent. The set is complete only when the endpoints add up so."""
    rng = np.random.default_rng([seed, 5])
    p1 = problem.target(T)
    pool = _Pool(Index(problem))
    e, s, _, _ = tracker.track(problem, start.p0, p1, unit_gamma(rng), start.solutions, wide=WIDE_POSE)
    missing = pool.first(canonical(problem, e), s)
    clean: list[tuple[int, int]] = []  # (endpoints found, chains at infinity) after each failure-free round
    for _ in range(RETRIES):
        if not missing or len(pool.found.rows) >= start.count or _confirmed(clean, start.count):
            break
        failed, ends = pool.retrack(problem, start, p1, unit_gamma(rng), missing)
        if not failed:
            clean.append((len(pool.found.rows), ends))
    infinite = clean[-1][1] if _confirmed(clean, start.count) else 0
    theta = np.array(pool.found.rows).reshape(-1, problem.n)
    keep = own_rows(problem, theta)
    accounted = len(pool.found.rows) + infinite
    complete = start.certified and accounted == start.count
    return Endpoints(
        theta[keep, : problem.joints],
        complete,
        start.count,
        max(start.count - accounted, 0),
        infinite,
        np.array(pool.found.loose, bool)[keep],
    )


def _confirmed(clean: list[tuple[int, int]], count: int) -> bool:
    """Whether the last CONFIRM failure-free rounds agree (no endpoint found in between, as many
    chains at infinity) and their endpoints and paths to infinity make up the count."""
    last = clean[-CONFIRM:]
    return len(last) == CONFIRM and len(set(last)) == 1 and sum(last[0]) == count
