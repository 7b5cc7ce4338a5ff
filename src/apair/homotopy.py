"""Every complex solution of an R/A chain's inverse kinematics by parameter homotopy (n = 1..6).

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
  chain's solutions at T, and the others are discarded.
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
- **Completeness**: a start set is `certified` by its trace test (apair.trace, passed to
  `start_system` as `certify`) where one has run. Otherwise, where it has as many solutions as the
  pattern's generic count (`generic_count`, from `apair show ik_counts`): the generic count bounds
  the isolated solutions of every design of the pattern (coefficient-parameter theory: the number
  of nonsingular isolated solutions is the same at generic parameters and no larger at any), so
  such a set has them all; monodromy stops as soon as it gets there. Otherwise it is `certified`
  when two independent monodromy runs (each from its own random start, each stable for STABLE
  loops) found the same number, the union's, and CHECK_LOOPS further loops carry every solution
  without losing a path. That is weaker: a solution that every run misses (far out in the complex,
  where paths lose digits) goes unnoticed. A pose's answer is complete when, in addition, every
  path ended (finite, or diverging to infinity) at a distinct point.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .study import from_matrix

FORMAT = 3  # of the cached start systems
STABLE = 20  # loops in a row without a new solution that end a monodromy run
MAX_LOOPS = 400
CHECK_LOOPS = 3  # loops after the runs in which no path may be lost for a certified start set
RETRIES = 10  # new γ for what paths that failed or jumped left undone (per pose: rounds, see solve)
SAME = 1e-4  # two endpoints whose angles differ by less than this are one solution
LOOSE = 1e-2  # the same for an endpoint not refined to full accuracy (far out, they are off by up to 1e-3)
VIRTUAL_ZERO = 1e-6  # |exp(iθ) − 1| under which a virtual joint is at 0
REAL = 1e-5  # |Im θ| under which an endpoint is a real candidate (fk verifies it)
OK, SINGULAR, FAILED, DIVERGED, TOO_LONG = range(5)
# |Im θ| beyond which a stalled Newton step goes to extended precision (tracking, endpoint), and the
# most tracking steps a path may take in it
WIDE_START = (4.0, 4.0, 500)
WIDE_POSE = (4.0, math.inf, 100)


# ----------------------------------------------------------------------------- the problem
def scale_of(chain) -> float:
    """The chain's length scale: its largest link length, offset or amplitude (at least 1 mm)."""
    lengths = [abs(x) for x in (*chain.a, *chain.offset)] + [p.amplitude for p in chain.pairs]
    return max(max(lengths), 1e-3)


@dataclass(frozen=True)
class Problem:
    """A chain's design as the tracker takes it (6 joints, the virtual ones last), lengths in units
    of `scale`; `joints` is the chain's own n."""

    kind: np.ndarray  # int32 (6,): 0 R-pair, 1 sinusoidal A-pair
    pair: np.ndarray  # (6, 2): (h, 0)
    dh: np.ndarray  # (6, 4)
    scale: float
    joints: int

    @property
    def n(self) -> int:
        return len(self.kind)

    @staticmethod
    def of(chain) -> "Problem":
        for i, p in enumerate(chain.pairs):
            if p.kind == "general":
                raise ValueError(f"pairs[{i}]: a general A-pair's motion is not rational; inverse kinematics "
                                 "needs sinusoidal A-pairs or R-pairs")
        s = scale_of(chain)
        kind = [0 if p.kind == "revolute" else 1 for p in chain.pairs]
        pair = [[p.amplitude / s, 0.0] for p in chain.pairs]
        dh = [[a / s, al, c / s, ph] for a, al, c, ph in zip(chain.a, chain.alpha, chain.offset, chain.theta_offset)]
        extra = 6 - chain.n
        kind += [0] * extra
        pair += [[0.0, 0.0]] * extra
        dh += [list(row) for row in VIRTUAL[:extra]]
        return Problem(np.array(kind, np.int32), np.array(pair, float), np.array(dh, float), s, chain.n)

    def key(self) -> str:
        """What the start system depends on, as text (floats exactly)."""
        return json.dumps({"kind": self.kind.tolist(), "pair": [float(x).hex() for x in self.pair[:, 0]],
                           "dh": [[float(x).hex() for x in row] for row in self.dh], "joints": self.joints})

    def pose(self, T: np.ndarray) -> np.ndarray:
        """The pose (4 × 4) the 6 tracked joints must reach for the chain to reach T (4 × 4): T in
        units of scale, times the virtual joints at 0."""
        Ts = np.array(T, float)
        Ts[:3, 3] /= self.scale
        for a, alpha, c, phi in self.dh[self.joints:]:
            Ts = Ts @ _dh(0.0, a, alpha, c, phi)
        return Ts

    def target(self, T: np.ndarray) -> np.ndarray:
        """pose(T) as (t, q) (7,), the homotopy's pose coordinates."""
        return target_of(self.pose(T))


