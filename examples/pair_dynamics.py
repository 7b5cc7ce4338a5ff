"""Worked example: how much do the legs of an A-pair matter dynamically?

A sinusoidal A-pair with congruent triangles r_b = r_p = 0.10 m (h = 0.141 m, legs 0.15 m long),
six aluminium legs (0.12 kg each), a 2.0 kg platform plate (I_zz = 0.011 kg m²). Along the pair's
usable range it splits the generalised inertia J(θ) and the gravity term G(θ) of
τ = J θ'' + ½ J' θ'² + G into the platform's and the legs' shares, prints the largest ratios and
saves a plot.

    python examples/pair_dynamics.py [OUT.png] [--force]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import apair


def contributions(pair: apair.APair, platform: apair.Link, theta: np.ndarray, g: float = 9.81):
    """(J, G) of the platform alone and of the legs alone along theta."""
    legs_only = apair.APair(pair.base_radius, pair.platform_radius, leg_mass=pair.leg_mass)
    bare = apair.APair(pair.base_radius, pair.platform_radius)
    plat = bare.dynamics(theta, platform=platform, g=g)
    legs = legs_only.dynamics(theta, platform=apair.Link(0.0), g=g)
    return plat[..., 1], plat[..., 3], legs[..., 1], legs[..., 3]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default="pair_dynamics.png", help="the plot to write (PNG)")
    ap.add_argument("--force", action="store_true", help="overwrite OUT if it exists")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if out.exists() and not args.force:
        print(f"{out} exists; give --force to overwrite it", file=sys.stderr)
        return 2

    r = 0.10
    pair = apair.APair(r, r, leg_mass=0.12)
    platform = apair.Link(2.0, com=[0.0, 0.0, 0.01], inertia=np.diag([0.0055, 0.0055, 0.011]))
    theta = np.linspace(-0.95 * np.pi, 0.95 * np.pi, 381)
    Jp, Gp, Jl, Gl = contributions(pair, platform, theta)
    i = np.argmax(np.abs(Gp))
    print(
        f"A-pair r_b = r_p = {r} m, h = {pair.amplitude:.4f} m, legs {pair.leg_lengths[0]:.3f} m, "
        f"6 x {pair.leg_mass} kg; platform {platform.mass} kg"
    )
    print(f"gravity term: legs/platform = {Gl[i] / Gp[i]:.3f} (3 m_leg / m, at every angle)")
    print(f"inertia J:    legs/platform = {np.min(Jl / Jp):.3f} .. {np.max(Jl / Jp):.3f} over the range")
    # kinetic energy at a typical speed, against the potential energy swing
    speed = 2.0  # rad/s
    T_legs = 0.5 * Jl * speed**2
    dV_plat = np.ptp(platform.mass * 9.81 * pair.translation(theta))
    print(
        f"at {speed} rad/s the legs carry at most {T_legs.max() * 1e3:.2f} mJ of kinetic energy; "
        f"the platform's potential energy swings by {dV_plat * 1e3:.1f} mJ"
    )

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    deg = np.degrees(theta)
    ax1.plot(deg, Jp * 1e3, label="platform")
    ax1.plot(deg, Jl * 1e3, label="legs")
    ax1.set(xlabel="θ [deg]", ylabel="J(θ) [g m²]", title="generalised inertia")
    ax2.plot(deg, Gp, label="platform")
    ax2.plot(deg, Gl, label="legs")
    ax2.set(xlabel="θ [deg]", ylabel="G(θ) [N m]", title="gravity term")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        ax.legend()
    fig.suptitle("A-pair r = 0.1 m: platform 2 kg, six legs of 0.12 kg")
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
