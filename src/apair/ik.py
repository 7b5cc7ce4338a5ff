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
  sampled points of the half (`_half_quadrics`); the one quadric in x alone (the spherical
  two-joint condition) divided by its (1 + u²) factors gives f(u_3, u_4) of bidegree (4, 4), a
  random combination of all quadrics gives g of bidegree (8, 8). Their resultant in u_4 (degree 64
  in u_3) is never expanded: the Sylvester matrix in u_4, whose rows have degree 4 or 8 in u_3, is
  linearised by rows into a 64 × 64 eigenvalue problem. Each real eigenvalue u_3 gives the common
  real roots u_4 of f and g; a pair is kept if every quadric of the left half vanishes on its
  image, and the left half is then solved for W(u_3, u_4) as above. Where the rotation condition
  holds on the whole image (parallel axes, as in examples/4a_chain.toml), f is a second random
  combination of the quadrics (a 128 × 128 problem).

Every real candidate is checked with the chain's own fk kernel, refined by up to two Gauss-Newton
steps where it is not already accurate to 1e-3·tol, and kept only if fk(q) reproduces T to `tol`
(largest entry of the 4×4 difference); duplicates are merged. Angles are returned in (−2π, 2π] for A-pairs
(their motion has period 4π) and (−π, π] for R-pairs. General (non-sinusoidal) A-pairs have an
elliptic, not rational, motion and are not supported; nor are chains of 5 or 6 joints.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import scipy.linalg

from . import _validate as V
from .study import _qmul, conjugate, from_matrix, multiply, normalise, to_matrix

SEED = 46  # fixed: the parameter shifts and random combinations are reproducible
OUTSIDE = [1, 2, 5, 6]  # components that vanish on the pair subalgebra
ROOT_RTOL = 1e-6  # relative residual under which a root is a candidate (verification decides)
REAL_TOL = 1e-6  # |Im u| / (1 + |u|) under which a root is taken as real


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


def _mobius(coeffs: np.ndarray, tau: float) -> np.ndarray:
    """(D+1, ...) coefficients of p(u) → those of (1 − τv)^D p((v + τ)/(1 − τv))."""
    P = np.polynomial.polynomial
    D = coeffs.shape[0] - 1
    out = np.zeros_like(coeffs)
    for m in range(D + 1):
        w = P.polymul(P.polypow([tau, 1.0], m), P.polypow([1.0, -tau], D - m))
        out[: len(w)] += np.multiply.outer(w, coeffs[m])
    return out


def _bivariate(a: np.ndarray, b: np.ndarray, form) -> np.ndarray:
    """Coefficients (i, j) of form(A(u, v), B(u, v)) for polynomial vector fields given by
    coefficients a, b (Du+1, Dv+1, ...) when `form` is bilinear: by FFT on a grid of unit roots."""
    nu = a.shape[0] + b.shape[0] - 1
    nv = a.shape[1] + b.shape[1] - 1
    A = np.fft.fft2(a, s=(nu, nv), axes=(0, 1))
    B = np.fft.fft2(b, s=(nu, nv), axes=(0, 1))
    return np.fft.ifft2(form(A, B), axes=(-2, -1))


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
def _scale(chain) -> float:
    """The chain's length scale: its largest link length, offset or amplitude (at least 1 mm)."""
    lengths = [abs(x) for x in (*chain.a, *chain.offset)] + [p.amplitude for p in chain.pairs]
    return max(max(lengths), 1e-3)


def _periods(chain) -> np.ndarray:
    """Each joint's period in θ: 2π for an R-pair, 4π for an A-pair (d changes sign at θ + 2π)."""
    return np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])


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
    """Joint i in a shifted parameter u: P(u) (D+1, 8); the x-part of A(u) = P(u)·K divided by
    (1 + u²) where it has that factor (Dx+1, 4); the constant K and K⁻¹; and the map u → θ."""

    kind: str
    delta: float
    P: np.ndarray
    xhat: np.ndarray
    K: np.ndarray
    Kinv: np.ndarray
    A: np.ndarray = field(init=False)

    def __post_init__(self):
        self.A = multiply(self.P, self.K)

    def theta(self, u):
        if self.kind == "revolute":
            return _wrap(2 * np.arctan(u) + self.delta, 2 * np.pi)
        return _wrap(4 * np.arctan(u) + self.delta, 4 * np.pi)


