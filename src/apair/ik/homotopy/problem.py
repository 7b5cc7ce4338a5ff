"""A chain's inverse kinematics as the homotopy takes it (apair.ik.homotopy): the `Problem` (six
joints, the virtual ones last, lengths in units of the chain's scale), its equations F(θ; t, q) by
the generated kernels (`law`, `system`), the pose coordinates (t, q), and when two complex angle
vectors are one solution (`canonical`, `Index`; the chain's own among the six-joint ones: `own`).
A P-pair's variable is its slide x in units of the scale (its angle held at θ_offset): "angles"
below include it, with no period, and how far out it is is log |x| (`far_of`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from ... import kernels
from ...study import from_matrix

SAME = 1e-4  # two endpoints whose angles differ by less than this are one solution
LOOSE = 1e-2  # the same for an endpoint not refined to full accuracy (far out, they are off by up to 1e-3)
VIRTUAL_ZERO = 1e-6  # |exp(iθ) − 1| under which a virtual joint is at 0
REAL = 1e-5  # |Im θ| under which an endpoint is a real candidate (fk verifies it)
KINDS = {"revolute": 0, "sinusoidal": 1, "prismatic": 4}  # the problem's joint kinds (apair_ik_problem)
LETTERS = {0: "R", 1: "A", 4: "P"}  # a kind's letter in a pattern (apair show ik_counts)
R_PAIR, A_PAIR, P_PAIR = 0, 1, 4


def scale_of(chain) -> float:
    """The chain's length scale: its largest link length, offset, amplitude or end of a P-pair's
    range (at least 1 mm), as apair.ik.poses.length_scale takes it."""
    lengths = [abs(x) for x in (*chain.a, *chain.offset)] + [_amplitude(p) for p in chain.pairs]
    lengths += [max(abs(lo), abs(hi)) for p, (lo, hi) in zip(chain.pairs, chain.limits) if p.kind == "prismatic"]
    return max(max(lengths), 1e-3)


@dataclass(frozen=True)
class Problem:
    """A chain's design as the tracker takes it (6 joints, the virtual ones last), lengths in units
    of `scale`; `joints` is the chain's own n."""

    kind: np.ndarray  # int32 (6,): 0 R-pair, 1 sinusoidal A-pair, 4 P-pair
    pair: np.ndarray  # (6, 2): (h, 0)
    dh: np.ndarray  # (6, 4)
    scale: float
    joints: int
    tail: np.ndarray | None = None  # n < 6: the fixed transform T·tail that the turned last joint reaches (`of`)

    @property
    def n(self) -> int:
        return len(self.kind)

    @property
    def slides(self) -> np.ndarray:
        """(n,) bool: the joints whose variable is a P-pair's slide (no period, no angle)."""
        return self.kind == P_PAIR

    @property
    def turning(self) -> np.ndarray:
        """(n,) ik_system's turning factors: 0 for a P-pair, else 1."""
        return np.where(self.slides, 0.0, 1.0)

    @property
    def pattern(self) -> str:
        """The chain's own joints as letters (R, A, P), as generated/ik_counts.json names them."""
        return "".join(LETTERS[int(k)] for k in self.kind[: self.joints])

    @staticmethod
    def of(chain) -> Problem:
        for i, p in enumerate(chain.pairs):
            if p.kind not in KINDS:
                raise ValueError(
                    f"pairs[{i}]: a {p.kind} pair's motion is not algebraic in the angle's half tangent; "
                    "inverse kinematics needs sinusoidal A-pairs, R-pairs or P-pairs"
                )
        s = scale_of(chain)
        kind = [KINDS[p.kind] for p in chain.pairs]
        pair = [[_amplitude(p) / s, 0.0] for p in chain.pairs]
        dh = [[a / s, al, c / s, ph] for a, al, c, ph in zip(chain.a, chain.alpha, chain.offset, chain.theta_offset)]
        extra = 6 - chain.n
        tail = None
        if extra:
            # the last joint's Tx(a)·Rx(α) turned to TURN's, so that the first virtual axis is generic
            # to it (with α = 0 and a = 0 it would be that joint's own axis: a curve of solutions):
            # frame n = (the turned frame)·K, K = Rx(−α')·Tx(a − a')·Rx(α), so the turned chain
            # reaches T·K⁻¹
            a, alpha = dh[-1][0], dh[-1][1]
            tail = _dh(0.0, 0.0, -alpha, 0.0, 0.0) @ _dh(0.0, TURN[0] - a, TURN[1], 0.0, 0.0)
            dh[-1][:2] = TURN
        kind += [0] * extra
        pair += [[0.0, 0.0]] * extra
        dh += [list(row) for row in VIRTUAL[:extra]]
        return Problem(np.array(kind, np.int32), np.array(pair, float), np.array(dh, float), s, chain.n, tail)

    def key(self) -> str:
        """What the start system depends on, as text (floats exactly)."""
        return json.dumps(
            {
                "kind": self.kind.tolist(),
                "pair": [float(x).hex() for x in self.pair[:, 0]],
                "dh": [[float(x).hex() for x in row] for row in self.dh],
                "joints": self.joints,
            }
        )

    def pose(self, T: np.ndarray) -> np.ndarray:
        """The pose (4 × 4) the 6 tracked joints must reach for the chain to reach T (4 × 4): T in
        units of scale, times the virtual joints at 0."""
        Ts = np.array(T, float)
        Ts[:3, 3] /= self.scale
        if self.tail is not None:
            Ts = Ts @ self.tail
        for a, alpha, c, phi in self.dh[self.joints :]:
            Ts = Ts @ _dh(0.0, a, alpha, c, phi)
        return Ts

    def target(self, T: np.ndarray) -> np.ndarray:
        """pose(T) as (t, q) (7,), the homotopy's pose coordinates."""
        return target_of(self.pose(T))


