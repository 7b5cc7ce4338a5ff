"""Polynomial algebra of the eliminations (apair.ik.elimination4, apair.ik.elimination1a5r).

- Univariate systems (ascending coefficients): their common roots (`common_roots`, and
  `unique_roots` where the coefficient matrix's null vector gives the one root directly).
- Bivariate polynomials (coefficients [i, j] of u^i v^j): the factors 1 + u² they carry at the
  isotropic parameters ±i (`isotropic_factors`, `isotropic_quotient`, `deflate`), and the hidden-variable
  pencil of two of them (`hidden_variable`: the Sylvester matrix in v, a matrix polynomial in u,
  linearised by rows; its eigenvalues are the u where the two have a common root v).
- Matrix polynomials (`Linearisation`): the eigenvalues of a square matrix polynomial
  M(τ) = Σ_p τ^p M_p whose determinant carries a factor (1 + τ²)^m (the isotropic points of a
  half-angle chart): the factor is divided out of its columns before the linearisation, so the
  eigenproblem is 2m smaller.

  Where M(±i) has a real null vector v, the column combination M(τ)·v vanishes at ±i and is
  divisible by 1 + τ²: it replaces the column of highest degree in v's support, divided once (the
  column degrees' sum drops by 2, and det M loses one factor). Repeated until M(±i) (of the current
  columns) has no real null vector, this gives M(τ)·N(τ)·diag((1 + τ²)^−e) with column degrees δ,
  N a polynomial matrix. Where the operations depend on the design only (as for the elimination of
  apair.ik.elimination1a5r), they are found once and kept as one linear map of M's coefficients;
  every use checks that the divisions are still exact. The result is linearised by column degrees
  (Kailath's column companion form): Σ δ states, its leading column coefficients inverted.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import scipy.linalg
from numpy.polynomial import polynomial as poly
from scipy.linalg import lapack

SEED = 46  # fixed: the parameter shifts and random combinations are reproducible
ROOT_RTOL = 1e-6  # relative residual under which a root is a candidate (verification decides)
# the smallest singular value of a system's shifted coefficient matrix (at most 16 × 8) above which,
# relative to the largest, it has no common root: a root of relative residual ROOT_RTOL bounds it by
# ROOT_RTOL·√(rows·cols) ≤ 1.2e-5 (`unique_roots`, apair_ik4_left)
NO_ROOT = 1e-4
LEAD_COND = 1e10  # 1-norm condition number of the Sylvester rows' leading coefficients under which
#                  the hidden-variable pencil is taken as regular and solved as B⁻¹A
DEFLATE_TOL = 1e-10  # relative residual of g(±i, ·) = f(±i, ·)·h under which g is deflated (`deflate`)


class Degenerate(Exception):
    """The elimination met an identically vanishing resultant (a non-generic design or pose)."""


def _relres(polys: np.ndarray, u) -> np.ndarray:
    """max_k |p_k(u)| / Σ_m max_k|c_km| |u|^m for polynomials (k, D+1) (ascending coefficients) at
    points u (r,): relative to the whole system's size, so that a polynomial which is zero up to
    rounding does not veto a root."""
    u = np.asarray(u)
    pw = u[:, None] ** np.arange(polys.shape[1])
    num = np.abs(pw @ polys.T).max(axis=1)
    den = np.abs(pw) @ np.abs(polys).max(axis=0)
    return num / np.maximum(den, 1e-300)


def common_roots(polys: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Common roots (complex) of univariate polynomials (k, D+1), ascending coefficients."""
    polys = polys[np.abs(polys).max(axis=1) > 1e-13 * max(np.abs(polys).max(), 1e-300)]
    if len(polys) == 0:
        raise Degenerate("every polynomial vanishes identically")
    comb = rng.standard_normal(len(polys)) @ polys
    coef = np.trim_zeros(comb[::-1], "f")
    if len(coef) <= 1:
        return np.zeros(0, complex)
    roots = np.roots(coef)
    return roots[_relres(polys, roots) <= ROOT_RTOL]


