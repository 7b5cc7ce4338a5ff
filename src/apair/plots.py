"""Pictures (matplotlib, Agg backend): clearance against θ, workspaces, chains in 3D, pair GIFs.

Every function writes a new file and refuses to replace an existing one unless overwrite=True.
"""
from __future__ import annotations

import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from . import collisions as C


def _target(path, overwrite: bool, suffix: str = ".png") -> Path:
    """The file a picture goes to, checked before any work: `suffix` is added when the name has
    none (so the file checked is the file written), a folder is refused, and so is an existing
    file or any symlink (dangling ones too) unless overwrite=True."""
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"path: expected a file name, got {path!r}")
    p = Path(path)
    if p.suffix == "":
        p = p.with_suffix(suffix)
    if p.suffix.lower() != suffix:
        raise ValueError(f"path: {str(p)!r} must end in {suffix} (the picture is written as {suffix[1:].upper()})")
    if p.is_dir():
        raise ValueError(f"path: {str(p)!r} is a folder")
    if (p.exists() or p.is_symlink()) and not overwrite:
        raise ValueError(f"path: {str(p)!r} exists; pass overwrite=True (or --force) to replace it")
    if not p.parent.is_dir():
        raise ValueError(f"path: folder {str(p.parent)!r} does not exist")
    return p


def write_text(path, text: str, overwrite: bool, suffix: str) -> Path:
    """Text (a MuJoCo model, a viewer page) to path by the rules of the pictures: `suffix` added
    where the name has none; an existing file only with overwrite=True."""
    p = _target(path, overwrite, suffix)

    def save(tmp):
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)

    return _write(p, overwrite, save)


def _write(p: Path, overwrite: bool, save) -> Path:
    """save(tmp) writes the picture to a new file beside p, which then becomes p: copied into a
    file created exclusively (what appeared in between is never replaced), or, with overwrite,
    renamed over p (a symlink is replaced itself; what it pointed to is never written)."""
    fd, tmp = tempfile.mkstemp(prefix=f".{p.stem}-", suffix=p.suffix, dir=p.parent)
    os.close(fd)
    try:
        save(tmp)
        os.chmod(tmp, 0o644)
        if overwrite:
            os.replace(tmp, p)
        else:
            try:
                out = open(p, "xb")  # exclusive: never replaces what is there
            except FileExistsError:
                raise ValueError(f"path: {str(p)!r} appeared while the picture was drawn; not replaced") from None
            with out, open(tmp, "rb") as src:
                shutil.copyfileobj(src, out)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
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
    _write(p, overwrite, lambda f: fig.savefig(f, dpi=120, format="png"))
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
    fig = plt.figure(figsize=(12, 9))
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    ax.scatter(*show.T, s=0.3, alpha=0.3)
    _axes_3d(ax, pts)
    what = (f"V = {ws.volume:.4g} ± {ws.volume_error:.2g} m³" if ws.dimension == 3 else
            f"{'curve, length' if ws.dimension == 1 else 'surface, area'} ≈ {ws.measure:.4g} m{'' if ws.dimension == 1 else '²'}")
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
    _write(p, overwrite, lambda f: fig.savefig(f, dpi=110, format="png"))
    plt.close(fig)
    return p


def section(ws, axis: int):
    """The cross-section of a workspace normal to `axis` through the centre of its boundary: the
    layer of voxel centres nearest that centre (they lie on a lattice the centre may fall half-way
    between), and masks of the samples within half a voxel of it and of its boundary voxels."""
    centre = 0.5 * (ws.boundary[:, axis].min() + ws.boundary[:, axis].max())
    layer = ws.boundary[np.argmin(np.abs(ws.boundary[:, axis] - centre)), axis]
    slab = np.abs(ws.points[:, axis] - layer) < 0.5 * ws.voxel
    edge = np.abs(ws.boundary[:, axis] - layer) < 0.25 * ws.voxel
    return float(layer), slab, edge


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


def _triangles(segs) -> list[np.ndarray]:
    """The plates as filled triangles (3, 3) from a chain's segments: each A-pair's base and
    platform triangle (three edges each, one vertex at the start of each edge)."""
    starts = [a for a, _, kind in segs if kind == "plate"]
    return [np.stack(starts[k: k + 3]) for k in range(0, len(starts), 3)]


def _draw(ax, chain, q, extent: float, segs=None):
    """Links (black), legs (blue, drawn as wide as their real radius where one is given), plates
    (filled orange triangles), the base (square) and the end effector (triangle, with its frame)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    points_per_m = 72 * 0.8 * ax.figure.get_figwidth() / (2 * extent)  # the axes span about 2·extent
    segs = segments(chain, q) if segs is None else segs
    legs = [p.leg_radius for p in chain.pairs if p.kind != "revolute" for _ in range(6)]
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


def _axes_3d(ax, pts) -> float:
    """Equal scale on all three axes around the points, labelled with units, readable ticks;
    returns the half-extent [m]."""
    from matplotlib.ticker import MaxNLocator

    extent = _equal_3d(ax, pts)
    ax.set_box_aspect((1, 1, 1))
    for name, axis in zip("xyz", (ax.xaxis, ax.yaxis, ax.zaxis)):
        axis.set_major_locator(MaxNLocator(4))
        axis.set_tick_params(labelsize=8)
    ax.set_xlabel("x [m]", fontsize=9)
    ax.set_ylabel("y [m]", fontsize=9)
    ax.set_zlabel("z [m]", fontsize=9)
    return extent


def _equal_3d(ax, pts) -> float:
    """Limits of one common span around the points (a margin of 10 %); returns the half-span."""
    c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    r = 0.55 * max(float(np.max(pts.max(axis=0) - pts.min(axis=0))), 1e-3)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    return r


def _scene_points(segs) -> np.ndarray:
    return np.array([x for a, b, _ in segs for x in (a, b)] + [np.zeros(3)])


def chain_picture(chain, q, path, overwrite: bool = False) -> Path:
    """A 3D picture of the chain at q, fit for a paper: equal scale on all axes, labelled in
    metres; links (black), legs (blue, their real radius where given), plates (filled orange),
    the base (square) and the end effector (triangle, with its frame: x red, y green, z blue)."""
    p = _target(path, overwrite)
    q = chain._q(q)
    plt = _figure()
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    segs = segments(chain, q)  # (one fk call per joint: computed once for the limits and the drawing)
    extent = _axes_3d(ax, _scene_points(segs))
    _draw(ax, chain, q, extent, segs)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(f"{getattr(chain, 'name', '')} at q = {np.round(q, 3).tolist()} rad", fontsize=9)
    _write(p, overwrite, lambda f: fig.savefig(f, dpi=150, format="png", bbox_inches="tight"))
    plt.close(fig)
    return p


def pair_animation(pair, path, frames: int = 48, overwrite: bool = False) -> Path:
    """A GIF of one A-pair turning through its collision-free range and back (Pillow writer)."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    from .chain import AChain

    p = _target(path, overwrite, suffix=".gif")
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
        extent = _axes_3d(ax, every)
        _draw(ax, chain, [angles[k]], extent)
        ax.set_title(f"theta = {math.degrees(angles[k]):+7.2f} deg  (limits {math.degrees(lo):.1f}, "
                     f"{math.degrees(hi):.1f}: {lim.what})", fontsize=8)

    anim = FuncAnimation(fig, frame, frames=len(angles))
    _write(p, overwrite, lambda f: anim.save(f, writer=PillowWriter(fps=12)))
    plt.close(fig)
    return p
