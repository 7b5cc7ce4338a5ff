"""The inverse kinematics of one chain (`Solver`, behind `AChain.ik`): the front that picks the
method by the chain's shape. 1 to 4 joints: the elimination by kinematic mapping
(apair.ik.elimination4), on the chain as given, else on the reversed chain, else a local search
(apair.ik.local) whose answer is not certified complete; 5 and 6 joints: the 6R elimination
(apair.ik.elimination6r), the one-A-pair elimination (apair.ik.elimination1a5r), else parameter
homotopy from the design's start system (apair.ik.homotopy). Every real candidate is verified and
refined by apair.ik.poses.refine.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import elimination1a5r, elimination6r, homotopy
from .elimination4 import CAND_TOL, Elimination
from .homotopy.problem import scale_of
from .local import local_search, on_continuum
from .pencil import SEED, Degenerate
from .poses import jacobian_rank, matrix_of, near_reach, pose_matrix, refine, study_point, with_twins

if TYPE_CHECKING:
    from .._typing import ChainLike
    from .homotopy import Endpoints, Problem, StartSystem


@dataclass
class Solution:
    """All real solutions `q` (k, n) of one pose, with the counts behind them.

    complex_count: solutions over the complex numbers found by the elimination (None unless
    asked for); candidates: real candidates examined; error: fk error of each solution;
    certified: False when the elimination degenerated (or found nothing) at this pose and the
    solutions come from the local fallback search, so that the set may be incomplete; method: how
    the set was found."""

    q: NDArray[np.float64]
    error: NDArray[np.float64]
    candidates: int
    complex_count: int | None = None
    certified: bool = True
    inside: NDArray[np.bool_] | None = None  # (k,) within the chain's joint limits (set by AChain.ik)
    method: str = "elimination"  # or "homotopy" (n = 5, 6), or "local search" (the fallback)


class Solver:
    """The inverse kinematics of one chain; the design-dependent work is done once.

    The elimination runs on the chain as given; where it degenerates (or finds nothing for a pose
    within reach) it runs on the reversed chain, and where that degenerates too a batched local
    search from many seeds gives the solutions, marked as not certified complete."""

    def __init__(self, chain: ChainLike, seed: int = SEED) -> None:
        n = chain.n
        if n not in (1, 2, 3, 4, 5, 6):
            raise ValueError(f"chain: inverse kinematics covers chains of 1 to 6 pairs, this one has {n}")
        for i, p in enumerate(chain.pairs):
            if p.kind == "general":
                raise ValueError(
                    f"pairs[{i}]: a general A-pair's motion is not rational; inverse kinematics "
                    "needs sinusoidal A-pairs or R-pairs"
                )
        self.chain = chain
        self.scale = scale_of(chain)
        self.seed = seed
        self._eliminations: dict[bool, Elimination] = {}
        self._problem: Problem | None = None  # n = 5, 6: the homotopy.Problem
        self._start: StartSystem | None = None  # and its StartSystem, loaded when first needed

    def _elimination(self, reverse: bool) -> Elimination:
        if reverse not in self._eliminations:
            self._eliminations[reverse] = Elimination(self.chain, self.scale, reverse, self.seed)
        return self._eliminations[reverse]

    def solve(self, T: ArrayLike, tol: float = 1e-9, count_complex: bool = False) -> Solution:
        if self.chain.n >= 5:
            return self._solve_homotopy(T, tol)
        target = study_point(T)
        target[4:] /= self.scale
        Tm = matrix_of(T)
        n = self.chain.n
        degenerate = []
        for reverse in (False, True) if n >= 2 else (False,):
            try:
                found = self._elimination(reverse).candidates(target, count_complex)
            except Degenerate as exc:
                degenerate.append(str(exc))
                continue
            cands = np.array(found, complex).reshape(-1, n)
            # points where a joint's rotation part vanishes (u = ±i, isotropic) are not displacements
            cands = cands[np.all(np.abs(1 + cands * cands) > 1e-3 * (1 + np.abs(cands) ** 2), axis=1)]
            count = len(_dedupe_complex(cands)) if count_complex else None
            real = cands[np.all(np.abs(cands.imag) <= CAND_TOL * (1 + np.abs(cands)), axis=1)]
            q = with_twins(self.chain, self._elimination(reverse).angles(real))
            q, err = refine(self.chain, q, Tm, tol)
            if len(q) or not near_reach(self.chain, Tm):
                return Solution(q, err, len(real), count)
        # every elimination degenerated, or found nothing for a pose within reach: local search
        q, err = refine(self.chain, local_search(self.chain, Tm), Tm, tol)
        if len(q) and on_continuum(self.chain, q[0], Tm, tol):
            why = f" ({degenerate[0]})" if degenerate else ""
            raise ValueError(
                f"T: the solutions at this pose are not isolated{why}: they form a curve (e.g. two R-pairs on one axis)"
            )
        certified = len(q) == 0 and not degenerate  # the elimination's "none" stands
        return Solution(q, err, 0, None, certified=certified, method="local search")

    def _solve_homotopy(self, T: ArrayLike, tol: float) -> Solution:
        """n = 5, 6: R-chains by the 6R elimination (apair.ik.elimination6r) where it certifies its
        16 solutions, chains with one A-pair by theirs (apair.ik.elimination1a5r, 48); otherwise
        every start solution tracked to T (apair.ik.homotopy). Real solutions verified."""
        Tm = pose_matrix(T)
        if self._problem is None:
            self._problem = homotopy.Problem.of(self.chain)
        problem = self._problem
        theta = None
        for route in (elimination6r, elimination1a5r):
            if route.applies(problem):
                theta = route.solve(problem, Tm)
        if theta is not None:
            theta, complete, method = homotopy.own(problem, theta), True, "elimination"
        else:
            if self._start is None:
                self._start = homotopy.start_system(problem)
            ends = homotopy.solve(problem, self._start, Tm)
            theta, complete, method = ends.theta, ends.complete, "homotopy"
            self._refuse_continuum(problem, ends, Tm, tol)
        real = homotopy.real_angles(problem, theta)
        q, err = refine(self.chain, real, Tm, tol)
        return Solution(q, err, len(real), len(theta), certified=complete, method=method)

    def _refuse_continuum(self, problem: Problem, ends: Endpoints, Tm: NDArray[np.float64], tol: float) -> None:
        """ValueError where the pose has a curve of real solutions (a wrist singularity: two R-pair
        axes in line). Paths then end at singular points of the curve's complexification, often not
        real ones: the real part of such an endpoint, corrected onto the pose, is a real point of
        the curve, where a step along the Jacobian's null space stays on the pose."""
        singular = ends.theta[ends.singular] if ends.singular is not None else ends.theta[:0]
        if len(singular) == 0:
            return
        q = homotopy.real_angles(problem, singular.real.astype(complex))
        q, _ = refine(self.chain, local_search(self.chain, Tm, start=q), Tm, tol)
        for k in np.flatnonzero(jacobian_rank(self.chain, q) < self.chain.n):
            if on_continuum(self.chain, q[k], Tm, tol):
                raise ValueError(
                    "T: the solutions at this pose are not isolated: they form a curve (e.g. a wrist "
                    "singularity, two R-pair axes in line)"
                )


def _dedupe_complex(cands: NDArray[np.complex128], tol: float = 1e-6) -> list[NDArray[np.complex128]]:
    out: list[NDArray[np.complex128]] = []
    for c in cands:
        if not any(np.max(np.abs(c - o) / (1 + np.abs(o))) < tol for o in out):
            out.append(c)
    return out