def _joint(chain, i: int, scale: float, delta: float) -> _Joint:
    pair = chain.pairs[i]
    if pair.kind == "revolute":
        tau = math.tan(delta / 2)
        base = np.zeros((2, 8))
        base[0, 0] = base[1, 3] = 1.0  # the rotation quaternion (1, 0, 0, tan(θ/2)), projectively
    else:
        tau = math.tan(delta / 4)
        base = _quartic() @ np.array([1.0, pair.amplitude / scale])
    P = _mobius(base, tau)
    P = multiply(multiply(_rot(2, chain.theta_offset[i]), _trans(2, chain.offset[i] / scale)), P)
    x = P[:, :4]
    if pair.kind != "revolute":  # x carries the factor (1 + u²) (up to a constant after the shift)
        Pn = np.polynomial.polynomial
        parts = [Pn.polydiv(x[:, j], [1.0, 0.0, 1.0]) for j in range(4)]
        if max(np.abs(r).max() for _, r in parts) > 1e-12 * np.abs(x).max():
            raise AssertionError("the pair's rotation part lost its (1 + u^2) factor")
        x = np.stack([np.pad(q, (0, 3 - len(q))) for q, _ in parts], 1)
    K = multiply(_trans(0, chain.a[i] / scale), _rot(0, chain.alpha[i]))
    return _Joint(pair.kind, delta, P, _qmul(x, K[:4]), K, conjugate(K))


class _Degenerate(Exception):
    """The elimination met an identically vanishing resultant (a non-generic design or pose)."""


# ----------------------------------------------------------------------------- the solver
@dataclass
class Solution:
    """All real solutions `q` (k, n) of one pose, with the counts behind them.

    complex_count: solutions over the complex numbers found by the elimination (None unless
    asked for); candidates: real candidates examined; error: fk error of each solution."""

    q: np.ndarray
    error: np.ndarray
    candidates: int
    complex_count: int | None = None


