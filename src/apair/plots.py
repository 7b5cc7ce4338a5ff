"""Pictures (matplotlib, Agg backend): clearance against θ, workspaces, chains in 3D, pair GIFs.

Every function writes a new file and refuses to replace an existing one unless overwrite=True.
The pictures that need no chain (clearance, workspace) live in apair.figures and are offered here.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .chain import AChain
from .figures import axes_3d, clearance, figure, section, workspace
from .files import target, write, write_text

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d import Axes3D

    from .pair import APair

# a drawn line: start, end, and what it is ("link", "leg" or "plate")
Segment = tuple[NDArray[np.float64], NDArray[np.float64], str]

__all__ = ["chain_picture", "clearance", "pair_animation", "section", "segments", "workspace", "write_text"]


def segments(chain: AChain, q: ArrayLike) -> list[Segment]:
    """The chain at q as line segments (start, end, "link" | "leg" | "plate") in the base frame.
    A pair is drawn in its base frame (frame i−1 turned by φ_i): legs, base and platform triangles.
    Frame i is the fk kernel's pose of the chain's first i joints."""
    q = np.asarray(q, dtype=float)
    T = np.eye(4)
    out = []
    for i, (pair, th) in enumerate(zip(chain.pairs, q)):
        phi = chain.theta_offset[i]
        F = T[:3, :3] @ np.array([[math.cos(phi), -math.sin(phi), 0], [math.sin(phi), math.cos(phi), 0], [0, 0, 1]])
        if pair.is_apair:
            legs = pair.leg_endpoints(th) @ F.T + T[:3, 3]
            out += [(leg[0], leg[1], "leg") for leg in legs]
            for tri in (legs[:3, 0], legs[3:, 1]):  # base vertices, platform vertices
                out += [(tri[k], tri[(k + 1) % 3], "plate") for k in range(3)]
        k = i + 1
        T_next = AChain(chain.pairs[:k], chain.a[:k], chain.alpha[:k], chain.offset[:k], chain.theta_offset[:k]).fk(
            q[:k]
        )
        out.append((T[:3, 3], T_next[:3, 3], "link"))
        T = T_next
    return out


def _triangles(segs: Sequence[Segment]) -> list[NDArray[np.float64]]:
    """The plates as filled triangles (3, 3) from a chain's segments: each A-pair's base and
    platform triangle (three edges each, one vertex at the start of each edge)."""
    starts = [a for a, _, kind in segs if kind == "plate"]
    return [np.stack(starts[k : k + 3]) for k in range(0, len(starts), 3)]


def _draw(ax: Axes3D, chain: AChain, q: ArrayLike, extent: float, segs: Sequence[Segment] | None = None) -> None:
    """Links (black), legs (blue, drawn as wide as their real radius where one is given), plates
    (filled orange triangles), the base (square) and the end effector (triangle, with its frame)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    points_per_m = 72 * 0.8 * ax.figure.get_figwidth() / (2 * extent)  # the axes span about 2·extent
    segs = segments(chain, q) if segs is None else segs
    legs = [p.leg_radius for p in chain.pairs if p.is_apair for _ in range(6)]
    k = 0
    for a, b, kind in segs:
        if kind == "link":
            ax.plot(*np.stack([a, b]).T, color="k", lw=2.5, solid_capstyle="round")
        elif kind == "leg":
            lw = max(0.8, 2 * legs[k] * points_per_m) if legs[k] > 0 else 1.0
            ax.plot(*np.stack([a, b]).T, color="C0", lw=lw, solid_capstyle="round")
            k += 1
    tris = _triangles(segs)
    if tris:
        ax.add_collection3d(Poly3DCollection(tris, facecolor="C1", edgecolor="C1", alpha=0.45, linewidths=1.0))
    T = chain.fk(q)
    ax.scatter([0], [0], [0], marker="s", s=40, color="k", label="base")
    ax.scatter(*T[:3, 3, None], marker="^", s=50, color="C3", label="end effector")
    for axis, colour in zip(T[:3, :3].T, ("tab:red", "tab:green", "tab:blue")):
        ax.plot(*np.stack([T[:3, 3], T[:3, 3] + 0.15 * extent * axis]).T, color=colour, lw=1.2)


def _scene_points(segs: Sequence[Segment]) -> NDArray[np.float64]:
    return np.array([x for a, b, _ in segs for x in (a, b)] + [np.zeros(3)])


def chain_picture(chain: AChain, q: ArrayLike, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
    """A 3D picture of the chain at q, fit for a paper: equal scale on all axes, labelled in
    metres; links (black), legs (blue, their real radius where given), plates (filled orange),
    the base (square) and the end effector (triangle, with its frame: x red, y green, z blue)."""
    p = target(path, overwrite)
    q = chain._q(q)
    plt = figure()
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    segs = segments(chain, q)  # (one fk call per joint: computed once for the limits and the drawing)
    extent = axes_3d(ax, _scene_points(segs))
    _draw(ax, chain, q, extent, segs)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(f"{getattr(chain, 'name', '')} at q = {np.round(q, 3).tolist()} rad", fontsize=9)
    write(p, overwrite, lambda f: fig.savefig(f, dpi=150, format="png", bbox_inches="tight"))
    plt.close(fig)
    return p


def pair_animation(pair: APair, path: str | os.PathLike[str], frames: int = 48, overwrite: bool = False) -> Path:
    """A GIF of one A-pair turning through its collision-free range and back (Pillow writer)."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    p = target(path, overwrite, suffix=".gif")
    if not pair.is_apair:
        raise ValueError(f"pair: a {pair.kind} pair has no legs to animate")
    lim = pair.collision_limits()
    lo = lim.theta_min if math.isfinite(lim.theta_min) else -math.pi
    hi = lim.theta_max if math.isfinite(lim.theta_max) else math.pi
    chain = AChain([pair], [0.0], [0.0])
    angles = np.concatenate([np.linspace(lo, hi, frames // 2), np.linspace(hi, lo, frames - frames // 2)])
    every = np.array([x for th in np.linspace(lo, hi, 9) for a, b, _ in segments(chain, [th]) for x in (a, b)])
    plt = figure()
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")

    def frame(k: int) -> None:
        ax.cla()
        extent = axes_3d(ax, every)
        _draw(ax, chain, [angles[k]], extent)
        ax.set_title(
            f"theta = {math.degrees(angles[k]):+7.2f} deg  (limits {math.degrees(lo):.1f}, "
            f"{math.degrees(hi):.1f}: {lim.what})",
            fontsize=8,
        )

    anim = FuncAnimation(fig, frame, frames=len(angles))
    write(p, overwrite, lambda f: anim.save(f, writer=PillowWriter(fps=12)))
    plt.close(fig)
    return p
