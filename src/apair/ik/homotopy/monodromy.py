"""Monodromy: every complex solution at one generic complex pose, by loops through random poses
that carry the known solutions to a permutation of them and add the new ones (`monodromy`); the
paths of a loop's segment that lost their way are tracked again with new γ (`segment`).
"""

from __future__ import annotations

import numpy as np

from . import tracker
from .problem import Index, Problem, linear_pose, random_pose, system
from .tracker import DIVERGED, FAILED, OK, TOO_LONG, unit_gamma

STABLE = 20  # loops in a row without a new solution that end a monodromy run
MAX_LOOPS = 400
SEED_DRAWS = 5  # random points in a row with a singular Jacobian before the solutions are taken as not isolated


def lost_paths(status: np.ndarray, finite: bool) -> np.ndarray:
    """Which paths lost their way: failed, too long, or (finite: toward a generic pose, where every
    solution is finite) diverged."""
    return (status == FAILED) | (status == TOO_LONG) | (finite & (status == DIVERGED))


def segment(problem: Problem, a, b, start: np.ndarray, rng, retries: int = 2, finite: bool = False):
    """start tracked from pose a to b, the paths that lost their way (`lost_paths`) again with a new γ (a
    path that fails in a loop of monodromy would hide its solution's images)."""
    end, status, _, _ = tracker.track(problem, a, b, unit_gamma(rng), start)
    for _ in range(retries):
        bad = np.flatnonzero(lost_paths(status, finite))
        if len(bad) == 0:
            break
        e, s, _, _ = tracker.track(problem, a, b, unit_gamma(rng), start[bad])
        end[bad], status[bad] = e, s
    return end, status


def _seed_solution(problem: Problem, rng):
    """A random complex joint vector and a generic pose p0 at which it is a regular solution. A
    point where the Jacobian is singular is drawn again: only where SEED_DRAWS of the points drawn are
    singular are the solutions taken as not isolated (a singular point of a generic design is a
    chance, one of a degenerate design the rule)."""
    n = problem.n
    singular = 0
    for _ in range(20):
        theta = rng.uniform(-np.pi, np.pi, n) + 0.3j * rng.standard_normal(n)
        p = _pose_through(problem, theta, rng)
        F, J, _ = system(problem, theta, p, np.zeros(7, complex))
        if np.max(np.abs(F)) > 1e-9 or np.abs(p[3:]).max() < 1e-3:
            continue
        sv = np.linalg.svd(J, compute_uv=False)
        if not sv[-1] < 1e-8 * sv[0]:
            return theta, p
        singular += 1
        if singular == SEED_DRAWS:
            raise ValueError(
                "chain: the inverse kinematics has no isolated solutions at a generic pose (the "
                f"Jacobian is singular at {SEED_DRAWS} random points: the solutions form curves, e.g. two "
                "R-pairs on one axis, or a joint that cannot move the end frame)"
            )
    raise RuntimeError("homotopy: no regular starting solution found")


def _pose_through(problem: Problem, theta: np.ndarray, rng) -> np.ndarray:
    """A random pose p with F(θ; p) = 0: A p + b = 0 (F is linear in the pose) by a particular
    solution plus a random element of the null space."""
    A, b = linear_pose(problem, theta)
    p, *_ = np.linalg.lstsq(A, -b, rcond=None)
    _, sv, Vh = np.linalg.svd(A)
    null = Vh[len(sv[sv > 1e-10 * sv[0]]) :].conj().T
    return np.asarray(p + null @ (rng.standard_normal(null.shape[1]) + 1j * rng.standard_normal(null.shape[1])))


def monodromy(
    problem: Problem,
    rng: np.random.Generator,
    stable: int = STABLE,
    max_loops: int = MAX_LOOPS,
    progress=None,
    p0=None,
    known=None,
    target: int = 0,
):
    """All solutions at one generic pose by monodromy loops: (p0, solutions (k, n), loops). Ends
    after `stable` loops in a row found nothing new, or once `target` (> 0) solutions are known."""
    index = Index(problem)
    if p0 is None:
        theta, p0 = _seed_solution(problem, rng)
        index.add(theta)
    else:
        for s in known:
            index.add(s)
    quiet, loops = 0, 0
    while quiet < stable and loops < max_loops and not 0 < target <= len(index.rows):
        loops += 1
        pa, pb = random_pose(rng), random_pose(rng)
        cur = np.array(index.rows)
        ok = np.ones(len(cur), bool)
        for a, b in ((p0, pa), (pa, pb), (pb, p0)):
            end, status = segment(problem, a, b, cur, rng)
            ok &= status == OK
            cur = end
        added = sum(index.add(s) for s in cur[ok])
        quiet = 0 if added else quiet + 1
        if progress:
            progress(loops, len(index.rows))
    return p0, np.array(index.rows), loops
