"""Study parameters: the normalisation used by the runtime (docs/conventions.md §1)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray


def normalise(study: NDArray[np.float64]) -> NDArray[np.float64]:
    """Scale (..., 8) Study points so that x0² + x1² + x2² + x3² = 1 (the sign is kept)."""
    norm = np.linalg.norm(study[..., :4], axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise ValueError("study: a point in the exceptional 3-space (x = 0) is not a displacement")
    return study / norm


def to_matrix(study: ArrayLike) -> NDArray[np.float64]:
    """(..., 8) Study points -> (..., 4, 4) transforms: R from x, t = 2 y x̃ / |x|²."""
    s = np.asarray(study, dtype=np.float64)
    x, y = s[..., :4], s[..., 4:]
    n = np.sum(x * x, axis=-1)
    w, a, b, c = np.moveaxis(x, -1, 0)
    R = (
        np.stack(
            [
                np.stack([w * w + a * a - b * b - c * c, 2 * (a * b - w * c), 2 * (a * c + w * b)], -1),
                np.stack([2 * (a * b + w * c), w * w - a * a + b * b - c * c, 2 * (b * c - w * a)], -1),
                np.stack([2 * (a * c - w * b), 2 * (b * c + w * a), w * w - a * a - b * b + c * c], -1),
            ],
            -2,
        )
        / n[..., None, None]
    )
    y0, y1, y2, y3 = np.moveaxis(y, -1, 0)
    # vector part of y x̃
    t = (
        2
        * np.stack(
            [
                -y0 * a + y1 * w - y2 * c + y3 * b,
                -y0 * b + y1 * c + y2 * w - y3 * a,
                -y0 * c - y1 * b + y2 * a + y3 * w,
            ],
            -1,
        )
        / n[..., None]
    )
    T = np.zeros(s.shape[:-1] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = t
    T[..., 3, 3] = 1.0
    return T


def _shepperd() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(C, D): the symmetric 4 × 4 matrix K = C·R + D whose rows are proportional to the quaternion
    of R, row k the best-conditioned where K_kk is largest (Shepperd): K_kk = 4 x_k²."""
    C, D = np.zeros((4, 4, 3, 3)), np.eye(4)
    for k in range(4):  # the diagonal: 1 + tr(R) and 1 + 2 R_jj − tr(R)
        for j in range(3):
            C[k, k, j, j] = -1.0 if k > 0 else 1.0
        if k > 0:
            C[k, k, k - 1, k - 1] = 1.0
    for k, (a, b) in enumerate(((2, 1), (0, 2), (1, 0)), start=1):  # row 0: R_ab − R_ba
        C[0, k, a, b] = C[k, 0, a, b] = 1.0
        C[0, k, b, a] = C[k, 0, b, a] = -1.0
    for j, k, (a, b) in ((1, 2, (0, 1)), (1, 3, (0, 2)), (2, 3, (1, 2))):  # the rest: R_ab + R_ba
        C[j, k, a, b] = C[j, k, b, a] = C[k, j, a, b] = C[k, j, b, a] = 1.0
    return C.reshape(16, 9).T, D


_SHEPPERD = _shepperd()
# y = ½ t x̃ with t = (0, t1, t2, t3): y_i = ½ Σ L[i, a, b] t_a x_b
_HALF_T = np.array(
    [
        [[0, -1, 0, 0], [0, 0, -1, 0], [0, 0, 0, -1]],
        [[1, 0, 0, 0], [0, 0, 0, 1], [0, 0, -1, 0]],
        [[0, 0, 0, -1], [1, 0, 0, 0], [0, 1, 0, 0]],
        [[0, 0, 1, 0], [0, -1, 0, 0], [1, 0, 0, 0]],
    ],
    float,
)


_HALF_T_ROWS = np.ascontiguousarray(_HALF_T.transpose(1, 0, 2).reshape(3, 16))  # t ↦ Σ_a t_a L[i, a, b]


def from_matrix(T: ArrayLike) -> NDArray[np.float64]:
    """(..., 4, 4) rigid transforms -> unit Study points (Shepperd's branch choice for x)."""
    T = np.asarray(T, dtype=np.float64)
    if T.shape == (4, 4):  # one pose: the same steps, with fewer array operations
        C, D = _SHEPPERD
        K = (T[:3, :3].reshape(9) @ C).reshape(4, 4) + D
        x = K[int(np.argmax(K.diagonal()))]
        x = x / math.sqrt(x @ x)
        return np.concatenate([x, 0.5 * ((T[:3, 3] @ _HALF_T_ROWS).reshape(4, 4) @ x)])
    C, D = _SHEPPERD
    K = (T[..., :3, :3].reshape(T.shape[:-2] + (9,)) @ C).reshape(T.shape[:-2] + (4, 4)) + D
    k = np.argmax(np.diagonal(K, axis1=-2, axis2=-1), axis=-1)
    x = np.take_along_axis(K, k[..., None, None], axis=-2)[..., 0, :]
    x = x / np.linalg.norm(x, axis=-1, keepdims=True)
    y = 0.5 * np.einsum("...a,iab,...b->...i", T[..., :3, 3], _HALF_T, x)
    return np.concatenate([x, y], -1)


def qmul(a: NDArray[Any], b: NDArray[Any]) -> NDArray[Any]:
    """Hamilton product of quaternions (..., 4), broadcasting (object arrays too)."""
    a0, a1, a2, a3 = np.moveaxis(a, -1, 0)
    b0, b1, b2, b3 = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
        ],
        -1,
    )


def multiply(p: ArrayLike, q: ArrayLike) -> NDArray[Any]:
    """Dual-quaternion product of (..., 8) Study points (broadcasting; real or complex):
    (x1 + εy1)(x2 + εy2) = x1x2 + ε(x1y2 + y1x2), the point of T1·T2."""
    p, q = np.asarray(p), np.asarray(q)
    return np.concatenate(
        [qmul(p[..., :4], q[..., :4]), qmul(p[..., :4], q[..., 4:]) + qmul(p[..., 4:], q[..., :4])], -1
    )


_CONJ = np.array([1.0, -1.0, -1.0, -1.0, 1.0, -1.0, -1.0, -1.0])


def conjugate(p: ArrayLike) -> NDArray[Any]:
    """(x̃, ỹ): projectively the inverse displacement of a point on the Study quadric."""
    return np.asarray(p) * _CONJ
