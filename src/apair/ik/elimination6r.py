"""Every complex solution of a general 6R pose at once: the Raghavan–Roth elimination, solved as
Manocha and Canny's eigenproblem.

The generated kernel `ik6r_equations` (derivations/chain_ik6r.py) gives the 14 equations
P(ψ3) X45 = Q X12 at the pose. Here, per pose:

1. Six combinations of the 14 rows free of X12's eight non-constant monomials (the left null space
   of those eight columns of Q).
2. Half-angle charts x_k = tan((ψ_k − σ_k)/2), k = 3, 4, 5, each turned by a fixed generic σ_k so
   that no solution sits at a chart's infinity; the six equations become Σ(x3) · x4^i x5^j = 0
   (i, j ≤ 2), and with their multiples by x4 a 12 × 12 matrix polynomial M(x3) of degree 2 acting
   on the 12 monomials x4^i x5^j (i ≤ 3, j ≤ 2).
3. det M(x3) = 0 as a 24 × 24 eigenproblem (the companion form of M2⁻¹ M(x3)): 16 eigenvalues
   are solutions, 8 are the spurious factor (1 + x3²)⁴ (x3 = ±i, e^{iψ3} = 0 or ∞, four each).
4. The eigenvectors are the monomial vectors: x4, x5 are ratios of their entries; X12 follows
   from the 14 equations by least squares, ψ6 from the first column of (A1 … A5)⁻¹ T (in C,
   apair_ik6r_angles, where the kernels are installed).
5. Every solution takes Newton steps on the homotopy system (ik_system6, complex; in C,
   apair_ik_newton, where the kernels are installed).

Where the compiled kernels are installed, `solve` runs all of it in one C call (apair_ik6r_solve,
with SciPy's LAPACK passed in); the NumPy steps here are its twin and the fallback.

The answer is certified complete when 16 distinct solutions come out regular with Newton
converged: no design has more than 16 isolated solutions at a pose (the generic count bounds the
isolated solutions of every member of a parameterised family, and 16 is the generic 6R count).
Where Q loses rank (axes 1 and 2 parallel, say) the chain is read from its end
(`reversed_chain`). Anything else — Q rank-deficient both ways, a singular M2, the spurious roots
not where they belong, a root that does not converge, one lost or doubled (designs with fewer
than 16 solutions, singular poses) — returns None, and the caller tracks the homotopy instead.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import lapack

from .. import kernels
from ..kernels import native_in_use
from .homotopy.problem import target_of
from .homotopy.tracker import newton

SIGMA = (0.4142, -0.7071, 0.5773)  # the charts' turns of ψ3, ψ4, ψ5 [rad] (fixed, generic)
_SIGMA = np.array(SIGMA)
COUNT = 16
ROWS = 14  # the Raghavan–Roth equations
RANK_TOL = 1e-9  # Q's eight columns are degenerate where their singular values span more than 1/RANK_TOL
SPURIOUS_TOL = 1e-3  # |x3 ∓ i| / (1 + |x3|) within which the eight spurious eigenvalues must lie
NEWTON = 8  # Newton steps at most per solution (roots far out, near the spurious ±i, start worse)
STALL = 0.25  # a step above this fraction of the one before no longer contracts
CONVERGED = 1e-8  # a Newton step [rad] under which a root has converged (the elimination gives ~1e-12)
ACCURATE = 1e-6  # the largest last step [rad] of a root that stalls at rounding level (large |Im θ|)
IMAG_MAX = 30.0  # |Im θ| beyond which a root is too near infinity to verify in double precision
SEPARATION = 1e3  # distinct roots must be this many last steps apart
SAME = 1e-6  # two solutions closer than this [rad] (modulo 2π) are one


def chart(sigma: float) -> np.ndarray:
    """(1, cos ψ, sin ψ) · (1 + x²) on the basis (1, x, x²), x = tan((ψ − σ)/2)."""
    c, s = np.cos(sigma), np.sin(sigma)
    one, cos_, sin_ = np.array([1.0, 0, 1]), np.array([1.0, 0, -1]), np.array([0.0, 2, 0])
    return np.array([one, c * cos_ - s * sin_, c * sin_ + s * cos_])


H3 = chart(SIGMA[0])
H45 = np.kron(chart(SIGMA[1]), chart(SIGMA[2]))  # X45 -> x4^i x5^j (i, j ≤ 2), row-major
# Σ · x4^i x5^j (i, j ≤ 2) and x4 · the same, on the 12 monomials x4^i x5^j (i ≤ 3, j ≤ 2)
EMBED = np.zeros((2, 9, 12))
for _i in range(3):
    for _j in range(3):
        EMBED[0, 3 * _i + _j, 3 * _i + _j] = 1
        EMBED[1, 3 * _i + _j, 3 * (_i + 1) + _j] = 1
_COMPANION = np.eye(24, k=12)  # [[0, I], [−M2⁻¹M0, −M2⁻¹M1]], the lower half filled per pose
# a row on (1, c3, s3) ⊗ X45 (27) → its coefficients of x3^p and its two embeddings (p, e, 12): the
# charts and the embeddings in one linear map
_MATRIX_POLY = np.einsum("kp,mn,enc->kmpec", H3, H45, EMBED).reshape(27, 72)


def cos_sin(psi: np.ndarray) -> np.ndarray:
    """(1, cos ψ, sin ψ) (..., 3) at complex ψ."""
    out = np.empty(psi.shape + (3,), complex)
    out[..., 0], out[..., 1], out[..., 2] = 1, np.cos(psi), np.sin(psi)
    return out


def angle_of(c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The complex ψ with (cos ψ, sin ψ) ∝ (c, s), near-unit (c, s) taken as exact."""
    return -1j * np.log((c + 1j * s) / np.sqrt(c * c + s * s))


