"""The common end-effector path: a polyline of points (by default a straight line through what both
chains reach, apair.compare.overlap.line) traversed in DURATION seconds with quintic timing, solved
on each chain and put through its inverse dynamics.

Each chain follows the path of its end-effector origin (its orientation is left free: a chain of
fewer than six joints reaches a line of points but not a line of poses). The first point is solved
from the chain's nearest workspace samples, every later one by damped least squares
(Levenberg-Marquardt on the position rows of the Jacobian) from the solution at the point before:
the nearest solution, the least joint motion where the chain is redundant. A step that does not
converge, would leave the joint limits, or jumps (a joint moves more than MAX_STEP between two
path points: another branch of solutions) ends the run: the path is reported as not followed by
that chain. Velocities and accelerations are second-order finite differences in time; the peak
torque is max |τ_i| per joint and the energy ∫ |τ · θ'| dt (what the motors put in or take out,
none recovered).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .. import _validate as V
from ..workspace import Workspace
from .result import PathRun
from .twin import Chain

DURATION = 1.0  # [s]
STEPS = 201  # path points, the ends included
MAX_STEP = 0.25  # [rad]: a larger change between two path points is a jump to another branch
MAX_ITER = 200  # Levenberg-Marquardt steps per path point
SEEDS = 16  # workspace samples tried for the first point
TOL = 1e-9  # residual [in units of the chain's length scale]
MAX_POINTS = STEPS - 1  # corners a given path may have (each is passed within one time step)


def points(path: object) -> NDArray[np.float64]:
    """A given path: (k, 3) end-effector points [m], k ≥ 2, consecutive points distinct."""
    p = V.real_array("path", path)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"path: expected points of shape (k, 3) (x, y, z in m), got shape {p.shape}")
    if not 2 <= len(p) <= MAX_POINTS:
        raise ValueError(f"path: expected 2 to {MAX_POINTS} points, got {len(p)}")
    if np.any(np.linalg.norm(np.diff(p, axis=0), axis=1) == 0):
        raise ValueError("path: two consecutive points are the same")
    return p


def read_csv(file: str) -> NDArray[np.float64]:
    """Points from a CSV file: one x, y, z [m] per line; `#` starts a comment. Reading stops
    (refused) past MAX_POINTS points, so a large file costs no more than a short one."""
    name = V.shorten(repr(file))
    values: list[list[float]] = []
    try:
        with open(file, encoding="utf-8") as f:
            for k, line in enumerate(f, 1):
                row = line.split("#", 1)[0].strip()
                if row:
                    values.append(_row(row, k, name))
                if len(values) > MAX_POINTS:
                    raise ValueError(f"path: {name} has more than {MAX_POINTS} points")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"path: cannot read {name}: {getattr(exc, 'strerror', None) or exc}") from None
    return points(np.array(values).reshape(-1, 3))


def _row(row: str, k: int, name: str) -> list[float]:
    """Line k's three numbers."""
    words = [w.strip() for w in row.split(",")]
    try:
        values = [float(w) for w in words]
    except ValueError:
        raise ValueError(f"path: line {k} of {name} is not numbers separated by commas") from None
    if len(words) != 3:
        raise ValueError(f"path: line {k} of {name} has {len(words)} numbers, expected 3 (x, y, z in m)")
    return values