def common_roots_many(polys: np.ndarray, rng: np.random.Generator) -> list:
    """common_roots of each system polys[r] (R, k, D+1) at once: one random combination per
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
        A[:, 0, :] = -comb[rows, d - 1 :: -1] / comb[rows, d, None]  # np.roots' companion form
        A[:, np.arange(1, d), np.arange(d - 1)] = 1
        roots = np.linalg.eigvals(A)  # (rows, d)
        pw = roots[:, :, None] ** np.arange(polys.shape[2])
        num = np.abs(np.einsum("rim,rkm->rik", pw, polys[rows])).max(axis=2)
        den = np.einsum("rim,rm->ri", np.abs(pw), np.abs(polys[rows]).max(axis=1))
        ok = num / np.maximum(den, 1e-300) <= ROOT_RTOL
        for j, r in enumerate(rows):
            out[r] = roots[j][ok[j]]
    return out


def shifted(polys: np.ndarray, m: int) -> np.ndarray:
    """(R, k(m+1), D+m+1): the polynomials (R, k, D+1) times u^0 … u^m, one row each."""
    R, k, d = polys.shape
    out = np.zeros((R, m + 1, k, d + m), polys.dtype)
    for s in range(m + 1):
        out[:, s, :, s : s + d] = polys
    return out.reshape(R, (m + 1) * k, d + m)


def unique_roots(M: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For systems M (R, k, D+1) of polynomials (ascending coefficients): (u (R,), ok (R,), none
    (R,)), ok where the coefficient matrix has rank D and its null vector is (1, u, …, u^D) of a
    root that passes the residual test. A common root puts its vector in the null space, so ok
    means exactly one common root (the others go to the eigenvalues: common_roots_many), and none
    (the smallest singular value above NO_ROOT of the largest) that there is no common root."""
    D = M.shape[2] - 1
    if len(M) == 0 or D < 1 or M.shape[1] < D:
        return np.zeros(len(M), M.dtype), np.zeros(len(M), bool), np.zeros(len(M), bool)
    _, sv, Vt = np.linalg.svd(M, full_matrices=False)
    v = Vt[:, -1].conj()
    u = np.sum(v[:, :-1].conj() * v[:, 1:], axis=1) / np.maximum(np.sum(np.abs(v[:, :-1]) ** 2, axis=1), 1e-300)
    vandermonde = np.linalg.norm(v[:, 1:] - u[:, None] * v[:, :-1], axis=1) <= 1e-8
    ok = (sv[:, D - 1] > 1e-6 * sv[:, 0]) & vandermonde & (relres_many(M, u) <= ROOT_RTOL)
    return u, ok, _rootless(M, sv)


def no_common_root(M: np.ndarray) -> np.ndarray:
    """(R,) for systems M (R, k, D+1) as in unique_roots: where they have no common root (the
    singular values from the eigenvalues of M^H M, which take a third of an SVD's time)."""
    if len(M) == 0 or M.shape[1] <= M.shape[2] - 1:
        return np.zeros(len(M), bool)
    lam = np.linalg.eigvalsh(np.swapaxes(M.conj(), 1, 2) @ M)  # ascending
    return _rootless(M, np.sqrt(np.maximum(lam[:, ::-1], 0.0)))


def _rootless(M: np.ndarray, sv: np.ndarray) -> np.ndarray:
    """No common root: the smallest singular value above NO_ROOT of the largest (a common root
    puts its vector (1, u, …, u^D) in the null space)."""
    return (M.shape[1] > M.shape[2] - 1) & (sv[:, -1] > NO_ROOT * sv[:, 0])