def target_of(pose: np.ndarray) -> np.ndarray:
    """A pose (4 × 4, in units of the scale) as the homotopy's pose coordinates (t, q) (7,)."""
    return np.concatenate([pose[:3, 3], from_matrix(pose)[:4]]).astype(complex)


def _dh(theta, a, alpha, c, phi) -> np.ndarray:
    """Rz(θ + φ)·Tz(c)·Tx(a)·Rx(α) (docs/conventions.md §3, an R-pair)."""
    ct, st, ca, sa = math.cos(theta + phi), math.sin(theta + phi), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, c], [0, 0, 0, 1]])


# The virtual joints that complete a chain of n < 6 joints (a, α, c, φ in units of the chain's
# scale): fixed, of generic geometry (no zero, parallel or perpendicular axes), so that the start
# systems and counts are reproducible.
VIRTUAL = ((0.61, 1.13, 0.37, 0.0), (0.83, -0.71, 0.29, 0.0), (0.47, 1.37, -0.53, 0.0), (0.71, -1.21, 0.41, 0.0),
           (0.53, 0.89, -0.31, 0.0))


def _native():
    """The compiled kernels' module, or None (the NumPy tracker is used then)."""
    from . import kernels

    return kernels._native()[0] if kernels.backend() == "c" else None


def law(problem: Problem, theta: np.ndarray):
    """(cos(θ/2), sin(θ/2), d, d') (…, n, 4) at complex angles θ (…, n), by the ik_law kernels."""
    from . import kernels

    v = np.exp(0.5j * np.asarray(theta))
    out = np.empty(v.shape + (4,), complex)
    for k in (0, 1):  # one call per kind of pair, over its joints
        idx = np.flatnonzero(problem.kind == k)
        if len(idx) == 0:
            continue
        vi = _pairs(v[..., idx])[..., None, :]
        if k == 0:
            (res,) = kernels.call("ik_law_revolute", vi)
        else:
            (res,) = kernels.call("ik_law_sinusoidal", vi, np.broadcast_to(problem.pair[idx, :1], vi.shape[:-2] + (1,)))
        out[..., idx, :] = _complex(res)
    return out


def _pairs(z: np.ndarray) -> np.ndarray:
    """Complex z (...) as (..., 2) (real, imaginary) float64 (a view where z is contiguous)."""
    z = np.ascontiguousarray(z, complex)
    return z.view(np.float64).reshape(z.shape + (2,))


def _complex(a: np.ndarray) -> np.ndarray:
    """(..., 2) (real, imaginary) pairs as complex (...)."""
    return a[..., 0] + 1j * a[..., 1]


def system(problem: Problem, theta: np.ndarray, target: np.ndarray, direction: np.ndarray):
    """F (6,), dF/dθ (6, n) and dF/d(direction) (6,) at one point (the generated kernel)."""
    from . import kernels

    lw = law(problem, theta)
    F, dF, dFs = kernels.call(f"ik_system{problem.n}", _pairs(lw), _pairs(target), _pairs(direction), problem.dh)
    return _complex(F), _complex(dF), _complex(dFs)


def _linear_pose(problem: Problem, theta: np.ndarray):
    """F(θ; p) = A p + b: (A (6, 7), b (6,)) at fixed θ (F is linear in the pose)."""
    zero = np.zeros(7, complex)
    b = system(problem, theta, zero, zero)[0]
    A = np.stack([system(problem, theta, zero, e)[2] for e in np.eye(7, dtype=complex)], 1)
    return A, b


