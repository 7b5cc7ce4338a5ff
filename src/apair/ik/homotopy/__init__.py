"""Every complex solution of an R/A/P chain's inverse kinematics by parameter homotopy (n = 1..6).

A P-pair's unknown is its slide x in units of the chain's scale (no period; "far out" by log |x|,
`problem.far_of`); below, "angles" include it.

The equations (derivations/chain_ik.py, kernel ik_system6) are F(θ; t, q) = 0: the chain's end
frame at the pose with translation t and rotation quaternion q (up to scale), over the complex
numbers. Paths are tracked in the complex angles θ. Two angle vectors are one solution when they
differ by a period in each joint: 4π for an A-pair (its pose changes with θ + 2π), 2π for an
R-pair. The pose enters linearly, the solution set over all poses is irreducible, and monodromy
reaches all of it:

- **Start system** (per design, once): a random complex θ* and a pose p0 solving F(θ*; p0) = 0
  give one solution; loops p0 → p_a → p_b → p0 through random complex poses carry every known
  solution to a permutation of them and add the new ones, until `STABLE` loops in a row add none.
  It is cached on disk under the design's content hash (`apair ik-prepare CHAIN.toml`, or the
  first `ik`). A chain of n < 6 joints reaches only an n-dimensional family of poses; it is
  tracked as a 6-joint chain, with 6 − n fixed virtual R-pairs of generic geometry appended
  (`VIRTUAL`), at the target T·A_virtual(0): its solutions with the virtual joints at 0 are the
  chain's solutions at T, and the others are discarded. Its last joint's Tx(a)·Rx(α) is tracked
  as a fixed generic one (`TURN`), the target moved by the constant difference (`Problem.tail`),
  so that the first virtual axis is never that joint's own (α = 0, a = 0: a curve of solutions).
- **Per pose**: the start solutions are tracked from p0 to the target with a random γ (path
  p0 + s (p1 − p0), s = γτ/(1 + (γ − 1)τ)), in C (`apair_ik_track`: RK4 predictor, Newton
  corrector, Newton refinement and a condition number at the end), or by `track_numpy` without
  the C kernels. The solutions that paths which failed, or landed on the same endpoint as another
  (a path jump), left missing are looked for with new γ (see `solve`). Real endpoints are the
  candidates; `apair.ik` verifies them with the fk kernel.
- **Far out** in the complex (|Im θ| ≈ 10) the terms of F that cancel are exp(2|Im θ|) larger
  than F and Newton in double stalls (at about 1e-5). The C tracker then takes F from
  ik_residual6 in extended precision (`wide`: beyond which |Im θ| a stalled Newton step does so,
  while tracking and at the endpoint, and the most steps a path may take so): WIDE_START for the
  start sets (their far-out endpoints are refined, and a regular one is OK), WIDE_POSE per pose
  (endpoints far out are not real, so they are not refined, and a path that crawls far out is
  given up after 100 such steps: with another γ it takes another way). An endpoint left
  unrefined (SINGULAR) is one with another within LOOSE. The NumPy fallback has double only.
- **Completeness**: a start set is `certified` by its trace test (apair.ik.homotopy.trace, passed to
  `start_system` as `certify`) where one has run. Otherwise, where it has as many solutions as the
  pattern's generic count (`generic_count`, from `apair show ik_counts`): the generic count bounds
  the isolated solutions of every design of the pattern (coefficient-parameter theory: the number
  of nonsingular isolated solutions is the same at generic parameters and no larger at any), so
  such a set has them all; monodromy stops as soon as it gets there. Otherwise it is `certified`
  when two independent monodromy runs (each from its own random start, each stable for STABLE
  loops) found the same number, the union's, and CHECK_LOOPS further loops carry every solution
  without losing a path. That is weaker: a solution that every run misses (far out in the complex,
  where paths lose digits) goes unnoticed. A pose's answer is complete when, in addition, its
  distinct finite endpoints plus its confirmed paths to infinity make up the start count. A path
  reported as diverging proves nothing by itself (at a generic pose every solution is finite, and
  a path can jump off to infinity): its start is tracked again with new γ, and paths to infinity
  count only when `endpoints.CONFIRM` rounds without failures agree on them (see `solve`).
- **Special poses** (axis-aligned rotations, the workspace's boundary, unreachable targets): per
  pose the C tracker ends a path found going to infinity by an endgame in log(1 − τ) once it is
  beyond |Im θ| = ENDGAME_FAR (apair_ik_track.c, to_infinity; such a path may instead end at a
  finite point farther out, and the endpoints beyond ENDGAME_FAR are taken alike, none real).
  Paths that meet at an ill-conditioned endpoint meet at a multiple root (a singular pose); the
  set is then certified by the pose moved by NEAR, solved and its solutions carried back by
  Newton (`solve_near`).
"""

from __future__ import annotations

from .endpoints import NEAR, Endpoints, merged, solve, solve_near
from .monodromy import segment
from .problem import (
    LOOSE,
    REAL,
    SAME,
    VIRTUAL,
    VIRTUAL_ZERO,
    Index,
    Problem,
    canonical,
    law,
    linear_pose,
    own,
    own_rows,
    random_pose,
    real_angles,
    scale_of,
    system,
    target_of,
)
from .startsets import StartSystem, generic_count, prepare, start_system, stored_counts
from .tracker import (
    DIVERGED,
    ENDGAME_FAR,
    FAILED,
    OK,
    RETRIES,
    SINGULAR,
    TOO_LONG,
    TRACK,
    WIDE_POSE,
    WIDE_START,
    newton,
    track,
    track_numpy,
    track_system,
    unit_gamma,
)

__all__ = [
    "DIVERGED",
    "ENDGAME_FAR",
    "FAILED",
    "LOOSE",
    "NEAR",
    "OK",
    "REAL",
    "RETRIES",
    "SAME",
    "SINGULAR",
    "TOO_LONG",
    "TRACK",
    "VIRTUAL",
    "VIRTUAL_ZERO",
    "WIDE_POSE",
    "WIDE_START",
    "Endpoints",
    "Index",
    "Problem",
    "StartSystem",
    "canonical",
    "generic_count",
    "law",
    "linear_pose",
    "merged",
    "newton",
    "own",
    "own_rows",
    "prepare",
    "random_pose",
    "real_angles",
    "scale_of",
    "segment",
    "solve",
    "solve_near",
    "start_system",
    "stored_counts",
    "system",
    "target_of",
    "track",
    "track_numpy",
    "track_system",
    "unit_gamma",
]
