"""Poses as the solvers take them (a 4×4 transform or a Study point, validated and normalised:
`Pose`), the chain's length scale, the joints' periods and the angles' ranges, and the
verification of candidates: Gauss-Newton refinement against the pose, weighted by the chain's
length scale, with duplicates merged (`refine`).

Every tolerance on a translation is relative to the chain's length scale (`length_scale`), so a
chain scaled by s has the same solutions at the pose with its translation scaled by s, at any s
where its lengths are doubles (§2: 1e-150 … 1e150 m).
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V
from ..study import from_matrix, to_matrix

EPS64 = float(np.finfo(np.float64).eps)
HUGE = 1e300  # translations below this (in units of |x|) are computed without an overflow check
FLOOR_ULPS = 64  # a float32 pose is verified to this many of its ulps at least (7.6e-6)


def length_scale(chain) -> float:
    """The chain's size: its largest link length, offset or pair amplitude (1 where all are 0, a
    chain of R-pairs through one point). No floor: a nanometre chain is solved as a metre one."""
    lengths = [abs(float(x)) for x in (*chain.a, *chain.offset)] + list(_slides(chain, 1.0))
    return max(lengths) or 1.0


def _slides(chain, rise: float) -> list[float]:
    """Per joint the largest translation of its pair: `rise` times an A-pair's amplitude, |d| at
    the ends of a P-pair's range and |pitch θ| at those of an H-pair's (chain.limits)."""
    out = []
    for p, (lo, hi) in zip(chain.pairs, chain.limits):
        end = max(abs(float(lo)), abs(float(hi)))
        out.append(end if p.kind == "prismatic" else abs(p.pitch) * end if p.kind == "helical" else rise * p.amplitude)
    return out


def reach_of(chain) -> float:
    """A bound on the distance of the last frame's origin from the base: Σ |a| + |c| + 2h (the
    largest slide of a P- or H-pair for 2h)."""
    return float(sum(abs(a) + abs(c) + s for a, c, s in zip(chain.a, chain.offset, _slides(chain, 2.0))))


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


class Pose:
    """A validated pose: its 4×4 matrix, its unit Study point (8,), computed when first asked for
    (the closed forms need the matrix alone), and `floor`, the smallest verification tolerance its
    own precision supports (0 for float64; for float32, whose entries carry 7 digits, a chain of
    fewer than 6 joints reaches the rounded pose only to about 1e-7)."""

    def __init__(self, matrix: np.ndarray, floor: float = 0.0, study: np.ndarray | None = None) -> None:
        self.matrix, self.floor, self._study = matrix, floor, study

    @property
    def study(self) -> np.ndarray:
        if self._study is None:
            M = self.matrix
            if np.abs(M[:3, 3]).max() < HUGE:
                self._study = from_matrix(M)
            else:  # y = ½ t x sums products of t's entries: they may overflow
                with np.errstate(over="ignore", invalid="ignore"):
                    study = from_matrix(M)
                if not np.isfinite(study).all():
                    raise ValueError("T: the translation overflows a double in Study coordinates (entries near 1e308)")
                self._study = study
        return self._study


def pose_of(T) -> Pose:
    """A pose given as a 4×4 matrix or a Study point (8,), validated. A Study point is projective:
    any non-zero multiple is the same pose (normalised without overflow); a float32 pose is
    converted, its checks at float32 precision, its rotation made orthonormal."""
    eps = _precision(T)
    A = V.real_array("T", T)
    tol = max(1e-9, 64 * eps)  # the checks of the rotation and the Study quadric
    floor = 0.0 if eps <= EPS64 else FLOOR_ULPS * eps
    if A.shape == (4, 4):
        M = check_matrix(A, tol)
        if eps > EPS64:  # a rounded rotation: the nearest rotation, so that fk can reproduce it
            pose = Pose(M, floor)
            M = to_matrix(pose.study)
            M[:3, 3] = A[:3, 3]
            return Pose(M, floor, pose.study)
        return Pose(M, floor)
    if A.shape == (8,):
        study = _unit_study(A, tol)
        if np.abs(study[4:]).max() < HUGE:
            M = to_matrix(study)
        else:  # t = 2 y x̃ sums products of y's entries: they may overflow
            with np.errstate(over="ignore", invalid="ignore"):
                M = to_matrix(study)
            if not np.isfinite(M).all():
                raise ValueError("T: the Study point's translation 2·y·x̃ overflows a double")
        return Pose(M, floor, study)
    raise ValueError(f"T: expected a 4x4 transform or an 8-vector Study point, got shape {A.shape}")


def _precision(T) -> float:
    """The unit roundoff of T's floating type (float64's for lists, integers and wider types)."""
    dtype = getattr(T, "dtype", None)
    if dtype is None or dtype == np.float64 or np.dtype(dtype).kind != "f":
        return EPS64
    eps = float(np.finfo(dtype).eps)
    if eps > 1e-6:
        raise ValueError(f"T: {np.dtype(dtype).name} carries too few digits for a pose; give float32 or float64")
    return max(eps, EPS64)


def _unit_study(S: np.ndarray, tol: float) -> np.ndarray:
    """The Study point S (8,), any non-zero multiple, scaled to |x| = 1 without overflow or
    underflow (by its largest |x_i| first); checked on the Study quadric to tol."""
    mx = float(np.abs(S[:4]).max())
    if mx == 0:
        raise ValueError("T: a Study point with x = 0 lies in the exceptional 3-space, not a pose")
    x = S[:4] / mx
    nx = math.sqrt(float(x @ x))  # in [1, 2]
    with np.errstate(over="ignore"):
        y = S[4:] / mx / nx
    if not np.isfinite(y).all():
        ratio = math.log10(float(np.abs(S[4:]).max())) - math.log10(mx)
        raise ValueError(f"T: the Study point's translation overflows a double (|y|/|x| ≈ 1e{ratio:.0f})")
    x = x / nx
    with np.errstate(over="ignore", invalid="ignore"):
        xy, ny = float(x @ y), float(np.abs(y).max())
    if not abs(xy) <= tol * max(ny, 1.0):
        raise ValueError(f"T: not on the Study quadric (x·y = {xy:.3g} for |x| = 1)")
    return np.concatenate([x, y])


def study_point(T) -> np.ndarray:
    """A pose given as a 4×4 matrix or a Study point (8,), validated → a unit Study point."""
    return pose_of(T).study


def pose_matrix(T) -> np.ndarray:
    """A pose given as a 4×4 matrix (kept as given) or a Study point (8,), validated → 4×4."""
    return pose_of(T).matrix


_LAST_ROW, _EYE3 = np.array([0.0, 0, 0, 1]), np.eye(3)
_LAST_TOL = 1e-12 + 1e-5 * _LAST_ROW


def check_matrix(T: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """T (4, 4) or a stack (..., 4, 4) of rigid transforms, checked at once: last row [0, 0, 0, 1],
    rotation part orthonormal to tol with det +1."""
    rows = T[..., 3, :].reshape(-1, 4)
    good = np.abs(rows - _LAST_ROW) <= _LAST_TOL
    if not good.all():
        bad = np.flatnonzero(~good.all(axis=1))
        raise ValueError(f"T: last row must be [0, 0, 0, 1], got {rows[bad[0]].tolist()}")
    R = T[..., :3, :3]
    ortho = np.abs(np.swapaxes(R, -1, -2) @ R - _EYE3)
    if ortho.size and (not (ortho.max() <= tol) or not (np.linalg.det(R) > 0).all()):
        raise ValueError("T: the rotation part is not a proper rotation (orthonormal, det +1)")
    return T


def refine(chain, q: np.ndarray, T: np.ndarray, tol: float, scale: float | None = None):
    """Up to two Gauss-Newton steps on the pose error; keep what reproduces T to tol (rotation
    entries, and translations in units of the chain's length scale `scale`), merged."""
    if len(q) == 0:
        return q, np.zeros(0)
    scale = length_scale(chain) if scale is None else scale
    e, err = pose_error(chain, q, T, scale)
    for _ in range(2):
        if np.all(err <= 1e-3 * tol):
            break
        J = chain.jacobian(q) * error_weights(chain, scale)
        step = np.einsum("kij,kj->ki", np.linalg.pinv(J, rcond=1e-12), e)
        q2 = q + step
        e2, err2 = pose_error(chain, q2, T, scale)
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


def jacobian_rank(chain, q: np.ndarray, scale: float | None = None) -> np.ndarray:
    """Numerical rank of the Jacobian at each joint vector (k, n), scaled by the chain's size."""
    return np.linalg.matrix_rank(chain.jacobian(q) * error_weights(chain, scale), tol=1e-8)


def error_weights(chain, scale: float | None = None) -> np.ndarray:
    """(6, 1): the rows of a Jacobian or pose error made dimensionless (positions / scale)."""
    w = 1 / (length_scale(chain) if scale is None else scale)
    return np.array([[w], [w], [w], [1.0], [1.0], [1.0]])


def translation_norm(T: np.ndarray) -> float:
    """|t| of a pose (4, 4) without overflow in the squares (inf only where |t| itself is)."""
    return norm3(T[:3, 3])


def norm3(v: np.ndarray) -> float:
    """The Euclidean norm of a short vector without overflow or underflow in the squares
    (math.hypot scales them; inf only where the norm itself is beyond the doubles)."""
    return math.hypot(*v.tolist())


def near_reach(chain, T: np.ndarray, reach: float | None = None, scale: float | None = None) -> bool:
    """Whether T's position is within the chain's crude reach bound (`reach_of`: Σ |a| + |c| + 2h
    from the base, a proof of unreachability beyond it): outside it no local search is needed to
    call the pose unreachable."""
    reach = reach_of(chain) if reach is None else reach
    scale = length_scale(chain) if scale is None else scale
    return translation_norm(T) <= 1.01 * reach + 1e-9 * scale


def pose_error(chain, q: np.ndarray, T: np.ndarray, scale: float | None = None):
    """(k, 6) pose error [Δp/scale; Δω] of fk(q) against T and (k,) the largest entry of the 4×4
    difference, its translations in units of the chain's length scale (`length_scale`)."""
    scale = length_scale(chain) if scale is None else scale
    F = chain.fk(q)
    dp = (T[:3, 3] - F[:, :3, 3]) / scale
    S = T[:3, :3] @ np.swapaxes(F[:, :3, :3], 1, 2)  # Σ_k f_k × t_k = vee(T Fᵀ − F Tᵀ) (columns f_k, t_k)
    dw = 0.5 * np.stack([S[:, 2, 1] - S[:, 1, 2], S[:, 0, 2] - S[:, 2, 0], S[:, 1, 0] - S[:, 0, 1]], 1)
    D = np.abs(F - T)
    D[:, :3, 3] /= scale
    return np.concatenate([dp, dw], 1), D.max(axis=(1, 2))
