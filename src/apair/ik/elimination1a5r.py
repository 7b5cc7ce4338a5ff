"""Every complex solution of a six-joint pose with one sinusoidal A-pair: the Raghavan–Roth
elimination with the A-pair's angle hidden, solved as one eigenproblem.

The generated kernels `ik1a5r_equations_k` (derivations/chain_ik1a5r.py, k = 1, 2, 3 the A-pair's
joint; a chain whose A-pair is joint 4, 5 or 6 is read from its end) give the 14 equations
P(C, S) X_{k+1,k+2} = Q X_right at the pose, (C, S) the A-pair's half angle. Per pose, as in
apair.ik.elimination6r:

1. Six combinations of the 14 rows free of X_right's eight non-constant monomials.
2. Charts: τ = tan((θ_k − σ_k)/4) for the A-pair (its angle lives in (−2π, 2π]: (C, S) is the
   half angle's point on the circle, each of its nine monomials times (1 + τ²)⁴ a polynomial of
   degree 8), x = tan((ψ − σ)/2) for joints k+1 and k+2; the six equations and their multiples by
   x_{k+1} make a 12 × 12 matrix polynomial M(τ) of degree 8 on the monomials x_{k+1}^i x_{k+2}^j
   (i ≤ 3, j ≤ 2).
3. det M(τ) = 0 has degree 96: 48 roots are solutions, 48 the spurious points τ = ±i (the
   isotropic points of the half angle's circle, 24 each). apair.ik.pencil divides 16 of those
   factors out of M's columns (operations found once per design: M(±i) depends on the design
   alone), so the eigenproblem is 64 × 64 (16 spurious eigenvalues left); the plain 96 × 96
   block companion where that does not certify.
4. The monomial vectors x_{k+1}^i x_{k+2}^j by inverse iteration on M(τ) at each eigenvalue, the
   right pair by least squares, the eliminated joint from the first column of its rotation, then
   Newton on the homotopy system (apair.ik.homotopy.newton).

Certified complete when every candidate that could be real (|Im θ_A| ≤ NEAR_REAL) has
Newton-converged and the converged ones are distinct. A real solution has a real eigenvalue τ,
never one of the spurious ones near ±i, so it is among the candidates; candidates far out (near
τ = ±i, solutions of near-degenerate designs such as two almost parallel axes) are not real, and
where Newton cannot verify them in double precision they are returned unrefined. 48 is the
pattern's generic count (`apair show ik_counts`), which bounds the isolated solutions of every
design; the elimination's degree says the same (96 less 48 spurious). Otherwise (Q
rank-deficient, a singular leading coefficient, spurious roots not where they belong, a root
that could be real not converging, or doubled: singular poses, designs with a double root) None,
and the caller tracks the homotopy.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import polynomial as poly
from scipy.linalg import lapack

from .. import kernels
from .elimination6r import EMBED, RANK_TOL, angle_of, chart, cos_sin, reversed_chain, verified
from .pencil import Linearisation

COUNT = 48
ROWS = 14
SIGMA = (0.4142, -0.7071, 0.5773)  # the charts' turns of θ_k, ψ_{k+1}, ψ_{k+2} [rad] (fixed, generic)
SPURIOUS_TOL = 1e-2  # |τ ∓ i| / (1 + |τ|) within which the spurious eigenvalues must lie (clusters
# of multiplicity four spread as the fourth root of rounding)
NEAR_REAL = 2.0  # candidates with |Im θ_A| up to this must converge; those beyond are not real
DEGREE = 8
SIZE = 12 * DEGREE


def _a_chart(sigma: float) -> np.ndarray:
    """(1, C, …, C⁴, S, S C, …, S C³) · (1 + τ²)⁴ on (1, τ, …, τ⁸), (C, S) = (cos, sin)(θ/2),
    τ = tan((θ − σ)/4)."""
    c, s = np.cos(sigma / 2), np.sin(sigma / 2)
    C = np.array([c, -2 * s, -c])  # (1 + τ²)·cos(σ/2 + γ), γ = 2 atan τ
    S = np.array([s, 2 * c, -s])
    one = np.array([1.0, 0, 1])
    rows = []
    for i, j in [(i, 0) for i in range(5)] + [(i, 1) for i in range(4)]:
        p = np.array([1.0])
        for f in [C] * i + [S] * j + [one] * (4 - i - j):
            p = poly.polymul(p, f)
        rows.append(p)
    return np.array(rows)


H_A = _a_chart(SIGMA[0])
H_R = np.kron(chart(SIGMA[1]), chart(SIGMA[2]))
_EMBED = EMBED
# a row on A_BASIS ⊗ X (81) → its coefficients of τ^p and its two embeddings (p, e, 12)
_MATRIX_POLY = np.einsum("kp,mn,enc->kmpec", H_A, H_R, _EMBED).reshape(81, (DEGREE + 1) * 24)
_PROBE = np.random.default_rng(1).standard_normal((12, 1))  # inverse iteration's start (fixed, generic)


def applies(problem) -> bool:
    """Whether the problem (virtual joints included) has six joints, one an A-pair, the others R-pairs."""
    return problem.n == 6 and int(np.count_nonzero(problem.kind == 1)) == 1 and not np.any(problem.kind > 1)


def _rotations(psi: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """Rz(ψ)·Rx(α) (..., 3, 3) at complex ψ (...,)."""
    c, s = np.cos(psi), np.sin(psi)
    ca, sa = np.cos(alpha), np.sin(alpha)
    R = np.zeros(psi.shape + (3, 3), complex)
    R[..., 0, 0], R[..., 0, 1], R[..., 0, 2] = c, -s * ca, s * sa
    R[..., 1, 0], R[..., 1, 1], R[..., 1, 2] = s, c * ca, -c * sa
    R[..., 2, 1], R[..., 2, 2] = sa, ca
    return R


_PLAIN = Linearisation.plain(DEGREE, 12)
_LINEARISATIONS: dict = {}


def _linearisation(key, M: np.ndarray) -> Linearisation:
    """The column divisions of M(τ) for a design (found at its first pose: M(±i) depends on the
    design alone), at most the 24 factors (1 + τ²) the spurious eigenvalues make; the plain form
    for a design where they failed once (`_demote`)."""
    lin = _LINEARISATIONS.get(key)
    if lin is None:
        lin = Linearisation.of(M, (SIZE - COUNT) // 2)
        if lin.degrees.min() < 1 or (lin.size - COUNT) % 2:
            lin = _PLAIN
        if len(_LINEARISATIONS) >= 64:
            _LINEARISATIONS.clear()
        _LINEARISATIONS[key] = lin
    return lin


def _key(dh: np.ndarray, h: float, k: int):
    return k, h, dh.tobytes()


def eliminate(dh: np.ndarray, h: float, k: int, T: np.ndarray, plain: bool = False) -> np.ndarray | None:
    """The 48 candidate angle vectors θ (48, 6) complex of a six-joint chain (dh (6, 4), T (4, 4),
    one length unit) whose joint k (1, 2 or 3) is a sinusoidal A-pair of amplitude h, the others
    R-pairs; None where the elimination does not apply (see the module). The eigenproblem is the
    design's deflated one (apair.ik.pencil, 64 × 64 for generic designs), or with `plain` the
    96 × 96 block companion."""
    P, Q = kernels.call(f"ik1a5r_equations_{k}", dh, np.array([h]), T)
    P = P.reshape(ROWS, 81)
    P[:, 0] -= Q[:, 0]  # the constant monomial goes to the left side
    U, sv, Vt, info = lapack.dgesdd(Q[:, 1:])
    if info or not sv[-1] > RANK_TOL * sv[0]:  # (NaN included)
        return None
    M = (U[:, 8:].T @ P @ _MATRIX_POLY).reshape(6, DEGREE + 1, 2, 12).transpose(1, 2, 0, 3).reshape(DEGREE + 1, 12, 12)
    lin = _PLAIN if plain else _linearisation(_key(dh, h, k), M)
    K = lin.companion(M)
    if K is None and lin.removed:  # this pose's M not divisible as the design's first one was
        lin = _PLAIN
        K = lin.companion(M)
    if K is None:  # the leading coefficients singular
        return None
    wr, wi, _, _, info = lapack.dgeev(K, compute_vl=0, compute_vr=0)
    if info:
        return None
    tau, spur = wr + 1j * wi, lin.size - COUNT
    near = np.minimum(np.abs(tau - 1j), np.abs(tau + 1j)) / (1 + np.abs(tau))
    order = np.argpartition(near, spur)
    spurious, keep = order[:spur], order[spur:]
    if np.any(near[spurious] > SPURIOUS_TOL) or np.count_nonzero(tau[spurious].imag > 0) != spur // 2:
        return None
    # the monomial vectors: M(τ)'s null vectors by one step of inverse iteration at the eigenvalue
    # (as accurate as the companion's eigenvectors, a sixth of the cost)
    tau = tau[keep]
    Mt = ((tau[:, None] ** np.arange(DEGREE + 1)) @ M.reshape(DEGREE + 1, 144)).reshape(COUNT, 12, 12)
    try:
        with np.errstate(all="ignore"):
            V = np.linalg.solve(Mt, np.broadcast_to(_PROBE, (COUNT, 12, 1)))[..., 0]
    except np.linalg.LinAlgError:  # some M(τ) exactly singular in floating point: its null vectors by SVD
        V = np.conj(np.linalg.svd(Mt)[2][:, -1, :])
    L = (U[:, :8] / sv) @ Vt  # (14, 8): X_right (without its constant) by least squares
    return angles(tau, V, P, L, dh, k, T)


def _split(k: int) -> tuple[tuple[int, int], int, tuple[int, int]]:
    """(joints k+1, k+2), the eliminated joint k+3, (the right pair r1 < r2): 1-based, as the kernels'."""
    r1, r2 = sorted(set(range(1, 7)) - {k, k + 1, k + 2, k + 3})
    return (k + 1, k + 2), k + 3, (r1, r2)


