"""One pose: the start system tracked to it, the endpoints pooled and the solutions that failed or
jumped paths left missing looked for with new γ (`solve`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import tracker
from .problem import Index, Problem, canonical, own_rows
from .startsets import StartSystem
from .tracker import DIVERGED, OK, RETRIES, SINGULAR, WIDE_POSE, unit_gamma


@dataclass
class Endpoints:
    """The tracked solutions at one pose: finite endpoints θ (k, n) that satisfy all six
    equations, whether the set is complete, and the path counts behind it."""

    theta: np.ndarray
    complete: bool
    paths: int
    failed: int
    diverged: int
    singular: np.ndarray | None = None  # (k,) bool: no path's endpoint there was refined (far out, or singular)


def solve(problem: Problem, start: StartSystem, T: np.ndarray, seed: int = 0) -> Endpoints:
    """Tracks the start system to the pose T (4 × 4, in the chain's units).

    Every regular endpoint is a solution (Newton converged at it), so the endpoints of all paths
    are pooled. The first γ takes every path. Where paths failed, or two ended at one endpoint
    (one of them jumped), as many solutions are missing: the first γ's endpoints of those starts,
    the set U. Each further round takes a new γ and from every start of U a chain of paths: where
    a path ends at the first γ's endpoint of another start, that start is tracked next. The two
    γ permute the solutions differently, and the chain is that permutation's cycle, which leaves
    the known endpoints only at one of U's: when no path fails, one round reaches all of them.
    Rounds go on until as many distinct endpoints (plus paths to infinity: the first γ's, and
    the chains' that end there in a round without failures) as start solutions are found, or
    RETRIES rounds are spent."""
    rng = np.random.default_rng([seed, 5])
    p1 = problem.target(T)
    found = Index(problem)
    owner: dict[int, int | None] = {}  # endpoint row -> the start it is the first γ's endpoint of
    missing: set[int] = set()  # U
    e, s, _, _ = tracker.track(problem, start.p0, p1, unit_gamma(rng), start.solutions, wide=WIDE_POSE)
    diverged = int(np.sum(s == DIVERGED))
    infinite = 0  # chains of a round without failures that end at infinity
    for j, endpoint, st in zip(range(start.count), canonical(problem, e), s):
        if st in (OK, SINGULAR):  # SINGULAR: not refined to full accuracy (far out, a multiple root)
            new, row = found.place(endpoint, is_canonical=True, loose=st == SINGULAR)
            if new:
                owner[row] = j
            elif st == OK and (first := owner[row]) is not None:
                missing |= {j, first}
                owner[row] = None
            elif st == OK:
                missing.add(j)
        elif st != DIVERGED:
            missing.add(j)
    for _ in range(RETRIES):
        if len(found.rows) + diverged + infinite >= start.count or not missing:
            break
        gamma, failed, ends = unit_gamma(rng), False, 0
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
                new, row = found.place(endpoint, is_canonical=True, loose=st == SINGULAR)
                if new:
                    owner[row] = None
                elif row in reached:  # two paths of this γ at one endpoint: one jumped
                    failed = True
                    continue
                reached.add(row)
                k = owner.get(row)
                if not new and k is not None and k not in tracked:
                    tracked.add(k)
                    chain.append(k)
            wave = chain
        if not failed:
            infinite = ends
            break
    theta = np.array(found.rows).reshape(-1, problem.n)
    keep = own_rows(problem, theta)
    accounted = len(found.rows) + diverged + infinite
    complete = start.certified and accounted == start.count
    return Endpoints(
        theta[keep, : problem.joints],
        complete,
        start.count,
        max(start.count - accounted, 0),
        diverged + infinite,
        np.array(found.loose, bool)[keep],
    )