def relres_many(M: np.ndarray, u: np.ndarray) -> np.ndarray:
    """_relres of each system M[r] (R, k, D+1) at its own point u[r]."""
    pw = u[:, None] ** np.arange(M.shape[2])
    num = np.abs(np.einsum("rm,rkm->rk", pw, M)).max(axis=1)
    den = np.einsum("rm,rm->r", np.abs(pw), np.abs(M).max(axis=1))
    return num / np.maximum(den, 1e-300)


def isotropic_factors(p: np.ndarray) -> tuple[int, int]:
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


def isotropic_quotient(p: np.ndarray, factors: tuple[int, int]) -> np.ndarray:
    """p (as in isotropic_factors) divided by (1 + u²)^a (1 + v²)^b, factors = (a, b)."""
    a, b = factors
    return _isotropic_division(p.shape[0] - 1, a) @ p @ _isotropic_division(p.shape[1] - 1, b).T


@cache
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


@cache
def _isotropic_product(d: int) -> np.ndarray:
    """The matrix ((d + 3) × (d + 1)) of q ↦ (1 + u²)·q for q of degree d."""
    return np.eye(d + 3, d + 1) + np.eye(d + 3, d + 1, -2)


def deflate(f: np.ndarray, g: np.ndarray, tol: float | None = None) -> np.ndarray | None:
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
        A[j : j + df + 1, j] = fi
    if not (np.abs(fi).max() > 0 and np.abs(gi).max() > 0):
        return None
    h = np.linalg.lstsq(A, gi, rcond=None)[0]
    if not np.abs(A @ h - gi).max() <= tol * np.abs(gi).max():
        return None
    rows = max(g.shape[0], f.shape[0] + 1)
    if rows < 4:  # the quotient would be constant in u
        return None
    out = np.zeros((rows, dg + 1))
    out[: g.shape[0]] = g
    for i, part in enumerate((h.real, h.imag)):  # − a·f, a = Re h + u Im h
        for j, c in enumerate(part):
            out[i : i + f.shape[0], j : j + df + 1] -= c * f
    return _isotropic_division(rows - 1, 1) @ out


def bezout_of(f: tuple, g: tuple) -> int:
    """The number of common zeros in P¹ × P¹ of two bivariate polynomials of coefficient shapes
    f and g (their bidegrees plus one)."""
    return (f[0] - 1) * (g[1] - 1) + (f[1] - 1) * (g[0] - 1)


@cache
def product_map(m: int, k: int) -> np.ndarray:
    """(m·k, m + k − 1): the coefficients of a product of two polynomials from their outer
    product (m, k), flattened."""
    i, j = np.divmod(np.arange(m * k), k)
    out = np.zeros((m * k, m + k - 1))
    out[np.arange(m * k), i + j] = 1.0
    return out