class Solver:
    """The inverse kinematics of one chain; the design-dependent work is done once."""

    def __init__(self, chain, seed: int = SEED):
        n = chain.n
        if n not in (1, 2, 3, 4):
            raise ValueError(f"chain: inverse kinematics covers chains of 1 to 4 pairs, this one has {n}")
        for i, p in enumerate(chain.pairs):
            if p.kind == "general":
                raise ValueError(f"pairs[{i}]: a general A-pair's motion is not rational; inverse kinematics "
                                 "needs sinusoidal A-pairs or R-pairs")
        self.chain = chain
        self.scale = _scale(chain)
        self.rng = np.random.default_rng(seed)
        self.joints = [_joint(chain, i, self.scale, self.rng.uniform(-np.pi, np.pi)) for i in range(n)]
        j1 = self.joints[0]
        if n >= 2:  # Z(u_1) = K_1⁻¹·P̃_1(u_1)·W·K_2⁻¹ = Σ u_1^m Zmap[m] W
            right = _right(self.joints[1].Kinv)
            self.Zmap = np.stack([_left(j1.Kinv) @ _left(c) @ right for c in conjugate(j1.P)])
        if n == 3:
            self.image = conjugate(self.joints[2].A)  # W(u_3) = T·Ã_3(u_3)
        if n == 4:
            j3, j4 = self.joints[2:]
            self.image = conjugate(multiply(j3.A[:, None, :], j4.A[None, :, :]))
            self.ximage = _qconj(_qmul(j3.xhat[:, None, :], j4.xhat[None, :, :]))
        if n >= 3:
            Q, Qx = self._half_quadrics()
            if len(Qx) == 0:
                raise AssertionError("no quadric in x vanishes on the rotations of a two-joint chain")
            self.Q = Q
            self.Qx = np.tensordot(self.rng.standard_normal(len(Qx)), Qx, 1)
            self.weights = self.rng.standard_normal(len(Q))
            self.weights2 = self.rng.standard_normal(len(Q))

    # -- design-dependent
    def _half_quadrics(self):
        """Quadrics through the left half's poses (all, and in x alone) by SVD on sampled points."""
        j1, j2 = self.joints[:2]
        u = np.tan(self.rng.uniform(-np.pi / 2, np.pi / 2, (2, 160)))
        pts = multiply(_eval(j1.A, u[0]), _eval(j2.A, u[1]))
        pts /= np.linalg.norm(pts, axis=1, keepdims=True)
        return _quadric_forms(pts), _quadric_forms(pts[:, :4])

    # -- per pose
    def solve(self, T: np.ndarray, tol: float = 1e-9, count_complex: bool = False) -> Solution:
        target = _study(T)
        target[4:] /= self.scale
        n = self.chain.n
        try:
            cands = self._solve_left(target, n) if n <= 2 else self._solve_right(target, count_complex)
        except _Degenerate as exc:
            raise ValueError(f"T: the solutions at this pose are not isolated ({exc}); the chain's "
                             "design is degenerate for inverse kinematics here") from None
        # points where a joint's rotation part vanishes (u = ±i, isotropic) are not displacements
        cands = [c for c in cands if np.all(np.abs(1 + c * c) > 1e-3 * (1 + np.abs(c) ** 2))]
        count = len(_dedupe_complex(cands)) if count_complex else None
        real = [c for c in cands if np.all(np.abs(np.imag(c)) <= REAL_TOL * (1 + np.abs(c)))]
        if real:
            U = np.real(np.array(real))
            q = np.stack([j.theta(U[:, i]) for i, j in enumerate(self.joints)], 1)
        else:
            q = np.zeros((0, n))
        q, err = _refine(self.chain, q, _matrix(T), tol)
        return Solution(q, err, len(real), count)

    def _solve_left(self, W: np.ndarray, n: int) -> list[np.ndarray]:
        """Parameters (u_1[, u_2]) with A_1 (A_2) ∝ W, complex; W may be complex."""
        j1 = self.joints[0]
        if n == 1:
            return [np.array([u]) for u in _on_curve(j1, multiply(W, j1.Kinv), self.rng)]
        Zc = self.Zmap @ W  # (D1+1, 8)
        out = []
        for u1 in _common_roots(Zc[:, OUTSIDE].T, self.rng):
            Z = (u1 ** np.arange(len(Zc))) @ Zc
            out += [np.array([u1, u2]) for u2 in _on_curve(self.joints[1], Z, self.rng)]
        return out

    def _quadric_image(self, C: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """Coefficients (u_3^i u_4^j) of Σ_k w_k Q_k(W(u_3, u_4)) for the left half's quadrics Q_k."""
        Q = np.tensordot(weights, self.Q, 1)
        return np.real(_bivariate(C, C, lambda A, B: np.einsum("...a,ab,...b->...", A, Q, B)))

    def _solve_right(self, T: np.ndarray, count_complex: bool) -> list[np.ndarray]:
        """Candidates for 3 and 4 joints: the right part's parameters from the left half's quadrics
        on the image W = T·(A_3 A_4)~, then the left half for each W."""
        LT = _left(T)
        C = self.image @ LT.T
        if self.chain.n == 3:
            G = np.einsum("ma,qab,kb->qmk", C, self.Q, C)
            G = np.stack([_antidiagonal_sums(g) for g in G])
            rights = [np.array([u3]) for u3 in _common_roots(G, self.rng)]
            images = [(r[0] ** np.arange(len(C))) @ C for r in rights]
        else:
            X = self.ximage @ LT[:4, :4].T
            f = np.real(_bivariate(X, X, lambda A, B: np.einsum("...a,ab,...b->...", A, self.Qx, B)))
            g = self._quadric_image(C, self.weights)
            if np.abs(f).max() <= 1e-12 * np.abs(X).max() ** 2 * np.abs(self.Qx).max():
                # the rotation condition holds on the whole image (e.g. parallel axes): use a
                # second combination of the quadrics instead
                f = self._quadric_image(C, self.weights2)
            u3s = _hidden_variable(f, g)
            if not count_complex:
                u3s = u3s[np.abs(u3s.imag) <= REAL_TOL * (1 + np.abs(u3s))].real
            rights, images = _second_roots(f, g, u3s, C, real=not count_complex)
            # a resultant root of f and g is kept only if every quadric of the left half vanishes
            Wn = images / np.linalg.norm(images, axis=1, keepdims=True)
            res = np.abs(np.einsum("ra,qab,rb->rq", Wn, self.Q, Wn)).max(axis=1, initial=0.0)
            keep = res <= ROOT_RTOL
            rights, images = rights[keep], images[keep]
        out = []
        for right, W in zip(rights, images):
            out += [np.concatenate([left, right]) for left in self._solve_left(W, 2)]
        return out


# ----------------------------------------------------------------------------- helpers
def _left(p: np.ndarray) -> np.ndarray:
    """The 8×8 matrix of v ↦ p·v (Study product)."""
    return multiply(p, np.eye(8)).T


def _right(p: np.ndarray) -> np.ndarray:
    """The 8×8 matrix of v ↦ v·p."""
    return multiply(np.eye(8), p).T


_PAIRS = np.triu_indices(8, 1)


def _on_curve(j: _Joint, Z: np.ndarray, rng) -> np.ndarray:
    """Parameters u with P_j(u) ∝ Z: common roots of the 2×2 minors P_a Z_b − P_b Z_a."""
    a, b = _PAIRS
    minors = j.P[:, a] * Z[b] - j.P[:, b] * Z[a]  # (D+1, 28)
    return _common_roots(minors.T, rng)


def _eval(coeffs: np.ndarray, u: np.ndarray) -> np.ndarray:
    return np.einsum("m...,rm->r...", coeffs, np.asarray(u)[:, None] ** np.arange(len(coeffs)))


def _qconj(x):
    return x * np.array([1.0, -1.0, -1.0, -1.0])


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


def _antidiagonal_sums(M: np.ndarray) -> np.ndarray:
    """Coefficients of the product of two polynomials from their outer product (m, k) → m + k."""
    out = np.zeros(M.shape[0] + M.shape[1] - 1, dtype=M.dtype)
    for m in range(M.shape[0]):
        out[m: m + M.shape[1]] += M[m]
    return out


@lru_cache(maxsize=None)
def _linearisation(degs: tuple):
    """Index structure of the row linearisation for row degrees `degs`: the shift equations
    z_{i,k+1} = u z_{i,k} (rows, columns of z_{i,k}) and each row's block (offset, degree)."""
    offs = np.concatenate([[0], np.cumsum(degs)])
    cols = np.concatenate([offs[i] + np.arange(d - 1) for i, d in enumerate(degs)]).astype(int)
    return np.arange(len(cols)), cols, [(int(offs[i]), d) for i, d in enumerate(degs)]


def _hidden_variable(f: np.ndarray, g: np.ndarray) -> np.ndarray:
    """All u with f(u, v) = g(u, v) = 0 for some v (coefficients [i, j] of u^i v^j): the zeros of
    the Sylvester matrix in v, a matrix polynomial in u whose rows have the degrees of f and g,
    linearised by rows (size Σ row degrees = the resultant's degree bound)."""
    df, dg = f.shape[1] - 1, g.shape[1] - 1
    N = df + dg
    rows = []  # (coefficients in u (d+1, N)) per row
    for r in range(dg):
        row = np.zeros((f.shape[0], N))
        row[:, r: r + df + 1] = f
        rows.append(row)
    for r in range(df):
        row = np.zeros((g.shape[0], N))
        row[:, r: r + dg + 1] = g
        rows.append(row)
    degs = tuple(len(r) - 1 for r in rows)
    if min(degs) < 1:
        raise _Degenerate("a Sylvester row is constant in the hidden variable")
    shift_rows, shift_cols, blocks = _linearisation(degs)
    size = sum(degs)
    A = np.zeros((size, size))
    B = np.zeros((size, size))
    A[shift_rows, shift_cols + 1] = 1.0
    B[shift_rows, shift_cols] = 1.0
    for (lo, d), row in zip(blocks, rows):  # the last N rows: Σ_i row_i(u)ᵀ w_i = 0
        A[size - N:, lo: lo + d] = -row[:d].T
        B[size - N:, lo + d - 1] = row[d]
    lead = B[size - N:, [lo + d - 1 for lo, d in blocks]]  # B is I plus this block, permuted
    if np.linalg.cond(lead) < 1e10:
        return np.linalg.eigvals(np.linalg.solve(B, A))
    w = scipy.linalg.eigvals(A, B)
    return w[np.isfinite(w)]


def _second_roots(f, g, u3s, C, real: bool):
    """For each u_3, the common roots u_4 of f(u_3, ·) and g(u_3, ·) (batched companion
    eigenvalues of f(u_3, ·), checked on g); returns the pairs (r, 2) and their images W (r, 8)."""
    if len(u3s) == 0:
        return np.zeros((0, 2)), np.zeros((0, 8))
    fu = (u3s[:, None] ** np.arange(f.shape[0])) @ f  # (R, df+1), ascending in u_4
    gu = (u3s[:, None] ** np.arange(g.shape[0])) @ g
    d = f.shape[1] - 1
    lead = fu[:, d]
    ok = np.abs(lead) > 1e-12 * np.abs(fu).max(axis=1)
    fu, gu, u3s, lead = fu[ok], gu[ok], u3s[ok], lead[ok]
    comp = np.zeros((len(fu), d, d), dtype=fu.dtype)
    comp[:, 1:, :-1] = np.eye(d - 1)
    comp[:, :, -1] = -fu[:, :d] / lead[:, None]
    u4 = np.linalg.eigvals(comp)  # (R, d)
    u3 = np.repeat(u3s, d)
    u4 = u4.ravel()
    both = np.zeros((len(u4), 2, max(fu.shape[1], gu.shape[1])), dtype=complex)
    both[:, 0, : fu.shape[1]] = np.repeat(fu, d, axis=0)
    both[:, 1, : gu.shape[1]] = np.repeat(gu, d, axis=0)
    pw = u4[:, None] ** np.arange(both.shape[2])
    num = np.abs(np.einsum("rkm,rm->rk", both, pw)).max(axis=1)
    den = np.einsum("rm,rm->r", np.abs(both).max(axis=1), np.abs(pw))
    keep = num <= ROOT_RTOL * den
    if real:
        keep &= np.abs(u4.imag) <= REAL_TOL * (1 + np.abs(u4))
    u3, u4 = u3[keep], u4[keep]
    if real:
        u4 = u4.real
    W = np.einsum("ri,rj,ija->ra", u3[:, None] ** np.arange(C.shape[0]), u4[:, None] ** np.arange(C.shape[1]), C)
    return np.stack([u3, u4], 1), W


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


def _check_matrix(T: np.ndarray) -> np.ndarray:
    R = T[:3, :3]
    if not np.allclose(T[3], [0, 0, 0, 1], atol=1e-12):
        raise ValueError(f"T: last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-9 or np.linalg.det(R) < 0:
        raise ValueError("T: the rotation part is not a proper rotation (orthonormal, det +1)")
    return T


def _matrix(T) -> np.ndarray:
    T = np.asarray(T, dtype=float)
    return T if T.shape == (4, 4) else to_matrix(normalise(T))


def _refine(chain, q: np.ndarray, T: np.ndarray, tol: float):
    """Up to two Gauss-Newton steps on the pose error; keep what reproduces T to tol, merged."""
    if len(q) == 0:
        return q, np.zeros(0)

    def error(q):
        F = chain.fk(q)
        dp = T[:3, 3] - F[:, :3, 3]
        dw = 0.5 * np.cross(F[:, :3, :3], T[:3, :3], axisa=1, axisb=0, axisc=1).sum(axis=2)
        return np.concatenate([dp, dw], 1), np.abs(F - T).max(axis=(1, 2))

    e, err = error(q)
    for _ in range(2):
        if np.all(err <= 1e-3 * tol):
            break
        J = chain.jacobian(q)
        step = np.einsum("kij,kj->ki", np.linalg.pinv(J, rcond=1e-12), e)
        q2 = q + step
        e2, err2 = error(q2)
        better = err2 < err
        q, e, err = np.where(better[:, None], q2, q), np.where(better[:, None], e2, e), np.where(better, err2, err)
    periods = _periods(chain)
    q = _wrap(q, periods)
    keep = err <= tol
    q, err = q[keep], err[keep]
    order = np.argsort(err, kind="stable")
    out, errs = [], []
    for k in order:
        d = np.abs(q[k] - np.array(out)) if out else None
        if d is not None:
            d = np.minimum(d, periods - d)
            if np.any(np.all(d < 1e-6, axis=1)):
                continue
        out.append(q[k])
        errs.append(err[k])
    if not out:
        return np.zeros((0, chain.n)), np.zeros(0)
    out, errs = np.array(out), np.array(errs)
    order = np.lexsort(out.T[::-1])
    return out[order], errs[order]


def distance(chain, T, starts: int = 24, seed: int = 0) -> tuple[float, float, np.ndarray]:
    """How far a pose is from the chain's reach: (position error [m], rotation error [rad], q) at
    the best of `starts` local least-squares fits of fk(q) to T (pose error weighted by the chain's
    length scale). An estimate for reporting unreachable poses, not part of the exact solver."""
    from scipy.optimize import least_squares

    _study(T)  # validates
    Tm = _matrix(T)
    scale = _scale(chain)
    rng = np.random.default_rng(seed)
    periods = _periods(chain)
    lo = np.array([-(p.theta_limit or per / 2) for p, per in zip(chain.pairs, periods)])
    bounds = (lo, -lo) if any(p.theta_limit for p in chain.pairs) else (-np.inf, np.inf)

    def residual(q):
        F = chain.fk(q)
        return np.concatenate([(F[:3, 3] - Tm[:3, 3]) / scale, (F[:3, :3] - Tm[:3, :3]).ravel() / 2])

    best = None
    for _ in range(starts):
        q0 = rng.uniform(lo, -lo) * 0.999
        r = least_squares(residual, q0, bounds=bounds, xtol=1e-14, ftol=1e-14)
        if best is None or r.cost < best.cost:
            best = r
    F = chain.fk(best.x)
    dp = float(np.linalg.norm(F[:3, 3] - Tm[:3, 3]))
    c = (np.trace(F[:3, :3].T @ Tm[:3, :3]) - 1) / 2
    return dp, float(np.arccos(np.clip(c, -1.0, 1.0))), _wrap(best.x, periods)

