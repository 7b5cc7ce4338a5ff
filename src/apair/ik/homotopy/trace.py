"""The trace test: whether a start system (apair.ik.homotopy) holds every complex solution.

Monodromy stops when its loops stop finding solutions, which proves nothing: a solution far out
in the complex can be missed by every run alike. The trace test of Leykin, Rodriguez and Sottile
(Arnold Math. J. 4, 2018), in the form used for parameter homotopies, decides it:

- Along a random complex line of poses p0 + λ w the solutions form a curve C in (θ, λ),
  irreducible because the solution set over all poses is; the start set S is C ∩ {λ = 0}.
- A random affine function ℓ of the joints' algebraic coordinates z_j = exp(iθ_j/2) (A-pair; its
  pose has period 4π) or exp(iθ_j) (R-pair) and of 1/z_j (a P-pair: its slide x_j, and 1) cuts C
  in the witness points
  W = C ∩ {ℓ = 1}, computed by monodromy (`witness_points`): loops through random ℓ, and
  loops through the family f = −t below, which also return any start solution S lacks.
- On C the function f = (ℓ − 1)·λ vanishes exactly on S ∪ W, and it is proper: every branch of C
  that leaves for infinity takes f with it (ℓ → ∞ where θ does, λ → ∞ otherwise). So the sum of
  the coordinates (z, 1/z, λ) over the points of {f = −t} is a polynomial in t of degree at most
  one, while the sum over a proper subset is not even single-valued. The points of S ∪ W are
  tracked to f = −t1 and f = −t2 (`Slice`), and the three traces must lie on a line: the
  deviation, relative to the sum of the coordinates' sizes, must be below `TRACE_TOL`.

Accuracy. Far out in the complex (|Im θ| of 8 or more in several joints) the equations' terms are
e^Σ|Im θ| large and cancel, and Newton's method in double precision stalls at 1e-5 there, which
would hide the deviation of a missing point. Such endpoints are refined by Newton's method with
the residual evaluated at `DIGITS` digits (FLINT's acb, by the 4×4 DH product and the quaternion
product: a route independent of the generated kernel), and the traces are summed at that precision.
A test that passes is strong numerical evidence, not a proof. A test that fails says that S ∪ W
is incomplete, the start set or the witnesses (so the witness monodromy goes on and the test is
repeated); a path that cannot be tracked leaves no verdict, which counts as a failure.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from typing import Any

import flint
import numpy as np

from ... import kernels
from ...kernels import native_in_use
from ...study import qmul
from .monodromy import segment
from .problem import R_PAIR, Index, Problem, canonical, complex_of, law, pairs_of, random_pose
from .startsets import StartSystem
from .tracker import OK, RETRIES, SINGULAR, solve_linear, threaded, track_system, unit_gamma

DIGITS = 50  # of the refinement of far-out endpoints and of the traces
TRACE_TOL = 1e-10  # complete sets measured 1e-14 to 1e-12 after refinement; one far-out witness missing 5e-9
REFINE_AT = 1e-13  # endpoints whose double-precision Newton step stays above this (relative) are refined
LOOP_SCALE = 5.0  # size of the monodromy loops' random hyperplanes relative to ℓ (small loops hardly permute)
QUIET = 60  # loops in a row without a new witness that end the monodromy
MAX_LOOPS = 3000
ROUNDS = 4  # trace tests at most (trace_test)
MAX_SOLUTIONS = 200  # start sets that certify() takes on: 48 take seconds, 128 (AARRRR) about 5 minutes
T_LOOP_EVERY = 4  # every so many monodromy loops go through the trace family (the others through ℓ)
T_SCALE = 2.0  # |t1|, |t2|: a missing point moves enough to show, and few paths go far enough to fail
T_TRIES = 4  # pairs t1, t2 tried for paths that all end (_deviation)
T_LOOP_SCALE = 5.0  # |t| of the monodromy loops through the trace family (before the random factor)


def coordinates(problem: Problem, theta: np.ndarray):
    """The algebraic coordinates (z, w) (..., 6) each of complex angles θ and their derivatives in θ
    (dz, dw): z = exp(ikθ) (k = 1/2 for an A-pair, 1 for an R-pair) and w = 1/z; a P-pair's z = x
    (its slide) and w = 1."""
    theta = np.asarray(theta)
    k = np.where(problem.kind == R_PAIR, 1.0, 0.5)
    slides = problem.slides
    e = np.exp(1j * k * np.where(slides, 0, theta))
    z, w = np.where(slides, theta, e), np.where(slides, 1.0, 1 / e)
    dz, dw = np.where(slides, 1.0, 1j * k * e), np.where(slides, 0.0, -1j * k / e)
    return z, w, dz, dw


@dataclass(frozen=True)
class Slice:
    """The system H(θ, λ; s) = [F(θ; p + λ w) ; (ℓ_s(θ) − 1)·μ + t0 + s·dt] in x = (θ, λ) (k, 7),
    with ℓ_s = ℓ + s·dℓ (coefficients (2, 6): of z and of w, `coordinates`) and μ = λ (`times_lambda`: the trace
    family f = −t) or 1 (monodromy in ℓ). F is ik_system6, linear in the pose, so ∂F/∂λ is its
    derivative along w: one kernel call gives every entry."""

    problem: Problem
    p: np.ndarray
    w: np.ndarray
    ell: np.ndarray
    dell: np.ndarray
    t0: complex
    dt: complex
    times_lambda: bool

    def __call__(self, x: np.ndarray, s: np.ndarray):
        pb = self.problem
        theta, lam = x[:, :6], x[:, 6]
        P = self.p[None, :] + lam[:, None] * self.w[None, :]
        F, dF, dFl = kernels.call(
            "ik_system6",
            pairs_of(law(pb, theta)),
            pairs_of(P),
            pairs_of(np.broadcast_to(self.w, P.shape)),
            pb.dh,
            pb.turning,
        )
        z, zw, dz, dzw = coordinates(pb, theta)
        a = self.ell[0][None, :] + s[:, None] * self.dell[0][None, :]
        b = self.ell[1][None, :] + s[:, None] * self.dell[1][None, :]
        ell = np.sum(a * z + b * zw, axis=1)
        mu = lam if self.times_lambda else np.ones_like(lam)
        H = np.concatenate([complex_of(F), ((ell - 1) * mu + self.t0 + s * self.dt)[:, None]], axis=1)
        J = np.zeros((len(x), 7, 7), complex)
        J[:, :6, :6] = complex_of(dF)
        J[:, :6, 6] = complex_of(dFl)
        J[:, 6, :6] = (a * dz + b * dzw) * mu[:, None]
        J[:, 6, 6] = (ell - 1) if self.times_lambda else 0.0
        Hs = np.zeros_like(H)
        Hs[:, 6] = np.sum(self.dell[0] * z + self.dell[1] * zw, axis=1) * mu + self.dt
        return H, J, Hs

    def track_once(self, gamma: complex, start: np.ndarray, engine: str | None = None):
        """start (k, 7) from s = 0 to 1 with γ: (end, status, steps, cond). engine: "c" (the
        generated apair_ik_track_slice), "numpy" (track_system) or None: C where installed."""
        start = np.ascontiguousarray(start, complex).reshape(-1, 7)
        native = native_in_use() if engine in (None, "c") else None
        if native is None:
            if engine == "c":
                raise RuntimeError("engine: the compiled C kernels are not installed")
            return track_system(self, gamma, start, self.problem)
        pb = self.problem
        args = (
            pb.kind,
            pb.pair,
            pb.dh,
            *(np.ascontiguousarray(v, complex) for v in (self.p, self.w, self.ell, self.dell)),
            complex(self.t0),
            complex(self.dt),
            bool(self.times_lambda),
            complex(gamma),
        )
        return threaded(lambda share: native.ik_track_slice(*args, share), start)

    def track(self, start: np.ndarray, rng) -> tuple[np.ndarray, np.ndarray]:
        """start (k, 7) from s = 0 to 1, paths that failed tracked again with new γ: (end, status)."""
        end, status, _, _ = self.track_once(unit_gamma(rng), start)
        for _ in range(RETRIES):
            bad = np.flatnonzero(~_ended(status))
            if len(bad) == 0:
                break
            e, st, _, _ = self.track_once(unit_gamma(rng), start[bad])
            end[bad], status[bad] = e, st
        return end, status


def _ended(status: np.ndarray) -> np.ndarray:
    """Paths that reached s = 1: OK, or SINGULAR, which far out in the complex means that Newton in
    double precision stalled above its tolerance (the endpoints are refined at DIGITS digits)."""
    return (status == OK) | (status == SINGULAR)


def _points(S: np.ndarray, W: np.ndarray) -> np.ndarray:
    """The start solutions S (m, 6) at λ = 0 and the witnesses W (k, 7) as one array (m + k, 7)."""
    return np.concatenate([np.concatenate([S, np.zeros((len(S), 1))], axis=1), W]).astype(complex)


def _crandn(rng, *shape) -> np.ndarray:
    return (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) / math.sqrt(2)


def witness_points(problem: Problem, start: StartSystem, rng, progress=None, known=None, quiet: int = QUIET):
    """(w, ℓ, W, S): a random pose direction w, a random ℓ, the points W (k, 7) of C ∩ {ℓ = 1} and
    the start set S (m, 6), by monodromy from one point of C (a start solution tracked to λ*, with
    ℓ scaled through it), until `quiet` loops in a row find nothing new. Two kinds of loop: through
    random ℓ (W alone), and, every T_LOOP_EVERY-th, through random t in the trace family f = −t,
    whose fibre over 0 is S ∪ W: these carry start solutions to witnesses and back, and a start
    solution that the set lacks, found so, is added to S. known: a (w, ℓ, W, S) to continue from."""
    index, sols = Index(problem), Index(problem)
    if known is not None:
        w, ell, W, S = known
        points = list(W)
    else:
        w, S = random_pose(rng), start.solutions
        # from a start solution near the real ones: ℓ is scaled through its image, and ℓ with small
        # coefficients would put the witnesses far out in the complex, where paths fail
        near = np.argsort(np.abs(S.imag).max(axis=1))[: max(4, len(S) // 8)]
        for _ in range(20):
            lam = complex(_crandn(rng, 1)[0])
            j = int(rng.choice(near))
            end, status = segment(problem, start.p0, start.p0 + lam * w, S[j : j + 1], rng)
            if status[0] == OK:
                break
        else:
            raise RuntimeError("trace: no point of the pose line's curve could be reached")
        theta = end[0]
        z, zw, _, _ = coordinates(problem, theta)
        ell = _crandn(rng, 2, 6)
        ell /= np.sum(ell[0] * z + ell[1] * zw)
        points = [np.concatenate([theta, [lam]])]
    for x in points:
        index.add(x[:6])
    for x in S:
        sols.add(x)
    S = list(S)
    size = LOOP_SCALE * np.mean(np.abs(ell))
    calm = loops = 0
    while calm < quiet and loops < MAX_LOOPS:
        loops += 1
        r = 10.0 ** rng.uniform(-1.0, 1.0)  # loops of many sizes: each encircles other branch points
        if loops % T_LOOP_EVERY:
            cur = np.array(points)
            la, lb = (ell + r * size * _crandn(rng, 2, 6) for _ in range(2))
            slices = [Slice(problem, start.p0, w, a, b - a, 0, 0, False) for a, b in ((ell, la), (la, lb), (lb, ell))]
        else:
            cur = _points(np.array(S), np.array(points))
            ta, tb = r * T_LOOP_SCALE * _crandn(rng, 2)
            slices = [
                Slice(problem, start.p0, w, ell, np.zeros_like(ell), a, b - a, True)
                for a, b in ((0, ta), (ta, tb), (tb, 0))
            ]
        ok, stalled = np.ones(len(cur), bool), np.zeros(len(cur), bool)
        for sl in slices:
            cur, status, _, _ = sl.track_once(unit_gamma(rng), cur)
            ok &= _ended(status)
            stalled |= status == SINGULAR
        # a SINGULAR endpoint is kept where Newton at DIGITS digits makes it a regular solution (far
        # out, double precision stalls above the tracker's tolerance): those are the hard witnesses
        check = np.flatnonzero(ok & stalled)
        if len(check):
            fine = _refine(Slice(problem, start.p0, w, ell, np.zeros_like(ell), 0, 0, True), cur[check])
            for i, xm in zip(check, fine):
                ok[i] = xm is not None
                if xm is not None:
                    cur[i] = [complex(v.mid()) for v in xm]
        added = 0
        for x in cur[ok]:
            if abs(x[6]) <= 1e-9:  # λ = 0: a start solution
                if sols.add(x[:6]):
                    S.append(canonical(problem, x[:6]))
                    added += 1
            elif index.add(x[:6]):
                points.append(x)
                added += 1
        calm = 0 if added else calm + 1
        if progress:
            progress(loops, len(points))
    return w, ell, np.array(points), np.array(S)


# ----------------------------------------------------------------------------- extended precision
def _acb(z) -> flint.acb:
    z = complex(z)
    return flint.acb(z.real, z.imag)


def _quat(a, b) -> np.ndarray:
    """Hamilton product of two quaternions of flint.acb (apair.study.qmul, over object arrays)."""
    return qmul(np.array(a, dtype=object), np.array(b, dtype=object))


def exact_system(problem: Problem, theta, P) -> list:
    """F(θ; P) (6 flint.acb) of ik_system6 at FLINT's working precision: the end frame's origin
    from the product of the 4×4 DH matrices Rz(θ + φ)·Tz(c + d(θ))·Tx(a)·Rx(α) minus t, and the
    vector part of q̄ ⊗ x with x the product of the quaternions of Rz(θ + φ) and Rx(α) (a P-pair:
    θ = 0 and d its slide)."""
    zero, one = flint.acb(0), flint.acb(1)
    T = [[one if r == c else zero for c in range(4)] for r in range(3)]
    x: tuple[Any, ...] | np.ndarray = (one, zero, zero, zero)
    for i in range(6):
        a, alpha, c, phi = (flint.acb(float(v)) for v in problem.dh[i])
        slide = bool(problem.slides[i])
        th = phi if slide else theta[i] + phi
        d = zero if problem.kind[i] == R_PAIR else flint.acb(float(problem.pair[i, 0])) * (theta[i] / 2).cos()
        if slide:
            d = theta[i]
        ct, st, ca, sa = th.cos(), th.sin(), alpha.cos(), alpha.sin()
        A = [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [zero, sa, ca, c + d]]
        T = [
            [
                T[r][0] * A[0][col] + T[r][1] * A[1][col] + T[r][2] * A[2][col] + (T[r][3] if col == 3 else zero)
                for col in range(4)
            ]
            for r in range(3)
        ]
        x = _quat(
            _quat(x, ((th / 2).cos(), zero, zero, (th / 2).sin())), ((alpha / 2).cos(), (alpha / 2).sin(), zero, zero)
        )
    q = (P[3], -P[4], -P[5], -P[6])
    return [T[r][3] - P[r] for r in range(3)] + list(_quat(q, x)[1:])


def _exact_coordinates(problem, theta) -> list:
    """The coordinates (z, w) of `coordinates` per joint, as flint.acb pairs."""
    out = []
    for j in range(6):
        if problem.slides[j]:
            out.append((theta[j], flint.acb(1)))
        else:
            z = (flint.acb(0, 1 if problem.kind[j] == R_PAIR else 0.5) * theta[j]).exp()
            out.append((z, 1 / z))
    return out


def _refine(sl: Slice, X: np.ndarray) -> list[list[Any] | None]:
    """The points X (k, 7) on H(·; s = 1) = 0 of a slice of the trace family, each polished by
    double-precision Newton and, where that stalls above REFINE_AT, by Newton with the residual at
    DIGITS digits (the Jacobian from the kernel): per point 7 flint.acb, or None where Newton does
    not converge (no regular solution there)."""
    assert sl.times_lambda
    pb = sl.problem
    one = np.ones(len(X))
    X = np.array(X, complex)
    step = np.full(len(X), np.inf)
    for _ in range(4):
        H, J, _ = sl(X, one)
        d = solve_linear(J, -H)
        better = np.isfinite(d).all(1) & (np.abs(d).max(1) < step)
        X[better] += d[better]
        step[better] = np.abs(d[better]).max(1)
    out: list[list[Any] | None] = []
    with flint.ctx.workdps(DIGITS):
        a = [[_acb(v) for v in row] for row in sl.ell + sl.dell]
        p, w, t = [_acb(v) for v in sl.p], [_acb(v) for v in sl.w], _acb(sl.t0 + sl.dt)
        for x, st in zip(X, step):
            xm = [_acb(v) for v in x]
            size = 1 + np.abs(x).max()
            if not st <= REFINE_AT * size:
                for _ in range(8):
                    lam = xm[6]
                    F = exact_system(pb, xm[:6], [p[k] + lam * w[k] for k in range(7)])
                    z = _exact_coordinates(pb, xm[:6])
                    ell = sum((a[0][j] * z[j][0] + a[1][j] * z[j][1] for j in range(6)), flint.acb(0))
                    G = np.array([complex(v.mid()) for v in F + [(ell - 1) * lam + t]])
                    _, J, _ = sl(np.array([[complex(v.mid()) for v in xm]]), one[:1])
                    with np.errstate(all="ignore"):
                        d = np.linalg.solve(J[0], -G) if np.all(np.isfinite(J)) else np.full(7, np.nan)
                    if not np.all(np.isfinite(d)):
                        break
                    xm = [(xm[k] + _acb(d[k])).mid() for k in range(7)]
                    if np.abs(d).max() <= 1e-30 * size:
                        break
                if not np.abs(d).max() <= 1e-20 * size:
                    out.append(None)
                    continue
            out.append(xm)
    return out


def _trace_sum(problem: Problem, points: list) -> list:
    """Σ (z, w, λ) (13 flint.acb) over refined points (7 flint.acb each), at DIGITS digits."""
    with flint.ctx.workdps(DIGITS):
        total = [flint.acb(0)] * 13
        for xm in points:
            z = _exact_coordinates(problem, xm[:6])
            for j in range(6):
                total[j] += z[j][0]
                total[6 + j] += z[j][1]
            total[12] += xm[6]
    return total


def _sizes(problem, X: np.ndarray) -> np.ndarray:
    z, zw, _, _ = coordinates(problem, X[:, :6])
    return np.concatenate([np.abs(z), np.abs(zw), np.abs(X[:, 6:7])], axis=1).sum(0)


@dataclass
class TraceTest:
    """A trace test's result: the start set judged (the given one with any solution the monodromy
    added), the witnesses found, the deviation of the three traces from a line relative to the
    coordinates' sizes (inf: a path could not be tracked), whether it passed, and its time."""

    solutions: np.ndarray
    witnesses: int
    deviation: float
    passed: bool
    seconds: float