def _complex_vectors(wi: np.ndarray, vr: np.ndarray) -> np.ndarray:
    """The complex eigenvectors from LAPACK's real form: for a pair wi[j] > 0 = −wi[j+1], columns
    j and j + 1 are the real and imaginary parts of the vector of eigenvalue j (its conjugate is
    eigenvalue j + 1's)."""
    v = vr.astype(complex)
    j = np.flatnonzero(wi > 0)
    v[:, j] += 1j * vr[:, j + 1]
    v[:, j + 1] = np.conj(v[:, j])
    return v


def eliminate(dh: np.ndarray, T: np.ndarray, engine: str | None = None) -> np.ndarray | None:
    """The 16 candidate angle vectors θ (16, 6) complex of a 6R chain (dh (6, 4), T (4, 4), both in
    one length unit), before Newton; None where the elimination does not apply (see the module).
    engine: of the back-substitution (`angles`)."""
    P, Q = kernels.call("ik6r_equations", dh, T)
    P = P.reshape(ROWS, 27)
    P[:, 0] -= Q[:, 0]  # the constant monomial goes to the left side
    # LAPACK directly (scipy.linalg.lapack): NumPy's wrappers cost more than these small problems
    U, sv, Vt, info = lapack.dgesdd(Q[:, 1:])
    if info or not sv[-1] > RANK_TOL * sv[0]:  # (NaN included)
        return None
    # six rows free of X12, as M(x3) = Σ_p x3^p M[p] (3, 12, 12): row (e, a) is row a, times x4 if e = 1
    M = (U[:, 8:].T @ P @ _MATRIX_POLY).reshape(6, 3, 2, 12).transpose(1, 2, 0, 3).reshape(3, 12, 12)
    _, _, A, info = lapack.dgesv(M[2], np.concatenate([M[0], M[1]], axis=1))
    if info or not np.isfinite(A).all():  # M2 singular
        return None
    K = _COMPANION.copy()
    K[12:] = -A
    wr, wi, _, vr, info = lapack.dgeev(K, compute_vl=0)
    if info:
        return None
    x3, vecs = wr + 1j * wi, _complex_vectors(wi, vr)  # vecs[:, k] = [m; x3 m], m = x4^i x5^j (i ≤ 3, j ≤ 2)
    # the spurious eigenvalues: four at +i, four at −i
    near = np.minimum(np.abs(x3 - 1j), np.abs(x3 + 1j)) / (1 + np.abs(x3))
    order = np.argpartition(near, 8)
    spurious, keep = order[:8], order[8:]
    if np.any(near[spurious] > SPURIOUS_TOL) or np.count_nonzero(x3[spurious].imag > 0) != 4:
        return None
    L = (U[:, :8] / sv) @ Vt  # (14, 8): X12 (without its constant) from the 14 equations by least squares
    return angles(x3[keep], vecs[:, keep].T, P, L, dh, T, engine=engine)