def sylvester_at(f: np.ndarray, g: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(R, N, N), N = f's plus g's degree in v: the Sylvester matrices in v of f(u, v) and g(u, v)
    at each u (R,) (coefficients [i, j] of u^i v^j), rows v^r f then v^r g."""
    fu = (u[:, None] ** np.arange(f.shape[0])) @ f
    gu = (u[:, None] ** np.arange(g.shape[0])) @ g
    df, dg = f.shape[1] - 1, g.shape[1] - 1
    S = np.zeros((len(u), df + dg, df + dg), fu.dtype)
    for r in range(dg):
        S[:, r, r : r + df + 1] = fu
    for r in range(df):
        S[:, dg + r, r : r + dg + 1] = gu
    return S


PROBE = np.random.default_rng(SEED).standard_normal(64)  # right-hand side of the inverse iterations


def null_vectors(S: np.ndarray) -> np.ndarray:
    """(R, N): unit null vectors of the singular matrices S (R, N, N) by two steps of inverse
    iteration from a fixed vector; NaN rows where LU meets an exact zero pivot."""
    x = np.broadcast_to(PROBE[: S.shape[1], None], (len(S), S.shape[1], 1))
    try:
        for _ in range(2):
            x = np.linalg.solve(S, x)
            x = x / np.linalg.norm(x, axis=1, keepdims=True)
        return x[:, :, 0]
    except np.linalg.LinAlgError:  # one by one, to find the matrix that is singular to rounding
        if len(S) == 1:
            return np.full((1, S.shape[1]), np.nan)
        return np.concatenate([null_vectors(s[None]) for s in S])


def two_roots(S: np.ndarray) -> np.ndarray:
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


def polished(f: np.ndarray, g: np.ndarray, u: np.ndarray, v: np.ndarray, steps: int = 3):
    """(u, v) after Newton steps on f(u, v) = g(u, v) = 0 (coefficients [i, j] of u^i v^j), real."""
    i, j = np.arange(f.shape[0]), np.arange(f.shape[1])
    k, m = np.arange(g.shape[0]), np.arange(g.shape[1])
    for _ in range(steps):

        def at(P, a, b):  # value, ∂u, ∂v
            pa, pb = u[:, None] ** a, v[:, None] ** b
            da = a * np.concatenate([np.zeros((len(u), 1)), pa[:, :-1]], 1)
            db = b * np.concatenate([np.zeros((len(v), 1)), pb[:, :-1]], 1)
            return (
                np.einsum("ra,ab,rb->r", pa, P, pb),
                np.einsum("ra,ab,rb->r", da, P, pb),
                np.einsum("ra,ab,rb->r", pa, P, db),
            )

        F, Fu, Fv = at(f, i, j)
        G, Gu, Gv = at(g, k, m)
        det = Fu * Gv - Fv * Gu
        det = np.where(det == 0, np.inf, det)
        u, v = u - (F * Gv - Fv * G) / det, v - (Fu * G - F * Gu) / det
    return u, v


@cache
def _linearisation(degs: tuple):
    """Index structure of the row linearisation for row degrees `degs`: the shift equations
    z_{i,k+1} = u z_{i,k} (rows, columns of z_{i,k}) and each row's block (offset, degree)."""
    offs = np.concatenate([[0], np.cumsum(degs)])
    cols = np.concatenate([offs[i] + np.arange(d - 1) for i, d in enumerate(degs)]).astype(int)
    return np.arange(len(cols)), cols, [(int(offs[i]), d) for i, d in enumerate(degs)]


def hidden_variable(f: np.ndarray, g: np.ndarray, rng, singular_ok: bool = True) -> np.ndarray:
    """All u with f(u, v) = g(u, v) = 0 for some v (coefficients [i, j] of u^i v^j): the zeros of
    the Sylvester matrix in v, a matrix polynomial in u whose rows have the degrees of f and g,
    linearised by rows (size Σ row degrees = the resultant's degree bound). Where the pencil is
    singular (f and g share a curve) its regular part's eigenvalues are returned, or, with
    singular_ok=False, Degenerate is raised."""
    df, dg = f.shape[1] - 1, g.shape[1] - 1
    N = df + dg
    dtype = np.result_type(f, g, float)  # complex where the pose's image is complex
    rows = []  # (coefficients in u (d+1, N)) per row
    for r in range(dg):
        row = np.zeros((f.shape[0], N), dtype)
        row[:, r : r + df + 1] = f
        rows.append(row)
    for r in range(df):
        row = np.zeros((g.shape[0], N), dtype)
        row[:, r : r + dg + 1] = g
        rows.append(row)
    degs = tuple(len(r) - 1 for r in rows)
    if min(degs) < 1:
        raise Degenerate("a Sylvester row is constant in the hidden variable")
    shift_rows, shift_cols, blocks = _linearisation(degs)
    size = sum(degs)
    A = np.zeros((size, size), dtype)
    B = np.zeros((size, size), dtype)
    A[shift_rows, shift_cols + 1] = 1.0
    B[shift_rows, shift_cols] = 1.0
    for (lo, d), row in zip(blocks, rows):  # the last N rows: Σ_i row_i(u)ᵀ w_i = 0
        A[size - N :, lo : lo + d] = -row[:d].T
        B[size - N :, lo + d - 1] = row[d]
    lead_cols = [lo + d - 1 for lo, d in blocks]
    lead = B[size - N :, lead_cols]  # B is I plus this block, permuted
    if np.linalg.cond(lead, 1) < LEAD_COND:  # then the pencil is regular (det has its full degree)
        M = np.zeros((size, size), dtype)  # B⁻¹A: the shift rows as they are, lead⁻¹ times the last N rows
        M[shift_cols, shift_cols + 1] = 1.0
        M[lead_cols] = np.linalg.solve(lead, A[size - N :])
        return eigenvalues(M)
    z = np.exp(2j * np.pi * rng.random())  # a random point on the unit circle
    sv = np.linalg.svd(np.stack([z ** np.arange(len(r)) @ r for r in rows]), compute_uv=False)
    deficit = int(np.count_nonzero(sv <= 1e-11 * sv[0]))
    if deficit:  # f and g share a curve: the resultant vanishes identically
        if not singular_ok:
            raise Degenerate("f and g have a common factor")
        return _regular_eigenvalues(A, B, deficit, rng)
    w = scipy.linalg.eigvals(A, B)
    return w[np.isfinite(w)]


def eigenvalues(M: np.ndarray) -> np.ndarray:
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


# ----------------------------------------------------------------------------- matrix polynomials
NULL_TOL = 1e-9  # singular values of M(±i) under this fraction of the largest span its null space
EXACT = 1e-8  # the largest remainder of a division, relative to M, that still counts as exact
_ONE_PLUS = np.array([1.0, 0.0, 1.0])  # 1 + τ²


def _real_null(A: np.ndarray) -> np.ndarray:
    """A real basis (n, r) of the real vectors v with A v = 0 (A complex, m × n)."""
    B = np.vstack([A.real, A.imag])
    _, s, Vt = np.linalg.svd(B)
    rank = int(np.count_nonzero(s > NULL_TOL * s[0])) if s.size and s[0] > 0 else 0
    return Vt[rank:].T


class Linearisation:
    """The column operations and degrees for one kind of M(τ) (degree D, n × n): `columns` are,
    per final column, (N_c (deg + 1, n) coefficients of τ^j, e_c): column c is M·N_c/(1 + τ²)^e_c."""

    def __init__(self, degree: int, n: int, columns: list[tuple[np.ndarray, int]]):
        self.degree, self.n = degree, n
        divided = any(e for _, e in columns)
        # G maps a row of M (coefficients (D + 1) × n, row-major) to the row's final columns'
        # coefficients (Σ (δ_c + 1)); R to the divisions' remainders
        blocks, rems, deg = [], [], []
        for N, e in columns:
            div = poly.polypow(_ONE_PLUS, e) if e else np.array([1.0])
            quo, rem = [], []
            for p in range(degree + 1):
                for j in range(n):
                    num = np.convolve(np.eye(degree + 1)[p], N[:, j])
                    q, r = poly.polydiv(np.pad(num, (0, max(0, len(div) - len(num)))), div)
                    quo.append(q)
                    rem.append(np.pad(r, (0, max(0, len(div) - 1 - len(r))))[: max(len(div) - 1, 1)])
            width = max(len(q) for q in quo)
            # the final degree: the highest power with a coefficient in the map
            Q = np.array([np.pad(q, (0, width - len(q))) for q in quo])
            nz = np.flatnonzero(np.abs(Q).max(axis=0) > 0)
            d = int(nz[-1]) if len(nz) else 0
            blocks.append(Q[:, : d + 1])
            rems.append(np.array(rem))
            deg.append(d)
        self.degrees = np.array(deg)
        self.G = np.concatenate(blocks, axis=1)
        self.size = int(self.degrees.sum())
        self.R = np.concatenate(rems, axis=1) if divided else None
        off = np.concatenate([[0], np.cumsum(self.degrees + 1)])
        self._top = off[1:] - 1  # each column's leading coefficient in G's output
        self._low = np.concatenate([np.arange(off[c], off[c + 1] - 1) for c in range(n)])
        state = np.concatenate([[0], np.cumsum(self.degrees)])
        self._rows = state[1:] - 1  # the state rows the leading coefficients solve for
        shift = np.concatenate([np.arange(state[c], state[c + 1] - 1) for c in range(n)])
        self._shift = (shift, shift + 1)

    @property
    def removed(self) -> int:
        """The factors (1 + τ²) divided out of the determinant."""
        return (self.degree * self.n - self.size) // 2

    @staticmethod
    def plain(degree: int, n: int) -> Linearisation:
        """No columns divided: the block companion form ((degree · n) states)."""
        return Linearisation(degree, n, [(np.eye(n)[None, c], 0) for c in range(n)])

    @staticmethod
    def of(M: np.ndarray, limit: int) -> Linearisation:
        """The operations found on M (D + 1, n, n), at most `limit` divisions."""
        D, n = M.shape[0] - 1, M.shape[1]
        cols = [M[:, :, c].copy() for c in range(n)]  # the current columns' coefficients (deg + 1, n)
        ops = [(np.eye(n)[None, c], 0) for c in range(n)]
        ipow = 1j ** np.arange(2 * D + 2)
        for _ in range(limit):
            Mi = np.stack([ipow[: len(c)] @ c for c in cols], axis=1)
            W = _real_null(Mi)
            if W.shape[1] == 0:
                break
            v = W[:, 0]
            degs = np.array([len(c) - 1 for c in cols])
            support = np.flatnonzero(np.abs(v) > NULL_TOL * np.abs(v).max())
            pivot = support[np.argmax(degs[support])]
            width = max(len(cols[c]) for c in support)
            comb = sum(v[c] * np.pad(cols[c], ((0, width - len(cols[c])), (0, 0))) for c in support)
            quo, rem = _divide(comb)
            if np.abs(rem).max() > EXACT * np.abs(comb).max():
                break
            E = max(ops[c][1] for c in support)
            width = max(len(ops[c][0]) + 2 * (E - ops[c][1]) for c in support)
            N = np.zeros((width, n))
            for c in support:
                Nc = ops[c][0]
                for _ in range(E - ops[c][1]):
                    Nc = np.array([np.convolve(_ONE_PLUS, Nc[:, j]) for j in range(n)]).T
                N[: len(Nc)] += v[c] * Nc
            cols[pivot], ops[pivot] = quo, (N, E + 1)
        return Linearisation(D, n, ops)

    def companion(self, M: np.ndarray) -> np.ndarray | None:
        """The real companion matrix (size, size) of M (D + 1, n, n) after the column operations,
        or None where a division is not exact for this M or the leading column coefficients are
        singular."""
        rows = M.transpose(1, 0, 2).reshape(self.n, -1)  # row r: (p, j) row-major
        if self.R is not None and np.abs(rows @ self.R).max() > EXACT * np.abs(rows).max():
            return None
        F = rows @ self.G
        _, _, A, info = lapack.dgesv(F[:, self._top], F[:, self._low])
        if info or not np.isfinite(A).all():
            return None
        K = np.zeros((self.size, self.size))
        K[self._shift] = 1.0
        K[self._rows] = -A
        return K


def _divide(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quotient and remainder of the polynomial vector c (deg + 1, n) by 1 + τ²."""
    c = c.copy()
    d = len(c) - 1
    if d < 2:
        return np.zeros((1, c.shape[1])), c
    q = np.zeros((d - 1, c.shape[1]))
    for j in range(d, 1, -1):
        q[j - 2] = c[j]
        c[j - 2] -= c[j]
    return q, c[:2]
