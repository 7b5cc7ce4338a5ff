"""Path tracking: every start solution carried from one pose to another along a γ arc, in C
(`apair_ik_track`, threads sharing the paths) or by `track_numpy`; Newton's method at a fixed
pose (`newton`). The statuses a path ends with, and the settings of the tracker, are here.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from typing import TypedDict

import numpy as np

from ... import kernels
from ...kernels import native_in_use
from .problem import Problem, complex_of, far_of, law, pairs_of, system

RETRIES = 10  # new γ for what paths that failed or jumped left undone (per pose: rounds, see solve)
OK, SINGULAR, FAILED, DIVERGED, TOO_LONG = range(5)
# |Im θ| beyond which a stalled Newton step goes to extended precision (tracking, endpoint), and the
# most tracking steps a path may take in it
WIDE_START = (4.0, 4.0, 500)
WIDE_POSE = (4.0, math.inf, 100)
# Per pose (wide_end infinite) the C tracker ends a path found going to infinity once it is beyond
# this |Im θ| (ENDGAME_FAR of apair_ik_track.c: an endgame in log(1 − τ)); it may instead be going
# to a finite point farther out, which double precision cannot tell apart, so the endpoints of a
# pose beyond it are all taken as "far" (apair.ik.homotopy.endpoints), none of them real.
ENDGAME_FAR = 8.0


def unit_gamma(rng: np.random.Generator) -> complex:
    """γ = exp(iφ), |φ| ≤ 1.2: the path's s(τ) is then an arc from 0 to 1 of bounded size (γ near
    −1 would send it through infinity)."""
    return complex(np.exp(1j * rng.uniform(-1.2, 1.2)))


def track(problem: Problem, p0, p1, gamma, start: np.ndarray, engine: str | None = None, wide=WIDE_START):
    """Every row of start (k, n) from p0 to p1: (end, status, steps, cond). engine: "c" (the
    generated tracker apair_ik_track), "numpy" (track_numpy), or None: C where it is installed.
    wide: (track, end, steps), the |Im θ| beyond which the C tracker's Newton steps that stall take
    the residual in extended precision, and the most tracking steps of a path in it; with `end`
    infinite (a pose's paths, WIDE_POSE) a path found going to infinity ends early (ENDGAME_FAR)."""
    start = np.ascontiguousarray(start, complex).reshape(-1, problem.n)
    native = native_in_use() if engine in (None, "c") else None
    if native is None:
        if engine == "c":
            raise RuntimeError("engine: the compiled C kernels are not installed")
        return track_numpy(problem, p0, p1, gamma, start, endgame=not wide[1] < math.inf)
    args = (
        problem.kind,
        problem.pair,
        problem.dh,
        np.ascontiguousarray(p0, complex),
        np.ascontiguousarray(p1, complex),
        complex(gamma),
    )
    return threaded(lambda share: native.ik_track(*args, share, *wide), start)


def threaded(track_share, start: np.ndarray):
    """track_share(rows) -> (end, status, steps, cond) over the rows of start: the paths are
    independent and the C trackers release the GIL, so one share per thread, the last one tracked
    by the calling thread."""
    threads = min(threads_for_tracking(), len(start) // PATHS_PER_THREAD)
    if threads <= 1:
        return track_share(start)
    shares = np.array_split(start, threads)
    futures = [_pool(threads - 1).submit(track_share, np.ascontiguousarray(share)) for share in shares[:-1]]
    last = track_share(np.ascontiguousarray(shares[-1]))
    parts = [f.result() for f in futures] + [last]
    return tuple(np.concatenate([part[i] for part in parts]) for i in range(4))


def newton(
    problem: Problem,
    theta: np.ndarray,
    p: np.ndarray,
    max_steps: int,
    tol: float,
    floor: float,
    stall: float,
    imag_max: float,
    engine: str | None = None,
):
    """Newton's method on F(θ; p) = 0 at the fixed pose p (7,) from each row of theta (k, n):
    (θ (k, n), size (k,)), size the last step's largest entry. A row stops when its step is <= tol,
    or <= floor but above stall × the step before (the rounding floor of a root far out, where the
    entries are e^|Im θ| large); size is inf where the Jacobian was singular, a value not finite
    or some |Im θ| > imag_max. In C (apair_ik_newton) where installed, else NumPy, all rows at once."""
    theta = np.ascontiguousarray(theta, complex).reshape(-1, problem.n)
    native = native_in_use() if engine in (None, "c") else None
    if native is not None:
        return native.ik_newton(
            problem.kind,
            problem.pair,
            problem.dh,
            np.ascontiguousarray(p, complex),
            theta,
            max_steps,
            tol,
            floor,
            stall,
            imag_max,
        )
    if engine == "c":
        raise RuntimeError("engine: the compiled C kernels are not installed")
    theta = theta.copy()
    size, prev = np.full(len(theta), np.inf), np.full(len(theta), np.inf)
    todo, still = np.ones(len(theta), bool), np.zeros(7, complex)
    for _ in range(max_steps):
        if not todo.any():
            break
        with np.errstate(all="ignore"):
            F, dF, _ = system(problem, theta[todo], p, still)
            step = solve_linear(dF, F)
        theta[todo] -= step
        prev[todo], size[todo] = size[todo], np.max(np.abs(step), axis=1)
        lost = ~(np.isfinite(size) & np.all(np.abs(theta.imag) <= imag_max, axis=1))
        size[lost] = np.inf
        todo &= ~lost & ~((size <= tol) | ((size <= floor) & (size > stall * prev)))
    return theta, size


PATHS_PER_THREAD = 8  # fewer paths than this per thread are tracked in the calling thread
_POOLS: dict[int, ThreadPoolExecutor] = {}
if hasattr(os, "register_at_fork"):  # a forked child has none of the parent's pool threads
    os.register_at_fork(after_in_child=_POOLS.clear)


def threads_for_tracking() -> int:
    """Threads that track paths at once: $APAIR_THREADS, else the CPUs this process may run on."""
    text = os.environ.get("APAIR_THREADS", "").strip()
    if text:
        if not text.isdigit() or int(text) < 1:
            raise ValueError(f"APAIR_THREADS: expected a positive whole number of threads, got {text!r}")
        return int(text)
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _pool(threads: int) -> ThreadPoolExecutor:
    if threads not in _POOLS:
        _POOLS[threads] = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="apair-track")
    return _POOLS[threads]


class TrackOptions(TypedDict):
    initial_step: float
    max_step: float
    min_step: float
    max_steps: int
    corrector_steps: int
    path_tol: float
    final_tol: float
    final_steps: int
    divergence: float
    singular_cond: float


# The tracker's settings: those of apair_ik_default_options in src/csrc/apair_ik_track.c.
TRACK: TrackOptions = {
    "initial_step": 0.1,
    "max_step": 0.5,
    "min_step": 1e-12,
    "max_steps": 500,
    "corrector_steps": 3,
    "path_tol": 1e-7,
    "final_tol": 1e-14,
    "final_steps": 30,
    "divergence": 40.0,
    "singular_cond": 1e10,
}


def _batched(problem: Problem, theta, s, p0, dp):
    """H (k, 6), dH/dθ (k, 6, 6) and ∂H/∂s (k, 6) at the poses p0 + s dp (k,), by the NumPy or C
    kernels (apair.kernels.call, batched)."""
    lw = law(problem, theta)
    target = p0[None, :] + s[:, None] * dp[None, :]
    F, dF, dFs = kernels.call(
        f"ik_system{problem.n}",
        pairs_of(lw),
        pairs_of(target),
        pairs_of(np.broadcast_to(dp, target.shape)),
        problem.dh,
        problem.turning,
    )
    return complex_of(F), complex_of(dF), complex_of(dFs)


def solve_linear(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with A x = b for stacked (k, n, n) and (k, n); NaN rows where A is singular."""
    try:
        return np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        out = np.full(b.shape, np.nan, complex)
        for m in range(len(A)):
            try:
                out[m] = np.linalg.solve(A[m], b[m])
            except np.linalg.LinAlgError:
                pass
        return out


def track_numpy(problem: Problem, p0, p1, gamma, start: np.ndarray, endgame: bool = False):
    """The tracker of apair_ik_track over NumPy, all paths at once (each with its own τ and step):
    the same predictor (RK4), corrector (Newton, at most `corrector_steps`, each step at most half
    the one before), step control, endgame (`endgame`: the paths of one pose) and endpoint test.
    The fallback without the C kernels, and an independent check of the C tracker."""
    p0, dp = np.asarray(p0, complex), np.asarray(p1, complex) - np.asarray(p0, complex)
    return track_system(lambda x, s: _batched(problem, x, s, p0, dp), gamma, start, problem, endgame)


# The endgame of apair_ik_track.c (to_infinity): from which τ it watches, how much a path to
# infinity's slope in log(1 − τ) may shrink per sample, the least outward slope (and ENDGAME_FAR)
ENDGAME = (0.5, 0.8, 0.1)


class _Endgame:
    """to_infinity of apair_ik_track.c for all paths at once: each path's last sample (L = log(1 −
    τ), the angles, a P-pair's slide x as the angle i log x continued from sample to sample, and x)
    and the slope over the interval that ended there."""

    def __init__(self, k: int, problem: Problem) -> None:
        angles = problem.n
        self.problem = problem
        self.samples = np.zeros(k, int)
        self.L = np.zeros(k)
        self.v = np.zeros((k, angles), complex)
        self.x = np.zeros((k, angles), complex)
        self.beta = np.zeros((k, angles), complex)

    def diverged(self, rows: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Which of the paths `rows`, just accepted at the angles v (r, angles) and τ (r,), go to
        infinity (see to_infinity in apair_ik_track.c); their samples are taken where due."""
        start, ratio, slope = ENDGAME
        with np.errstate(divide="ignore"):
            L = np.log1p(-tau)
        take = (tau >= start) & (tau < 1) & ((self.samples[rows] == 0) | (self.L[rows] - L >= math.log(2)))
        rows, x, L = rows[take], v[take], L[take]
        out = np.zeros(len(take), bool)
        had = self.samples[rows] > 0
        slides = self.problem.slides
        v = x.copy()
        with np.errstate(all="ignore"):
            if slides.any():
                logs = np.where(had[:, None], self.v[rows] + 1j * np.log(x / self.x[rows]), 1j * np.log(x))
                v[:, slides] = logs[:, slides]
            joint_far = np.where(slides, np.maximum(0.0, np.log(np.abs(x))), np.abs(x.imag))
        beta = np.zeros_like(v)
        beta[had] = (v[had] - self.v[rows[had]]) / (L[had] - self.L[rows[had]])[:, None]
        j = np.argmax(joint_far, axis=1)
        at = np.arange(len(rows))
        far = joint_far[at, j]
        b, b0 = beta[at, j], self.beta[rows, j]
        sign = np.where(v[at, j].imag > 0, -1.0, 1.0)
        size = np.abs(b)
        verdict = (
            (self.samples[rows] >= 2)
            & (far > ENDGAME_FAR)
            & (sign * b.imag >= slope)
            & (sign * b.imag >= ratio * sign * b0.imag)
            & (np.abs(b - b0) <= 0.5 * size)
            & (size >= ratio * np.abs(b0))
            & (far > size * math.log(2) * ratio / (1 - ratio))
        )
        self.beta[rows[had]] = beta[had]
        self.L[rows], self.v[rows], self.x[rows] = L, v, x
        self.samples[rows] += 1
        out[np.flatnonzero(take)] = verdict
        return out


def track_system(evaluate, gamma, start: np.ndarray, problem: Problem, endgame: bool = False):
    """track_numpy's tracker for any square system H(x; s) = 0 from s = 0 to 1 along the γ arc:
    evaluate(x (k, m), s (k,)) gives H (k, m), dH/dx (k, m, m) and ∂H/∂s (k, m); the first
    problem.n columns of x are the problem's complex joint variables (the divergence and far-out
    tests look at them, `far_of`; apair.ik.homotopy.trace tracks an extra column that is no joint).
    endgame: end the paths found going to infinity (_Endgame). Returns (end, status, steps, cond)."""
    angles = problem.n
    o = TRACK
    g = complex(gamma)
    k = len(start)
    v = np.array(start, complex)
    tau, h = np.zeros(k), np.full(k, o["initial_step"])
    good, steps = np.zeros(k, int), np.zeros(k, int)
    status = np.full(k, -1)
    k1s, have = np.zeros_like(v), np.zeros(k, bool)  # dv/dτ at (v, τ), as the C tracker keeps it
    watch = _Endgame(k, problem) if endgame else None

    def s_of(t):
        den = 1 + (g - 1) * t
        return g * t / den, g / den**2

    def tangent(x, t):
        s, ds = s_of(t)
        _, J, Fs = evaluate(x, s)
        return solve_linear(J, -(Fs * ds[:, None]))

    def correct(x, t, iters, tol, kt=None):
        """Newton in place on x; kt (if given): the tangent at the last point evaluated."""
        ok, prev, last = np.zeros(len(x), bool), np.full(len(x), np.inf), np.full(len(x), np.inf)
        live = np.ones(len(x), bool)
        s, ds = s_of(t)
        for it in range(iters):
            if not live.any():
                break
            F, J, Fs = evaluate(x[live], s[live])
            d = solve_linear(J, -F)
            idx = np.flatnonzero(live)
            if kt is not None:
                kt[idx] = solve_linear(J, -(Fs * ds[idx, None]))
            x[idx] += d
            dn = np.abs(d).max(1)
            last[idx] = dn
            conv = dn <= tol * (1 + np.abs(x[idx]).max(1))
            ok[idx[conv]] = True
            stall = (it > 0) & (dn > 0.5 * prev[idx]) & ~conv
            far = far_of(problem, x[idx, :angles])
            ok[idx[stall & (far > 4.0) & (dn <= 1e3 * tol * (1 + np.abs(x[idx]).max(1)))]] = True
            live[idx[conv | stall]] = False
            prev[idx] = dn
        return ok, last

    with np.errstate(all="ignore"):
        while True:
            act = np.flatnonzero(status < 0)
            act = act[tau[act] < 1.0]
            if len(act) == 0:
                break
            steps[act] += 1
            long = steps[act] > o["max_steps"]
            status[act[long]] = TOO_LONG
            act = act[~long]
            hh = np.minimum(h[act], 1 - tau[act])
            x, t = v[act], tau[act]
            need = ~have[act]
            if need.any():
                k1s[act[need]] = tangent(x[need], t[need])
            k1 = k1s[act]
            have[act] = np.all(np.isfinite(k1), axis=1)
            k2 = tangent(x + 0.5 * hh[:, None] * k1, t + 0.5 * hh)
            k3 = tangent(x + 0.5 * hh[:, None] * k2, t + 0.5 * hh)
            k4 = tangent(x + hh[:, None] * k3, t + hh)
            pred = x + hh[:, None] / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            knext = np.zeros_like(pred)
            ok, _ = correct(pred, t + hh, o["corrector_steps"], o["path_tol"], knext)
            ok &= np.all(np.isfinite(pred), axis=1)
            acc, rej = act[ok], act[~ok]
            v[acc] = pred[ok]
            k1s[acc] = knext[ok]  # the next step's first stage, from the corrector
            tau[acc] = np.where(hh[ok] == 1 - tau[acc], 1.0, tau[acc] + hh[ok])
            good[acc] += 1
            grow = good[acc] >= 2
            h[acc[grow]] = np.minimum(2 * h[acc[grow]], o["max_step"])
            good[acc[grow]] = 0
            status[acc[far_of(problem, v[acc, :angles]) > o["divergence"]]] = DIVERGED
            if watch is not None:
                status[acc[watch.diverged(acc, v[acc, :angles], tau[acc])]] = DIVERGED
            h[rej] *= 0.5
            good[rej] = 0
            status[rej[h[rej] < o["min_step"]]] = FAILED
        cond = np.full(k, np.inf)
        fin = np.flatnonzero(status < 0)
        if len(fin):
            x = v[fin]
            prev = np.full(len(fin), np.inf)
            for _ in range(o["final_steps"]):
                y = x.copy()
                _, d = correct(y, np.ones(len(fin)), 1, o["final_tol"])
                better = np.isfinite(d) & (d < prev)
                x[better], prev[better] = y[better], d[better]
                if not better.any():
                    break
            v[fin] = x
            s, _ = s_of(np.ones(len(fin)))
            _, J, _ = evaluate(x, s)
            cond[fin] = np.linalg.cond(J, 1)
            conv = prev <= o["path_tol"] * (1 + np.abs(x).max(1))
            out = ~np.all(np.isfinite(x), axis=1) | (far_of(problem, x[:, :angles]) > o["divergence"])
            status[fin] = np.where(out, DIVERGED, np.where(conv & (cond[fin] <= o["singular_cond"]), OK, SINGULAR))
    return v, status.astype(np.int32), steps.astype(np.int32), cond
