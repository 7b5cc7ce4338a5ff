"""Inverse kinematics of A-chains by kinematic mapping: every real solution, each verified.

Joint i moves as A_i(u) = P_i(u)·K_i: P_i(u) = Rz(φ_i)·Tz(c_i)·(pair point) lies in the pair
subalgebra spanned by 1, k, ε, εk (rotations about and translations along z) and is polynomial in
its parameter (the derived rational quartic of `apair_motion` in u = tan(θ/4) for a sinusoidal
A-pair, (1, 0, 0, u) with u = tan(θ/2) for an R-pair); K_i = Tx(a_i)·Rx(α_i) is constant. Each
parameter is shifted by a random angle (a Möbius substitution) so that no solution sits at u = ∞.

- 1 joint: T·K_1⁻¹ must be proportional to P_1(u): univariate.
- 2 joints: A_1(u_1)A_2(u_2) = T ⇔ K_1⁻¹·P̃_1(u_1)·T·K_2⁻¹ lies in the pair subalgebra (its
  components x1, x2, y1, y2 vanish: four polynomials in u_1 with common roots) and is proportional
  to P_2(u_2) (polynomials in u_2): two univariate problems.
- 3 and 4 joints: the left half's (joints 1, 2) constraint variety, evaluated on the right part's
  parametrised image W(u_3, u_4) = T·(A_3A_4)~, must vanish. Its quadrics are found by SVD on
  sampled points of the half (`_half_quadrics`). Their images Q(W(u_3, u_4)) have bidegree
  (8, 8), less the factors 1 + u² they carry at every pose (found once per design and divided
  out): the quadric in x alone (the spherical two-joint condition) gives f of bidegree (4, 4), a
  quadric without a yy block g of bidegree (6, 6) (for A-pairs), random combinations (8, 8).
  Their resultant in u_4 has degree 48 in u_3, 16 of its roots spurious: at u_3 = ±i and where
  u_4 = ±i, g is a multiple of f, and g − a·f, divided by 1 + u², removes them (`_deflated`:
  bidegree (4, 4), 32 roots). The resultant is never expanded: the Sylvester matrix in u_4, whose
  rows have degree 4 in u_3, is linearised by rows into a 32 × 32 eigenvalue problem. At each
  real eigenvalue u_3 the Sylvester matrix's null vector (1, u_4, u_4², …) gives u_4, and the
  pair is kept if every quadric of the left half vanishes on its image (`_screen`; undecided
  ones get the common roots u_4 of all quadrics, `_right_pairs`); the left half is then solved
  for W(u_3, u_4) as above. The usual path of every step is in generated C (apair_ik4_pencil,
  apair_ik4_screen, apair_ik4_left) where the kernels are installed, NumPy otherwise.

Special designs (twists of 0 and 90°, zero lengths: what robots are built from) make parts of this
degenerate, and each has its own remedy:
- the rotation condition holds on the whole image (parallel axes, as in examples/4a_chain.toml),
  or f and g share a curve: other combinations of the quadrics take their place, the pair with
  the smallest resultant first (parallel axes give every image more factors 1 + u²: the
  example's pair has bidegrees (4, 4), a 32 × 32 problem; undivided, the factors made every
  pencil singular); where every pair shares a curve, the u_3 are the eigenvalues of the singular
  pencil's regular part (a random rank completion, `_regular_eigenvalues`);
- at some u_3 every u_4 satisfies f (or g): each u_3 gets the common roots u_4 of *all* the
  left half's quadrics (`_right_pairs`), not of f and g alone;
- joints 1 and 2 on one axis (a_1 = α_1 = 0): u_1 and u_2 come together from a bivariate
  system (`_solve_coaxial`);
- what still degenerates is solved on the reversed chain (K_n·T̃ = Π P̃ K̃, the halves swapped);
  where both orientations fail (or find nothing for a pose within reach), a batched
  Levenberg-Marquardt search from 64 seeds finds the solutions, and the answer says that it is
  not certified complete (`Solution.certified`). A curve of solutions (two R-pairs on one axis)
  is refused with a ValueError.

Every real candidate is checked with the chain's own fk kernel, refined by up to two Gauss-Newton
steps where it is not already accurate to 1e-3·tol, and kept only if fk(q) reproduces T to `tol`
(largest entry of the 4×4 difference); duplicates are merged. Angles are returned in (−2π, 2π] for A-pairs
(their motion has period 4π) and (−π, π] for R-pairs. General (non-sinusoidal) A-pairs have an
elliptic, not rational, motion and are not supported.

Chains of 5 and 6 joints are solved by parameter homotopy (apair.homotopy), and `ik_local` is a
Levenberg-Marquardt search from seeds in C for any chain.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import scipy.linalg
from scipy.linalg import lapack

from . import _validate as V
from .homotopy import _native, scale_of
from .study import conjugate, from_matrix, multiply, normalise, to_matrix

SEED = 46  # fixed: the parameter shifts and random combinations are reproducible
OUTSIDE = [1, 2, 5, 6]  # components that vanish on the pair subalgebra
INSIDE = [0, 3, 4, 7]  # the subalgebra's components: 1, k, ε, εk
ROOT_RTOL = 1e-6  # relative residual under which a root is a candidate (verification decides)
REAL_TOL = 1e-6  # |Im u| / (1 + |u|) under which a root is taken as real
CAND_TOL = 1e-4  # the same for an intermediate root (multiple roots lose half their digits)
LEAD_COND = 1e10  # 1-norm condition number of the Sylvester rows' leading coefficients under which
#                  the hidden-variable pencil is taken as regular and solved as B⁻¹A
DEFLATE_TOL = 1e-10  # relative residual of g(±i, ·) = f(±i, ·)·h under which g is deflated (_deflated)
SCREEN_TOL = (1e-8, 1e-8, 1e-6)  # the screen: Vandermonde null vector; accept; reject (see _screen)
_SCREEN_TOL = np.array(SCREEN_TOL)
# apair_ik4_left: ROOT_RTOL; a single null vector's rank gap; its Vandermonde test; no root at all
# (the smallest singular value above 1e-4 of the largest; a root of relative residual ROOT_RTOL
# bounds it by ROOT_RTOL·√(rows·cols) ≤ 1.2e-5 of it for the at most 16 × 8 matrices)
LEFT_TOL = np.array([ROOT_RTOL, 1e-6, 1e-8, 1e-4])


# ----------------------------------------------------------------------------- polynomials
def _relres(polys: np.ndarray, u) -> np.ndarray:
    """max_k |p_k(u)| / Σ_m max_k|c_km| |u|^m for polynomials (k, D+1) (ascending coefficients) at
    points u (r,): relative to the whole system's size, so that a polynomial which is zero up to
    rounding does not veto a root."""
    u = np.asarray(u)
    pw = u[:, None] ** np.arange(polys.shape[1])
    num = np.abs(pw @ polys.T).max(axis=1)
    den = np.abs(pw) @ np.abs(polys).max(axis=0)
    return num / np.maximum(den, 1e-300)


def _common_roots(polys: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Common roots (complex) of univariate polynomials (k, D+1), ascending coefficients."""
    polys = polys[np.abs(polys).max(axis=1) > 1e-13 * max(np.abs(polys).max(), 1e-300)]
    if len(polys) == 0:
        raise _Degenerate("every polynomial vanishes identically")
    comb = rng.standard_normal(len(polys)) @ polys
    coef = np.trim_zeros(comb[::-1], "f")
    if len(coef) <= 1:
        return np.zeros(0, complex)
    roots = np.roots(coef)
    return roots[_relres(polys, roots) <= ROOT_RTOL]


def _common_roots_many(polys: np.ndarray, rng: np.random.Generator) -> list:
    """_common_roots of each system polys[r] (R, k, D+1) at once: one random combination per
    system, the companion matrices of equal degree in one batched eigenvalue call; None for a
    system whose polynomials all vanish identically."""
    size = np.abs(polys).max(axis=2)  # (R, k)
    live = size > 1e-13 * np.maximum(size.max(axis=1, keepdims=True), 1e-300)
    polys = np.where(live[:, :, None], polys, 0)  # a dropped polynomial: zero in the combination
    comb = np.einsum("rk,rkm->rm", rng.standard_normal(live.shape) * live, polys)
    nonzero = comb != 0
    degree = np.where(nonzero.any(axis=1), polys.shape[2] - 1 - np.argmax(nonzero[:, ::-1], axis=1), 0)
    out: list = [None if not live[r].any() else np.zeros(0, complex) for r in range(len(polys))]
    for d in np.unique(degree[degree >= 1]):
        rows = np.flatnonzero((degree == d) & live.any(axis=1))
        if len(rows) == 0:
            continue
        A = np.zeros((len(rows), d, d), comb.dtype)
        A[:, 0, :] = -comb[rows, d - 1::-1] / comb[rows, d, None]  # np.roots' companion form
        A[:, np.arange(1, d), np.arange(d - 1)] = 1
        roots = np.linalg.eigvals(A)  # (rows, d)
        pw = roots[:, :, None] ** np.arange(polys.shape[2])
        num = np.abs(np.einsum("rim,rkm->rik", pw, polys[rows])).max(axis=2)
        den = np.einsum("rim,rm->ri", np.abs(pw), np.abs(polys[rows]).max(axis=1))
        ok = num / np.maximum(den, 1e-300) <= ROOT_RTOL
        for j, r in enumerate(rows):
            out[r] = roots[j][ok[j]]
    return out


def _shifted(polys: np.ndarray, m: int) -> np.ndarray:
    """(R, k(m+1), D+m+1): the polynomials (R, k, D+1) times u^0 … u^m, one row each."""
    R, k, d = polys.shape
    out = np.zeros((R, m + 1, k, d + m), polys.dtype)
    for s in range(m + 1):
        out[:, s, :, s: s + d] = polys
    return out.reshape(R, (m + 1) * k, d + m)


