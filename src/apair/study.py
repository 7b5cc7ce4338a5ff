"""Study parameters: the normalisation used by the runtime (docs/conventions.md §1)."""
from __future__ import annotations

import numpy as np


def normalise(study: np.ndarray) -> np.ndarray:
    """Scale (..., 8) Study points so that x0² + x1² + x2² + x3² = 1 (the sign is kept)."""
    norm = np.linalg.norm(study[..., :4], axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise ValueError("study: a point in the exceptional 3-space (x = 0) is not a displacement")
    return study / norm


def to_matrix(study) -> np.ndarray:
    """(..., 8) Study points -> (..., 4, 4) transforms: R from x, t = 2 y x̃ / |x|²."""
    s = np.asarray(study, dtype=np.float64)
    x, y = s[..., :4], s[..., 4:]
    n = np.sum(x * x, axis=-1)
    w, a, b, c = np.moveaxis(x, -1, 0)
    R = np.stack([
        np.stack([w * w + a * a - b * b - c * c, 2 * (a * b - w * c), 2 * (a * c + w * b)], -1),
        np.stack([2 * (a * b + w * c), w * w - a * a + b * b - c * c, 2 * (b * c - w * a)], -1),
        np.stack([2 * (a * c - w * b), 2 * (b * c + w * a), w * w - a * a - b * b + c * c], -1),
    ], -2) / n[..., None, None]
    y0, y1, y2, y3 = np.moveaxis(y, -1, 0)
    # vector part of y x̃
    t = 2 * np.stack([
        -y0 * a + y1 * w - y2 * c + y3 * b,
        -y0 * b + y1 * c + y2 * w - y3 * a,
        -y0 * c - y1 * b + y2 * a + y3 * w,
    ], -1) / n[..., None]
    T = np.zeros(s.shape[:-1] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = t
    T[..., 3, 3] = 1.0
    return T


def from_matrix(T) -> np.ndarray:
    """(..., 4, 4) rigid transforms -> unit Study points (Shepperd's branch choice for x)."""
    T = np.asarray(T, dtype=np.float64)
    R, t = T[..., :3, :3], T[..., :3, 3]
    tr = np.trace(R, axis1=-2, axis2=-1)
    cands = np.stack([
        np.stack([1 + tr, R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1),
        np.stack([R[..., 2, 1] - R[..., 1, 2], 1 + 2 * R[..., 0, 0] - tr, R[..., 0, 1] + R[..., 1, 0], R[..., 0, 2] + R[..., 2, 0]], -1),
        np.stack([R[..., 0, 2] - R[..., 2, 0], R[..., 0, 1] + R[..., 1, 0], 1 + 2 * R[..., 1, 1] - tr, R[..., 1, 2] + R[..., 2, 1]], -1),
        np.stack([R[..., 1, 0] - R[..., 0, 1], R[..., 0, 2] + R[..., 2, 0], R[..., 1, 2] + R[..., 2, 1], 1 + 2 * R[..., 2, 2] - tr], -1),
    ], -2)
    diag = np.stack([1 + tr, 1 + 2 * R[..., 0, 0] - tr, 1 + 2 * R[..., 1, 1] - tr, 1 + 2 * R[..., 2, 2] - tr], -1)
    k = np.argmax(diag, axis=-1)
    x = np.take_along_axis(cands, k[..., None, None], axis=-2)[..., 0, :]
    x = x / np.linalg.norm(x, axis=-1, keepdims=True)
    w, a, b, c = np.moveaxis(x, -1, 0)
    t1, t2, t3 = np.moveaxis(t, -1, 0)
    # y = ½ t x with t = (0, t1, t2, t3)
    y = 0.5 * np.stack([
        -t1 * a - t2 * b - t3 * c,
        t1 * w + t2 * c - t3 * b,
        -t1 * c + t2 * w + t3 * a,
        t1 * b - t2 * a + t3 * w,
    ], -1)
    return np.concatenate([x, y], -1)


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a0, a1, a2, a3 = np.moveaxis(a, -1, 0)
    b0, b1, b2, b3 = np.moveaxis(b, -1, 0)
    return np.stack([a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
                     a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
                     a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
                     a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0], -1)


def multiply(p, q) -> np.ndarray:
    """Dual-quaternion product of (..., 8) Study points (broadcasting; real or complex):
    (x1 + εy1)(x2 + εy2) = x1x2 + ε(x1y2 + y1x2), the point of T1·T2."""
    p, q = np.asarray(p), np.asarray(q)
    return np.concatenate([_qmul(p[..., :4], q[..., :4]),
                           _qmul(p[..., :4], q[..., 4:]) + _qmul(p[..., 4:], q[..., :4])], -1)


_CONJ = np.array([1.0, -1.0, -1.0, -1.0, 1.0, -1.0, -1.0, -1.0])


def conjugate(p) -> np.ndarray:
    """(x̃, ỹ): projectively the inverse displacement of a point on the Study quadric."""
    return np.asarray(p) * _CONJ
