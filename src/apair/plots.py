"""Pictures (matplotlib, Agg backend): the clearance of an A-pair's legs and plates against θ.

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