def trace_test(problem: Problem, start: StartSystem, seed: int = 0, progress=None, witnesses=None) -> TraceTest:
    """The trace test of the start set (module docstring), with the start solutions its monodromy
    adds. A failure can also come from witnesses that the monodromy has not reached yet (the last
    ones come slowly): then the monodromy goes on, with twice the quiet loops each time, or, where
    it finds nothing more, starts again with a new w and ℓ (some witnesses are hard to reach from
    some), and the test is repeated, at most ROUNDS times; one pass certifies.
    witnesses: (w, ℓ, W, S) of witness_points, judged as given (tests judge several sets against
    one witness set)."""
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, 23])
    wit = witness_points(problem, start, rng, progress) if witnesses is None else witnesses
    deviation = _deviation(problem, start.p0, wit, rng)
    for k in range(1, ROUNDS if witnesses is None else 1):
        if deviation <= TRACE_TOL:
            break
        more = witness_points(problem, start, rng, progress, known=wit, quiet=QUIET << k)
        if len(more[2]) + len(more[3]) == len(wit[2]) + len(wit[3]):  # stuck: a new witness set
            start = dataclasses.replace(start, solutions=wit[3])
            more = witness_points(problem, start, rng, progress)
        wit = more
        deviation = _deviation(problem, start.p0, wit, rng)
    return TraceTest(wit[3], len(wit[2]), deviation, bool(deviation <= TRACE_TOL), time.perf_counter() - t0)