# ----------------------------------------------------------------------------- start systems
@dataclass
class StartSystem:
    """The complete complex solution set at a generic complex pose p0 (see the module docstring)."""

    problem_key: str
    p0: np.ndarray  # (7,) complex
    solutions: np.ndarray  # (k, n) complex
    loops: int  # monodromy loops run
    runs: list  # solution counts of the independent runs
    certified: bool  # the trace test passed; without one: the count was stable and reproduced
    seconds: float
    trace: float = math.nan  # the trace test's relative deviation from affine (apair.trace); NaN: not run
    witnesses: int = 0  # the trace test's extra witness points
    generic: int = 0  # the pattern's generic count the set was prepared against (generic_count); 0: none known

    @property
    def count(self) -> int:
        return len(self.solutions)

    @property
    def traced(self) -> bool:
        """Whether a trace test has judged this set (then `certified` is its verdict)."""
        return not math.isnan(self.trace)

    @property
    def runs_agree(self) -> bool:
        """Whether two independent monodromy runs found the set's count on their own."""
        return sum(c == self.count for c in self.runs) >= 2

    @property
    def how(self) -> str:
        """How `certified` was decided, in words."""
        if self.traced:
            return (f"the trace test {'passed' if self.certified else 'failed'} (deviation {self.trace:.1e}, "
                    f"{self.witnesses} witnesses)")
        if self.generic and self.count == self.generic:
            return f"it has the pattern's generic count {self.generic} (apair show ik_counts), which no design exceeds"
        if self.generic and self.count > self.generic:
            return (f"it has more solutions than the pattern's generic count {self.generic}: a solution is "
                    "counted twice (or the stored count is short)")
        return ("two monodromy runs found it" if self.certified else
                "a path was lost in the check loops" if self.runs_agree else "the monodromy runs disagree") + \
            (f" (the pattern's generic count is {self.generic})" if self.generic else "")

    def save(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        with open(tmp, "wb") as f:
            np.savez(f, format=FORMAT, problem_key=self.problem_key, p0=self.p0, solutions=self.solutions, loops=self.loops, runs=np.array(self.runs),
                     certified=self.certified, seconds=self.seconds, trace=self.trace, witnesses=self.witnesses,
                     generic=self.generic)
        os.replace(tmp, path)

    @staticmethod
    def load(path: Path, key: str) -> "StartSystem | None":
        try:
            with np.load(path, allow_pickle=False) as z:
                if int(z["format"]) != FORMAT or str(z["problem_key"]) != key:
                    return None
                return StartSystem(key, z["p0"], z["solutions"],
                                   int(z["loops"]), [int(x) for x in z["runs"]], bool(z["certified"]),
                                   float(z["seconds"]), float(z["trace"]), int(z["witnesses"]), int(z["generic"]))
        except (OSError, ValueError, KeyError):
            return None


def _distinct(sols: np.ndarray, known: np.ndarray | None = None) -> np.ndarray:
    """Indices of the rows of sols (k, n) that differ from each other and from every row of known."""
    keep = []
    ref = [] if known is None else list(known)
    for i, s in enumerate(sols):
        if all(np.max(np.abs(s - r) / (1 + np.abs(r))) > SAME for r in ref):
            keep.append(i)
            ref.append(s)
    return np.array(keep, int)


def canonical(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """θ with its real part in (−π, π] (R-pair) or (−2π, 2π] (A-pair), the imaginary part kept."""
    half = np.where(problem.kind == 0, np.pi, 2 * np.pi)
    re = np.real(theta)
    with np.errstate(invalid="ignore"):  # a failed path's endpoint (NaN, inf) stays what it is
        return (re - 2 * half * np.ceil((re - half) / (2 * half))) + 1j * np.imag(theta)


class _Index:
    """Solutions (complex angles) with a bucket index on Im θ_1, so that membership tests of
    thousands of them are fast. Two solutions are one when their angles differ by at most SAME in
    every joint (LOOSE if either is `loose`, not refined to full accuracy), the real parts modulo
    the joint's period (one pose: 2π for an R-pair, 4π for an A-pair)."""

    def __init__(self, problem: Problem):
        self.problem = problem
        self.period = np.where(problem.kind == 0, 2 * np.pi, 4 * np.pi)
        self.rows: list[np.ndarray] = []
        self.loose: list[bool] = []
        self.buckets: dict = {}

    def add(self, theta) -> bool:
        """Adds θ unless it is already there; whether it was new."""
        return self.place(theta)[0]

    def place(self, theta, is_canonical: bool = False, loose: bool = False) -> tuple[bool, int]:
        """Adds θ unless it is already there: (whether it was new, its row). is_canonical: θ is
        already canonical (a batch canonicalised at once). A refined θ that is a loose row's
        solution takes that row's place."""
        theta = np.asarray(theta) if is_canonical else canonical(self.problem, np.asarray(theta))
        key = int(math.floor(theta[0].imag / LOOSE))
        for k in (key - 1, key, key + 1):
            for j in self.buckets.get(k, ()):
                d = theta - self.rows[j]
                re = np.abs(d.real) % self.period
                if np.all(np.maximum(np.minimum(re, self.period - re), np.abs(d.imag))
                          <= (LOOSE if loose or self.loose[j] else SAME)):
                    if self.loose[j] and not loose:
                        self.buckets[k].remove(j)
                        self.buckets.setdefault(key, []).append(j)
                        self.rows[j], self.loose[j] = theta, False
                    return False, j
        self.buckets.setdefault(key, []).append(len(self.rows))
        self.rows.append(theta)
        self.loose.append(loose)
        return True, len(self.rows) - 1


def random_pose(rng: np.random.Generator) -> np.ndarray:
    """A random complex pose (t, q), entries standard complex normal (the loops of monodromy need
    poses well away from the real ones to permute the solutions)."""
    return (rng.standard_normal(7) + 1j * rng.standard_normal(7)) / math.sqrt(2)


def _unit_gamma(rng: np.random.Generator) -> complex:
    """γ = exp(iφ), |φ| ≤ 1.2: the path's s(τ) is then an arc from 0 to 1 of bounded size (γ near
    −1 would send it through infinity)."""
    return complex(np.exp(1j * rng.uniform(-1.2, 1.2)))


def track(problem: Problem, p0, p1, gamma, start: np.ndarray, engine: str | None = None, wide=WIDE_START):
    """Every row of start (k, n) from p0 to p1: (end, status, steps, cond). engine: "c" (the
    generated tracker apair_ik_track), "numpy" (track_numpy), or None: C where it is installed.
    wide: (track, end, steps), the |Im θ| beyond which the C tracker's Newton steps that stall take
    the residual in extended precision, and the most tracking steps of a path in it."""
    start = np.ascontiguousarray(start, complex).reshape(-1, problem.n)
    native = _native() if engine in (None, "c") else None
    if native is None:
        if engine == "c":
            raise RuntimeError("engine: the compiled C kernels are not installed")
        return track_numpy(problem, p0, p1, gamma, start)
    args = (problem.kind, problem.pair, problem.dh, np.ascontiguousarray(p0, complex),
            np.ascontiguousarray(p1, complex), complex(gamma))
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


def newton(problem: Problem, theta: np.ndarray, p: np.ndarray, max_steps: int, tol: float, floor: float,
           stall: float, imag_max: float, engine: str | None = None):
    """Newton's method on F(θ; p) = 0 at the fixed pose p (7,) from each row of theta (k, n):
    (θ (k, n), size (k,)), size the last step's largest entry. A row stops when its step is <= tol,
    or <= floor but above stall × the step before (the rounding floor of a root far out, where the
    entries are e^|Im θ| large); size is inf where the Jacobian was singular, a value not finite
    or some |Im θ| > imag_max. In C (apair_ik_newton) where installed, else NumPy, all rows at once."""
    theta = np.ascontiguousarray(theta, complex).reshape(-1, problem.n)
    native = _native() if engine in (None, "c") else None
    if native is not None:
        return native.ik_newton(problem.kind, problem.pair, problem.dh, np.ascontiguousarray(p, complex), theta,
                                max_steps, tol, floor, stall, imag_max)
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
            step = _solve(dF, F)
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


# The tracker's settings: those of apair_ik_default_options in generated/c/apair_ik.c.
TRACK = {"initial_step": 0.1, "max_step": 0.5, "min_step": 1e-12, "max_steps": 500, "corrector_steps": 3,
         "path_tol": 1e-7, "final_tol": 1e-14, "final_steps": 30, "divergence": 40.0, "singular_cond": 1e10}


def _batched(problem: Problem, theta, s, p0, dp):
    """H (k, 6), dH/dθ (k, 6, 6) and ∂H/∂s (k, 6) at the poses p0 + s dp (k,), by the NumPy or C
    kernels (apair.kernels.call, batched)."""
    from . import kernels

    lw = law(problem, theta)
    target = p0[None, :] + s[:, None] * dp[None, :]
    F, dF, dFs = kernels.call(f"ik_system{problem.n}", _pairs(lw), _pairs(target),
                              _pairs(np.broadcast_to(dp, target.shape)), problem.dh)
    return _complex(F), _complex(dF), _complex(dFs)


def _solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
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


def track_numpy(problem: Problem, p0, p1, gamma, start: np.ndarray):
    """The tracker of apair_ik_track over NumPy, all paths at once (each with its own τ and step):
    the same predictor (RK4), corrector (Newton, at most `corrector_steps`, each step at most half
    the one before), step control and endpoint test. The fallback without the C kernels, and an
    independent check of the C tracker."""
    p0, dp = np.asarray(p0, complex), np.asarray(p1, complex) - np.asarray(p0, complex)
    return track_system(lambda x, s: _batched(problem, x, s, p0, dp), gamma, start, problem.n)


def track_system(evaluate, gamma, start: np.ndarray, angles: int):
    """track_numpy's tracker for any square system H(x; s) = 0 from s = 0 to 1 along the γ arc:
    evaluate(x (k, m), s (k,)) gives H (k, m), dH/dx (k, m, m) and ∂H/∂s (k, m); the first
    `angles` columns of x are complex joint angles (the divergence and far-out tests look at
    them; apair.trace tracks an extra column that is not an angle). Returns (end, status, steps, cond)."""
    o = TRACK
    g = complex(gamma)
    k = len(start)
    v = np.array(start, complex)
    tau, h = np.zeros(k), np.full(k, o["initial_step"])
    good, steps = np.zeros(k, int), np.zeros(k, int)
    status = np.full(k, -1)
    k1s, have = np.zeros_like(v), np.zeros(k, bool)  # dv/dτ at (v, τ), as the C tracker keeps it

    def s_of(t):
        den = 1 + (g - 1) * t
        return g * t / den, g / den ** 2

    def tangent(x, t):
        s, ds = s_of(t)
        _, J, Fs = evaluate(x, s)
        return _solve(J, -(Fs * ds[:, None]))

    def correct(x, t, iters, tol, kt=None):
        """Newton in place on x; kt (if given): the tangent at the last point evaluated."""
        ok, prev, last = np.zeros(len(x), bool), np.full(len(x), np.inf), np.full(len(x), np.inf)
        live = np.ones(len(x), bool)
        s, ds = s_of(t)
        for it in range(iters):
            if not live.any():
                break
            F, J, Fs = evaluate(x[live], s[live])
            d = _solve(J, -F)
            idx = np.flatnonzero(live)
            if kt is not None:
                kt[idx] = _solve(J, -(Fs * ds[idx, None]))
            x[idx] += d
            dn = np.abs(d).max(1)
            last[idx] = dn
            conv = dn <= tol * (1 + np.abs(x[idx]).max(1))
            ok[idx[conv]] = True
            stall = (it > 0) & (dn > 0.5 * prev[idx]) & ~conv
            far = np.abs(x[idx, :angles].imag).max(1)
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
            status[acc[np.abs(v[acc, :angles].imag).max(1) > o["divergence"]]] = DIVERGED
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
            out = ~np.all(np.isfinite(x), axis=1) | (np.abs(x[:, :angles].imag).max(1) > o["divergence"])
            status[fin] = np.where(out, DIVERGED, np.where(conv & (cond[fin] <= o["singular_cond"]), OK, SINGULAR))
    return v, status.astype(np.int32), steps.astype(np.int32), cond


def _lost(status: np.ndarray, finite: bool) -> np.ndarray:
    """Which paths lost their way: failed, too long, or (finite: toward a generic pose, where every
    solution is finite) diverged."""
    return (status == FAILED) | (status == TOO_LONG) | (finite & (status == DIVERGED))


def _segment(problem: Problem, a, b, start: np.ndarray, rng, retries: int = 2, finite: bool = False):
    """start tracked from pose a to b, the paths that lost their way (`_lost`) again with a new γ (a
    path that fails in a loop of monodromy would hide its solution's images)."""
    end, status, _, _ = track(problem, a, b, _unit_gamma(rng), start)
    for _ in range(retries):
        bad = np.flatnonzero(_lost(status, finite))
        if len(bad) == 0:
            break
        e, s, _, _ = track(problem, a, b, _unit_gamma(rng), start[bad])
        end[bad], status[bad] = e, s
    return end, status


def _seed_solution(problem: Problem, rng):
    """A random complex joint vector and a generic pose p0 at which it is a solution."""
    n = problem.n
    for _ in range(20):
        theta = rng.uniform(-np.pi, np.pi, n) + 0.3j * rng.standard_normal(n)
        A, b = _linear_pose(problem, theta)
        # A p + b = 0: a particular solution plus a random element of the null space
        M, rhs = A, -b
        p, *_ = np.linalg.lstsq(M, rhs, rcond=None)
        _, sv, Vh = np.linalg.svd(M)
        null = Vh[len(sv[sv > 1e-10 * sv[0]]):].conj().T
        p = p + null @ (rng.standard_normal(null.shape[1]) + 1j * rng.standard_normal(null.shape[1]))
        F, J, _ = system(problem, theta, p, np.zeros(7, complex))
        H, Hv = F, J
        if np.max(np.abs(H)) > 1e-9 or np.abs(p[3:]).max() < 1e-3:
            continue
        sv = np.linalg.svd(Hv, compute_uv=False)
        if sv[-1] < 1e-8 * sv[0]:
            raise ValueError("chain: the inverse kinematics has no isolated solutions at a generic pose (the "
                             "solutions form curves: e.g. two R-pairs on one axis, or a joint that cannot move the "
                             "end frame)")
        return theta, p
    raise RuntimeError("homotopy: no regular starting solution found")


def monodromy(problem: Problem, rng: np.random.Generator, stable: int = STABLE,
              max_loops: int = MAX_LOOPS, progress=None, p0=None, known=None, target: int = 0):
    """All solutions at one generic pose by monodromy loops: (p0, solutions (k, n), loops). Ends
    after `stable` loops in a row found nothing new, or once `target` (> 0) solutions are known."""
    index = _Index(problem)
    if p0 is None:
        theta, p0 = _seed_solution(problem, rng)
        index.add(theta)
    else:
        for s in known:
            index.add(s)
    quiet, loops = 0, 0
    while quiet < stable and loops < max_loops and not 0 < target <= len(index.rows):
        loops += 1
        pa, pb = random_pose(rng), random_pose(rng)
        cur = np.array(index.rows)
        ok = np.ones(len(cur), bool)
        for a, b in ((p0, pa), (pa, pb), (pb, p0)):
            end, status = _segment(problem, a, b, cur, rng)
            ok &= status == OK
            cur = end
        added = sum(index.add(s) for s in cur[ok])
        quiet = 0 if added else quiet + 1
        if progress:
            progress(loops, len(index.rows))
    return p0, np.array(index.rows), loops


def prepare(problem: Problem, seed: int = 0, progress=None, runs: int = 4, generic: int = 0) -> StartSystem:
    """A start system: independent monodromy runs (each from its own random starting solution and
    pose), merged at the pose of the larger set (the other's solutions tracked there; where the
    union grows, monodromy continues from it), at most `runs`. generic: the pattern's generic count
    (generic_count; 0: not known), where monodromy stops and the set is certified (module
    docstring). Below it, certified when two runs found the union's count on their own and
    CHECK_LOOPS more loops lose no path."""
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, problem.n, problem.joints, 17])
    p0, sols, loops = monodromy(problem, rng, progress=progress, target=generic)
    counts = [len(sols)]
    while (len(counts) < runs and sum(c == len(sols) for c in counts) < 2
           and not 0 < generic <= len(sols)):
        q0, other, more = monodromy(problem, rng, progress=progress, target=generic)
        loops += more
        counts.append(len(other))
        if len(other) > len(sols):  # merge into the larger set, at its pose
            p0, sols, q0, other = q0, other, p0, sols
        end, status = _segment(problem, q0, p0, other, rng)
        index = _Index(problem)
        for s in sols:
            index.add(s)
        if sum(index.add(s) for s in end[status == OK]):  # the union is larger: loop again from it
            p0, sols, more = monodromy(problem, rng, progress=progress, p0=p0, known=index.rows, target=generic)
            loops += more
    if 0 < generic <= len(sols):  # all of them, or one counted twice: no loops decide more
        certified = len(sols) == generic
    else:
        # every solution is carried around CHECK_LOOPS more loops: a path that cannot be tracked (far
        # out in the complex, where digits are lost; diverging, where every solution is finite)
        # with any of RETRIES gammas marks a set whose missing members could hide there
        lost = 0
        for _ in range(CHECK_LOOPS):
            pa, pb = random_pose(rng), random_pose(rng)
            cur = sols
            for a, b in ((p0, pa), (pa, pb), (pb, p0)):
                cur, status = _segment(problem, a, b, cur, rng, retries=RETRIES, finite=True)
                lost += int(np.sum(_lost(status, True)))
        certified = bool(sum(c == len(sols) for c in counts) >= 2 and lost == 0)
    return StartSystem(problem.key(), p0, sols, loops, counts, certified, time.perf_counter() - t0, generic=generic)