def angles(
    tau: np.ndarray, vecs: np.ndarray, P: np.ndarray, L: np.ndarray, dh: np.ndarray, k: int, T: np.ndarray
) -> np.ndarray:
    """θ (m, 6) from m eigenvalues τ (m,) and their monomial vectors (m, 12): step 4."""
    (m1, m2), e, (r1, r2) = _split(k)
    m = len(tau)
    V = vecs.reshape(m, 4, 3)  # x_{k+1}^i x_{k+2}^j
    x1 = np.sum(np.conj(V[:, :-1, :]) * V[:, 1:, :], axis=(1, 2)) / np.sum(np.abs(V[:, :-1, :]) ** 2, axis=(1, 2))
    x2 = np.sum(np.conj(V[:, :, :-1]) * V[:, :, 1:], axis=(1, 2)) / np.sum(np.abs(V[:, :, :-1]) ** 2, axis=(1, 2))
    theta_k = SIGMA[0] + 4 * np.arctan(tau)
    psi = np.zeros((m, 6), complex)
    psi[:, k - 1] = theta_k + dh[k - 1, 3]
    psi[:, m1 - 1] = SIGMA[1] + 2 * np.arctan(x1)
    psi[:, m2 - 1] = SIGMA[2] + 2 * np.arctan(x2)
    C, S = np.cos(theta_k / 2), np.sin(theta_k / 2)
    basis = np.stack([C**i * S**j for i, j in [(i, 0) for i in range(5)] + [(i, 1) for i in range(4)]], 1)
    cs = cos_sin(psi[:, [m1 - 1, m2 - 1]])
    X = np.einsum("ki,kj->kij", cs[:, 0], cs[:, 1]).reshape(m, 9)
    XR: np.ndarray = np.ones((m, 9), complex)  # (1, c, s)_{r1} ⊗ (1, c, s)_{r2}, the rest by least squares
    XR[:, 1:] = (basis[:, :, None] * X[:, None, :]).reshape(m, 81) @ P.T @ L
    XR = XR.reshape(m, 3, 3)
    # XR = a bᵀ, a = (1, c, s)_{r1}, b = (1, c, s)_{r2}: a from its largest column, b from its
    # largest row (far-out roots have entries of very different sizes, e^|Im ψ|)
    rows = np.arange(m)
    col = np.argmax(np.sum(np.abs(XR) ** 2, axis=1), axis=1)
    row = np.argmax(np.sum(np.abs(XR) ** 2, axis=2), axis=1)
    a = XR[rows, :, col] / XR[rows, 0, col][:, None]
    b = XR[rows, row, :] / XR[rows, row, 0][:, None]
    psi[:, r1 - 1] = angle_of(a[:, 1], a[:, 2])
    psi[:, r2 - 1] = angle_of(b[:, 1], b[:, 2])
    # the eliminated joint: the first column (cos ψ_e, sin ψ_e, 0) of R_e = Rz(ψ_e)·Rx(α_e), from
    # A_e = (A_k A_{k+1} A_{k+2})⁻¹ · A_{k−1}⁻¹ … A_1⁻¹ · T · A_6⁻¹ … A_{k+4}⁻¹
    R = _rotations(psi, dh[:, 1])
    v = np.zeros((m, 3), complex)
    v[:, 0] = 1
    transpose = lambda i, x: np.einsum("kji,kj->ki", R[:, i - 1], x)
    for i in range(k + 4, 7):
        v = transpose(i, v)
    v = v @ T[:3, :3].T
    for i in (*range(1, k), k, m1, m2):
        v = transpose(i, v)
    psi[:, e - 1] = angle_of(v[:, 0], v[:, 1])
    return psi - dh[:, 3]