def _track_distinct(sl: Slice, X0: np.ndarray, rng) -> np.ndarray | None:
    """X0 tracked by sl to distinct endpoints: paths that fail, and both paths of an endpoint that
    two reached (one of them jumped), are tracked again with new γ, RETRIES times at most; None
    if that does not do."""
    X, status = sl.track(X0, rng)
    for _ in range(RETRIES + 1):
        if not np.all(_ended(status)):
            return None
        index, owner, again = Index(sl.problem), {}, set()
        for i, x in enumerate(X):
            new, row = index.place(x[:6])
            if new:
                owner[row] = i
            else:
                again |= {i, owner[row]}
        if not again:
            return X
        redo = np.array(sorted(again))
        X[redo], status[redo] = sl.track(X0[redo], rng)
    return None


def _deviation(problem: Problem, p0: np.ndarray, witnesses, rng) -> float:
    """How far the traces at f = 0, −t1, −t2 are from a line, relative to the coordinates' sizes
    (inf where no verdict could be had: a path that was lost, or paths that keep meeting, for
    T_TRIES pairs t1, t2; far out in the complex a path can fail for one t and not for another)."""
    w, ell, W, S = witnesses
    X0 = _points(S, W)
    base = Slice(problem, p0, w, ell, np.zeros_like(ell), 0, 0, True)
    points = _refine(base, X0)
    if any(x is None for x in points):
        return math.inf
    traces, sizes = [_trace_sum(problem, points)], [_sizes(problem, X0)]
    for _ in range(T_TRIES):
        ts = T_SCALE * _crandn(rng, 2)
        for t in ts:
            sl = dataclasses.replace(base, dt=complex(t))
            X = _track_distinct(sl, X0, rng)
            if X is None:
                break
            points = _refine(sl, X)
            if any(x is None for x in points):
                break
            traces.append(_trace_sum(problem, points))
            sizes.append(_sizes(problem, X))
        else:
            break
        del traces[1:], sizes[1:]
    else:
        return math.inf
    scale = np.max(sizes, axis=0)
    with flint.ctx.workdps(DIGITS):
        r = _acb(ts[1] / ts[0])
        dev = [abs((traces[2][c] - traces[0][c] - r * (traces[1][c] - traces[0][c])).mid()) for c in range(13)]
    return max(float(d) / s for d, s in zip(dev, scale))


def certify(problem: Problem, start: StartSystem, progress=None) -> StartSystem:
    """The start set with the trace test's verdict (its `certified`, `trace` and `witnesses`), and
    with the solutions the test's monodromy added (then `runs` gets the larger count too)."""
    if start.count > MAX_SOLUTIONS:
        raise ValueError(
            f"trace: the start set has {start.count} complex solutions; the trace test is limited to "
            f"{MAX_SOLUTIONS} (its witnesses number about ten times as many, far out in the complex)"
        )
    result = trace_test(problem, start, progress=progress)
    runs = start.runs + ([len(result.solutions)] if len(result.solutions) > start.count else [])
    return dataclasses.replace(
        start,
        solutions=result.solutions,
        runs=runs,
        certified=result.passed,
        trace=result.deviation,
        witnesses=result.witnesses,
    )