def stored_counts() -> list[dict]:
    """The generic counts of every pattern (generated/ik_counts.json, written by apair.ikcounts)."""
    from importlib import resources

    return json.loads(resources.files("apair.generated").joinpath("ik_counts.json").read_text())["counts"]


def generic_count(problem: Problem) -> int:
    """The certified generic number of solutions of the problem's pattern from the stored counts,
    or 0. For 6 joints the pattern or its reverse; for fewer, the start set with the virtual joints,
    stored for the pattern as written."""
    pattern = "".join("A" if k else "R" for k in problem.kind[:problem.joints])
    rows = stored_counts()
    names = {pattern, pattern[::-1]} if problem.joints == 6 else {pattern}
    return next((int(r["start_count"]) for r in rows if r["pattern"] in names and r["certified"]), 0)


def _cache_path(problem: Problem) -> Path:
    from .specialise import cache_root, toolkit_digest

    own = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()  # this module decides the start set too
    h = hashlib.sha256((problem.key() + "\0" + toolkit_digest() + f"\0{FORMAT}\0{own}").encode()).hexdigest()[:16]
    return cache_root() / "ik" / f"{h}.npz"


def start_system(problem: Problem, progress=None, refresh: bool = False, certify=None) -> StartSystem:
    """The design's start system from the cache, or prepared now and cached. certify: a function
    (problem, start) -> start run on a set that no trace test has judged yet (apair.trace.certify),
    its verdict cached with the set."""
    path = _cache_path(problem)
    start = None
    if not refresh and path.exists():
        start = StartSystem.load(path, problem.key())
        if start is not None and (certify is None or start.traced):
            return start
    if start is None:
        start = prepare(problem, progress=progress, generic=generic_count(problem))
    if certify is not None:
        start = certify(problem, start, progress=progress)
    try:
        start.save(path)
    except OSError:
        pass  # a read-only cache: the start system is used without being kept
    return start


