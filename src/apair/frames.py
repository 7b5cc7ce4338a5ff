"""Base and tool frames of a chain (docs/conventions.md §9): URDF's roll-pitch-yaw, the rigid
transforms `frame` builds and `check_frame` validates, their inverse, one DH joint's matrix
(used where a held joint is folded into its neighbours, apair.hold), and ik_local's framed fast path."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _validate as V

FRAME_TOL = 1e-9  # a base or tool rotation is orthonormal to this (largest entry of |RᵀR − I|)
EYE4 = np.eye(4)
EYE4.flags.writeable = False


def rpy_matrix(rpy: ArrayLike) -> NDArray[np.float64]:
    """(3, 3): URDF's fixed-axis roll-pitch-yaw rotation Rz(yaw)·Ry(pitch)·Rx(roll) [rad]."""
    r, p, y = np.asarray(rpy, float)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def frame(xyz: ArrayLike = (0.0, 0.0, 0.0), rpy: ArrayLike = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """(4, 4): the rigid transform of a translation xyz [m] and a URDF roll-pitch-yaw rpy [rad]
    (`rpy_matrix`), as a chain's `base` or `tool`."""
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(V.vector("rpy", rpy, 3))
    T[:3, 3] = V.vector("xyz", xyz, 3)
    return T


def check_frame(name: str, value: object) -> NDArray[np.float64] | None:
    """A base or tool transform, validated: (4, 4), finite, the rotation orthonormal to FRAME_TOL
    with det +1, last row exactly [0, 0, 0, 1], the translation within the length range apair
    computes in. Returns a read-only float64 copy, or None for None or the identity exactly (no
    frame: the methods skip the composition)."""
    if value is None:
        return None
    T = np.array(V.real_array(name, value), dtype=np.float64)
    if T.shape != (4, 4):
        raise ValueError(f"{name}: expected a 4x4 rigid transform, got shape {T.shape}")
    if not np.array_equal(T[3], [0.0, 0.0, 0.0, 1.0]):
        raise ValueError(f"{name}: last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    R = T[:3, :3]
    err = float(np.abs(R.T @ R - np.eye(3)).max())
    if err > FRAME_TOL:
        raise ValueError(f"{name}: the rotation part is not orthonormal (|RᵀR − I| = {err:.3g} > {FRAME_TOL:g})")
    if np.linalg.det(R) < 0:
        raise ValueError(f"{name}: the rotation part is a reflection (det −1), not a rotation")
    V.in_range(f"{name} translation", T[:3, 3], "m")
    if np.array_equal(T, EYE4):
        return None
    T.flags.writeable = False
    return T


def inverse(T: NDArray[np.float64]) -> NDArray[np.float64]:
    """The inverse of a rigid transform."""
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -(T[:3, :3].T @ T[:3, 3])
    return out


def dh_matrix(a: float, alpha: float, c: float, angle: float) -> NDArray[np.float64]:
    """Rz(angle) · Tz(c) · Tx(a) · Rx(alpha) (one DH joint at θ + φ = angle, d included in c)."""
    ct, st, ca, sa = math.cos(angle), math.sin(angle), math.cos(alpha), math.sin(alpha)
    return np.array(
        [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0.0, sa, ca, c], [0.0, 0.0, 0.0, 1.0]]
    )


class FramedLocal:
    """ik_local's single-pose fast path of a chain with frames (AChain.ik_local): the world pose T
    made frame n's (base⁻¹·T·tool⁻¹, from the inverses B_inv, T_inv) before the frameless chain's
    native call `fast`; None (the validating path) for any T but a finite float64 4×4 array."""

    def __init__(self, fast: Any, B_inv: NDArray[np.float64], T_inv: NDArray[np.float64]) -> None:
        self._inner, self._B_inv, self._T_inv = fast.call, B_inv, T_inv

    def call(self, T: Any, q0: Any, tol: Any, max_iter: Any) -> Any:
        if type(T) is not np.ndarray or T.dtype != np.float64 or T.shape != (4, 4) or not np.isfinite(T).all():
            return None
        return self._inner(self._B_inv @ T @ self._T_inv, q0, tol, max_iter)