def timing(corners: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(t (STEPS,) [s], points (STEPS, 3) [m]): the polyline at arc length L·s(t/DURATION),
    s(u) = 10u³ − 15u⁴ + 6u⁵ (at rest at both ends, no jump in acceleration)."""
    t = np.linspace(0.0, DURATION, STEPS)
    u = t / DURATION
    seg = np.linalg.norm(np.diff(corners, axis=0), axis=1)
    along = np.concatenate([[0.0], np.cumsum(seg)])
    s = along[-1] * (10 * u**3 - 15 * u**4 + 6 * u**5)
    return t, np.stack([np.interp(s, along, corners[:, k]) for k in range(3)], axis=1)


def _bounds(chain: Chain) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The joint bounds a step stays in: the chain's hard limits (±inf where a joint turns fully),
    a hair inside (at a general A-pair's range end d' is unbounded)."""
    hard = chain.hard_limits()
    span = np.where(np.isfinite(hard).all(axis=1), hard[:, 1] - hard[:, 0], 0.0)
    return hard[:, 0] + 1e-9 * span, hard[:, 1] - 1e-9 * span


def _step(
    J: NDArray[np.float64],
    e: NDArray[np.float64],
    mu: float,
    q: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The damped least-squares step J⁺e, without the joints that sit on a bound and would be
    pushed past it (they are held and the others move: an active set, at most n passes)."""
    held = np.zeros(len(q), dtype=bool)
    for _ in range(len(q)):
        Jf = np.where(held, 0.0, J)
        dq = Jf.T @ np.linalg.solve(Jf @ Jf.T + mu * np.eye(3), e)
        out = ((q <= lo) & (dq < 0)) | ((q >= hi) & (dq > 0))
        if not np.any(out & ~held):
            return dq
        held |= out
    return dq


def solve(
    chain: Chain, p: NDArray[np.float64], q0: NDArray[np.float64], tol: float
) -> tuple[NDArray[np.float64], bool]:
    """A joint vector in the bounds whose end-effector origin is p (residual ≤ tol), from q0 by
    Levenberg-Marquardt on the position rows; (q, converged)."""
    lo, hi = _bounds(chain)
    q = np.clip(q0, lo, hi)
    e = p - chain.fk(q)[:3, 3]
    mu = 1e-3 * float(np.max(np.abs(chain.jacobian(q)[:3]))) ** 2 + 1e-300
    floor = 1e-12 * mu  # the damping never vanishes: J Jᵀ + μ I stays invertible at a singularity
    for _ in range(MAX_ITER):
        if np.max(np.abs(e)) <= tol:
            return q, True
        trial = np.clip(q + _step(chain.jacobian(q)[:3], e, mu, q, lo, hi), lo, hi)
        e_trial = p - chain.fk(trial)[:3, 3]
        if np.linalg.norm(e_trial) < np.linalg.norm(e):
            q, e, mu = trial, e_trial, max(mu / 3, floor)
        else:
            mu *= 4
    return q, bool(np.max(np.abs(e)) <= tol)


def start(
    chain: Chain, ws: Workspace, p: NDArray[np.float64], tol: float, first: NDArray[np.float64] | None = None
) -> NDArray[np.float64] | None:
    """The first point's solution: from `first` if given (the twin starts from the chain's start,
    so that both take the same branch where they can), else from the SEEDS workspace samples
    nearest to the point, nearest first."""
    order = np.argsort(np.linalg.norm(ws.points - p, axis=1))[:SEEDS]
    seeds = ([] if first is None else [first]) + [ws.q[k] for k in order]
    for seed in seeds:
        q, ok = solve(chain, p, seed, tol)
        if ok:
            return q
    return None


def follow(
    chain: Chain,
    ws: Workspace,
    t: NDArray[np.float64],
    pts: NDArray[np.float64],
    scale: float,
    first: NDArray[np.float64] | None = None,
) -> PathRun:
    """The chain along the path points `pts` at times `t` (module docstring), with its dynamics;
    `first`: a joint vector to start the first point's solution from. A run that stops keeps the
    joint vectors it found (`q`), for the picture and for a twin to start from."""
    if chain.n < 3:
        return PathRun(False, f"{chain.n} joints reach a surface or curve of points, not a path through space")
    tol = TOL * scale
    q0 = start(chain, ws, pts[0], tol, first)
    if q0 is None:
        return PathRun(False, "no solution found at the path's first point")
    qs = [q0]
    for k in range(1, len(pts)):
        q, ok = solve(chain, pts[k], qs[-1], tol)
        where = f"at {k / (len(pts) - 1):.0%} of the path (t = {t[k]:.3g} s)"
        if not ok:
            return PathRun(False, f"no solution within the joint limits {where}", q=np.array(qs))
        if np.max(np.abs(q - qs[-1])) > MAX_STEP:
            return PathRun(False, f"the solution jumps to another branch {where}", q=np.array(qs))
        qs.append(q)
    return dynamics(chain, t, np.array(qs))


def dynamics(chain: Chain, t: NDArray[np.float64], q: NDArray[np.float64]) -> PathRun:
    """The motion q(t) (k, n) through the inverse dynamics: velocities and accelerations by
    second-order finite differences, torques, their peaks, the energy and the signed work."""
    qd = np.gradient(q, t, axis=0, edge_order=2)
    qdd = np.gradient(qd, t, axis=0, edge_order=2)
    tau = chain.inverse_dynamics(q, qd, qdd)
    power = np.sum(tau * qd, axis=1)
    return PathRun(
        True,
        t=t,
        q=q,
        qd=qd,
        qdd=qdd,
        tau=tau,
        peak_torque=np.abs(tau).max(axis=0),
        energy=float(np.trapezoid(np.abs(power), t)),
        work=float(np.trapezoid(power, t)),
        max_step=float(np.max(np.abs(np.diff(q, axis=0)))) if len(q) > 1 else 0.0,
    )