def _unique_roots(M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For systems M (R, k, D+1) of polynomials (ascending coefficients): (u (R,), ok (R,)), ok
    where the coefficient matrix has rank D and its null vector is (1, u, …, u^D) of a root that
    passes the residual test. A common root puts its vector in the null space, so ok means
    exactly one common root (the others go to the eigenvalues: _common_roots_many)."""
    D = M.shape[2] - 1
    if len(M) == 0 or D < 1 or M.shape[1] < D:
        return np.zeros(len(M), M.dtype), np.zeros(len(M), bool)
    _, sv, Vt = np.linalg.svd(M)
    v = Vt[:, -1].conj()
    u = np.sum(v[:, :-1].conj() * v[:, 1:], axis=1) / np.maximum(np.sum(np.abs(v[:, :-1]) ** 2, axis=1), 1e-300)
    vandermonde = np.linalg.norm(v[:, 1:] - u[:, None] * v[:, :-1], axis=1) <= 1e-8
    ok = (sv[:, D - 1] > 1e-6 * sv[:, 0]) & vandermonde & (_relres_many(M, u) <= ROOT_RTOL)
    return u, ok


def _relres_many(M: np.ndarray, u: np.ndarray) -> np.ndarray:
    """_relres of each system M[r] (R, k, D+1) at its own point u[r]."""
    pw = u[:, None] ** np.arange(M.shape[2])
    num = np.abs(np.einsum("rm,rkm->rk", pw, M)).max(axis=1)
    den = np.einsum("rm,rm->r", np.abs(pw), np.abs(M).max(axis=1))
    return num / np.maximum(den, 1e-300)


def _mobius(coeffs: np.ndarray, tau: float) -> np.ndarray:
    """(D+1, ...) coefficients of p(u) → those of (1 − τv)^D p((v + τ)/(1 − τv))."""
    P = np.polynomial.polynomial
    D = coeffs.shape[0] - 1
    out = np.zeros_like(coeffs)
    for m in range(D + 1):
        w = P.polymul(P.polypow([tau, 1.0], m), P.polypow([1.0, -tau], D - m))
        out[: len(w)] += np.multiply.outer(w, coeffs[m])
    return out


@lru_cache(maxsize=None)
def _quartic() -> np.ndarray:
    """(5, 8, 2): the coefficient of u^m h^k in component j of the sinusoidal pair's Study point,
    read from the derived set `apair_motion` (entries rational_x0 … rational_y3)."""
    import sympy as sp

    from . import polynomials

    eqs = polynomials.load("apair_motion")
    out = np.zeros((5, 8, 2))
    for j, name in enumerate(("x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3")):
        expr = sp.expand(eqs[f"rational_{name}"])
        syms = {s.name: s for s in expr.free_symbols}
        poly = sp.Poly(expr, syms.get("u", sp.Symbol("u")), syms.get("h", sp.Symbol("h")))
        for (m, k), c in poly.terms():
            out[m, j, k] = float(c)
    return out


# ----------------------------------------------------------------------------- chain constants
_scale = scale_of  # the chain's length scale (apair.homotopy.scale_of)


def _periods(chain) -> np.ndarray:
    """Each joint's period in θ: 2π for an R-pair, 4π for an A-pair (d changes sign at θ + 2π)."""
    return np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])


def _with_twins(chain, q: np.ndarray, near: float = 1e-4) -> np.ndarray:
    """q (k, n) and, for each A-pair angle within `near` of ±π, the twin with the other sign: a
    sinusoidal pair's pose curve crosses itself there (Rz(±π)·Tz(h cos(±π/2)) is one pose), so
    two joint vectors give one pose. An elimination that solves for the right half's pose and
    then reads its angles back sees that pose once; the twin is its second preimage."""
    if len(q) == 0:
        return q
    periods = _periods(chain)
    if not np.any(np.abs(np.abs(q[:, periods > 2 * np.pi]) - np.pi) <= near):
        return q
    out = [q]
    for i, p in enumerate(chain.pairs):
        if p.kind == "revolute":
            continue
        at = np.abs(np.abs(q[:, i]) - np.pi) <= near
        if at.any():
            twin = q[at].copy()
            twin[:, i] = -twin[:, i]
            out.append(twin)
    return np.concatenate(out) if len(out) > 1 else q


def _wrap(theta, period):
    """θ into (−period/2, period/2]."""
    return theta - period * np.ceil((theta - period / 2) / period)


# ----------------------------------------------------------------------------- joints
def _rot(axis: int, angle: float) -> np.ndarray:
    p = np.zeros(8)
    p[0], p[1 + axis] = math.cos(angle / 2), math.sin(angle / 2)
    return p


def _trans(axis: int, dist: float) -> np.ndarray:
    p = np.zeros(8)
    p[0], p[5 + axis] = 1.0, dist / 2
    return p


@dataclass
class _Joint:
    """Joint i in a shifted parameter u: P(u) (D+1, 8); the constant K and K⁻¹; and the map θ → u."""

    kind: str
    delta: float
    P: np.ndarray
    K: np.ndarray
    Kinv: np.ndarray
    A: np.ndarray = field(init=False)

    def __post_init__(self):
        self.A = multiply(self.P, self.K)
        # P's rotation is about z by the angle sign·θ + offset (sign −1 for a reversed chain)
        a = self._rotation(self.parameter(np.array([0.0, 1.0])))
        self.sign = float(np.round(_wrap(a[1] - a[0], 2 * np.pi)))
        self.offset = a[0]

    def parameter(self, theta):
        return np.tan((theta - self.delta) / (2 if self.kind == "revolute" else 4))

    def _rotation(self, u) -> np.ndarray:
        x = _eval(self.P, u)
        return 2 * np.arctan2(x[:, 3], x[:, 0])

    def parameters_of(self, Z: np.ndarray) -> np.ndarray:
        """(R, 1) for an R-pair, (R, 2) for an A-pair: the parameters u whose rotation is that of
        the points Z (R, 8) in the pair subalgebra (an A-pair's two angles θ and θ + 2π share it;
        which of them has P(u) ∝ Z is for the caller to test)."""
        theta = (2 * np.arctan2(Z[:, 3].real, Z[:, 0].real) - self.offset) / self.sign
        if self.kind == "revolute":
            return self.parameter(theta)[:, None]
        return self.parameter(np.stack([theta, theta + 2 * np.pi], 1))


def _pair_curve(chain, i: int, scale: float, delta: float) -> np.ndarray:
    """P_i(u) (D+1, 8) = Rz(φ_i)·Tz(c_i)·(pair point in the parameter shifted by delta)."""
    pair = chain.pairs[i]
    if pair.kind == "revolute":
        tau = math.tan(delta / 2)
        base = np.zeros((2, 8))
        base[0, 0] = base[1, 3] = 1.0  # the rotation quaternion (1, 0, 0, tan(θ/2)), projectively
    else:
        tau = math.tan(delta / 4)
        base = _quartic() @ np.array([1.0, pair.amplitude / scale])
    P = _mobius(base, tau)
    return multiply(multiply(_rot(2, chain.theta_offset[i]), _trans(2, chain.offset[i] / scale)), P)


def _link(chain, i: int, scale: float) -> np.ndarray:
    """K_i = Tx(a_i)·Rx(α_i), the joint's constant part."""
    return multiply(_trans(0, chain.a[i] / scale), _rot(0, chain.alpha[i]))


def _make_joint(kind: str, delta: float, P: np.ndarray, K: np.ndarray) -> _Joint:
    return _Joint(kind, delta, P, K, conjugate(K))


def _chain_joints(chain, scale: float, deltas, reverse: bool):
    """The joints as the elimination sees them, and the map of the target pose.

    Forward: A_i = P_i(u)·K_i, target T. Reversed: T = Π P_i K_i gives K_n·T̃ = Π_j P'_j K'_j
    with P'_j = P̃_{n+1−j} (still in the pair subalgebra, in the same parameter) and
    K'_j = K̃_{n−j}, K'_n = 1: the same problem with the chain's halves swapped, which is
    regular where the forward split degenerates (e.g. where joints 1 and 2 are parallel)."""
    n = chain.n
    kinds = [p.kind for p in chain.pairs]
    P = [_pair_curve(chain, i, scale, deltas[i]) for i in range(n)]
    K = [_link(chain, i, scale) for i in range(n)]
    if not reverse:
        return [_make_joint(kinds[i], deltas[i], P[i], K[i]) for i in range(n)], None
    one = np.zeros(8)
    one[0] = 1.0
    joints = [_make_joint(kinds[i], deltas[i], conjugate(P[i]), conjugate(K[i - 1]) if i else one)
              for i in reversed(range(n))]
    return joints, K[n - 1]


class _Degenerate(Exception):
    """The elimination met an identically vanishing resultant (a non-generic design or pose)."""


# ----------------------------------------------------------------------------- the solver
@dataclass
class Solution:
    """All real solutions `q` (k, n) of one pose, with the counts behind them.

    complex_count: solutions over the complex numbers found by the elimination (None unless
    asked for); candidates: real candidates examined; error: fk error of each solution;
    certified: False when the elimination degenerated (or found nothing) at this pose and the
    solutions come from the local fallback search, so that the set may be incomplete; method: how
    the set was found."""

    q: np.ndarray
    error: np.ndarray
    candidates: int
    complex_count: int | None = None
    certified: bool = True
    inside: np.ndarray | None = None  # (k,) within the chain's joint limits (set by AChain.ik)
    method: str = "elimination"  # or "homotopy" (n = 5, 6), or "local search" (the fallback)