def _amplitude(pair) -> float:
    """A pair's amplitude h, 0 for a P-pair (its slide is the joint's variable)."""
    return 0.0 if pair.kind == "prismatic" else pair.amplitude


def target_of(pose: np.ndarray) -> np.ndarray:
    """A pose (4 × 4, in units of the scale) as the homotopy's pose coordinates (t, q) (7,)."""
    return np.concatenate([pose[:3, 3], from_matrix(pose)[:4]]).astype(complex)


def _dh(theta, a, alpha, c, phi) -> np.ndarray:
    """Rz(θ + φ)·Tz(c)·Tx(a)·Rx(α) (docs/conventions.md §3, an R-pair)."""
    ct, st, ca, sa = math.cos(theta + phi), math.sin(theta + phi), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, c], [0, 0, 0, 1]])


TURN = (0.43, 0.97)  # n < 6: the last joint's (a, α) in the tracked chain (units of the scale; `Problem.of`)

# The virtual joints that complete a chain of n < 6 joints (a, α, c, φ in units of the chain's
# scale): fixed, of generic geometry (no zero, parallel or perpendicular axes), so that the start
# systems and counts are reproducible.
VIRTUAL = (
    (0.61, 1.13, 0.37, 0.0),
    (0.83, -0.71, 0.29, 0.0),
    (0.47, 1.37, -0.53, 0.0),
    (0.71, -1.21, 0.41, 0.0),
    (0.53, 0.89, -0.31, 0.0),
)


def law(problem: Problem, theta: np.ndarray):
    """(cos(θ/2), sin(θ/2), d, d') (…, n, 4) at complex angles θ (…, n), by the ik_law kernels; a
    P-pair's (1, 0, x, 1) at its slide x."""
    theta = np.asarray(theta)
    v = np.exp(0.5j * np.where(problem.slides, 0, theta))
    out = np.empty(v.shape + (4,), complex)
    idx = np.flatnonzero(problem.slides)
    if len(idx):
        out[..., idx, :] = [1, 0, 0, 1]
        out[..., idx, 2] = theta[..., idx]
    for k in (R_PAIR, A_PAIR):  # one call per kind of pair, over its joints
        idx = np.flatnonzero(problem.kind == k)
        if len(idx) == 0:
            continue
        vi = pairs_of(v[..., idx])[..., None, :]
        if k == 0:
            (res,) = kernels.call("ik_law_revolute", vi)
        else:
            (res,) = kernels.call("ik_law_sinusoidal", vi, np.broadcast_to(problem.pair[idx, :1], vi.shape[:-2] + (1,)))
        out[..., idx, :] = complex_of(res)
    return out


