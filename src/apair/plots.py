"""Pictures (matplotlib, Agg backend): clearance against θ, workspaces, chains in 3D, pair GIFs.

Every function writes a new file and refuses to replace an existing one unless overwrite=True.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from . import collisions as C


def _target(path, overwrite: bool) -> Path:
    p = Path(path)
    if p.exists() and not overwrite:
        raise ValueError(f"path: {str(p)!r} exists; pass overwrite=True (or --force) to replace it")
    if not p.parent.is_dir():
        raise ValueError(f"path: folder {str(p.parent)!r} does not exist")
    return p


def _figure():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def clearance(pair, path, overwrite: bool = False, samples: int = 2001) -> Path:
    """Clearance against θ: the closest two legs (segment distance − 2·leg_radius) and the plates
    (d − thickness), with the collision limits marked; θ spans the limits and a margin beyond."""
    p = _target(path, overwrite)
    lim = pair.collision_limits()
    lo = lim.theta_min if math.isfinite(lim.theta_min) else -math.pi
    hi = lim.theta_max if math.isfinite(lim.theta_max) else math.pi
    span = hi - lo
    lo, hi = lo - 0.1 * span, hi + 0.1 * span
    if pair.theta_limit is not None:
        lo, hi = max(lo, -pair.theta_limit), min(hi, pair.theta_limit)
    th = np.linspace(lo, hi, samples)
    legs, plate = C.clearances(pair, th)
    plt = _figure()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(np.degrees(th), 1e3 * legs.min(axis=-1), label="closest legs")
    ax.plot(np.degrees(th), 1e3 * plate, label="plates")
    ax.axhline(0.0, color="k", lw=0.8)
    for value, side in ((lim.theta_min, "min"), (lim.theta_max, "max")):
        if math.isfinite(value):
            ax.axvline(math.degrees(value), color="C3", ls="--", lw=1)
            ax.annotate(f"θ_{side} = {math.degrees(value):.3f}°", (math.degrees(value), 0), xytext=(4, 8),
                        textcoords="offset points", color="C3", rotation=90, va="bottom")
    ax.set_xlabel("θ [deg]")
    ax.set_ylabel("clearance [mm]")
    ax.set_title(f"{pair!r}: first touch {lim.what}", fontsize=9)
    ax.legend()
    fig.tight_layout()
    fig.savefig(p, dpi=120)
    plt.close(fig)
    return p


def workspace(ws, path, overwrite: bool = False, max_points: int = 20_000) -> Path:
    """A 3D view of the sampled end-effector origins (a random subset) and three cross-sections
    (slabs one voxel thick through the centre of the boundary), with the volume and its error."""
    p = _target(path, overwrite)
    plt = _figure()
    rng = np.random.default_rng(0)
    pts = ws.points
    show = pts[rng.choice(len(pts), min(max_points, len(pts)), replace=False)]
    centre = 0.5 * (ws.boundary.min(axis=0) + ws.boundary.max(axis=0))
    fig = plt.figure(figsize=(12, 9))
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    ax.scatter(*show.T, s=0.3, alpha=0.3)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(f"{ws.chain_name}: V = {ws.volume:.4g} ± {ws.volume_error:.2g} m³ ({len(pts)} samples)", fontsize=9)
    names = "xyz"
    for k, axis in enumerate(range(3)):
        a, b = [i for i in range(3) if i != axis]
        slab = np.abs(pts[:, axis] - centre[axis]) < 0.5 * ws.voxel
        edge = np.abs(ws.boundary[:, axis] - centre[axis]) < 0.5 * ws.voxel
        sub = fig.add_subplot(2, 2, k + 2)
        sub.scatter(pts[slab, a], pts[slab, b], s=0.3, alpha=0.3, label="samples")
        sub.scatter(ws.boundary[edge, a], ws.boundary[edge, b], s=4, c="C3", marker="s", label="boundary voxels")
        sub.set_aspect("equal")
        sub.set_xlabel(f"{names[a]} [m]")
        sub.set_ylabel(f"{names[b]} [m]")
        sub.set_title(f"section {names[axis]} = {centre[axis]:.3g} m", fontsize=9)
    sub.legend(loc="upper right", fontsize=7, markerscale=3)
    fig.tight_layout()
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p


def segments(chain, q) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """The chain at q as line segments (start, end, "link" | "leg" | "plate") in the base frame.
    A pair is drawn in its base frame (frame i−1 turned by φ_i): legs, base and platform triangles.
    Frame i is the fk kernel's pose of the chain's first i joints."""
    from .chain import AChain

    q = np.asarray(q, dtype=float)
    T = np.eye(4)
    out = []
    for i, (pair, th) in enumerate(zip(chain.pairs, q)):
        phi = chain.theta_offset[i]
        F = T[:3, :3] @ np.array([[math.cos(phi), -math.sin(phi), 0], [math.sin(phi), math.cos(phi), 0], [0, 0, 1]])
        if pair.kind != "revolute":
            legs = pair.leg_endpoints(th) @ F.T + T[:3, 3]
            out += [(leg[0], leg[1], "leg") for leg in legs]
            for tri in (legs[:3, 0], legs[3:, 1]):  # base vertices, platform vertices
                out += [(tri[k], tri[(k + 1) % 3], "plate") for k in range(3)]
        k = i + 1
        T_next = AChain(chain.pairs[:k], chain.a[:k], chain.alpha[:k], chain.offset[:k], chain.theta_offset[:k]).fk(q[:k])
        out.append((T[:3, 3], T_next[:3, 3], "link"))
        T = T_next
    return out


def _draw(ax, chain, q):
    style = {"link": dict(color="k", lw=2.5), "leg": dict(color="C0", lw=1.2), "plate": dict(color="C1", lw=1.5)}
    for a, b, kind in segments(chain, q):
        ax.plot(*np.stack([a, b]).T, **style[kind])


def _equal_3d(ax, pts):
    c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    r = 0.5 * max(float(np.max(pts.max(axis=0) - pts.min(axis=0))), 1e-3)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)


def chain_picture(chain, q, path, overwrite: bool = False) -> Path:
    """A 3D picture of the chain at q: links (black), legs (blue), plates (orange)."""
    p = _target(path, overwrite)
    q = chain._q(q)
    plt = _figure()
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    _draw(ax, chain, q)
    _equal_3d(ax, np.array([x for a, b, _ in segments(chain, q) for x in (a, b)]))
    ax.set_title(f"{getattr(chain, 'name', '')} at q = {np.round(q, 3).tolist()} rad", fontsize=9)
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p


def pair_animation(pair, path, frames: int = 48, overwrite: bool = False) -> Path:
    """A GIF of one A-pair turning through its collision-free range and back (Pillow writer)."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    from .chain import AChain

    p = _target(path, overwrite)
    if pair.kind == "revolute":
        raise ValueError("pair: an R-pair has no legs to animate")
    lim = pair.collision_limits()
    lo = lim.theta_min if math.isfinite(lim.theta_min) else -math.pi
    hi = lim.theta_max if math.isfinite(lim.theta_max) else math.pi
    chain = AChain([pair], [0.0], [0.0])
    angles = np.concatenate([np.linspace(lo, hi, frames // 2), np.linspace(hi, lo, frames - frames // 2)])
    every = np.array([x for th in np.linspace(lo, hi, 9) for a, b, _ in segments(chain, [th]) for x in (a, b)])
    plt = _figure()
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")

    def frame(k):
        ax.cla()
        _draw(ax, chain, [angles[k]])
        _equal_3d(ax, every)
        ax.set_title(f"theta = {math.degrees(angles[k]):+7.2f} deg  (limits {math.degrees(lo):.1f}, "
                     f"{math.degrees(hi):.1f}: {lim.what})", fontsize=8)

    FuncAnimation(fig, frame, frames=len(angles)).save(p, writer=PillowWriter(fps=12))
    plt.close(fig)
    return p