class Solver:
    """The inverse kinematics of one chain; the design-dependent work is done once.

    The elimination runs on the chain as given; where it degenerates (or finds nothing for a pose
    within reach) it runs on the reversed chain, and where that degenerates too a batched local
    search from many seeds gives the solutions, marked as not certified complete."""

    def __init__(self, chain, seed: int = SEED):
        n = chain.n
        if n not in (1, 2, 3, 4, 5, 6):
            raise ValueError(f"chain: inverse kinematics covers chains of 1 to 6 pairs, this one has {n}")
        for i, p in enumerate(chain.pairs):
            if p.kind == "general":
                raise ValueError(f"pairs[{i}]: a general A-pair's motion is not rational; inverse kinematics "
                                 "needs sinusoidal A-pairs or R-pairs")
        self.chain = chain
        self.scale = _scale(chain)
        self.seed = seed
        self._eliminations = {}
        self._problem = None  # n = 5, 6: the homotopy.Problem
        self._start = None  # and its StartSystem, loaded when first needed

    def _elimination(self, reverse: bool) -> "_Elimination":
        if reverse not in self._eliminations:
            self._eliminations[reverse] = _Elimination(self.chain, self.scale, reverse, self.seed)
        return self._eliminations[reverse]

    def solve(self, T: np.ndarray, tol: float = 1e-9, count_complex: bool = False) -> Solution:
        if self.chain.n >= 5:
            return self._solve_homotopy(T, tol)
        target = _study(T)
        target[4:] /= self.scale
        Tm = _matrix(T)
        n = self.chain.n
        degenerate = []
        for reverse in (False, True) if n >= 2 else (False,):
            try:
                cands = self._elimination(reverse).candidates(target, count_complex)
            except _Degenerate as exc:
                degenerate.append(str(exc))
                continue
            cands = np.array(cands, complex).reshape(-1, n)
            # points where a joint's rotation part vanishes (u = ±i, isotropic) are not displacements
            cands = cands[np.all(np.abs(1 + cands * cands) > 1e-3 * (1 + np.abs(cands) ** 2), axis=1)]
            count = len(_dedupe_complex(cands)) if count_complex else None
            real = cands[np.all(np.abs(cands.imag) <= CAND_TOL * (1 + np.abs(cands)), axis=1)]
            q = _with_twins(self.chain, self._elimination(reverse).angles(real))
            q, err = _refine(self.chain, q, Tm, tol)
            if len(q) or not _near_reach(self.chain, Tm):
                return Solution(q, err, len(real), count)
        # every elimination degenerated, or found nothing for a pose within reach: local search
        q, err = _refine(self.chain, local_search(self.chain, Tm), Tm, tol)
        if len(q) and _on_continuum(self.chain, q[0], Tm, tol):
            why = f" ({degenerate[0]})" if degenerate else ""
            raise ValueError(f"T: the solutions at this pose are not isolated{why}: they form a curve (e.g. "
                             "two R-pairs on one axis)")
        certified = len(q) == 0 and not degenerate  # the elimination's "none" stands
        return Solution(q, err, 0, None, certified=certified, method="local search")

    def _solve_homotopy(self, T, tol: float) -> Solution:
        """n = 5, 6: R-chains by the 6R elimination (apair.ik6r) where it certifies its 16
        solutions, chains with one A-pair by theirs (apair.ik1a5r, 48); otherwise every start
        solution tracked to T (apair.homotopy). Real solutions verified."""
        from . import homotopy, ik1a5r, ik6r

        Tm = _pose_matrix(T)
        if self._problem is None:
            self._problem = homotopy.Problem.of(self.chain)
        problem = self._problem
        theta = None
        for route in (ik6r, ik1a5r):
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
        q, err = _refine(self.chain, real, Tm, tol)
        return Solution(q, err, len(real), len(theta), certified=complete, method=method)

    def _refuse_continuum(self, problem, ends, Tm: np.ndarray, tol: float) -> None:
        """ValueError where the pose has a curve of real solutions (a wrist singularity: two R-pair
        axes in line). Paths then end at singular points of the curve's complexification, often not
        real ones: the real part of such an endpoint, corrected onto the pose, is a real point of
        the curve, where a step along the Jacobian's null space stays on the pose."""
        from . import homotopy

        singular = ends.theta[ends.singular] if ends.singular is not None else ends.theta[:0]
        if len(singular) == 0:
            return
        q = homotopy.real_angles(problem, singular.real.astype(complex))
        q, _ = _refine(self.chain, local_search(self.chain, Tm, start=q), Tm, tol)
        for k in np.flatnonzero(_rank(self.chain, q) < self.chain.n):
            if _on_continuum(self.chain, q[k], Tm, tol):
                raise ValueError("T: the solutions at this pose are not isolated: they form a curve (e.g. a wrist "
                                 "singularity, two R-pair axes in line)")