def pairs_of(z: np.ndarray) -> np.ndarray:
    """Complex z (...) as (..., 2) (real, imaginary) float64 (a view where z is contiguous)."""
    z = np.ascontiguousarray(z, complex)
    return z.view(np.float64).reshape(z.shape + (2,))


def complex_of(a: np.ndarray) -> np.ndarray:
    """(..., 2) (real, imaginary) pairs as complex (...)."""
    return a[..., 0] + 1j * a[..., 1]


def system(problem: Problem, theta: np.ndarray, target: np.ndarray, direction: np.ndarray):
    """F (6,), dF/dθ (6, n) and dF/d(direction) (6,) at one point (the generated kernel)."""
    lw = law(problem, theta)
    F, dF, dFs = kernels.call(
        f"ik_system{problem.n}", pairs_of(lw), pairs_of(target), pairs_of(direction), problem.dh, problem.turning
    )
    return complex_of(F), complex_of(dF), complex_of(dFs)


def linear_pose(problem: Problem, theta: np.ndarray):
    """F(θ; p) = A p + b: (A (6, 7), b (6,)) at fixed θ (F is linear in the pose)."""
    zero = np.zeros(7, complex)
    b = system(problem, theta, zero, zero)[0]
    A = np.stack([system(problem, theta, zero, e)[2] for e in np.eye(7, dtype=complex)], 1)
    return A, b


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
    """θ with its real part in (−π, π] (R-pair) or (−2π, 2π] (A-pair), the imaginary part kept (a
    P-pair's slide as it is)."""
    half = np.where(problem.kind == R_PAIR, np.pi, 2 * np.pi)
    re = np.real(theta)
    with np.errstate(invalid="ignore"):  # a failed path's endpoint (NaN, inf) stays what it is
        wrapped = re - 2 * half * np.ceil((re - half) / (2 * half))
        return np.where(problem.slides, re, wrapped) + 1j * np.imag(theta)


def far_of(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """How far out in the complex each point θ (..., n) is (...,): the largest |Im θ| of its angles
    and log |x| of its P-pairs' slides x (0 within |x| ≤ 1), as the C tracker measures it."""
    theta = np.asarray(theta)
    far = np.abs(theta.imag)
    if problem.slides.any():
        with np.errstate(divide="ignore", invalid="ignore"):
            far = np.where(problem.slides, np.maximum(0.0, np.log(np.abs(theta))), far)
    return far.max(axis=-1)


class Index:
    """Solutions (complex angles) with a bucket index on Im θ_1, so that membership tests of
    thousands of them are fast. Two solutions are one when their angles differ by at most SAME in
    every joint (LOOSE if either is `loose`, not refined to full accuracy), the real parts modulo
    the joint's period (one pose: 2π for an R-pair, 4π for an A-pair, none for a P-pair's slide)."""

    def __init__(self, problem: Problem):
        self.problem = problem
        self.period = np.where(problem.slides, np.inf, np.where(problem.kind == R_PAIR, 2 * np.pi, 4 * np.pi))
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
                if np.all(
                    np.maximum(np.minimum(re, self.period - re), np.abs(d.imag))
                    <= (LOOSE if loose or self.loose[j] else SAME)
                ):
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


def own_rows(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """(k,) bool: which 6-joint solutions θ (k, 6) are the chain's own (the virtual joints at 0)."""
    v = np.exp(1j * theta[:, problem.joints :])  # the virtual joints are R-pairs
    return np.all(np.abs(v - 1) <= VIRTUAL_ZERO, axis=1)


def own(problem: Problem, theta: np.ndarray) -> np.ndarray:
    """The chain's own solutions (k', n) among the 6-joint solutions θ (k, 6)."""
    return theta[own_rows(problem, theta), : problem.joints]


def real_angles(problem: Problem, theta: np.ndarray, tol: float = REAL) -> np.ndarray:
    """The real endpoints' angles (m, n): (−π, π] for R-pairs, (−2π, 2π] for A-pairs, a P-pair's
    slide in units of the scale."""
    n = problem.joints
    if len(theta) == 0:
        return np.zeros((0, n))
    real = np.all(np.abs(np.imag(theta)) <= tol, axis=1)
    kind = Problem(problem.kind[:n], problem.pair[:n], problem.dh[:n], problem.scale, n)
    return np.ascontiguousarray(np.real(canonical(kind, theta[real])))  # (the kernels' fast path wants it contiguous)
