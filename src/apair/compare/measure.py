"""Both chains measured on the same work: their workspaces on one grid, their joint spaces sampled
alike, the common path followed by each."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..workspace import Workspace
from . import metrics, overlap
from .path import follow, timing
from .result import Measures, PathRun, Shared
from .twin import Chain, name_of

DEXTERITY_SAMPLES = 20_000  # joint samples for dexterity, gravity torques and inertia
IK_POSES = 12  # sampled poses at which the real inverse-kinematics solutions are counted
Say = Callable[[str], object]


def joint_space(chain: Chain, ws: Workspace, scale: float, seed: int, say: Say) -> Measures:
    """The chain's measurements beside its workspace `ws`, those over the joint space (metrics)
    from DEXTERITY_SAMPLES uniform samples inside the limits (the same random numbers for every
    chain of one seed)."""
    q = metrics.uniform(chain, DEXTERITY_SAMPLES, np.random.default_rng((seed, 1)))
    w, kappa, near = metrics.dexterity(chain, q, scale)
    g_max, g_rms = metrics.gravity(chain, q)
    mass, legs = metrics.masses(chain)
    say(f"inverse kinematics of {name_of(chain)} at {IK_POSES} poses")
    complex_count, real, inside = metrics.ik_counts(chain, q[:IK_POSES])
    return Measures(
        workspace=ws,
        name=name_of(chain),
        pairs=[p.kind for p in chain.pairs],
        limits=chain.limits,
        full_turn=metrics.full_turns(chain),
        axial_travel=metrics.axial_travel(chain),
        mass=mass,
        leg_mass=legs,
        inertia_mean=metrics.inertia(chain, q),
        manipulability=w,
        condition=kappa,
        near_singular=near,
        gravity_torque_max=g_max,
        gravity_torque_rms=g_rms,
        ik_complex_count=complex_count,
        ik_real_counts=real,
        ik_real_inside_counts=inside,
    )


def shared(a: Workspace, b: Workspace, corners: NDArray[np.float64] | None, seed: int) -> Shared:
    """The two workspaces on one grid, and the common path: `corners` if given, else the longest
    straight line found inside what both reach."""
    h = overlap.grid_size(a, b)
    origin = np.minimum(a.points.min(axis=0), b.points.min(axis=0))
    cells_a, cells_b = overlap.voxels(a.points, origin, h), overlap.voxels(b.points, origin, h)
    only_a, only_b, both = overlap.shares(cells_a, cells_b)
    out = Shared(h, only_a, only_b, both, overlap.sections(cells_a, cells_b, origin, h))
    flat = min(a.dimension, b.dimension) < 3
    if corners is None and flat:
        out.path_note = "the end effector reaches a surface or curve, not a volume: no common path through space"
    elif corners is None:
        corners = overlap.line(cells_a & cells_b, origin, h, np.random.default_rng((seed, 37)))
        if corners is None:
            out.path_note = "no straight line found inside the workspace both chains reach"
    if corners is not None:
        out.path_corners = corners
        out.path_t, out.path_points = timing(corners)
    return out


def measures(
    chain: Chain,
    ws: Workspace,
    common: Shared,
    scale: float,
    seed: int,
    say: Say,
    first: NDArray[np.float64] | None = None,
) -> Measures:
    """One chain's `Measures`: its workspace, joint space and run along the common path (started
    from `first`, if given and it converges there)."""
    m = joint_space(chain, ws, scale, seed, say)
    if common.path_points is None or common.path_t is None:
        m.path = PathRun(False, common.path_note)
    else:
        say(f"{name_of(chain)} along the common path")
        m.path = follow(chain, ws, common.path_t, common.path_points, scale, first)
    return m