class _Elimination:
    """The elimination for one orientation of the chain (forward or reversed, see _chain_joints)."""

    def __init__(self, chain, scale: float, reverse: bool, seed: int):
        n = chain.n
        self.chain, self.scale, self.reverse = chain, scale, reverse
        self.rng = np.random.default_rng(seed)
        deltas = self.rng.uniform(-np.pi, np.pi, n)
        self.joints, self.pre = _chain_joints(chain, scale, deltas, reverse)
        self.theta_map = (np.array([2.0 if j.kind == "revolute" else 4.0 for j in self.joints]),
                          np.array([j.delta for j in self.joints]))
        j1 = self.joints[0]
        if n >= 2:  # Z(u_1) = K_1⁻¹·P̃_1(u_1)·W·K_2⁻¹ = Σ u_1^m Zmap[m] W
            right = _right(self.joints[1].Kinv)
            self.Zmap = np.stack([_left(j1.Kinv) @ _left(c) @ right for c in conjugate(j1.P)])
        if n == 3:
            self.image = conjugate(self.joints[2].A)  # W(u_3) = T·Ã_3(u_3)
        if n == 4:
            j3, j4 = self.joints[2:]
            self.image = conjugate(multiply(j3.A[:, None, :], j4.A[None, :, :]))
        if n >= 3:
            Q, Qx = self._half_quadrics()
            if len(Qx) == 0:
                raise AssertionError("no quadric in x vanishes on the rotations of a two-joint chain")
            self.Q = Q
            self.Qx = np.tensordot(self.rng.standard_normal(len(Qx)), Qx, 1)
            Qx8 = np.zeros((8, 8))
            Qx8[:4, :4] = self.Qx
            combinations = [Qx8] + list(np.tensordot(self.rng.standard_normal((3, len(Q))), Q, 1))
            xy = _without_yy(Q, Qx8)
            self.combinations = np.array(combinations + ([xy] if xy is not None else []))  # (4 or 5, 8, 8)
        if n == 4:  # the factors 1 + u² of the images at a random pose (not on the chain's image)
            x, y = self.rng.standard_normal((2, 4))
            x /= np.linalg.norm(x)
            pose = np.concatenate([x, y - (x @ y) * x])  # on the Study quadric
            images = self._quadric_images(self.image @ _left(pose).T)
            self.factors = [_isotropic_factors(g) for g in images]
            divided = [_divided(g, k) for g, k in zip(images, self.factors)]
            self.shapes = [d.shape for d in divided]
            # per pair, whether g(±i, ·) is a multiple of f(±i, ·), and then g(·, ±i) one of
            # f(·, ±i): the spurious roots at u_3 = ±i and at u_4 = ±i (_deflated), removed where
            # that holds at the pose too
            self.deflatable = {}
            for a, b in self._tries(True):
                f, g = divided[a + 1], divided[b + 1]
                du = _deflated(f, g)
                dv = _deflated(f.T, (g if du is None else du).T)
                self.deflatable[a, b] = (du is not None, dv is not None)

    def _half_quadrics(self):
        """Quadrics through the left half's poses (all, and in x alone) by SVD on sampled points."""
        j1, j2 = self.joints[:2]
        u = np.tan(self.rng.uniform(-np.pi / 2, np.pi / 2, (2, 160)))
        pts = multiply(_eval(j1.A, u[0]), _eval(j2.A, u[1]))
        pts /= np.linalg.norm(pts, axis=1, keepdims=True)
        return _quadric_forms(pts), _quadric_forms(pts[:, :4])

    def candidates(self, target: np.ndarray, count_complex: bool) -> list[np.ndarray]:
        """Complex parameter vectors (in this elimination's joint order) for a unit target."""
        if self.pre is not None:
            target = multiply(self.pre, conjugate(target))
        n = self.chain.n
        return self._solve_left(target, n) if n <= 2 else self._solve_right(target, count_complex)

    def angles(self, real: np.ndarray) -> np.ndarray:
        """Joint angles (k, n) in the chain's order from real parameter vectors (k, n)."""
        if len(real) == 0:
            return np.zeros((0, self.chain.n))
        k, delta = self.theta_map  # θ = k·arctan(u) + δ, k = 2 (R-pair) or 4: _Joint.parameter inverted
        q = _wrap(k * np.arctan(np.real(real)) + delta, np.pi * k)
        return q[:, ::-1] if self.reverse else q

    def _solve_left(self, W: np.ndarray, n: int) -> list[np.ndarray]:
        """Parameters (u_1[, u_2]) with A_1 (A_2) ∝ W, complex; W may be complex."""
        j1 = self.joints[0]
        if n == 1:
            return [np.array([u]) for u in _on_curve(j1, multiply(W, j1.Kinv), self.rng)]
        return self._solve_left_many(W[None])[0]

    def _solve_left_many(self, Ws: np.ndarray) -> list[list[np.ndarray]]:
        """Parameters (u_1, u_2) with A_1 A_2 ∝ W for each row of Ws (R, 8): the usual single
        solution of a real W in C (apair_ik4_left, the first step of _solve_left_general) where
        the kernels are installed, every other row by _solve_left_general."""
        native = _native()
        if native is None or len(Ws) == 0 or np.iscomplexobj(Ws):
            return self._solve_left_general(Ws)
        j2 = self.joints[1]
        joint = np.array([j2.kind == "revolute", j2.delta, j2.offset, j2.sign], float)
        status, u1, u2, ok = native.ik4_left(Ws, self.Zmap, j2.P, joint, LEFT_TOL)
        out = [[np.array([x, y]) for y, good in zip(ys, oks) if good] for x, ys, oks in zip(u1, u2, ok)]
        rest = np.flatnonzero(status == 1)  # 2: no root u_1 at all
        for r, sols in zip(rest, self._solve_left_general(Ws[rest])):
            out[r] = sols
        return out

    def _solve_left_general(self, Ws: np.ndarray) -> list[list[np.ndarray]]:
        """Parameters (u_1, u_2) with A_1 A_2 ∝ W for each row of Ws (R, 8), complex: the common
        roots of all rows at once."""
        if len(Ws) == 0:
            return []
        Zc = np.einsum("mab,rb->rma", self.Zmap, Ws)  # (R, D1+1, 8)
        outside = Zc[:, :, OUTSIDE]
        coaxial = np.abs(outside).max(axis=(1, 2)) <= 1e-10 * np.abs(Zc).max(axis=(1, 2))
        out: list = [self._solve_coaxial(Zc[r]) if coaxial[r] else [] for r in range(len(Ws))]
        rows = np.flatnonzero(~coaxial)
        # the usual case, one (u_1, u_2) per W, from two null vectors; the rest by eigenvalues
        polys = np.swapaxes(outside[rows], 1, 2)  # (R, 4, D1+1)
        u1, one = _unique_roots(_shifted(polys, polys.shape[2] - 2))  # as apair_ik4_left does
        if not np.iscomplexobj(Ws):
            Z = np.einsum("km,kma->ka", u1[:, None] ** np.arange(Zc.shape[1]), Zc[rows])
            u2 = self.joints[1].parameters_of(Z)  # (R, 1 or 2), each tested
            ok = np.stack([_relres_many(np.swapaxes(_minors(self.joints[1].P, Z), 1, 2), u2[:, j]) <= ROOT_RTOL
                           for j in range(u2.shape[1])], 1)
            one &= ok.any(axis=1)
            for r, x, ys, oks in zip(rows[one], u1[one], u2[one], ok[one]):
                out[r] = [np.array([x, y]) for y, good in zip(ys, oks) if good]
        else:
            one[:] = False
        rows = rows[~one]
        u1s = _common_roots_many(np.swapaxes(outside[rows], 1, 2), self.rng)
        if any(u is None for u in u1s):
            raise _Degenerate("every polynomial vanishes identically")
        owner = np.concatenate([np.full(len(u), r) for r, u in zip(rows, u1s)] + [np.zeros(0, int)]).astype(int)
        u1 = np.concatenate(list(u1s) + [np.zeros(0, complex)])
        if len(u1) == 0:
            return out
        Z = np.einsum("km,kma->ka", u1[:, None] ** np.arange(Zc.shape[1]), Zc[owner])  # (K, 8)
        u2s = _common_roots_many(np.swapaxes(_minors(self.joints[1].P, Z), 1, 2), self.rng)
        if any(u is None for u in u2s):
            raise _Degenerate("every polynomial vanishes identically")
        for r, x, u2 in zip(owner, u1, u2s):
            out[r] += [np.array([x, y]) for y in u2]
        return out

    def _solve_coaxial(self, Zc: np.ndarray) -> list[np.ndarray]:
        """Joints 1 and 2 on one axis (a_1 = 0, α_1 = 0): Z(u_1) lies in the pair subalgebra for
        every u_1, so u_1 and u_2 come together from Z(u_1) ∝ P_2(u_2): the 2×2 minors of the
        subalgebra components are bivariate; two random combinations are eliminated (hidden
        variable u_1), and each u_1 gets the common roots u_2 of all minors. Two R-pairs on one
        axis have a curve of solutions (the resultant vanishes identically): _Degenerate."""
        P2 = self.joints[1].P
        a, b = np.array([(a, b) for i, a in enumerate(INSIDE) for b in INSIDE[i + 1:]]).T
        minors = (Zc[:, None, a] * P2[None, :, b] - Zc[:, None, b] * P2[None, :, a]).transpose(2, 0, 1)
        f, g = (np.tensordot(self.rng.standard_normal(len(minors)), minors, 1) for _ in range(2))
        out = []
        for u1 in _hidden_variable(f, g, self.rng):
            row = np.einsum("kij,i->kj", minors, u1 ** np.arange(len(Zc)))
            try:
                out += [np.array([u1, u2]) for u2 in _common_roots(row, self.rng)]
            except _Degenerate:
                continue
        return out

    def _quadric_images(self, C: np.ndarray, factors=None) -> list[np.ndarray]:
        """Coefficients (u_3^i u_4^j) of Q(W(u_3, u_4)) for the rotation quadric Qx (first: f), three
        random combinations Q of the left half's quadrics and the one without a yy block (last,
        where there is one), from one FFT of W, each divided by
        the factors 1 + u² it has at every pose (`factors`, found once per design: f has two of
        each at least, since W's rotation part carries (1 + u_3²)(1 + u_4²))."""
        s = (2 * C.shape[0] - 1, 2 * C.shape[1] - 1)
        F = np.fft.fft2(C, s=s, axes=(0, 1)).reshape(-1, 8)
        values = np.einsum("qpb,pb->qp", F @ self.combinations, F)  # (q, s0·s1)
        images = np.real(np.fft.ifft2(values.reshape((-1,) + s), axes=(-2, -1)))
        if factors is None:
            return images
        return [_divided(g, k) for g, k in zip(images, factors)]

    def _resultant_roots(self, C: np.ndarray):
        """Every u_3 at which two conditions on W(u_3, u_4) have a common root u_4: the rotation
        condition f (bidegree (4, 4)) with a combination g of the quadrics (the one without a yy
        block first: bidegree (6, 6), 48 roots, 32 once deflated, `_deflated`), else (where f
        vanishes on the whole image, or f and g share a curve, as special designs make them) other
        combinations, until the
        resultant is not identically zero; where every pair shares a curve, the regular part of
        the first pair's pencil. The pair with the fewest roots is tried first (special designs
        give the images more factors 1 + u²: two parallel axes halve their bidegrees). Returns
        the roots and the pair eliminated (None for a singular pencil's regular part)."""
        native = _native()
        # the first pair that the loop below would not skip for a row constant in u_3, in C
        a, b = next((ab for ab in self._tries(True) if min(self.shapes[ab[0] + 1][0], self.shapes[ab[1] + 1][0]) >= 2),
                    (0, 0))
        if native is not None and a < b and not np.iscomplexobj(C):
            du, dv = self.deflatable[a, b]
            out = native.ik4_pencil(C, self.combinations[a + 1], self._factor_array(a + 1), self.combinations[b + 1],
                                    self._factor_array(b + 1), LEAD_COND, int(du) + 2 * int(dv), DEFLATE_TOL)
            if out is not None:
                f, g, M = out
                return _eigenvalues(M), (f, g)
        f, *g = self._quadric_images(C, self.factors)

        def poly(k: int) -> np.ndarray:  # −1: f; 0, 1, 2: random combinations; 3: without yy
            return f if k < 0 else g[k]

        tries = self._tries(np.abs(f).max() > 1e-12 * np.abs(C).max() ** 2 * np.abs(self.Qx).max())
        for a, b in tries:
            pa, pb = poly(a), poly(b)
            du, dv = self.deflatable[a, b]
            deflated = _deflated(pa, pb) if du else None
            pb = pb if deflated is None else deflated
            deflated = _deflated(pa.T, pb.T) if dv else None
            pb = pb if deflated is None else deflated.T
            try:
                return _hidden_variable(pa, pb, self.rng, singular_ok=False), (pa, pb)
            except _Degenerate:
                continue
        # every pair shares a curve
        return _hidden_variable(poly(tries[0][0]), poly(tries[0][1]), self.rng), None

    def _tries(self, with_f: bool) -> list[tuple[int, int]]:
        """The pairs of images to eliminate (−1: f; k ≥ 0: the k-th other), fewest roots first."""
        tries = [(0, 1), (1, 2)]
        if with_f:
            tries = [(-1, k) for k in range(len(self.combinations) - 1)] + tries
        return sorted(tries, key=lambda ab: _bezout_of(self.shapes[ab[0] + 1], self.shapes[ab[1] + 1]))

    def _factor_array(self, k: int) -> np.ndarray:
        return np.array(self.factors[k], np.int32)

    def _screen(self, u3s: np.ndarray, pair, C: np.ndarray):
        """The real u_3 sorted by two steps of inverse iteration: the Sylvester matrix of the
        eliminated pair `pair` is singular at each u_3, and where its null vector comes out as
        (1, u_4, u_4², …) (one common root u_4), the left half's quadrics on W(u_3, u_4) accept the
        pair (relative residual ≤ 1e-8) or reject u_3 (> 1e-6: most of the resultant's roots are
        not common roots of the other quadrics). Where the null space is two-dimensional, each of
        its two roots u_4 is polished by Newton and tested alike. Returns the accepted pairs (r, 2),
        their images (r, 8), and the u_3 left undecided (a residual in between, or a null space
        that says neither) for _right_pairs."""
        none = np.zeros((0, 2)), np.zeros((0, 8)), u3s
        if pair is None or len(u3s) == 0 or np.iscomplexobj(C) or np.iscomplexobj(pair[0]):
            return none
        vand_tol, accept_tol, reject_tol = SCREEN_TOL
        native = _native()
        if native is not None:  # in C (apair_ik4_screen), the same steps
            N = pair[0].shape[1] + pair[1].shape[1] - 2
            status, u4, W, rel, two, two_ok, W2, rel2 = native.ik4_screen(u3s, C, pair[0], pair[1], self.Q,
                                                                           _PROBE[:N], _SCREEN_TOL)
            vandermonde = status <= 2
            rows = np.flatnonzero(~vandermonde)
            known, real = status[rows] == 3, two_ok[rows].astype(bool)
            a, b, W2, rel2 = two[rows, :, 0], two[rows, :, 1], W2[rows], rel2[rows]
        else:
            x = _null_vectors(_sylvester_at(*pair, u3s))
            solved = np.isfinite(x).all(axis=1)
            u4 = np.sum(x[:, :-1] * x[:, 1:], axis=1) / np.maximum(np.sum(x[:, :-1] ** 2, axis=1), 1e-300)
            vandermonde = solved & (np.linalg.norm(x[:, 1:] - u4[:, None] * x[:, :-1], axis=1) <= vand_tol)
            u4 = np.where(solved, u4, 0.0)
            W, rel = self._on_quadrics(u3s, u4, C)
            rows = np.flatnonzero(~vandermonde)
            # two roots u_4: each real one polished on the eliminated pair
            v = _two_roots(_sylvester_at(*pair, u3s[rows]))
            known = np.isfinite(v).all(axis=1)
            real = known[:, None] & (np.abs(v.imag) <= 1e-2 * (1 + np.abs(v)))
            a, b = np.zeros(real.shape), np.zeros(real.shape)
            a[real], b[real] = _polished(*pair, np.repeat(u3s[rows], 2)[real.ravel()], v.real[real])
            W2, rel2 = np.zeros(real.shape + (8,)), np.zeros(real.shape)
            W2[real], rel2[real] = self._on_quadrics(a[real], b[real], C)
        accept, reject = vandermonde & (rel <= accept_tol), vandermonde & ~(rel <= reject_tol)
        pairs, images = np.stack([u3s[accept], u4[accept]], 1), W[accept]
        if len(rows) == 0:
            return pairs, images, u3s[~(accept | reject)]
        # a u_3 with two roots is decided where both real ones are (complex ones are no solutions);
        # a null space that says neither leaves it undecided
        good, bad = real & (rel2 <= accept_tol), real & ~(rel2 <= reject_tol)
        undecided = ~known | np.any(real & ~(good | bad), axis=1)
        reject[rows[~undecided]] = True
        pairs = np.concatenate([pairs, np.stack([a[good], b[good]], 1)])
        images = np.concatenate([images, W2[good]])
        return pairs, images, u3s[~(accept | reject)]

    def _on_quadrics(self, u3: np.ndarray, u4: np.ndarray, C: np.ndarray):
        """The images W(u_3, u_4) (r, 8) and the left half's largest quadric on each, relative to |W|²."""
        W = np.einsum("ri,ija->rja", u3[:, None] ** np.arange(C.shape[0]), C)
        W = np.einsum("rj,rja->ra", u4[:, None] ** np.arange(C.shape[1]), W)
        rel = np.abs(np.einsum("ra,kab,rb->rk", W, self.Q, W)).max(axis=1) / np.maximum(np.sum(W * W, axis=1), 1e-300)
        return W, rel

    def _right_pairs(self, u3s: np.ndarray, C: np.ndarray, real: bool):
        """For each u_3, the u_4 where every quadric of the left half vanishes on W(u_3, u_4) (their
        common roots: complete even where f or g alone vanishes for all u_4 at that u_3); the
        pairs (r, 2) and their images W (r, 8). A u_3 at which all of them vanish for every u_4
        (a curve of candidates, never a solution of a full-rank pose) is skipped."""
        if len(u3s) == 0:
            return np.zeros((0, 2)), np.zeros((0, 8))
        Cu = np.einsum("ri,ija->rja", u3s[:, None] ** np.arange(C.shape[0]), C)  # (R, D4+1, 8)
        outer = (Cu[:, None] @ self.Q) @ np.swapaxes(Cu, 1, 2)[:, None]  # (R, k, D4+1, D4+1)
        D = Cu.shape[1]
        polys = outer.reshape(outer.shape[:2] + (D * D,)) @ _product_map(D, D)
        owner, u4 = [np.zeros(0, int)], [np.zeros(0, complex if not real else float)]
        for r, u4s in enumerate(_common_roots_many(polys, self.rng)):
            if u4s is None:  # every quadric vanishes for all u4 at this u3
                continue
            if real:
                u4s = u4s[np.abs(u4s.imag) <= CAND_TOL * (1 + np.abs(u4s))].real
            owner.append(np.full(len(u4s), r))
            u4.append(u4s)
        owner, u4 = np.concatenate(owner), np.concatenate(u4)
        if len(u4) == 0:
            return np.zeros((0, 2)), np.zeros((0, 8))
        images = np.einsum("kj,kja->ka", u4[:, None] ** np.arange(D), Cu[owner])
        return np.stack([u3s[owner], u4], 1), images

    def _solve_right(self, T: np.ndarray, count_complex: bool) -> list[np.ndarray]:
        """Candidates for 3 and 4 joints: the right part's parameters from the left half's quadrics
        on the image W = T·(A_3 A_4)~, then the left half for each W."""
        LT = _left(T)
        C = self.image @ LT.T
        if self.chain.n == 3:
            G = np.einsum("ma,qab,kb->qmk", C, self.Q, C)
            G = G.reshape(len(G), -1) @ _product_map(*G.shape[1:])
            rights = [np.array([u3]) for u3 in _common_roots(G, self.rng)]
            images = [(r[0] ** np.arange(len(C))) @ C for r in rights]
        else:
            u3s, pair = self._resultant_roots(C)
            if count_complex:
                rights, images = self._right_pairs(_with_means(u3s), C, real=False)
            else:
                # a mean within CAND_TOL of the real axis has both roots within 2·CAND_TOL of it
                u3s = _with_means(u3s[np.abs(u3s.imag) <= 2 * CAND_TOL * (1 + np.abs(u3s))])
                u3s = u3s[np.abs(u3s.imag) <= CAND_TOL * (1 + np.abs(u3s))].real
                rights, images, rest = self._screen(u3s, pair, C)
                if len(rest):
                    more, more_images = self._right_pairs(rest, C, real=True)
                    rights, images = np.concatenate([rights, more]), np.concatenate([images, more_images])
            rights, images = _with_cluster_means(rights, images, C)
        out = []
        for right, lefts in zip(rights, self._solve_left_many(np.asarray(images).reshape(-1, 8))):
            out += [np.concatenate([left, right]) for left in lefts]
        return out


