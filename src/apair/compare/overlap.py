"""Two sampled workspaces on one voxel grid: the shares that only one of them reaches, their
cross-sections overlaid, and a straight line inside what both reach (the common path's default).

The grid's voxels are as large as the coarser of the two volume estimates' (the finest size at which
both sample sets fill their voxels, apair.workspace): finer, unsampled voxels inside a workspace
would count as reached by the other one only.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..workspace import Workspace

CANDIDATES = 400  # random pairs of interior voxels tried for the default line
CHECKS_PER_VOXEL = 3  # points checked along a candidate line per voxel length
NEIGHBOURS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])


def grid_size(a: Workspace, b: Workspace) -> float:
    """The voxel size [m] of the common grid: the larger of the two volume voxels (the boundary
    voxels' size for a curve or surface, which has no volume)."""
    return float(max(ws.volume_voxel or ws.voxel for ws in (a, b)))


def _keys(idx: NDArray[np.int64]) -> set[tuple[int, int, int]]:
    return set(map(tuple, np.unique(idx, axis=0).tolist()))


def voxels(points: NDArray[np.float64], origin: NDArray[np.float64], h: float) -> set[tuple[int, int, int]]:
    """The voxels (integer indices on the grid anchored at origin) that the points hit."""
    return _keys(np.floor((points - origin) / h).astype(np.int64))


def shares(a: set[tuple[int, int, int]], b: set[tuple[int, int, int]]) -> tuple[float, float, float]:
    """(only a, only b, both) as shares of the voxels either reaches."""
    union = len(a | b)
    return len(a - b) / union, len(b - a) / union, len(a & b) / union


def sections(
    a: set[tuple[int, int, int]], b: set[tuple[int, int, int]], origin: NDArray[np.float64], h: float
) -> list[tuple[float, NDArray[np.float64], NDArray[np.int8]]]:
    """Per axis, the layer of voxels through the middle of both: (its centre's coordinate [m], the
    image's lower corner [m] in the other two axes, an image of 1 only a, 2 only b, 3 both)."""
    every = np.array(sorted(a | b))
    lo, hi = every.min(axis=0), every.max(axis=0)
    out = []
    for axis in range(3):
        rest = [k for k in range(3) if k != axis]
        layer = (lo[axis] + hi[axis]) // 2
        image = np.zeros(hi[rest] - lo[rest] + 1, dtype=np.int8)
        for code, cells in ((1, a), (2, b)):
            sel = np.array([c for c in cells if c[axis] == layer]).reshape(-1, 3)
            image[tuple((sel[:, rest] - lo[rest]).T)] += code
        corner = origin[rest] + lo[rest] * h
        out.append((float(origin[axis] + (layer + 0.5) * h), corner, image))
    return out


def interior(cells: set[tuple[int, int, int]]) -> set[tuple[int, int, int]]:
    """The voxels whose six face neighbours are in `cells` too."""
    return {c for c in cells if all((c[0] + dx, c[1] + dy, c[2] + dz) in cells for dx, dy, dz in NEIGHBOURS)}


def line(
    cells: set[tuple[int, int, int]], origin: NDArray[np.float64], h: float, rng: np.random.Generator
) -> NDArray[np.float64] | None:
    """The longest of CANDIDATES random segments between voxel centres of `interior(cells)` whose
    points (CHECKS_PER_VOXEL per voxel length) all lie in such voxels: (2, 3) [m], or None."""
    inner = interior(cells)
    if len(inner) < 2:
        return None
    centres = np.array(sorted(inner))
    best, best_length = None, 0.0
    for _ in range(CANDIDATES):
        i, j = rng.choice(len(centres), 2, replace=False)
        p, q = centres[i] + 0.5, centres[j] + 0.5  # in voxel units
        length = float(np.linalg.norm(q - p))
        if length <= best_length:
            continue
        s = np.linspace(0.0, 1.0, max(2, int(np.ceil(CHECKS_PER_VOXEL * length)) + 1))
        on = np.floor(p + s[:, None] * (q - p)).astype(np.int64)
        if all(tuple(c) in inner for c in on.tolist()):
            best, best_length = np.stack([p, q]), length
    return None if best is None else origin + best * h