def solve(problem, T: np.ndarray) -> np.ndarray | None:
    """Every complex solution θ (48, 6) of the problem (apair.ik.homotopy.Problem, one A-pair, virtual
    joints included) at the pose T (4 × 4, the chain's units): distinct, each Newton-converged on
    the homotopy system; None where the elimination does not certify them (see the module)."""
    pose = problem.pose(T)
    a = int(np.flatnonzero(problem.kind)[0]) + 1
    h = float(problem.pair[a - 1, 0])
    if a <= 3:
        dh, k, Tk = problem.dh, a, pose
    else:  # read from the end: joint a becomes 7 − a, θ' = −θ reversed, φ' = −φ, amplitude −h
        dh, Tk = reversed_chain(problem.dh, pose)
        dh[:, 3] = -problem.dh[::-1, 3]
        k, h = 7 - a, -h
    for plain in (False, True):  # the deflated eigenproblem; where it does not certify, the plain one
        theta = eliminate(dh, h, k, Tk, plain)
        if theta is not None and a > 3:
            theta = -theta[:, ::-1]
        if theta is not None:
            # candidates that could be real must converge; those far out (|Im θ_A| > NEAR_REAL) are not real
            theta = verified(problem, theta, pose, COUNT, must=~(np.abs(theta[:, a - 1].imag) > NEAR_REAL))
        if theta is not None:
            if plain:  # the design's deflation failed here: the plain form from now on
                _LINEARISATIONS[_key(dh, h, k)] = _PLAIN
            return theta
        if _LINEARISATIONS.get(_key(dh, h, k)) is _PLAIN:
            break
    return None