def angles(
    x3: np.ndarray,
    vecs: np.ndarray,
    P: np.ndarray,
    L: np.ndarray,
    dh: np.ndarray,
    T: np.ndarray,
    engine: str | None = None,
) -> np.ndarray:
    """θ (k, 6) from k eigenpairs (x3 (k,), vecs (k, 24)) of the companion matrix: step 4 of the
    module. In C (apair_ik6r_angles) where installed, else NumPy."""
    native = native_in_use() if engine in (None, "c") else None
    if native is not None:
        return native.ik6r_angles(x3, np.ascontiguousarray(vecs), P, L, _SIGMA, dh, T)
    if engine == "c":
        raise RuntimeError("engine: the compiled C kernels are not installed")
    count = len(x3)
    # the monomial vector: the half of [v; x3 v] with the larger norm
    top = np.abs(x3) <= 1
    V = np.where(top[:, None], vecs[:, :12], vecs[:, 12:]).reshape(count, 4, 3)  # [sol, i (x4), j (x5)]
    x4 = np.sum(np.conj(V[:, :-1, :]) * V[:, 1:, :], axis=(1, 2)) / np.sum(np.abs(V[:, :-1, :]) ** 2, axis=(1, 2))
    x5 = np.sum(np.conj(V[:, :, :-1]) * V[:, :, 1:], axis=(1, 2)) / np.sum(np.abs(V[:, :, :-1]) ** 2, axis=(1, 2))
    psi = np.zeros((count, 6), complex)
    psi[:, 2] = SIGMA[0] + 2 * np.arctan(x3)
    psi[:, 3] = SIGMA[1] + 2 * np.arctan(x4)
    psi[:, 4] = SIGMA[2] + 2 * np.arctan(x5)
    cs = cos_sin(psi[:, 2:5])
    X45 = np.einsum("ki,kj->kij", cs[:, 1], cs[:, 2]).reshape(count, 9)
    rhs = (cs[:, 0, :, None] * X45[:, None, :]).reshape(count, 27) @ P.T  # P(ψ3) X45: (k, 14)
    X12 = rhs @ L  # (k, 8)
    # X12 = (1, c1, s1) ⊗ (1, c2, s2): index 3 c1, 6 s1, 1 c2, 2 s2 (minus one: the constant is gone)
    psi[:, 0] = angle_of(X12[:, 2], X12[:, 5])
    psi[:, 1] = angle_of(X12[:, 0], X12[:, 1])
    # ψ6: A_6's first column (cos ψ6, sin ψ6, 0) = R_5ᵀ … R_1ᵀ T e_x, each R_i = Rz(ψ_i)·Rx(α_i)
    u0, u1, u2 = (np.full(count, T[k, 0], complex) for k in range(3))
    c, s = np.cos(psi[:, :5]).T, np.sin(psi[:, :5]).T
    for i in range(5):
        ca, sa = math.cos(dh[i, 1]), math.sin(dh[i, 1])
        u0, u1 = c[i] * u0 + s[i] * u1, c[i] * u1 - s[i] * u0
        u1, u2 = ca * u1 + sa * u2, ca * u2 - sa * u1
    psi[:, 5] = angle_of(u0, u1)
    return psi - dh[:, 3]


