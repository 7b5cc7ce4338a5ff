"""Poses as the solvers take them (a 4×4 transform or a Study point, validated), the joints'
periods and the angles' ranges, and the verification of candidates: Gauss-Newton refinement
against the pose, weighted by the chain's length scale, with duplicates merged (`refine`).
"""

from __future__ import annotations

import numpy as np

from .. import _validate as V
from ..study import from_matrix, normalise, to_matrix
from .homotopy.problem import scale_of


def joint_periods(chain) -> np.ndarray:
    """Each joint's period in θ: 2π for an R-pair, 4π for an A-pair (d changes sign at θ + 2π)."""
    return np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])


def with_twins(chain, q: np.ndarray, near: float = 1e-4) -> np.ndarray:
    """q (k, n) and, for each A-pair angle within `near` of ±π, the twin with the other sign: a
    sinusoidal pair's pose curve crosses itself there (Rz(±π)·Tz(h cos(±π/2)) is one pose), so
    two joint vectors give one pose. An elimination that solves for the right half's pose and
    then reads its angles back sees that pose once; the twin is its second preimage."""
    if len(q) == 0:
        return q
    periods = joint_periods(chain)
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


def wrap(theta, period):
    """θ into (−period/2, period/2]."""
    return theta - period * np.ceil((theta - period / 2) / period)


def study_point(T) -> np.ndarray:
    """A pose given as a 4×4 matrix or a Study point (8,), validated → a unit Study point."""
    T = V.real_array("T", T)
    if T.shape == (4, 4):
        return from_matrix(check_matrix(T))
    if T.shape == (8,):
        x, y = T[:4], T[4:]
        nx = np.linalg.norm(x)
        if nx == 0:
            raise ValueError("T: a Study point with x = 0 lies in the exceptional 3-space, not a pose")
        if abs(x @ y) > 1e-9 * nx * max(np.linalg.norm(y), nx):
            raise ValueError(f"T: not on the Study quadric (x·y = {x @ y:.3g})")
        return normalise(T)
    raise ValueError(f"T: expected a 4x4 transform or an 8-vector Study point, got shape {T.shape}")


def pose_matrix(T) -> np.ndarray:
    """A pose given as a 4×4 matrix (kept as given) or a Study point (8,), validated → 4×4."""
    A = V.real_array("T", T)
    return check_matrix(A) if A.shape == (4, 4) else matrix_of(study_point(A))


_LAST_ROW, _EYE3 = np.array([0.0, 0, 0, 1]), np.eye(3)
_LAST_TOL = 1e-12 + 1e-5 * _LAST_ROW


def check_matrix(T: np.ndarray) -> np.ndarray:
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


def matrix_of(T) -> np.ndarray:
    T = np.asarray(T, dtype=float)
    return T if T.shape == (4, 4) else to_matrix(normalise(T))


def refine(chain, q: np.ndarray, T: np.ndarray, tol: float):
    """Up to two Gauss-Newton steps on the pose error; keep what reproduces T to tol, merged."""
    if len(q) == 0:
        return q, np.zeros(0)

    e, err = pose_error(chain, q, T)
    for _ in range(2):
        if np.all(err <= 1e-3 * tol):
            break
        J = chain.jacobian(q) * error_weights(chain)
        step = np.einsum("kij,kj->ki", np.linalg.pinv(J, rcond=1e-12), e)
        q2 = q + step
        e2, err2 = pose_error(chain, q2, T)
        better = err2 < err
        q, e, err = np.where(better[:, None], q2, q), np.where(better[:, None], e2, e), np.where(better, err2, err)
    periods = joint_periods(chain)
    q = wrap(q, periods)
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


def jacobian_rank(chain, q: np.ndarray) -> np.ndarray:
    """Numerical rank of the Jacobian at each joint vector (k, n), scaled by the chain's size."""
    return np.linalg.matrix_rank(chain.jacobian(q) * error_weights(chain), tol=1e-8)


def error_weights(chain) -> np.ndarray:
    """(6, 1): the rows of a Jacobian or pose error made dimensionless (positions / scale)."""
    return np.array([1 / scale_of(chain)] * 3 + [1.0] * 3)[:, None]


def near_reach(chain, T: np.ndarray) -> bool:
    """Whether T's position is within the chain's crude reach bound (Σ |a| + |c| + 2h from the
    base): outside it no local search is needed to call the pose unreachable."""
    reach = sum(abs(a) + abs(c) + 2 * p.amplitude for a, c, p in zip(chain.a, chain.offset, chain.pairs))
    return bool(np.linalg.norm(T[:3, 3]) <= 1.01 * reach + 1e-9 * scale_of(chain))


def pose_error(chain, q: np.ndarray, T: np.ndarray):
    """(k, 6) pose error [Δp/scale; Δω] of fk(q) against T and (k,) the largest entry of the 4×4
    difference."""
    F = chain.fk(q)
    dp = (T[:3, 3] - F[:, :3, 3]) / scale_of(chain)
    S = T[:3, :3] @ np.swapaxes(F[:, :3, :3], 1, 2)  # Σ_k f_k × t_k = vee(T Fᵀ − F Tᵀ) (columns f_k, t_k)
    dw = 0.5 * np.stack([S[:, 2, 1] - S[:, 1, 2], S[:, 0, 2] - S[:, 2, 0], S[:, 1, 0] - S[:, 0, 1]], 1)
    return np.concatenate([dp, dw], 1), np.abs(F - T).max(axis=(1, 2))
