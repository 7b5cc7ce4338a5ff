"""The inverse kinematics of one chain (`Solver`, behind `AChain.ik`): the front that picks the
method by the chain's shape. 1 to 4 joints: the elimination by kinematic mapping
(apair.ik.elimination4), on the chain as given, else on the reversed chain, else a local search
(apair.ik.local) whose answer is not certified complete; 5 and 6 joints: the 6R elimination
(apair.ik.elimination6r), the one-A-pair elimination (apair.ik.elimination1a5r), else parameter
homotopy from the design's start system (apair.ik.homotopy; at a singular pose, where its paths
do not account for every start solution, by way of a pose moved by 1e-6). Chains with P-pairs of
any length go to the homotopy (1 to 4 joints with the virtual joints it appends), whose unknown
at a P-pair is its slide in units of L. Every real candidate is verified and refined by
apair.ik.poses.refine.

Every method works on the chain in units of its length scale L (apair.ik.poses.length_scale: the
pose's translation divided by L, the design's lengths too), and the tolerances on translations
are relative to L: a chain scaled by s has the same solutions at the pose with its translation
scaled by s. A pose beyond the chain's reach bound is answered without any elimination.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..kernels import native_in_use, native_module
from . import elimination1a5r, elimination6r, homotopy
from .elimination4 import CAND_TOL, Elimination
from .families import classify
from .forms import Form, closed_form
from .local import local_search, on_continuum
from .pencil import SEED, Degenerate
from .poses import (
    Pose,
    jacobian_rank,
    length_scale,
    near_reach,
    pose_of,
    reach_of,
    refine,
    translation_norm,
    with_twins,
)

if TYPE_CHECKING:
    from .._typing import ChainLike
    from .homotopy import Endpoints, Problem, StartSystem


@dataclass
class Solution:
    """All real solutions `q` (k, n) of one pose, with the counts behind them.

    complex_count: solutions over the complex numbers found by the elimination or the homotopy
    (None unless asked for); candidates: real candidates examined; error: fk error of each
    solution; certified: the set is proven complete (an empty one: the pose is unreachable), to
    the solvers' tolerances; False where it may be incomplete: the local fallback search's answer
    (n ≤ 4), or a start set or paths that do not account for every solution (n = 5, 6); method:
    how the set was found ("reach bound": the pose's position lies beyond Σ |a| + |c| + 2h from
    the base, so no joint vector reaches it); note: why it is not certified, or how it was where
    the method alone did not (a singular pose certified by a pose moved by 1e-6), else empty;
    family: the key of the chain's kinematic family (`apair.ik.families`: which axes are parallel or
    meet, "general" where no subproblem decomposition is known). Six R-pairs with a spherical wrist
    or three parallel inner axes are solved in closed form (method "closed form", apair.ik.wrist,
    apair.ik.parallel: complex_count None; at a continuum one member of it, named in `note`); the
    other families by the general methods."""

    q: NDArray[np.float64]
    error: NDArray[np.float64]
    candidates: int
    complex_count: int | None = None
    certified: bool = True
    inside: NDArray[np.bool_] | None = None  # (k,) within the chain's joint limits (set by AChain.ik)
    method: str = "elimination"  # or "closed form", "homotopy" (n = 5, 6), "local search" (the fallback), "reach bound"
    note: str = ""  # why the set is not certified, or how it was where not by the method alone
    family: str = ""  # the chain's kinematic family (apair.ik.families; "unclassified" for n != 6)


FAR = 1e6  # beyond FAR times the reach bound a pose is answered by the bound even when complex
#           solutions are counted (the eliminations' coefficients would span 1e12 and more)


class _Pair(NamedTuple):
    kind: str
    amplitude: float


@dataclass(frozen=True)
class _UnitDesign:
    """The chain's design in units of its length scale, as homotopy.Problem.of reads a chain (its
    scale comes out exactly 1, its normalised lengths bit for bit those of the chain itself
    wherever the chain's scale is 1 mm or more, so that the cached start systems' keys agree)."""

    pairs: list[_Pair]
    a: np.ndarray
    alpha: np.ndarray
    offset: np.ndarray
    theta_offset: np.ndarray
    limits: list[tuple[float, float]]  # a P-pair's range in units of the scale (the others' as they are)

    @property
    def n(self) -> int:
        return len(self.pairs)

    @staticmethod
    def of(chain: ChainLike, scale: float) -> _UnitDesign:
        pairs = [_Pair(p.kind, 0.0 if p.kind == "prismatic" else p.amplitude / scale) for p in chain.pairs]
        limits = [
            (lo / scale, hi / scale) if p.kind == "prismatic" else (lo, hi)
            for p, (lo, hi) in zip(chain.pairs, chain.limits)
        ]
        return _UnitDesign(pairs, chain.a / scale, chain.alpha, chain.offset / scale, chain.theta_offset, limits)


class Solver:
    """The inverse kinematics of one chain; the design-dependent work is done once.

    The elimination runs on the chain as given; where it degenerates (or finds nothing for a pose
    within reach) it runs on the reversed chain, and where that degenerates too a batched local
    search from many seeds gives the solutions, marked as not certified complete. Where an
    elimination ran to its end and found nothing, the search checks it, and that "none" stands
    (certified) unless the search finds a solution."""

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
            if p.kind == "helical":
                raise ValueError(
                    f"pairs[{i}]: a helical pair's d = pitch*theta is not algebraic in the angle's half "
                    "tangent, so all-solutions inverse kinematics does not apply; use ik_local(T, q0)"
                )
        self.chain = chain
        self.family = classify(chain)
        self.scale = length_scale(chain)
        self._closed = closed_form(chain, self.family, self.scale)
        self.slides = np.array([p.kind == "prismatic" for p in chain.pairs])
        # the reach bound counts a P-pair's slide within its limits; its solutions are any real d
        self.reach = math.inf if self.slides.any() else reach_of(chain)
        # the closed form's single-pose fast path in C (apair._native.ClosedIK: call(T, tol) gives what
        # solve(T, tol) would, or None where the pose needs the validating path), or None
        # six R-pairs of no closed-form family: their DH constants (6, 4) for the 6R elimination in C
        six_r = self._closed is None and n == 6 and all(p.kind == "revolute" for p in chain.pairs)
        self._dh6r = np.stack([chain.a, chain.alpha, chain.offset, chain.theta_offset], 1) if six_r else None
        self.fast = _fast_path(self._closed, self.scale, self.reach, self._dh6r)
        self.seed = seed
        self._eliminations: dict[bool, Elimination] = {}
        self._problem: Problem | None = None  # n = 5, 6: the homotopy.Problem
        self._start: StartSystem | None = None  # and its StartSystem, loaded when first needed

    def _elimination(self, reverse: bool) -> Elimination:
        if reverse not in self._eliminations:
            self._eliminations[reverse] = Elimination(self.chain, self.scale, reverse, self.seed)
        return self._eliminations[reverse]

    def solve(self, T: ArrayLike, tol: float = 1e-9, count_complex: bool = False) -> Solution:
        """All real solutions at T, verified to tol (rotation entries; translations in units of
        the chain's length scale; a float32 pose to its own precision at least, `Pose.floor`)."""
        sol = self._solve(T, tol, count_complex)
        return sol if sol.family else dataclasses.replace(sol, family=self.family.key)

    def _solve(self, T: ArrayLike, tol: float, count_complex: bool) -> Solution:
        pose = pose_of(T)
        tol = max(tol, pose.floor)
        if self._beyond_reach(pose.matrix, count_complex):
            n = self.chain.n
            return Solution(np.zeros((0, n)), np.zeros(0), 0, None, method="reach bound")
        if self._closed is not None:
            return self._solve_closed(self._closed, pose, tol)
        if self.chain.n >= 5 or self.slides.any():
            return self._solve_homotopy(pose, tol)
        return self._solve_elimination(pose, tol, count_complex)

    def _beyond_reach(self, Tm: NDArray[np.float64], count_complex: bool) -> bool:
        """Whether the pose is answered by the reach bound alone: beyond it (where only a count of
        the complex solutions needs an elimination) or beyond FAR times it."""
        if not math.isfinite(self.reach) or near_reach(self.chain, Tm, self.reach, self.scale):
            return False
        return not count_complex or translation_norm(Tm) > FAR * (self.reach + self.scale)

    def _solve_elimination(self, pose: Pose, tol: float, count_complex: bool) -> Solution:
        """n ≤ 4: the elimination on the chain as given, else reversed, else the local search."""
        target = pose.study.copy()
        target[4:] /= self.scale
        Tm = pose.matrix
        n = self.chain.n
        degenerate: list[str] = []
        none: Solution | None = None  # the first orientation that ran to its end and found no solution
        for reverse in (False, True) if n >= 2 else (False,):
            try:
                found = self._elimination(reverse).candidates(target, count_complex)
            except Degenerate as exc:
                degenerate.append(str(exc))
                continue
            cands = np.array(found, complex).reshape(-1, n)
            if not np.isfinite(cands).all():  # a lost candidate: its "none" would prove nothing
                degenerate.append("a candidate is not finite")
                continue
            # points where a joint's rotation part vanishes (u = ±i, isotropic) are not displacements
            cands = cands[np.all(np.abs(1 + cands * cands) > 1e-3 * (1 + np.abs(cands) ** 2), axis=1)]
            count = len(_dedupe_complex(cands)) if count_complex else None
            real = cands[np.all(np.abs(cands.imag) <= CAND_TOL * (1 + np.abs(cands)), axis=1)]
            q = with_twins(self.chain, self._elimination(reverse).angles(real))
            q, err = refine(self.chain, q, Tm, tol, self.scale)
            if len(q):
                self._refuse_a_curve(q, Tm, tol, "")
                return Solution(q, err, len(real), count)
            if not near_reach(self.chain, Tm, self.reach, self.scale):
                return Solution(q, err, len(real), count)
            none = none or Solution(q, err, len(real), count)
        return self._local(Tm, tol, none, degenerate)

    def _refuse_a_curve(self, q: NDArray[np.float64], Tm: NDArray[np.float64], tol: float, why: str) -> None:
        """A one-line refusal where the solutions found lie on a curve of solutions (a rank-deficient
        Jacobian at every one of them and a step along its null space landing on another: e.g.
        joints on one axis, a self-motion): the elimination's isolated points would be a sample."""
        if np.all(jacobian_rank(self.chain, q, self.scale) < self.chain.n) and on_continuum(self.chain, q[0], Tm, tol):
            raise ValueError(
                f"T: the solutions at this pose are not isolated{why}: they form a curve (e.g. two R-pairs on one axis)"
            )

    def _local(self, Tm: NDArray[np.float64], tol: float, none: Solution | None, degenerate: list[str]) -> Solution:
        """n ≤ 4 where every orientation degenerated, or found nothing for a pose within reach: a
        local search from many seeds. Where it finds nothing either, an elimination's "none" stands
        (`none`: method "elimination", certified: no real solution within its tolerances); where
        it finds solutions, they are the answer, not certified complete."""
        q, err = refine(self.chain, local_search(self.chain, Tm), Tm, tol, self.scale)
        why = f" ({degenerate[0]})" if degenerate else ""
        if len(q) and on_continuum(self.chain, q[0], Tm, tol):
            self._refuse_a_curve(q, Tm, tol, why)
        if len(q) == 0 and none is not None:
            return none
        if none is not None:
            note = f"the elimination found no solution where a local search found {len(q)}: the set may be incomplete"
        elif len(q):
            note = f"the elimination degenerated at this pose{why}: the solutions come from a local search"
        else:
            note = f"the elimination degenerated at this pose{why}, and a local search found no solution"
        return Solution(q, err, 0, None, certified=False, method="local search", note=note)

    def _solve_closed(self, closed: Form, pose: Pose, tol: float) -> Solution:
        """The family's closed form (apair.ik.forms: a spherical wrist, three parallel inner axes, or
        axes 1-3 parallel with 5 and 6 meeting, at the tool end or the base end): every real solution,
        verified. Where the polynomial vanishes identically (a pose or design the closed form does
        not separate) the homotopy answers."""
        try:
            q, err, candidates, note = closed.solve(pose.matrix, tol)
        except ValueError:
            return self._solve_homotopy(pose, tol)
        return Solution(q, err, candidates, None, method="closed form", note=note, family=self.family.key)

    def _solve_homotopy(self, pose: Pose, tol: float) -> Solution:
        """n = 5, 6 and chains with P-pairs: R-chains by the 6R elimination
        (apair.ik.elimination6r) where it certifies its 16 solutions, chains with one A-pair by
        theirs (apair.ik.elimination1a5r, 48); otherwise every start solution tracked to T
        (apair.ik.homotopy). Real solutions verified. All three work on the design in units of its
        length scale (`_UnitDesign`) and T's translation too (a P-pair's slide is read back in m)."""
        Tm = pose.matrix
        declined = False  # six R-pairs: the 6R elimination and the real solutions in one C call (apair_ik6r)
        if self._dh6r is not None and (native := native_in_use()) is not None:
            out = native.ik6r(self._dh6r, self.scale, Tm, tol)
            if out is not None:
                q, err, found, candidates = out
                k = int(found[0])
                return Solution(q[:k], err[:k], int(candidates[0]), elimination6r.COUNT, method="elimination")
            declined = True  # not certified: the same elimination in elimination6r.solve would decline again
        Tu = Tm.copy()
        Tu[:3, 3] /= self.scale
        if self._problem is None:
            self._problem = homotopy.Problem.of(_UnitDesign.of(self.chain, self.scale))
        problem = self._problem
        theta = None
        for route in (elimination6r, elimination1a5r):
            if route.applies(problem) and not (declined and route is elimination6r):
                theta = route.solve(problem, Tu)
        note = ""
        if theta is not None:
            theta, complete, method = homotopy.own(problem, theta), True, "elimination"
        else:
            theta, complete, note = self._homotopy(problem, Tu, Tm, tol)
            method = "homotopy"
        real = self._joint_values(homotopy.real_angles(problem, theta))
        q, err = refine(self.chain, real, Tm, tol, self.scale)
        return Solution(q, err, len(real), len(theta), certified=complete, method=method, note=note)

    def _homotopy(
        self, problem: Problem, Tu: NDArray[np.float64], Tm: NDArray[np.float64], tol: float
    ) -> tuple[NDArray[np.complex128], bool, str]:
        """Every start solution tracked to Tu (homotopy.solve); where the paths do not account for
        all of them but the start set is certified (a singular pose, where paths meet at a
        multiple root), also from a pose moved by homotopy.NEAR (homotopy.solve_near), whose
        certificate then stands for T's. (theta, complete, note: how it was certified or why not)."""
        if self._start is None:
            self._start = homotopy.start_system(problem)
        start = self._start
        ends = homotopy.solve(problem, start, Tu)
        self._refuse_continuum(problem, ends, Tm, tol)
        if ends.complete:
            return ends.theta, True, ""
        if not start.certified:
            return ends.theta, False, f"the start set is not certified: {start.how}"
        near = homotopy.solve_near(problem, start, Tu)
        theta = homotopy.merged(problem, ends.theta, near.theta)
        here = _unaccounted(ends)
        if near.complete:
            how = f"certified at a pose moved by {near.near:g}, its solutions carried back onto T by Newton's method"
            return theta, True, f"{how} (at T {here})"
        return theta, False, f"at T {here}, and at a pose moved by {near.near:g} {_unaccounted(near)}"

    def _refuse_continuum(self, problem: Problem, ends: Endpoints, Tm: NDArray[np.float64], tol: float) -> None:
        """ValueError where the pose has a curve of real solutions (a wrist singularity: two R-pair
        axes in line). Paths then end at singular points of the curve's complexification, often not
        real ones: the real part of such an endpoint, corrected onto the pose, is a real point of
        the curve, where a step along the Jacobian's null space stays on the pose."""
        singular = ends.theta[ends.singular] if ends.singular is not None else ends.theta[:0]
        if len(singular) == 0:
            return
        q = self._joint_values(homotopy.real_angles(problem, singular.real.astype(complex)))
        q, _ = refine(self.chain, local_search(self.chain, Tm, start=q), Tm, tol, self.scale)
        for k in np.flatnonzero(jacobian_rank(self.chain, q, self.scale) < self.chain.n):
            if on_continuum(self.chain, q[k], Tm, tol):
                raise ValueError(
                    "T: the solutions at this pose are not isolated: they form a curve (e.g. a wrist "
                    "singularity, two R-pair axes in line)"
                )

    def _joint_values(self, real: NDArray[np.float64]) -> NDArray[np.float64]:
        """The homotopy's real joint values (m, n) as the chain's: a P-pair's slide from units of
        the length scale to metres (angles as they are)."""
        return np.where(self.slides, real * self.scale, real)


GENERAL_6R = 128  # apair._native.ClosedIK's code for six R-pairs by the 6R elimination (apair_ik6r)


def _fast_path(closed: Form | None, scale: float, reach: float, dh6r: NDArray[np.float64] | None) -> Any:
    """apair._native.ClosedIK for the closed form, or for six R-pairs of no closed-form family (their
    DH constants dh6r) the 6R elimination in one C call, where the C extension is installed; else None."""
    native, _ = native_module()
    if native is None:
        return None
    try:
        if closed is not None:
            return native.ClosedIK(closed.code, closed.dh, scale, reach, closed.amplitude)
        if dh6r is not None:
            return native.ClosedIK(GENERAL_6R, dh6r, scale, reach)
    # a design its C form does not prepare, or no SciPy LAPACK: the validating path answers
    except (ValueError, ImportError):
        return None
    return None


def _unaccounted(ends: Endpoints) -> str:
    """What kept a pose's endpoints (homotopy.Endpoints) from accounting for every start solution."""
    parts = ["paths met at a multiple root (a singular pose)"] if ends.multiple else []
    if ends.failed or not parts:
        parts.append(f"{ends.failed} of {ends.paths} start solutions were not accounted for")
    return " and ".join(parts)


def _dedupe_complex(cands: NDArray[np.complex128], tol: float = 1e-6) -> list[NDArray[np.complex128]]:
    out: list[NDArray[np.complex128]] = []
    for c in cands:
        if not any(np.max(np.abs(c - o) / (1 + np.abs(o))) < tol for o in out):
            out.append(c)
    return out