# ----------------------------------------------------------------------------- one pose
@dataclass
class Endpoints:
    """The tracked solutions at one pose: finite endpoints θ (k, n) that satisfy all six
    equations, whether the set is complete, and the path counts behind it."""

    theta: np.ndarray
    complete: bool
    paths: int
    failed: int
    diverged: int
    singular: np.ndarray | None = None  # (k,) bool: no path's endpoint there was refined (far out, or singular)


def solve(problem: Problem, start: StartSystem, T: np.ndarray, seed: int = 0) -> Endpoints:
    """Tracks the start system to the pose T (4 × 4, in the chain's units).

    Every regular endpoint is a solution (Newton converged at it), so the endpoints of all paths
    are pooled. The first γ takes every path. Where paths failed, or two ended at one endpoint
    (one of them jumped), as many solutions are missing: the first γ's endpoints of those starts,
    the set U. Each further round takes a new γ and from every start of U a chain of paths: where
    a path ends at the first γ's endpoint of another start, that start is tracked next. The two
    γ permute the solutions differently, and the chain is that permutation's cycle, which leaves
    the known endpoints only at one of U's: when no path fails, one round reaches all of them.
    Rounds go on until as many distinct endpoints (plus paths to infinity: the first γ's, and
    the chains' that end there in a round without failures) as start solutions are found, or
    RETRIES rounds are spent."""
    rng = np.random.default_rng([seed, 5])
    p1 = problem.target(T)
    found = _Index(problem)
    owner: dict[int, int | None] = {}  # endpoint row -> the start it is the first γ's endpoint of
    missing: set[int] = set()  # U
    e, s, _, _ = track(problem, start.p0, p1, _unit_gamma(rng), start.solutions, wide=WIDE_POSE)
    diverged = int(np.sum(s == DIVERGED))
    infinite = 0  # chains of a round without failures that end at infinity
    for j, endpoint, st in zip(range(start.count), canonical(problem, e), s):
        if st in (OK, SINGULAR):  # SINGULAR: not refined to full accuracy (far out, a multiple root)
            new, row = found.place(endpoint, is_canonical=True, loose=st == SINGULAR)
            if new:
                owner[row] = j
            elif st == OK and owner[row] is not None:
                missing |= {j, owner[row]}
                owner[row] = None
            elif st == OK:
                missing.add(j)
        elif st != DIVERGED:
            missing.add(j)
    for _ in range(RETRIES):
        if len(found.rows) + diverged + infinite >= start.count or not missing:
            break
        gamma, failed, ends = _unit_gamma(rng), False, 0
        tracked = set(missing)
        reached: set[int] = set()  # the endpoint rows paths of this γ reached
        wave = sorted(missing)
        while wave:
            e, s, _, _ = track(problem, start.p0, p1, gamma, start.solutions[wave], wide=WIDE_POSE)
            chain = []
            for endpoint, st in zip(canonical(problem, e), s):
                if st not in (OK, SINGULAR):
                    failed |= st != DIVERGED
                    ends += st == DIVERGED
                    continue
                new, row = found.place(endpoint, is_canonical=True, loose=st == SINGULAR)
                if new:
                    owner[row] = None
                elif row in reached:  # two paths of this γ at one endpoint: one jumped
                    failed = True
                    continue
                reached.add(row)
                k = owner.get(row)
                if not new and k is not None and k not in tracked:
                    tracked.add(k)
                    chain.append(k)
            wave = chain
        if not failed:
            infinite = ends
            break
    theta = np.array(found.rows).reshape(-1, problem.n)
    keep = own_rows(problem, theta)
    accounted = len(found.rows) + diverged + infinite
    complete = start.certified and accounted == start.count
    return Endpoints(theta[keep, :problem.joints], complete, start.count, max(start.count - accounted, 0), diverged + infinite,
                     np.array(found.loose, bool)[keep])


def own_rows(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """(k,) bool: which 6-joint solutions θ (k, 6) are the chain's own (the virtual joints at 0)."""
    v = np.exp(1j * theta[:, problem.joints:])  # the virtual joints are R-pairs
    return np.all(np.abs(v - 1) <= VIRTUAL_ZERO, axis=1)


def own(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """The chain's own solutions (k', n) among the 6-joint solutions θ (k, 6)."""
    return theta[own_rows(problem, theta), :problem.joints]


def real_angles(problem: Problem, theta: np.ndarray, tol: float = REAL) -> np.ndarray:
    """The real endpoints' angles (m, n): (−π, π] for R-pairs, (−2π, 2π] for A-pairs."""
    n = problem.joints
    if len(theta) == 0:
        return np.zeros((0, n))
    real = np.all(np.abs(np.imag(theta)) <= tol, axis=1)
    kind = Problem(problem.kind[:n], problem.pair[:n], problem.dh[:n], problem.scale, n)
    return np.ascontiguousarray(np.real(canonical(kind, theta[real])))  # (the kernels' fast path wants it contiguous)
