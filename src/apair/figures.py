"""Figures (matplotlib, Agg backend) that need no chain: a pair's clearance against θ, a sampled
workspace with its cross-sections, and the common set-up (equal 3D axes in metres). Chains are
drawn by apair.plots, which offers these too.

Every function writes a new file and refuses to replace an existing one unless overwrite=True
(apair.files).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from . import collisions as C
from .files import target, write

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d import Axes3D

    from ._typing import WorkspaceLike
    from .pair import APair


def figure() -> ModuleType:
    """matplotlib.pyplot with the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def clearance(pair: APair, path: str | os.PathLike[str], overwrite: bool = False, samples: int = 2001) -> Path:
    """Clearance against θ: the closest two legs (segment distance − 2·leg_radius) and the plates
    (d − thickness), with the collision limits marked; θ spans the limits and a margin beyond."""
    p = target(path, overwrite)
    lim = pair.collision_limits()
    lo = lim.theta_min if math.isfinite(lim.theta_min) else -math.pi
    hi = lim.theta_max if math.isfinite(lim.theta_max) else math.pi
    span = hi - lo
    lo, hi = lo - 0.1 * span, hi + 0.1 * span
    if pair.theta_limit is not None:
        lo, hi = max(lo, -pair.theta_limit), min(hi, pair.theta_limit)
    th = np.linspace(lo, hi, samples)
    legs, plate = C.clearances(pair, th)
    plt = figure()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(np.degrees(th), 1e3 * legs.min(axis=-1), label="closest legs")
    ax.plot(np.degrees(th), 1e3 * plate, label="plates")
    ax.axhline(0.0, color="k", lw=0.8)
    for value, side in ((lim.theta_min, "min"), (lim.theta_max, "max")):
        if math.isfinite(value):
            ax.axvline(math.degrees(value), color="C3", ls="--", lw=1)
            ax.annotate(
                f"θ_{side} = {math.degrees(value):.3f}°",
                (math.degrees(value), 0),
                xytext=(4, 8),
                textcoords="offset points",
                color="C3",
                rotation=90,
                va="bottom",
            )
    ax.set_xlabel("θ [deg]")
    ax.set_ylabel("clearance [mm]")
    ax.set_title(f"{pair!r}: first touch {lim.what}", fontsize=9)
    ax.legend()
    fig.tight_layout()
    write(p, overwrite, lambda f: fig.savefig(f, dpi=120, format="png"))
    plt.close(fig)
    return p


def workspace(
    ws: WorkspaceLike, path: str | os.PathLike[str], overwrite: bool = False, max_points: int = 20_000
) -> Path:
    """A 3D view of the sampled end-effector origins (a random subset) and three cross-sections
    (slabs one voxel thick through the centre of the boundary), with the volume and its error."""
    p = target(path, overwrite)
    plt = figure()
    rng = np.random.default_rng(0)
    pts = ws.points
    show = pts[rng.choice(len(pts), min(max_points, len(pts)), replace=False)]
    fig = plt.figure(figsize=(12, 9))
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    ax.scatter(*show.T, s=0.3, alpha=0.3)
    axes_3d(ax, pts)
    what = (
        f"V = {ws.volume:.4g} ± {ws.volume_error:.2g} m³"
        if ws.dimension == 3
        else f"{'curve, length' if ws.dimension == 1 else 'surface, area'} ≈ {ws.measure:.4g} m{'' if ws.dimension == 1 else '²'}"
    )
    ax.set_title(f"{ws.chain_name}: {what} ({len(pts)} samples)", fontsize=9)
    names = "xyz"
    for k, axis in enumerate(range(3)):
        a, b = [i for i in range(3) if i != axis]
        layer, slab, edge = section(ws, axis)
        sub = fig.add_subplot(2, 2, k + 2)
        sub.scatter(pts[slab, a], pts[slab, b], s=0.3, alpha=0.3, label="samples")
        sub.scatter(ws.boundary[edge, a], ws.boundary[edge, b], s=4, c="C3", marker="s", label="boundary voxels")
        sub.set_aspect("equal")
        sub.set_xlabel(f"{names[a]} [m]")
        sub.set_ylabel(f"{names[b]} [m]")
        sub.set_title(f"section {names[axis]} = {layer:.3g} m", fontsize=9)
    sub.legend(loc="upper right", fontsize=7, markerscale=3)
    fig.tight_layout()
    write(p, overwrite, lambda f: fig.savefig(f, dpi=110, format="png"))
    plt.close(fig)
    return p


def section(ws: WorkspaceLike, axis: int) -> tuple[float, NDArray[np.bool_], NDArray[np.bool_]]:
    """The cross-section of a workspace normal to `axis` through the centre of its boundary: the
    layer of voxel centres nearest that centre (they lie on a lattice the centre may fall half-way
    between), and masks of the samples within half a voxel of it and of its boundary voxels."""
    centre = 0.5 * (ws.boundary[:, axis].min() + ws.boundary[:, axis].max())
    layer = ws.boundary[np.argmin(np.abs(ws.boundary[:, axis] - centre)), axis]
    slab = np.abs(ws.points[:, axis] - layer) < 0.5 * ws.voxel
    edge = np.abs(ws.boundary[:, axis] - layer) < 0.25 * ws.voxel
    return float(layer), slab, edge


def axes_3d(ax: Axes3D, pts: NDArray[np.float64]) -> float:
    """Equal scale on all three axes around the points, labelled with units, readable ticks;
    returns the half-extent [m]."""
    from matplotlib.ticker import MaxNLocator

    extent = _equal_3d(ax, pts)
    ax.set_box_aspect((1, 1, 1))
    for _name, axis in zip("xyz", (ax.xaxis, ax.yaxis, ax.zaxis)):
        axis.set_major_locator(MaxNLocator(4))
        axis.set_tick_params(labelsize=8)
    ax.set_xlabel("x [m]", fontsize=9)
    ax.set_ylabel("y [m]", fontsize=9)
    ax.set_zlabel("z [m]", fontsize=9)
    return extent


def _equal_3d(ax: Axes3D, pts: NDArray[np.float64]) -> float:
    """Limits of one common span around the points (a margin of 10 %); returns the half-span."""
    c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    r = 0.55 * max(float(np.max(pts.max(axis=0) - pts.min(axis=0))), 1e-3)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    return r
