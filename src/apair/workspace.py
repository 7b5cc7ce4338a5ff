"""Reachable workspaces: adaptive sampling of joint space, occupancy grids, an extrapolated volume.

1. Joint vectors are drawn uniformly inside the chain's limits (`AChain.limits`) and put through
   the batched fk kernel, in batches with their own seeds (so a Dask run returns exactly what a
   local run does).
2. Later rounds put half of their samples near the samples that landed in boundary voxels (an
   occupied voxel with an empty face neighbour): a Gaussian step in joint space, reflected back
   into the limits. The boundary, where the sample density is lowest, is where coverage is refined.
3. Every voxel computation runs on the points normalised to unit size (the bounding box's longest
   side is 1); lengths, areas and volumes are scaled back at the end, so a chain scaled by s has s³
   times the volume (and the uncertainty) wherever s³ is a normal double.
4. The volume: voxels of size h hit by a sample overcount the body by about half a voxel over its
   surface, so each exposed voxel face takes half a voxel off: V(h) = h³(occupied − ½ faces). That
   holds only for a voxel body the samples fill: a voxel with no sample inside the body leaves a hole
   whose six faces cost it four voxels, and too few samples for the voxels made V(h) negative. So
   the volume is measured at the finest voxel size from 1/resolution upwards (steps of 1.25) at
   which there are FILL samples per occupied voxel. What remains is of order h (curvature,
   coverage), so V(h) is measured at five voxel sizes from h to 2h, each with three random grid
   offsets, and extrapolated linearly to size 0. The standard uncertainty adds, in quadrature, the
   fit's standard error, half the extrapolation's length, the change when every voxel is 1.5 times
   larger (resolution: edges and thin parts that a linear extrapolation misses), and the coverage
   still missing. An estimate below 0 (a body thinner than its voxels) is replaced by what is known
   for certain: the volume lies between 0 and the occupied voxels' volume, reported as that
   interval's middle and standard deviation (uniform).
5. Coverage: the measured volume after each round grows like V∞ − A·N^(−γ) as sampled regions fill
   in; fitted to the last three rounds, the remainder A·N^(−γ) is added to the volume. Its
   uncertainty is the larger of that remainder and three times the change from half the samples to all of
   them.

The cost is linear in the sample count: the fk kernel (about 1 µs per sample) and one np.unique
per voxel size and offset (some 60 of them).
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, TextIO, TypeAlias, cast

import numpy as np
from numpy.typing import NDArray

from . import figures

if TYPE_CHECKING:
    from ._typing import ChainLike

LEVELS = (1.0, 1.25, 1.5, 1.75, 2.0)  # voxel sizes in units of h₀
OFFSETS = 3  # random grid offsets per voxel size
BATCH = 50_000
COVERAGE_FACTOR = 3.0  # the remaining coverage deficit, in units of the last doubling's change (γ ≈ 0.4)
COARSER = 1.5  # the same estimate with voxels this much larger measures the resolution's effect
MAX_GRID_BYTES = 2 * 2**30  # a voxel grid larger than this is refused, not attempted
MAX_SAMPLE_BYTES = 8 * 2**30  # the kept samples (points, joint values, poses)
MAX_SAMPLES = 10**8  # samples a call may ask for (about 10 minutes of fk and voxel counting)
MAX_ROUNDS = 100
MIN_RESOLUTION = 4  # voxels along the longest side: the coarsest grid a volume is measured on
FILL = 12  # samples per occupied voxel at which the voxel body counts as filled
LADDER = 1.25  # the step between the voxel sizes tried for that
SIDE_RANGE = (1e-102, 1e102)  # the workspace's size [m] for which its cube is a normal double
GAMMA_RANGE = (0.2, 5.0)  # coverage exponents γ taken as a power law; slower growth is not extrapolated
LOCAL_ENGINES = ("threads", "processes", "synchronous")
CONNECT_TIMEOUT = "10s"  # to reach a scheduler address

Progress: TypeAlias = Callable[[int, int], object]  # progress(done, total)
# a batch of samples (_batch's arguments): chain, limits lo and hi, seed, count, centres, sigma, poses
_Task: TypeAlias = tuple[
    "ChainLike",
    NDArray[np.float64],
    NDArray[np.float64],
    tuple[int, int, int],
    int,
    NDArray[np.float64] | None,
    NDArray[np.float64] | None,
    bool,
]


@dataclass
class Workspace:
    """The sampled workspace of a chain.

    points: (m, 3) end-effector origins of all samples; poses: (m, 8) their Study points (if
    asked for); q: (m, n) the joint samples; boundary: (k, 3) centres of the boundary voxels of
    size `voxel`; volume, volume_error: the extrapolated volume [m³] and one standard uncertainty;
    dimension: that of the set of reachable points (3, or 1 and 2 for a curve or a surface, whose
    volume is None and whose length [m] or area [m²] estimate is `measure`);
    volume_voxel: the voxel size [m] the volume was measured at (coarser than `voxel` when the
    samples are too few to fill finer voxels); history: (samples, corrected occupancy volume [m³]
    at volume_voxel) after each round, the convergence record.
    """

    points: NDArray[np.float64]
    q: NDArray[np.float64]
    boundary: NDArray[np.float64]
    voxel: float
    volume: float | None
    volume_error: float | None
    poses: NDArray[np.float64] | None = None
    history: list[tuple[int, float]] = field(default_factory=list)
    chain_name: str = ""
    dimension: int = 3
    measure: float | None = None
    volume_voxel: float | None = None

    @property
    def summary(self) -> str:
        """One line: the volume with its uncertainty, or what a curve or surface is instead."""
        if self.dimension == 3:
            return f"volume {self.volume:.6g} ± {self.volume_error:.2g} m^3 (one standard uncertainty)"
        kind, unit = ("a curve", "length") if self.dimension == 1 else ("a surface", "area")
        power = "" if self.dimension == 1 else "^2"
        return (
            f"{kind} (dimension {self.dimension}, no volume); estimated {unit} {self.measure:.4g} m{power} "
            f"(from voxel crossings, a few per cent)"
        )

    def plot(self, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
        """A 3D view of the points and three cross-sections through the centre (matplotlib)."""
        return figures.workspace(self, path, overwrite=overwrite)


def _batch(
    chain: ChainLike,
    q_lo: NDArray[np.float64],
    q_hi: NDArray[np.float64],
    seed: tuple[int, int, int],
    count: int,
    centres: NDArray[np.float64] | None,
    sigma: NDArray[np.float64] | None,
    poses: bool,
) -> dict[str, NDArray[np.float64]]:
    """One batch of samples: uniform in the limits, or Gaussian about centres (reflected)."""
    rng = np.random.default_rng(seed)
    if centres is None:
        q = rng.uniform(q_lo, q_hi, (count, len(q_lo)))
    else:
        step = cast(NDArray[np.float64], sigma)  # given with the centres
        q = centres[rng.integers(0, len(centres), count)] + rng.normal(0.0, 1.0, (count, len(q_lo))) * step
        span = q_hi - q_lo
        q = q_lo + span - np.abs(np.mod(q - q_lo, 2 * span) - span)  # reflected into [lo, hi]
    T = chain.fk(q)
    out = {"q": q, "points": T[:, :3, 3].copy()}
    if poses:
        out["poses"] = chain.fk_study(q)
    return out


def _run(tasks: Sequence[_Task], engine: object, progress: Progress | None) -> list[dict[str, NDArray[np.float64]]]:
    """Evaluate the batch tasks locally or on Dask, in order."""
    if engine is None:
        out: list[dict[str, NDArray[np.float64]]] = []
        for k, t in enumerate(tasks):
            out.append(_batch(*t))
            if progress:
                progress(k + 1, len(tasks))
        return out
    import dask

    delayed = [dask.delayed(_batch)(*t) for t in tasks]
    if isinstance(engine, str) and engine in LOCAL_ENGINES:
        res = dask.compute(*delayed, scheduler=engine)
    else:
        from dask.distributed import Client

        client = engine if isinstance(engine, Client) else None
        if client is None:
            try:
                client = Client(engine, timeout=CONNECT_TIMEOUT)
            except (OSError, TimeoutError, ValueError) as exc:
                raise ValueError(
                    f"engine: cannot reach a Dask scheduler at {engine!r} within {CONNECT_TIMEOUT} "
                    f"({type(exc).__name__}: {exc})"
                ) from None
        try:
            res = client.gather(client.compute(delayed))
        finally:
            if client is not engine:
                client.close()
    if progress:
        progress(len(tasks), len(tasks))
    return list(res)


def _check_engine(engine: object) -> None:
    """engine: None, a local Dask scheduler name, a scheduler address or a Client."""
    if engine is None:
        return
    if isinstance(engine, str):
        if engine in LOCAL_ENGINES or "://" in engine or ":" in engine:
            return
        raise ValueError(
            f"engine: expected None, one of {LOCAL_ENGINES}, a scheduler address (tcp://host:port) "
            f"or a dask.distributed.Client, got {engine!r}"
        )
    from dask.distributed import Client

    if not isinstance(engine, Client):
        raise ValueError(
            f"engine: expected None, one of {LOCAL_ENGINES}, a scheduler address or a "
            f"dask.distributed.Client, got {engine!r}"
        )


def _voxels(points: NDArray[np.float64], origin: NDArray[np.float64], h: float) -> NDArray[np.int64]:
    """The distinct voxel indices (k, 3) hit by the points (grid anchored at origin)."""
    idx = np.floor((points - origin) / h).astype(np.int64)
    base = idx.min(axis=0)
    dims = idx.max(axis=0) - base + 1
    flat = np.unique(np.ravel_multi_index(tuple((idx - base).T), dims))
    return np.stack(np.unravel_index(flat, dims), axis=1) + base


def _grid(vox: NDArray[np.int64]) -> NDArray[np.bool_]:
    lo = vox.min(axis=0) - 1
    grid = np.zeros(vox.max(axis=0) - lo + 2, dtype=bool)
    grid[tuple((vox - lo).T)] = True
    return grid


def _corrected_volume(points: NDArray[np.float64], origin: NDArray[np.float64], h: float) -> float:
    """h³ (occupied voxels − ½ exposed faces): the occupancy volume without its half-voxel layer."""
    grid = _grid(_voxels(points, origin, h))
    faces = sum(np.count_nonzero(np.diff(grid, axis=a)) for a in range(3))
    return (np.count_nonzero(grid) - 0.5 * faces) * h**3


def _boundary(points: NDArray[np.float64], origin: NDArray[np.float64], h: float) -> NDArray[np.int64]:
    """Occupied voxels with an empty face neighbour: their integer indices."""
    vox = _voxels(points, origin, h)
    grid = _grid(vox)
    inner = vox - (vox.min(axis=0) - 1)
    full = np.ones(len(vox), dtype=bool)
    for axis in range(3):
        for step in (-1, 1):
            nb = inner.copy()
            nb[:, axis] += step
            full &= grid[tuple(nb.T)]
    return vox[~full]


def _estimate(
    points: NDArray[np.float64], origin: NDArray[np.float64], h0: float, rng: np.random.Generator
) -> tuple[float, float]:
    """Intercept and standard error of V(h) = V + c₁h over LEVELS × OFFSETS (sizes in units of h₀,
    so the fit's conditioning does not depend on the chain's size)."""
    levels, volumes = [], []
    for level in LEVELS:
        for _ in range(OFFSETS):
            levels.append(level)
            volumes.append(_corrected_volume(points, origin - rng.uniform(0, h0 * level, 3), h0 * level))
    x, vs = np.array(levels), np.array(volumes)
    A = np.stack([np.ones_like(x), x], axis=1)
    coef, *_ = np.linalg.lstsq(A, vs, rcond=None)
    resid = vs - A @ coef
    cov = np.linalg.inv(A.T @ A) * (resid @ resid / (len(vs) - 2))
    # the extrapolation itself is a model: half its length (from level 1 to 0) counts as uncertainty
    model = 0.5 * abs(coef[1])
    return float(coef[0]), float(math.hypot(math.sqrt(cov[0, 0]), model))


def _occupied(points: NDArray[np.float64], h: float) -> int:
    """How many voxels of size h (grid at −h/2) the points hit."""
    return len(_voxels(points, np.full(3, -0.5 * h), h))


def _working_size(unit: NDArray[np.float64], resolution: int) -> float:
    """The finest voxel size from 1/resolution upwards (steps of LADDER, at most 1/MIN_RESOLUTION)
    with FILL samples per occupied voxel: coarser than that, holes of unsampled voxels inside the
    body would each take four voxels off V(h) (module docstring, 4)."""
    r = float(resolution)
    while r / LADDER >= MIN_RESOLUTION and len(unit) < FILL * _occupied(unit, 1.0 / r):
        r /= LADDER
    return 1.0 / r


def _unit_volume(
    unit: NDArray[np.float64], counts: Sequence[int], resolution: int, seed: int
) -> tuple[float, float, float, list[tuple[int, float]]]:
    """The volume of the points normalised to unit size (module docstring, 4 and 5): volume, its
    standard uncertainty, the voxel size it was measured at and the per-round record (samples after
    each round in `counts`, V(h) then)."""
    h = _working_size(unit, resolution)
    origin = np.full(3, -0.5 * h)
    history = [(n, _corrected_volume(unit[:n], origin, h)) for n in counts]

    def rng() -> np.random.Generator:
        return np.random.default_rng((seed, 99))

    volume, fit_err = _estimate(unit, origin, h, rng())
    coarse, _ = _estimate(unit, origin, COARSER * h, rng())
    half, _ = _estimate(unit[: len(unit) // 2], origin, h, rng())
    remainder = _coverage_remainder(history) or 0.0
    coverage = max(remainder, COVERAGE_FACTOR * abs(volume - half))
    error = math.sqrt(fit_err**2 + coverage**2 + (volume - coarse) ** 2)
    volume += remainder
    if volume < 0:  # a body thinner than its voxels: only 0 ≤ V ≤ the occupied volume is known
        top = _occupied(unit, h) * h**3
        volume, error = 0.5 * top, top / math.sqrt(12)
    return volume, error, h, history


def _check_counts(
    chain: ChainLike, samples: object, resolution: object, rounds: object, poses: bool
) -> tuple[int, int, int]:
    """samples, resolution and rounds as integers within the work and memory they may ask for."""
    from . import _validate as V

    samples = V.integer("samples", samples, maximum=MAX_SAMPLES)
    top = int(MAX_GRID_BYTES ** (1 / 3)) - 4  # (resolution + 4)³ bytes: the finest voxel grid with margins
    resolution = V.integer("resolution", resolution, minimum=MIN_RESOLUTION, maximum=top)
    rounds = V.integer("rounds", rounds, maximum=MAX_ROUNDS)
    per_sample = (3 + len(chain.pairs)) * 8 + (8 * 8 if poses else 0)  # points, joint values, poses
    if samples * per_sample > MAX_SAMPLE_BYTES:
        raise ValueError(
            f"samples: {samples} samples need more than {MAX_SAMPLE_BYTES / 2**30:.0f} GiB to keep; "
            f"at most {MAX_SAMPLE_BYTES // per_sample} fit"
        )
    if samples < 1000 * rounds:
        raise ValueError(f"samples: at least {1000 * rounds} are needed for {rounds} rounds, got {samples}")
    return samples, resolution, rounds


def _unit_box(pts: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """The lower corner and longest side [m] of the first round's points, refused when the
    points are not finite or the volume of a box that size is not a normal double."""
    if not np.isfinite(pts).all():
        raise ValueError("chain: the forward kinematics gives non-finite end-effector positions")
    box_lo = pts.min(axis=0)
    side = float(np.max(pts.max(axis=0) - box_lo))
    if side <= 0:
        raise ValueError("chain: every sample reaches the same point; the workspace has no volume")
    lo, hi = SIDE_RANGE
    if not lo <= side <= hi:
        raise ValueError(
            f"chain: the workspace is {side:.3g} m across; its volume is computed for sizes from {lo:g} "
            f"to {hi:g} m (where volumes are normal doubles)"
        )
    return box_lo, side


def workspace(
    chain: ChainLike,
    samples: int = 200_000,
    resolution: int = 40,
    rounds: int = 4,
    poses: bool = False,
    engine: object = None,
    seed: int = 0,
    progress: Progress | None = None,
) -> Workspace:
    """Approximate the reachable workspace of the end-effector origin (see the module docstring).

    samples: total joint samples (1000 per round to MAX_SAMPLES); resolution: voxels along the
    longest side of the bounding box for the boundary (h₀ = side / resolution), the finest the
    volume is measured at; rounds: sampling rounds (the first uniform, at most MAX_ROUNDS); poses:
    keep the Study points too; engine: None (this process), "threads" or "processes" (local Dask),
    a dask.distributed scheduler address or Client; progress: callable(done, total) or None.
    """
    from . import _validate as V

    samples, resolution, rounds = _check_counts(chain, samples, resolution, rounds, V.flag("poses", poses))
    seed = V.seed(seed)
    _check_engine(engine)
    lim = chain.limits
    lo, hi = lim[:, 0], lim[:, 1]
    per_round = samples // rounds
    sigma = 0.05 * (hi - lo)
    parts: list[dict[str, NDArray[np.float64]]] = []
    counts: list[int] = []  # samples after each round
    # the round's centres of its Gaussian samples and their spread (none in the first round)
    centres: NDArray[np.float64] | None = None
    step: NDArray[np.float64] | None = None
    h0 = 1.0 / resolution  # in units of the bounding box's longest side, as every voxel below
    origin = np.full(3, -0.5 * h0)
    done, total = 0, rounds * math.ceil(per_round / BATCH)
    for r in range(rounds):
        sizes = [min(BATCH, per_round - k) for k in range(0, per_round, BATCH)]
        tasks: list[_Task] = [
            (chain, lo, hi, (seed, r, k), c, centres if k % 2 else None, step, poses) for k, c in enumerate(sizes)
        ]
        tick = (lambda k, _n, done=done: progress(done + k, total)) if progress else None
        parts += _run(tasks, engine, tick)
        done += len(sizes)
        pts = np.concatenate([p["points"] for p in parts])
        qs = np.concatenate([p["q"] for p in parts])
        if r == 0:
            box_lo, side = _unit_box(pts)
        unit = (pts - box_lo) / side
        counts.append(len(pts))
        if r + 1 < rounds:  # the next round: half of its samples near those in boundary voxels
            edge = _boundary(unit, origin, h0)
            on_edge = _member(np.floor((unit - origin) / h0).astype(np.int64), edge)
            centres = qs[on_edge] if on_edge.any() else qs
            step = sigma / (1 + (r + 1))
    dimension = _dimension(chain, qs, side)
    ws = Workspace(
        points=pts,
        q=qs,
        boundary=box_lo + side * (origin + (_boundary(unit, origin, h0) + 0.5) * h0),
        voxel=side * h0,
        volume=None,
        volume_error=None,
        poses=np.concatenate([p["poses"] for p in parts]) if poses else None,
        chain_name=getattr(chain, "name", ""),
        dimension=dimension,
    )
    if dimension < 3:
        ws.measure = _measure(chain, unit, qs, origin, h0, dimension) * side**dimension
        return ws
    volume, error, h, history = _unit_volume(unit, counts, resolution, seed)
    scale = side**3  # a normal double: side is within SIDE_RANGE
    ws.volume, ws.volume_error, ws.volume_voxel = volume * scale, error * scale, h * side
    ws.history = [(n, v * scale) for n, v in history]
    return ws


def _dimension(chain: ChainLike, qs: NDArray[np.float64], side: float, probes: int = 256) -> int:
    """The dimension of the reachable point set: the largest rank of the position rows of the
    Jacobian over a spread of samples (relative tolerance 1e-7 of the workspace's size)."""
    J = chain.jacobian(qs[:: max(1, len(qs) // probes)])[:, :3, :]
    return int(np.linalg.matrix_rank(J, tol=1e-7 * max(side, 1e-300)).max())


def _measure(
    chain: ChainLike,
    pts: NDArray[np.float64],
    qs: NDArray[np.float64],
    origin: NDArray[np.float64],
    h: float,
    dimension: int,
) -> float:
    """Length (dimension 1) or area (2) of the reachable set, in units of the points' (the caller
    scales it back), from the voxels its samples occupy:
    a curve with unit tangent t crosses |t|₁/h voxels per unit length, a surface with unit normal n
    |n|₁/h² per unit area, so each occupied voxel contributes h/|t|₁ (h²/|n|₁) with the tangent
    (normal) of one sample in it, from the Jacobian there; measured at the voxel sizes LEVELS,
    from the finest from h up at which the samples fill the voxels (FILL per occupied voxel, as
    for volumes: finer, unsampled gaps would count as missing length or area), and extrapolated
    linearly to size 0. The extrapolation removes the rim's excess, a fraction of the finest
    size's value; where it would remove more than half (voxels too coarse for a line fit, the
    estimate could even turn negative), the finest size's value is kept."""

    def at(size: float) -> float:
        idx = np.floor((pts - origin) / size).astype(np.int64)
        _, first = np.unique(idx, axis=0, return_index=True)
        U = np.linalg.svd(chain.jacobian(qs[first])[:, :3, :])[0]  # (k, 3, 3): left singular vectors
        direction = U[:, :, 0] if dimension == 1 else U[:, :, 2]  # the tangent, or the normal
        return float(np.sum(size**dimension / np.abs(direction).sum(axis=1)))

    # voxels at the rim (the ends) are partly outside: an excess of order h, extrapolated away
    while h * LADDER <= 1.0 / MIN_RESOLUTION and len(pts) < FILL * _occupied(pts, h):
        h *= LADDER
    sizes = h * np.array(LEVELS)
    values = [at(size) for size in sizes]
    zero = float(np.polyfit(sizes, values, 1)[1])
    return zero if 0.5 * values[0] <= zero <= values[0] else values[0]


def _coverage_remainder(history: Sequence[tuple[int, float]]) -> float | None:
    """The volume still to come as the sample count grows without bound, from the occupancy of the
    last three rounds: V(N) = V∞ − A·N^(−γ) fitted exactly; None when the rounds do not grow
    like that (fewer than three rounds, no growth, growth that does not slow down, or γ outside
    GAMMA_RANGE: slower growth extrapolates to an unbounded remainder)."""
    if len(history) < 3:
        return None
    (n1, v1), (n2, v2), (n3, v3) = history[-3:]
    d1, d2 = v2 - v1, v3 - v2
    if not (d1 > 0 and d2 > 0 and d1 > d2):
        return None

    def ratio(g: float) -> float:
        return (n1**-g - n2**-g) / (n2**-g - n3**-g)

    lo, hi = GAMMA_RANGE
    target = d1 / d2
    if not ratio(lo) < target < ratio(hi):
        return None
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ratio(mid) < target else (lo, mid)
    g = 0.5 * (lo + hi)
    return float(d2 * n3**-g / (n2**-g - n3**-g))


def _member(keys: NDArray[np.int64], table: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Rows of keys (m, 3) that occur in table (k, 3)."""
    both = np.concatenate([table, keys])
    _, inv = np.unique(both, axis=0, return_inverse=True)
    inv = inv.ravel()
    in_table = np.zeros(inv.max() + 1, dtype=bool)
    in_table[inv[: len(table)]] = True
    return in_table[inv[len(table) :]]


def text_progress(stream: TextIO | None = None, width: int = 40) -> Callable[[int, int], None]:
    """A progress bar for the command line (on stderr by default): callable(done, total)."""

    def show(done: int, total: int) -> None:
        out = stream or sys.stderr
        filled = int(width * done / max(total, 1))
        out.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} batches")
        if done >= total:
            out.write("\n")
        out.flush()

    return show
