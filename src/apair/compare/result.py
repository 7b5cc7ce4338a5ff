"""The findings of a comparison as plain data: per chain (`Measures`, with its `PathRun`), what the
two share (`Shared`), and the settings (`Findings`), each turned into the JSON document's entries."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..workspace import Workspace

UNITS = {
    "volume": "m^3",
    "volume_error": "m^3 (one standard uncertainty)",
    "measure": "m (a curve) or m^2 (a surface)",
    "limits": "rad",
    "limits_deg": "deg",
    "axial_travel": "m",
    "mass": "kg",
    "inertia_mean": "kg m^2 (mean diagonal of the mass matrix over the joint space)",
    "manipulability": "(translations in units of length_scale, so scale-free)",
    "gravity_torque": "N m",
    "peak_torque": "N m",
    "energy": "J",
    "voxel": "m",
    "path": "m, s",
}


@dataclass
class PathRun:
    """One chain on the common path: whether it followed it (every step solved inside the limits
    without a jump), why not, and what the motion takes. t (k,), q, qd, qdd, tau (k, n)."""

    followed: bool
    reason: str = ""
    t: NDArray[np.float64] | None = None
    q: NDArray[np.float64] | None = None
    qd: NDArray[np.float64] | None = None
    qdd: NDArray[np.float64] | None = None
    tau: NDArray[np.float64] | None = None
    peak_torque: NDArray[np.float64] | None = None  # (n,) max |tau_i| [N m]
    energy: float | None = None  # ∫ |tau · qd| dt [J]
    work: float | None = None  # ∫ tau · qd dt [J] (signed: the change of energy)
    max_step: float | None = None  # the largest joint change between two path points [rad]

    def as_dict(self) -> dict[str, Any]:
        return {
            "followed": self.followed,
            "reason": self.reason or None,
            "peak_torque": self.peak_torque,
            "energy": self.energy,
            "work": self.work,
            "max_step": self.max_step,
        }


@dataclass
class Measures:
    """One chain's measurements (`compare`'s module docstring says how each is taken)."""

    name: str
    pairs: list[str]
    workspace: Workspace
    limits: NDArray[np.float64]  # (n, 2) [rad]
    full_turn: list[bool]
    axial_travel: NDArray[np.float64]  # (n,) max d − min d over the joint's range [m]
    mass: float  # links and legs [kg]
    leg_mass: float  # the legs alone [kg]
    inertia_mean: NDArray[np.float64]  # (n,) mean of diag M over the joint space [kg m²]
    manipulability: NDArray[np.float64]  # (m,) per joint sample
    condition: NDArray[np.float64]  # (m,)
    near_singular: float  # share of the joint samples near a singularity
    gravity_torque_max: NDArray[np.float64]  # (n,) [N m]
    gravity_torque_rms: NDArray[np.float64]  # (n,) [N m]
    ik_complex_count: int | None = None
    ik_real_counts: list[int] = field(default_factory=list)
    ik_real_inside_counts: list[int] = field(default_factory=list)
    path: PathRun = field(default_factory=lambda: PathRun(False, "not run"))

    def percentiles(self, what: str) -> tuple[float, float, float]:
        """(5 %, median, 95 %) of "manipulability" or "condition" over the joint samples."""
        p5, p50, p95 = np.percentile(getattr(self, what), [5, 50, 95])
        return float(p5), float(p50), float(p95)

    def as_dict(self) -> dict[str, Any]:
        ws = self.workspace
        m5, m50, m95 = self.percentiles("manipulability")
        c5, c50, c95 = self.percentiles("condition")
        return {
            "name": self.name,
            "pairs": self.pairs,
            "volume": ws.volume,
            "volume_error": ws.volume_error,
            "dimension": ws.dimension,
            "measure": ws.measure,
            "workspace_samples": len(ws.points),
            "limits": self.limits,
            "limits_deg": np.degrees(self.limits),
            "full_turn": self.full_turn,
            "axial_travel": self.axial_travel,
            "mass": self.mass,
            "leg_mass": self.leg_mass,
            "inertia_mean": self.inertia_mean,
            "manipulability_median": m50,
            "manipulability_p5": m5,
            "manipulability_p95": m95,
            "condition_median": c50,
            "condition_p5": c5,
            "condition_p95": c95,
            "near_singular": self.near_singular,
            "gravity_torque_max": self.gravity_torque_max,
            "gravity_torque_rms": self.gravity_torque_rms,
            "ik_complex_count": self.ik_complex_count,
            "ik_real_counts": self.ik_real_counts,
            "ik_real_inside_counts": self.ik_real_inside_counts,
            "path": self.path.as_dict(),
        }


@dataclass
class Shared:
    """What the two workspaces share, on one voxel grid of size `voxel` [m]: the shares of the
    voxels either reaches that only the chain, only the twin, or both reach; the cross-sections
    (per axis: the layer's coordinate [m], the image's corner [m] and a 2D array with 1 chain only,
    2 twin only, 3 both, 0 neither); and the common path (points (k, 3) [m], time t (k,) [s])."""

    voxel: float
    only_chain: float
    only_twin: float
    both: float
    sections: list[tuple[float, NDArray[np.float64], NDArray[np.int8]]]
    path_points: NDArray[np.float64] | None = None
    path_t: NDArray[np.float64] | None = None
    path_corners: NDArray[np.float64] | None = None  # the polyline's vertices (the line's two ends)
    path_note: str = ""

    def as_dict(self) -> dict[str, Any]:
        corners = self.path_corners
        length = None if corners is None else float(np.linalg.norm(np.diff(corners, axis=0), axis=1).sum())
        return {
            "voxel": self.voxel,
            "only_chain": self.only_chain,
            "only_twin": self.only_twin,
            "both": self.both,
            "path": {
                "points": corners,
                "length": length,
                "duration": None if self.path_t is None else float(self.path_t[-1]),
                "steps": None if self.path_t is None else len(self.path_t),
                "timing": "quintic: s(t) = L (10 u^3 - 15 u^4 + 6 u^5), u = t / duration",
                "note": self.path_note or None,
            },
        }


@dataclass
class Findings:
    """A comparison's data: the chain's and the twin's measures, what they share, the settings."""

    chain: Measures
    twin: Measures
    shared: Shared
    settings: dict[str, Any]

    def as_dict(self) -> dict[str, Any]:
        """The JSON document: {"chain": {...}, "twin": {...}, "shared": {...}, "settings": {...},
        "units": {...}}."""
        return {
            "chain": self.chain.as_dict(),
            "twin": self.twin.as_dict(),
            "shared": self.shared.as_dict(),
            "settings": self.settings,
            "units": UNITS,
        }