# ----------------------------------------------------------------------------- helpers
def _close_pairs(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices i < j of the rows of x (r, m) that agree to CAND_TOL in every entry."""
    close = np.all(np.abs(x[:, None] - x[None]) <= CAND_TOL * (1 + np.abs(x[:, None])), axis=-1)
    return np.nonzero(np.triu(close, 1))


def _with_means(u: np.ndarray) -> np.ndarray:
    """The roots u (r,) and the mean of every two that agree to CAND_TOL: a double root comes out
    as two simple roots (or a complex pair) about √ε apart, too inaccurate for what is solved from
    it, while their mean is accurate to about ε (the sum of roots is a smooth function of the
    coefficients). At a pose where the left half's surface crosses itself (an A-pair at ±π) the
    resultant has such a double root. The roots themselves are kept, and means at the isotropic
    points u = ±i (never a displacement) are not added."""
    i, j = _close_pairs(u[:, None])
    means = (u[i] + u[j]) / 2
    means = means[np.abs(1 + means * means) > 1e-3 * (1 + np.abs(means) ** 2)]
    return np.concatenate([u, means]) if len(means) else u


def _with_cluster_means(pairs: np.ndarray, images: np.ndarray, C: np.ndarray):
    """The pairs (u_3, u_4) and their images, plus the mean of every two pairs that agree to
    CAND_TOL: a double root (special poses square the resultant) comes out as two simple roots
    about √ε apart, too inaccurate for the left half, while their mean is accurate to about ε.
    Candidates are kept as they are, so two close genuine solutions are not merged (verification
    and deduplication decide)."""
    if len(pairs) < 2:
        return pairs, images
    i, j = _close_pairs(pairs)
    if len(i) == 0:
        return pairs, images
    means = (pairs[i] + pairs[j]) / 2
    Cu = np.einsum("ri,ija->rja", means[:, 0:1] ** np.arange(C.shape[0]), C)
    extra = np.einsum("rj,rja->ra", means[:, 1:2] ** np.arange(C.shape[1]), Cu)
    return np.concatenate([pairs, means]), np.concatenate([images, extra])


_EYE8 = np.eye(8)
_LEFT = np.stack([multiply(e, _EYE8).T for e in _EYE8])  # _LEFT[a] @ v = e_a·v
_RIGHT = np.stack([multiply(_EYE8, e).T for e in _EYE8])  # _RIGHT[a] @ v = v·e_a


_LEFT_ROWS = _LEFT.reshape(8, 64)


def _left(p: np.ndarray) -> np.ndarray:
    """The 8×8 matrix of v ↦ p·v (Study product)."""
    p = np.asarray(p)
    return (p @ _LEFT_ROWS).reshape(p.shape[:-1] + (8, 8))


def _right(p: np.ndarray) -> np.ndarray:
    """The 8×8 matrix of v ↦ v·p."""
    return np.tensordot(p, _RIGHT, 1)


_PAIRS = np.triu_indices(8, 1)


def _on_curve(j: _Joint, Z: np.ndarray, rng) -> np.ndarray:
    """Parameters u with P_j(u) ∝ Z: common roots of the 2×2 minors P_a Z_b − P_b Z_a."""
    return _common_roots(_minors(j.P, Z).T, rng)


def _minors(P: np.ndarray, Z: np.ndarray) -> np.ndarray:
    """The 2×2 minors P_a(u) Z_b − P_b(u) Z_a (..., D+1, 28) of a curve P (D+1, 8) and points Z (..., 8)."""
    a, b = _PAIRS
    return P[:, a] * Z[..., None, b] - P[:, b] * Z[..., None, a]


def _eval(coeffs: np.ndarray, u: np.ndarray) -> np.ndarray:
    return np.einsum("m...,rm->r...", coeffs, np.asarray(u)[:, None] ** np.arange(len(coeffs)))


def _without_yy(Q: np.ndarray, Qx8: np.ndarray) -> np.ndarray | None:
    """A quadric of the span of Q (k, 8, 8) without a yy block, orthogonal (Frobenius) to the
    rotation quadric Qx8 and to the Study quadric x·y (both are in that subspace: the Study
    quadric vanishes on every image, and a large Qx part would make its image nearly a
    multiple of f, the resultant's roots inaccurate); None where there is no such quadric.
    Its image carries the factor (1 + u_3²)(1 + u_4²), so it has bidegree (6, 6), not (8, 8),
    and its resultant with f has 48 roots, not 64."""
    _, sv, Vt = np.linalg.svd(Q[:, 4:, 4:].reshape(len(Q), -1).T)
    sv = np.concatenate([sv, np.zeros(len(Q) - len(sv))])
    null = Vt[sv <= 1e-10 * max(sv[0], 1e-300)]
    if len(null) == 0:
        return None
    basis = np.tensordot(null, Q, 1).reshape(len(null), -1).T  # (64, m)
    study = np.zeros((8, 8))
    study[:4, 4:] = study[4:, :4] = np.eye(4)
    known = np.stack([Qx8.ravel(), study.ravel()], 1)
    _, sv, Vt = np.linalg.svd(known.T @ basis)
    sv = np.concatenate([sv, np.zeros(basis.shape[1] - len(sv))])
    if sv[-1] > 1e-8 * max(sv[0], 1e-300):  # every combination has a Qx or Study part
        return None
    xy = (basis @ Vt[-1]).reshape(8, 8)
    return xy / np.linalg.norm(xy)


def _quadric_forms(pts: np.ndarray) -> np.ndarray:
    """Symmetric matrices (k, d, d) of the quadratic forms vanishing on the points (N, d)."""
    d = pts.shape[1]
    i, j = np.triu_indices(d)
    A = pts[:, i] * pts[:, j]
    _, s, Vt = np.linalg.svd(A)
    s = np.concatenate([s, np.zeros(Vt.shape[0] - len(s))])
    null = Vt[s <= 1e-10 * s[0]]
    Q = np.zeros((len(null), d, d))
    Q[:, i, j] = null
    return (Q + np.swapaxes(Q, 1, 2)) / 2


def _isotropic_factors(p: np.ndarray) -> tuple[int, int]:
    """How often a real bivariate polynomial (coefficients [i, j] of u^i v^j) has the factors
    1 + u² and 1 + v²: they vanish at the isotropic parameters ±i (never a displacement), and
    where the quadrics of a special design (parallel axes) all have them they are common roots
    for every v, which makes the resultant vanish identically."""
    counts = []
    for axis in (0, 1):
        q, m = np.moveaxis(p, axis, 0), 0
        while q.shape[0] > 2:
            quot = _isotropic_division(q.shape[0] - 1, 1) @ q.reshape(q.shape[0], -1)
            rem = q.reshape(q.shape[0], -1) - _isotropic_product(quot.shape[0] - 1) @ quot
            if not np.abs(rem).max() <= 1e-11 * np.abs(q).max():
                break
            q, m = quot.reshape((-1,) + q.shape[1:]), m + 1
        counts.append(m)
    return counts[0], counts[1]


def _divided(p: np.ndarray, factors: tuple[int, int]) -> np.ndarray:
    """p (as in _isotropic_factors) divided by (1 + u²)^a (1 + v²)^b, factors = (a, b)."""
    a, b = factors
    return _isotropic_division(p.shape[0] - 1, a) @ p @ _isotropic_division(p.shape[1] - 1, b).T


@lru_cache(maxsize=None)
def _isotropic_division(d: int, m: int) -> np.ndarray:
    """The matrix ((d − 2m + 1) × (d + 1)) of p ↦ the quotient of p (degree d) by (1 + u²)^m: the
    recurrence quot_k = p_k − quot_{k−2}, m times."""
    M = np.eye(d + 1)
    for _ in range(m):
        div = np.zeros((M.shape[0] - 2, M.shape[0]))
        for k in range(M.shape[0] - 2):
            div[k, k::-2] = (-1.0) ** np.arange(k // 2 + 1)
        M = div @ M
    return M


@lru_cache(maxsize=None)
def _isotropic_product(d: int) -> np.ndarray:
    """The matrix ((d + 3) × (d + 1)) of q ↦ (1 + u²)·q for q of degree d."""
    return np.eye(d + 3, d + 1) + np.eye(d + 3, d + 1, -2)


def _deflated(f: np.ndarray, g: np.ndarray, tol: float = None) -> np.ndarray | None:
    """g'' = (g − a·f) / (1 + u²) for bivariate f, g (coefficients [i, j] of u^i v^j, g's degree in v
    at least f's), where g(±i, v) = f(±i, v)·h(v) (to relative residual tol): a(u, v) = Re h(v) +
    u Im h(v), so g − a·f vanishes at u = ±i. f and g'' have the common roots of f and g except
    at u = ±i (never a displacement), and their resultant the degree of theirs less 2·deg_v f:
    the images' pair (f, the quadric without yy) has 8 spurious roots at u_3 = ±i, 48 → 40, and,
    transposed, 8 more where u_4 = ±i, 40 → 32. None where g(±i, ·) is no such multiple (or
    f(±i, ·) vanishes). In C, apair_ik4_pencil does the same."""
    tol = DEFLATE_TOL if tol is None else tol
    df, dg = f.shape[1] - 1, g.shape[1] - 1
    if dg < df or f.shape[0] < 1:
        return None
    fi = (1j ** np.arange(f.shape[0])) @ f
    gi = (1j ** np.arange(g.shape[0])) @ g
    k = dg - df
    A = np.zeros((dg + 1, k + 1), complex)  # g(i, ·) = f(i, ·)·h: convolution by f(i, ·)
    for j in range(k + 1):
        A[j: j + df + 1, j] = fi
    if not (np.abs(fi).max() > 0 and np.abs(gi).max() > 0):
        return None
    h = np.linalg.lstsq(A, gi, rcond=None)[0]
    if not np.abs(A @ h - gi).max() <= tol * np.abs(gi).max():
        return None
    rows = max(g.shape[0], f.shape[0] + 1)
    if rows < 4:  # the quotient would be constant in u
        return None
    out = np.zeros((rows, dg + 1))
    out[:g.shape[0]] = g
    for i, part in enumerate((h.real, h.imag)):  # − a·f, a = Re h + u Im h
        for j, c in enumerate(part):
            out[i: i + f.shape[0], j: j + df + 1] -= c * f
    return _isotropic_division(rows - 1, 1) @ out


def _bezout_of(f: tuple, g: tuple) -> int:
    """The number of common zeros in P¹ × P¹ of two bivariate polynomials of coefficient shapes
    f and g (their bidegrees plus one)."""
    return (f[0] - 1) * (g[1] - 1) + (f[1] - 1) * (g[0] - 1)


@lru_cache(maxsize=None)
def _product_map(m: int, k: int) -> np.ndarray:
    """(m·k, m + k − 1): the coefficients of a product of two polynomials from their outer
    product (m, k), flattened."""
    i, j = np.divmod(np.arange(m * k), k)
    out = np.zeros((m * k, m + k - 1))
    out[np.arange(m * k), i + j] = 1.0
    return out


def _sylvester_at(f: np.ndarray, g: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(R, N, N), N = f's plus g's degree in v: the Sylvester matrices in v of f(u, v) and g(u, v)
    at each u (R,) (coefficients [i, j] of u^i v^j), rows v^r f then v^r g."""
    fu = (u[:, None] ** np.arange(f.shape[0])) @ f
    gu = (u[:, None] ** np.arange(g.shape[0])) @ g
    df, dg = f.shape[1] - 1, g.shape[1] - 1
    S = np.zeros((len(u), df + dg, df + dg), fu.dtype)
    for r in range(dg):
        S[:, r, r: r + df + 1] = fu
    for r in range(df):
        S[:, dg + r, r: r + dg + 1] = gu
    return S


_PROBE = np.random.default_rng(SEED).standard_normal(64)  # right-hand side of the inverse iterations


def _null_vectors(S: np.ndarray) -> np.ndarray:
    """(R, N): unit null vectors of the singular matrices S (R, N, N) by two steps of inverse
    iteration from a fixed vector; NaN rows where LU meets an exact zero pivot."""
    x = np.broadcast_to(_PROBE[:S.shape[1], None], (len(S), S.shape[1], 1))
    try:
        for _ in range(2):
            x = np.linalg.solve(S, x)
            x = x / np.linalg.norm(x, axis=1, keepdims=True)
        return x[:, :, 0]
    except np.linalg.LinAlgError:  # one by one, to find the matrix that is singular to rounding
        if len(S) == 1:
            return np.full((1, S.shape[1]), np.nan)
        return np.concatenate([_null_vectors(s[None]) for s in S])


def _two_roots(S: np.ndarray) -> np.ndarray:
    """(R, 2) for real Sylvester matrices S (R, N, N): where the null space is two-dimensional,
    the two common roots v (the eigenvalues of the shift X with N[1:] = N[:-1]·X on a null basis
    N), else NaN. At a real u_3 of a sinusoidal A-pair these are often v and about −1/v (the
    joint's angles θ and θ + 2π share the rotation), and u_3 a near-double eigenvalue accurate to
    about 1e-8: the null space is two-dimensional to about that, and the roots need polishing."""
    out = np.full((len(S), 2), np.nan, complex)
    if len(S) == 0:
        return out
    _, sv, Vt = np.linalg.svd(S)
    two = (sv[:, -2] <= 1e-5 * sv[:, 0]) & (sv[:, -3] > 1e3 * sv[:, -2])
    if not two.any():
        return out
    N = np.swapaxes(Vt[two, -2:], 1, 2)  # (r, N, 2)
    X = np.linalg.pinv(N[:, :-1]) @ N[:, 1:]
    shifted = np.linalg.norm(N[:, :-1] @ X - N[:, 1:], axis=(1, 2)) <= 1e-4
    out[np.flatnonzero(two)[shifted]] = np.linalg.eigvals(X[shifted])
    return out


def _polished(f: np.ndarray, g: np.ndarray, u: np.ndarray, v: np.ndarray, steps: int = 3):
    """(u, v) after Newton steps on f(u, v) = g(u, v) = 0 (coefficients [i, j] of u^i v^j), real."""
    i, j = np.arange(f.shape[0]), np.arange(f.shape[1])
    k, m = np.arange(g.shape[0]), np.arange(g.shape[1])
    for _ in range(steps):
        def at(P, a, b):  # value, ∂u, ∂v
            pa, pb = u[:, None] ** a, v[:, None] ** b
            da = a * np.concatenate([np.zeros((len(u), 1)), pa[:, :-1]], 1)
            db = b * np.concatenate([np.zeros((len(v), 1)), pb[:, :-1]], 1)
            return (np.einsum("ra,ab,rb->r", pa, P, pb), np.einsum("ra,ab,rb->r", da, P, pb),
                    np.einsum("ra,ab,rb->r", pa, P, db))
        F, Fu, Fv = at(f, i, j)
        G, Gu, Gv = at(g, k, m)
        det = Fu * Gv - Fv * Gu
        det = np.where(det == 0, np.inf, det)
        u, v = u - (F * Gv - Fv * G) / det, v - (Fu * G - F * Gu) / det
    return u, v


@lru_cache(maxsize=None)
def _linearisation(degs: tuple):
    """Index structure of the row linearisation for row degrees `degs`: the shift equations
    z_{i,k+1} = u z_{i,k} (rows, columns of z_{i,k}) and each row's block (offset, degree)."""
    offs = np.concatenate([[0], np.cumsum(degs)])
    cols = np.concatenate([offs[i] + np.arange(d - 1) for i, d in enumerate(degs)]).astype(int)
    return np.arange(len(cols)), cols, [(int(offs[i]), d) for i, d in enumerate(degs)]


def _hidden_variable(f: np.ndarray, g: np.ndarray, rng, singular_ok: bool = True) -> np.ndarray:
    """All u with f(u, v) = g(u, v) = 0 for some v (coefficients [i, j] of u^i v^j): the zeros of
    the Sylvester matrix in v, a matrix polynomial in u whose rows have the degrees of f and g,
    linearised by rows (size Σ row degrees = the resultant's degree bound). Where the pencil is
    singular (f and g share a curve) its regular part's eigenvalues are returned, or, with
    singular_ok=False, _Degenerate is raised."""
    df, dg = f.shape[1] - 1, g.shape[1] - 1
    N = df + dg
    dtype = np.result_type(f, g, float)  # complex where the pose's image is complex
    rows = []  # (coefficients in u (d+1, N)) per row
    for r in range(dg):
        row = np.zeros((f.shape[0], N), dtype)
        row[:, r: r + df + 1] = f
        rows.append(row)
    for r in range(df):
        row = np.zeros((g.shape[0], N), dtype)
        row[:, r: r + dg + 1] = g
        rows.append(row)
    degs = tuple(len(r) - 1 for r in rows)
    if min(degs) < 1:
        raise _Degenerate("a Sylvester row is constant in the hidden variable")
    shift_rows, shift_cols, blocks = _linearisation(degs)
    size = sum(degs)
    A = np.zeros((size, size), dtype)
    B = np.zeros((size, size), dtype)
    A[shift_rows, shift_cols + 1] = 1.0
    B[shift_rows, shift_cols] = 1.0
    for (lo, d), row in zip(blocks, rows):  # the last N rows: Σ_i row_i(u)ᵀ w_i = 0
        A[size - N:, lo: lo + d] = -row[:d].T
        B[size - N:, lo + d - 1] = row[d]
    lead_cols = [lo + d - 1 for lo, d in blocks]
    lead = B[size - N:, lead_cols]  # B is I plus this block, permuted
    if np.linalg.cond(lead, 1) < LEAD_COND:  # then the pencil is regular (det has its full degree)
        M = np.zeros((size, size), dtype)  # B⁻¹A: the shift rows as they are, lead⁻¹ times the last N rows
        M[shift_cols, shift_cols + 1] = 1.0
        M[lead_cols] = np.linalg.solve(lead, A[size - N:])
        return _eigenvalues(M)
    z = np.exp(2j * np.pi * rng.random())  # a random point on the unit circle
    sv = np.linalg.svd(np.stack([z ** np.arange(len(r)) @ r for r in rows]), compute_uv=False)
    deficit = int(np.count_nonzero(sv <= 1e-11 * sv[0]))
    if deficit:  # f and g share a curve: the resultant vanishes identically
        if not singular_ok:
            raise _Degenerate("f and g have a common factor")
        return _regular_eigenvalues(A, B, deficit, rng)
    w = scipy.linalg.eigvals(A, B)
    return w[np.isfinite(w)]


def _eigenvalues(M: np.ndarray) -> np.ndarray:
    """The eigenvalues of a square matrix (real: LAPACK's dgeev directly, NumPy's wrapper costs more)."""
    if np.iscomplexobj(M):
        return np.linalg.eigvals(M)
    wr, wi, _, _, info = lapack.dgeev(M, compute_vl=0, compute_vr=0)
    return wr + 1j * wi if info == 0 else np.linalg.eigvals(M)


def _regular_eigenvalues(A: np.ndarray, B: np.ndarray, k: int, rng, tol: float = 1e-5) -> np.ndarray:
    """The finite eigenvalues of the regular part of a singular pencil A − λB of normal rank
    size − k (where the rank drops below that: here, the u_3 with a common root besides the
    shared curve), by a random rank-k completion (Hochstenbach, Mehl and Plestenjak, SIMAX 2019):
    the pencil A + U Dₐ V*, B + U D_b V* is regular; its eigenvalues of the true part keep
    right eigenvectors x with V*x = 0 and left ones y with U*y = 0, the others are random."""
    size = len(A)

    def crandn(*shape):  # real where the pencil is: the same test, in real arithmetic
        if np.iscomplexobj(A):
            return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
        return rng.standard_normal(shape)

    U, Vh = crandn(size, k), crandn(k, size)
    At = A + U @ np.diag(crandn(k)) @ Vh
    Bt = B + U @ np.diag(crandn(k)) @ Vh
    if np.linalg.cond(Bt) < 1e10:  # the standard problem: right eigenvectors, left ones from X⁻¹
        w, vr = np.linalg.eig(np.linalg.solve(Bt, At))
        vl = (np.linalg.inv(vr) @ np.linalg.inv(Bt)).conj().T
    else:
        w, vl, vr = scipy.linalg.eig(At, Bt, left=True, right=True)
    right = np.linalg.norm(Vh @ vr, axis=0) / (np.linalg.norm(Vh) * np.linalg.norm(vr, axis=0))
    left = np.linalg.norm(U.conj().T @ vl, axis=0) / (np.linalg.norm(U) * np.linalg.norm(vl, axis=0))
    return w[np.isfinite(w) & (right <= tol) & (left <= tol)]


def _dedupe_complex(cands, tol: float = 1e-6) -> list:
    out = []
    for c in cands:
        if not any(np.max(np.abs(c - o) / (1 + np.abs(o))) < tol for o in out):
            out.append(c)
    return out


def _study(T) -> np.ndarray:
    """A pose given as a 4×4 matrix or a Study point (8,), validated → a unit Study point."""
    T = V.real_array("T", T)
    if T.shape == (4, 4):
        return from_matrix(_check_matrix(T))
    if T.shape == (8,):
        x, y = T[:4], T[4:]
        nx = np.linalg.norm(x)
        if nx == 0:
            raise ValueError("T: a Study point with x = 0 lies in the exceptional 3-space, not a pose")
        if abs(x @ y) > 1e-9 * nx * max(np.linalg.norm(y), nx):
            raise ValueError(f"T: not on the Study quadric (x·y = {x @ y:.3g})")
        return normalise(T)
    raise ValueError(f"T: expected a 4x4 transform or an 8-vector Study point, got shape {T.shape}")


def _pose_matrix(T) -> np.ndarray:
    """A pose given as a 4×4 matrix (kept as given) or a Study point (8,), validated → 4×4."""
    A = V.real_array("T", T)
    return _check_matrix(A) if A.shape == (4, 4) else _matrix(_study(A))


_LAST_ROW, _EYE3 = np.array([0.0, 0, 0, 1]), np.eye(3)
_LAST_TOL = 1e-12 + 1e-5 * _LAST_ROW


def _check_matrix(T: np.ndarray) -> np.ndarray:
    """T (4, 4) or a stack (..., 4, 4) of rigid transforms, checked at once: last row [0, 0, 0, 1],
    rotation part orthonormal with det +1."""
    rows = T[..., 3, :].reshape(-1, 4)
    good = np.abs(rows - _LAST_ROW) <= _LAST_TOL
    if not good.all():
        bad = np.flatnonzero(~good.all(axis=1))
        raise ValueError(f"T: last row must be [0, 0, 0, 1], got {rows[bad[0]].tolist()}")
    R = T[..., :3, :3]
    ortho = np.abs(np.swapaxes(R, -1, -2) @ R - _EYE3)
    if ortho.size and (not (ortho.max() <= 1e-9) or not (np.linalg.det(R) > 0).all()):
        raise ValueError("T: the rotation part is not a proper rotation (orthonormal, det +1)")
    return T


def _matrix(T) -> np.ndarray:
    T = np.asarray(T, dtype=float)
    return T if T.shape == (4, 4) else to_matrix(normalise(T))


def _refine(chain, q: np.ndarray, T: np.ndarray, tol: float):
    """Up to two Gauss-Newton steps on the pose error; keep what reproduces T to tol, merged."""
    if len(q) == 0:
        return q, np.zeros(0)

    e, err = _pose_error(chain, q, T)
    for _ in range(2):
        if np.all(err <= 1e-3 * tol):
            break
        J = chain.jacobian(q) * _weights(chain)
        step = np.einsum("kij,kj->ki", np.linalg.pinv(J, rcond=1e-12), e)
        q2 = q + step
        e2, err2 = _pose_error(chain, q2, T)
        better = err2 < err
        q, e, err = np.where(better[:, None], q2, q), np.where(better[:, None], e2, e), np.where(better, err2, err)
    periods = _periods(chain)
    q = _wrap(q, periods)
    keep = err <= tol
    q, err = q[keep], err[keep]
    if len(q) <= 1:
        return (q, err) if len(q) else (np.zeros((0, chain.n)), np.zeros(0))
    order = np.argsort(err, kind="stable")
    q, err = q[order], err[order]
    d = np.abs(q[:, None] - q[None])
    same = np.all(np.minimum(d, periods - d) < 1e-6, axis=-1)  # (k, k)
    k = np.arange(len(q))
    first = ~np.any(same & (k[:, None] > k), axis=1)  # not a copy of a more accurate one before it
    out, errs = q[first], err[first]
    order = np.lexsort(out.T[::-1])
    return out[order], errs[order]


def _rank(chain, q: np.ndarray) -> np.ndarray:
    """Numerical rank of the Jacobian at each joint vector (k, n), scaled by the chain's size."""
    return np.linalg.matrix_rank(chain.jacobian(q) * _weights(chain), tol=1e-8)


def _weights(chain) -> np.ndarray:
    """(6, 1): the rows of a Jacobian or pose error made dimensionless (positions / scale)."""
    return np.array([1 / _scale(chain)] * 3 + [1.0] * 3)[:, None]


def _near_reach(chain, T: np.ndarray) -> bool:
    """Whether T's position is within the chain's crude reach bound (Σ |a| + |c| + 2h from the
    base): outside it no local search is needed to call the pose unreachable."""
    reach = sum(abs(a) + abs(c) + 2 * p.amplitude for a, c, p in zip(chain.a, chain.offset, chain.pairs))
    return bool(np.linalg.norm(T[:3, 3]) <= 1.01 * reach + 1e-9 * _scale(chain))


def _pose_error(chain, q: np.ndarray, T: np.ndarray):
    """(k, 6) pose error [Δp/scale; Δω] of fk(q) against T and (k,) the largest entry of the 4×4
    difference."""
    F = chain.fk(q)
    dp = (T[:3, 3] - F[:, :3, 3]) / _scale(chain)
    S = T[:3, :3] @ np.swapaxes(F[:, :3, :3], 1, 2)  # Σ_k f_k × t_k = vee(T Fᵀ − F Tᵀ) (columns f_k, t_k)
    dw = 0.5 * np.stack([S[:, 2, 1] - S[:, 1, 2], S[:, 0, 2] - S[:, 2, 0], S[:, 1, 0] - S[:, 0, 1]], 1)
    return np.concatenate([dp, dw], 1), np.abs(F - T).max(axis=(1, 2))


def _on_continuum(chain, q: np.ndarray, T: np.ndarray, tol: float) -> bool:
    """Whether the solution q lies on a curve of solutions: where the Jacobian is rank-deficient,
    a step along its null space, corrected back onto the pose, lands on another solution."""
    if _rank(chain, q[None])[0] == chain.n:
        return False
    v = np.linalg.svd(chain.jacobian(q) * _weights(chain))[2][-1]
    moved = local_search(chain, T, start=(q + 1e-2 * v)[None])
    _, err = _pose_error(chain, moved, T)
    return bool(err[0] <= tol and np.abs(moved[0] - q).max() > 1e-3)


def local_search(chain, T: np.ndarray, seeds: int = 64, iterations: int = 60, seed: int = SEED,
                 bounds: np.ndarray | None = None, start: np.ndarray | None = None) -> np.ndarray:
    """Levenberg-Marquardt on the pose error from `seeds` joint vectors drawn uniformly (in
    `bounds` (n, 2), default each joint's period), all at once over the batched fk and Jacobian
    kernels (or from the rows of `start`); returns the end points, kept inside the bounds. Not
    complete: the fallback where the elimination degenerates, and the nearest-pose search."""
    periods = _periods(chain)
    if bounds is None:
        bounds = np.stack([-periods / 2, periods / 2], 1)
        for i, p in enumerate(chain.pairs):
            if p.theta_limit is not None:
                bounds[i] = -p.theta_limit, p.theta_limit
    lo, hi = bounds[:, 0], bounds[:, 1]
    rng = np.random.default_rng(seed)
    q = rng.uniform(lo, hi, (seeds, chain.n)) if start is None else np.clip(start, lo, hi)
    seeds = len(q)
    W = _weights(chain)
    lam = np.full(seeds, 1e-3)
    e, _ = _pose_error(chain, q, T)
    cost = np.sum(e * e, axis=1)
    for _ in range(iterations):
        J = chain.jacobian(q) * W
        JtJ = np.einsum("kia,kib->kab", J, J)
        g = np.einsum("kia,ki->ka", J, e)
        A = JtJ + lam[:, None, None] * (np.eye(chain.n) * (np.einsum("kaa->ka", JtJ)[:, :, None] + 1e-12))
        step = np.einsum("kab,kb->ka", np.linalg.pinv(A), g)
        q2 = np.clip(q + step, lo, hi)
        e2, _ = _pose_error(chain, q2, T)
        cost2 = np.sum(e2 * e2, axis=1)
        better = cost2 < cost
        q, e, cost = np.where(better[:, None], q2, q), np.where(better[:, None], e2, e), np.where(better, cost2, cost)
        lam = np.where(better, lam / 3, lam * 4)
        if np.all(cost < 1e-28):
            break
    return q


def distance(chain, T, starts: int = 64, seed: int = SEED) -> tuple[float, float, np.ndarray]:
    """How far a pose is from the chain's reach inside its joint limits (`chain.limits`):
    (position error [m], rotation error [rad], q) at the best of `starts` batched
    Levenberg-Marquardt fits of fk(q) to T (pose error weighted by the chain's length scale), a
    bounded amount of work (60 iterations of one batched fk and Jacobian call). An estimate for
    reporting unreachable poses, not part of the exact solver."""
    _study(T)  # validates
    Tm = _matrix(T)
    q = local_search(chain, Tm, seeds=starts, seed=seed, bounds=chain.limits)
    e, _ = _pose_error(chain, q, Tm)
    best = q[int(np.argmin(np.sum(e * e, axis=1)))]
    F = chain.fk(best)
    dp = float(np.linalg.norm(F[:3, 3] - Tm[:3, 3]))
    c = (np.trace(F[:3, :3].T @ Tm[:3, :3]) - 1) / 2
    return dp, float(np.arccos(np.clip(c, -1.0, 1.0))), best


# ----------------------------------------------------------------------------- the local solver
@dataclass
class LocalSolution:
    """ik_local's result, one row per (pose, seed): q (..., n), the largest entry of |fk(q) − T|
    and whether it is within tol."""

    q: np.ndarray
    residual: np.ndarray
    converged: np.ndarray


def ik_local(chain, T, q0, tol: float = 1e-10, max_iter: int = 100) -> LocalSolution:
    """Levenberg-Marquardt from the seeds q0 (n,) or (..., n) to the poses T (4, 4) or (..., 4, 4)
    (broadcast together), each step projected onto chain.limits, in C (apair_ik_local on the fk and
    Jacobian kernels)."""
    from . import kernels

    native, why = kernels._native()
    if native is None:
        raise RuntimeError(f"ik_local needs the compiled C kernels: {why}")
    T = V.real_array("T", T)
    if T.shape[-2:] != (4, 4):
        raise ValueError(f"T: expected a 4x4 transform or an array of them (..., 4, 4), got shape {T.shape}")
    _check_matrix(T)
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
        pair[i, :len(params)] = params
    q, res, conv = native.ik_local(kind, pair, np.ascontiguousarray(chain._dh, float),
                                   np.ascontiguousarray(lim[:, 0]), np.ascontiguousarray(lim[:, 1]), _scale(chain),
                                   Tb, qb, tol, max_iter)
    return LocalSolution(q.reshape(shape + (n,)), res.reshape(shape), conv.reshape(shape).astype(bool))