def reversed_chain(dh: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The chain read from its end, (dh', T') with ψ'_j = −ψ_{6−j} (1-based; φ' = 0): A_i⁻¹ =
    Rx(−α_i)·Tx(−a_i)·Tz(−c_i)·Rz(−ψ_i), regrouped as T⁻¹ = Rx(−α6)·Tx(−a6) · Π_{k=6..1}
    Rz(−ψ_k)·Tz(−c_k)·Tx(−a_{k−1})·Rx(−α_{k−1}) (a_0 = α_0 = 0). Where the first two axes are
    parallel (Q rank-deficient) the last two usually are not."""
    a, alpha, c = dh[:, 0], dh[:, 1], dh[:, 2]
    prev = lambda x: np.concatenate([[0.0], x[:-1]])
    rev = np.stack([-prev(a), -prev(alpha), -c, np.zeros(6)], 1)[::-1]
    ca, sa = math.cos(alpha[5]), math.sin(alpha[5])
    base = np.array([[1, 0, 0, a[5]], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]])  # Tx(a6)·Rx(α6)
    Ti = np.eye(4)
    Ti[:3, :3] = T[:3, :3].T
    Ti[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return np.ascontiguousarray(rev), base @ Ti


def applies(problem) -> bool:
    """Whether the problem is a 6R chain (its own joints and the virtual ones all R-pairs)."""
    return problem.n == 6 and not np.any(problem.kind)


def solve(problem, T: np.ndarray, engine: str | None = None) -> np.ndarray | None:
    """Every complex solution θ (16, 6) of the 6R problem (apair.ik.homotopy.Problem, virtual joints
    included) at the pose T (4 × 4, the chain's units): distinct, each Newton-converged on the
    homotopy system; None where the elimination does not certify them (see the module). In one C
    call (apair_ik6r_solve) where installed, else (engine "numpy") the NumPy steps."""
    pose = problem.pose(T)
    native = native_in_use() if engine in (None, "c") else None
    if native is not None:
        return native.ik6r_solve(problem.kind, problem.pair, problem.dh, pose, _SIGMA)
    if engine == "c":
        raise RuntimeError("engine: the compiled C kernels are not installed")
    theta = eliminate(problem.dh, pose, engine)
    if theta is None:  # e.g. the first two axes parallel: read the chain from its end
        psi = eliminate(*reversed_chain(problem.dh, pose), engine)
        theta = None if psi is None else -psi[:, ::-1] - problem.dh[:, 3]
    return None if theta is None else verified(problem, theta, pose, COUNT, engine=engine)


def verified(
    problem, theta: np.ndarray, pose: np.ndarray, count: int, must: np.ndarray | None = None, engine: str | None = None
) -> np.ndarray | None:
    """The `count` candidates θ (count, 6) of an elimination after Newton on the homotopy system
    at the pose, or None unless every candidate in `must` (default: all) converged and the
    converged ones are distinct (then the set is complete where `count` is the pattern's generic
    count). A candidate outside `must` that does not converge is returned as it came."""
    must = np.ones(count, bool) if must is None else must
    if not np.all(np.abs(theta[must].imag) <= IMAG_MAX):  # (NaN included)
        return None
    refined, size = newton(problem, theta, target_of(pose), NEWTON, CONVERGED, ACCURATE, STALL, IMAG_MAX, engine)
    # large |Im θ| makes the system's entries large (e^|Im θ|) and Newton stalls at its rounding
    # level; a stalled root still counts when it is far from every other root
    ok = size <= ACCURATE
    if not np.all(ok[must]):
        return None
    # distinct: |e^{iθ} − e^{iθ'}| over the mean modulus is |θ − θ'| (mod 2π; an A-pair's half
    # angle, mod 4π) to first order
    z = np.exp(1j * refined[ok] * np.where(problem.kind == 1, 0.5, 1.0))
    m = np.abs(z)
    gap = np.max(np.abs(z[:, None] - z[None]) / (0.5 * (m[:, None] + m[None])), axis=-1)
    gap[np.diag_indices(len(z))] = np.inf
    if len(z) > 1 and not gap.min() > max(SAME, SEPARATION * size[ok].max()):
        return None
    return np.where(ok[:, None], refined, theta)
