"""`Link`: the rigid body carrying pair i's platform and frame i (docs/conventions.md §4)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _validate as V

_SYM_TOL = 1e-12


class Link:
    """Mass [kg], centre of mass [m] in frame i, inertia tensor [kg m²] about the centre of mass in
    frame i. The inertia must be symmetric and physically realisable: positive semi-definite with
    principal moments obeying the triangle inequality."""

    def __init__(self, mass: ArrayLike, com: ArrayLike = (0.0, 0.0, 0.0), inertia: ArrayLike | None = None) -> None:
        self.mass = V.scalar("mass", mass, nonnegative=True)
        V.in_range("mass", self.mass, "kg")
        self.com = V.vector("com", com, 3)
        V.in_range("com", self.com, "m")
        I = np.zeros((3, 3)) if inertia is None else V.real_array("inertia", inertia)
        if I.shape != (3, 3):
            raise ValueError(f"inertia: expected shape (3, 3), got {I.shape}")
        V.in_range("inertia", I, "kg m^2", V.INERTIA_RANGE)
        scale = max(1.0, float(np.max(np.abs(I))))
        if np.max(np.abs(I - I.T)) > _SYM_TOL * scale:
            raise ValueError("inertia: must be symmetric")
        I = (I + I.T) / 2
        p = np.linalg.eigvalsh(I)
        tol = _SYM_TOL * scale
        if p[0] < -tol:
            raise ValueError(f"inertia: must be positive semi-definite, has principal moment {p[0]:.6g}")
        if p[0] + p[1] < p[2] - tol:
            raise ValueError(f"inertia: principal moments {p.tolist()} violate the triangle inequality")
        self.inertia = I

    def __repr__(self) -> str:
        return f"Link({self.mass!r}, com={self.com.tolist()}, inertia={self.inertia.tolist()})"

    def as_row(self) -> NDArray[np.float64]:
        """(10,): mass, com, Ixx, Iyy, Izz, Ixy, Ixz, Iyz, the layout of the dynamics kernels."""
        I = self.inertia
        return np.array([self.mass, *self.com, I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])
