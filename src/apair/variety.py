"""Constraint varieties of 2-joint chains: the implicit equations of all their poses in P^7.

A 2-joint chain's poses form a surface on the Study quadric. Its equations are found by exact
linear algebra on points of the image. Each joint is parametrised rationally: an A-pair in
u = tan(θ/4) (the rational quartic derived in `apair show apair_motion`), an R-pair in
u = tan(θ/2), and the DH constants enter through the half-angle pairs (cos, sin) of φ and α, taken
projectively. For every degree k ≤ 4, all forms of degree k that vanish on sampled points are
found as the integer nullspace of their monomial matrix (FLINT). The canonical (RREF) basis of each
degree is then reduced to the generators that the lower degrees do not already give. The Hilbert
function values, computed further (k ≤ 6) by ranks modulo a large prime, give the degree of the
surface.

Designs whose constants are not rational (to 1e-12 relative, denominators ≤ 10^6), and general
A-pairs (whose curve is not rational), use the floating-point variant: nullspaces by SVD on
sampled poses, reported with their residual on fresh poses.
"""

from __future__ import annotations

import itertools
import math
import random
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Generic, TypeVar

import numpy as np
import sympy as sp
from numpy.typing import NDArray

if TYPE_CHECKING:
    from ._typing import ChainLike

VARS = sp.symbols("x0 x1 x2 x3 y0 y1 y2 y3", real=True)
MAX_DENOMINATOR = 10**6
RATIONAL_TOL = 1e-12
PRIME = 2**31 - 1  # products of two residues fit in int64

N = TypeVar("N", Fraction, float)  # the numbers of a design: exact rationals, or floating point
Exponents = tuple[int, ...]  # of a monomial in x0..y3


class Variety(list):
    """The equations (homogeneous sympy.Poly in x0..y3), with what certifies them.

    degree: the surface's degree; hilbert: {k: value of the Hilbert function}; dims: {k: number of
    independent forms of degree k that vanish}; exact: rational arithmetic (else floating point, with
    `residual` the largest |F| on fresh unit-normalised poses, coefficients normalised to norm 1).
    """

    def __init__(self, equations: Iterable[Any], **info: Any) -> None:
        super().__init__(equations)
        self.degree: int | None = info.get("degree")
        self.hilbert: dict = info.get("hilbert", {})
        self.dims: dict = info.get("dims", {})
        self.exact: bool = info.get("exact", True)
        self.residual: float = info.get("residual", 0.0)
        self.design: list = info.get("design", [])


# ----------------------------------------------------------------------------- exact dual quaternions
def _qmul(a: Sequence[N], b: Sequence[N]) -> tuple[N, N, N, N]:
    return (
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    )


def _smul(p: Sequence[N], q: Sequence[N]) -> tuple[N, ...]:
    """Study product (x1 + εy1)(x2 + εy2) = x1x2 + ε(x1y2 + y1x2)."""
    x = _qmul(p[:4], q[:4])
    y1, y2 = _qmul(p[:4], q[4:]), _qmul(p[4:], q[:4])
    return x + tuple(s + t for s, t in zip(y1, y2))


def _rot(axis: int, c: N, s: N, zero: N) -> tuple[N, ...]:
    x = [c, zero, zero, zero]
    x[1 + axis] = s
    return tuple(x) + (zero,) * 4


def _trans(axis: int, dist: N, one: N, zero: N) -> tuple[N, ...]:
    y = [zero] * 4
    y[1 + axis] = dist / 2
    return (one, zero, zero, zero) + tuple(y)


# ----------------------------------------------------------------------------- designs
@dataclass
class JointDesign(Generic[N]):
    """One joint: kind, amplitude h (sinusoidal), a, c and the half-angle pairs of α and φ, in
    rationals (an exact design) or floats."""

    kind: str
    h: N
    a: N
    c: N
    alpha: tuple[N, N]
    phi: tuple[N, N]


def _rational(x: float) -> Fraction | None:
    f = Fraction(x).limit_denominator(MAX_DENOMINATOR)
    return f if abs(float(f) - x) <= RATIONAL_TOL * max(1.0, abs(x)) else None


def _half_pair(angle: float) -> tuple[Fraction, Fraction] | None:
    """(cos, sin) of angle/2 up to a common factor, rational if tan(angle/2) (or its inverse) is."""
    c, s = math.cos(angle / 2), math.sin(angle / 2)
    if abs(c) >= abs(s):
        t = _rational(s / c)
        return None if t is None else (Fraction(1), t)
    t = _rational(c / s)
    return None if t is None else (t, Fraction(1))


def designs(chain: ChainLike) -> tuple[list[JointDesign[Any]], bool]:
    """Exact joint designs when every constant is rational and every pair rational; else floats
    (JointDesign[Fraction] or JointDesign[float], as the flag says)."""
    exact = True
    exact_joints: list[JointDesign[Fraction]] = []
    float_joints: list[JointDesign[float]] = []
    for i, p in enumerate(chain.pairs):
        a, c = chain.a[i], chain.offset[i]
        h = 0.0 if p.kind == "revolute" else p.amplitude
        if p.kind == "general":
            exact = False
        ra, rc, rh = _rational(float(a)), _rational(float(c)), _rational(h)
        al, ph = _half_pair(chain.alpha[i]), _half_pair(chain.theta_offset[i])
        if ra is None or rc is None or rh is None or al is None or ph is None:
            exact = False
        else:
            exact_joints.append(JointDesign(p.kind, rh, ra, rc, al, ph))
        float_joints.append(
            JointDesign(
                p.kind,
                h,
                a,
                c,
                (math.cos(chain.alpha[i] / 2), math.sin(chain.alpha[i] / 2)),
                (math.cos(chain.theta_offset[i] / 2), math.sin(chain.theta_offset[i] / 2)),
            )
        )
    return (exact_joints, True) if exact else (float_joints, False)


def _pair_point_exact(j: JointDesign[Fraction], u: Fraction) -> tuple[Fraction, ...]:
    """The joint's Study point at parameter u, exactly (polynomial in u, projective)."""
    one, zero = Fraction(1), Fraction(0)
    P: tuple[Fraction, ...]
    if j.kind == "revolute":
        P = (one, zero, zero, u, zero, zero, zero, zero)  # u = tan(θ/2)
    else:
        P = _rational_quartic(j.h, u)
    return _constant_factors(j, P, one, zero)


def _constant_factors(j: JointDesign[N], P: Sequence[N], one: N, zero: N) -> tuple[N, ...]:
    left = _rot(2, j.phi[0], j.phi[1], zero)
    right = _smul(_smul(_trans(2, j.c, one, zero), _trans(0, j.a, one, zero)), _rot(0, j.alpha[0], j.alpha[1], zero))
    return _smul(_smul(left, P), right)


_QUARTIC: list[list[tuple[int, int, Fraction]]] | None = None


def _rational_quartic(h: Fraction, u: Fraction) -> tuple[Fraction, ...]:
    """The sinusoidal pair's Study point in u = tan(θ/4), from the derived polynomials."""
    global _QUARTIC
    if _QUARTIC is None:
        from . import polynomials

        eqs = polynomials.load("apair_motion")
        usym, hsym = sp.Symbol("u", real=True), sp.Symbol("h", real=True)
        _QUARTIC = []
        for name in ("x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3"):
            poly = sp.Poly(eqs[f"rational_{name}"], usym, hsym)
            _QUARTIC.append([(int(m[0]), int(m[1]), Fraction(int(c.p), int(c.q))) for m, c in poly.terms()])
    return tuple(sum((c * u**i * h**k for i, k, c in terms), Fraction(0) * u) for terms in _QUARTIC)


def _sample_exact(js: Sequence[JointDesign[Fraction]], count: int, rng: random.Random) -> list[list[int]]:
    """Primitive integer Study points of the chain at random rational parameters."""
    pts: list[list[int]] = []
    while len(pts) < count:
        us = [Fraction(rng.randint(-40, 40), rng.randint(1, 40)) for _ in js]
        P = _pair_point_exact(js[0], us[0])
        for j, u in zip(js[1:], us[1:]):
            P = _smul(P, _pair_point_exact(j, u))
        den = math.lcm(*(f.denominator for f in P))
        ints = [int(f * den) for f in P]
        g = math.gcd(*ints)
        if g == 0:
            continue
        pts.append([v // g for v in ints])
    return pts


def monomials(k: int) -> list[Exponents]:
    """Exponent vectors of the degree-k monomials in x0..y3, in a fixed order."""
    out = []
    for combo in itertools.combinations_with_replacement(range(8), k):
        e = [0] * 8
        for v in combo:
            e[v] += 1
        out.append(tuple(e))
    return out


def _monomial_rows(points: Sequence[Sequence[int]], mons: Sequence[Exponents]) -> list[list[int]]:
    rows = []
    for p in points:
        rows.append([math.prod(p[i] ** e for i, e in enumerate(m) if e) for m in mons])
    return rows


def _forms_exact(points: Sequence[Sequence[int]], k: int) -> tuple[list[Exponents], list[list[int]]]:
    """RREF basis (integer rows, primitive) of the degree-k forms vanishing at the points."""
    import flint

    mons = monomials(k)
    A = flint.fmpz_mat(_monomial_rows(points, mons))
    X, nullity = A.nullspace()
    if nullity == 0:
        return mons, []
    basis = flint.fmpq_mat(X.transpose().tolist()[:nullity])
    R, rank = basis.rref()
    rows = []
    for r in range(rank):
        vals = [Fraction(int(v.p), int(v.q)) for v in (R[r, c] for c in range(len(mons)))]
        den = math.lcm(*(v.denominator for v in vals))
        ints = [int(v * den) for v in vals]
        g = math.gcd(*ints)
        rows.append([v // g for v in ints])
    return mons, rows


def _rank_mod_p(rows: Sequence[Sequence[float]]) -> int:
    import flint

    if len(rows) == 0:
        return 0
    return flint.nmod_mat([[int(v) % PRIME for v in r] for r in rows], PRIME).rank()


def _monomial_rows_mod_p(points: Sequence[Sequence[int]], mons: Sequence[Exponents]) -> NDArray[np.int64]:
    """The monomial matrix modulo PRIME, vectorised over the points."""
    P = np.array([[v % PRIME for v in p] for p in points], dtype=np.int64)
    k = sum(mons[0])
    powers = [np.ones_like(P)]
    for _ in range(k):
        powers.append(powers[-1] * P % PRIME)
    out = np.ones((len(points), len(mons)), dtype=np.int64)
    for c, m in enumerate(mons):
        col = out[:, c]
        for i, e in enumerate(m):
            if e:
                col = col * powers[e][:, i] % PRIME
        out[:, c] = col
    return out


def _shift(
    rows_prev: Sequence[Sequence[float]], mons_prev: Sequence[Exponents], mons: Sequence[Exponents]
) -> list[list[float]]:
    """x_j · F for every F of degree k−1 and every variable, in the degree-k monomial basis."""
    index = {m: i for i, m in enumerate(mons)}
    out: list[list[float]] = []
    for r in rows_prev:
        for j in range(8):
            v: list[float] = [0] * len(mons)
            for coeff, m in zip(r, mons_prev):
                if coeff:
                    e = list(m)
                    e[j] += 1
                    v[index[tuple(e)]] += coeff
            out.append(v)
    return out


def _poly(row: Sequence[float], mons: Sequence[Exponents]) -> Any:
    return sp.Poly.from_dict({m: int(c) for m, c in zip(mons, row) if c}, *VARS)


def constraint_variety(chain: ChainLike, max_degree: int = 4, hilbert_degree: int = 6, seed: int = 0) -> Variety:
    """The equations of a 2-joint chain's poses, generating every vanishing form of degree ≤ max_degree."""
    if chain.n != 2:
        raise ValueError(f"chain: constraint varieties are computed for 2-pair chains, this one has {chain.n}")
    js, exact = designs(chain)
    if not exact:
        return _constraint_variety_float(chain, max_degree, seed)
    rng = random.Random(seed)
    equations: list[Any] = []
    dims: dict[int, int] = {}
    hilbert: dict[int, int] = {}
    prev_rows: list[list[int]] = []
    prev_mons: list[Exponents] = []
    for k in range(1, max_degree + 1):
        mons = monomials(k)
        pts = _sample_exact(js, len(mons) + 24, rng)
        mons, rows = _forms_exact(pts, k)
        dims[k] = len(rows)
        hilbert[k] = len(mons) - len(rows)
        # the generators of degree k that x_j · (lower degrees) do not already give
        known = _shift(prev_rows, prev_mons, mons) if prev_rows else []
        r = _rank_mod_p(known)
        kept: list[list[int]] = []
        for row in rows:
            if r + len(kept) == len(rows):
                break  # the lower degrees already give every form of degree k
            if _rank_mod_p(known + kept + [row]) > r + len(kept):
                kept.append(row)
        equations += [_poly(row, mons) for row in kept]
        prev_rows, prev_mons = rows, mons
    for k in range(max_degree + 1, hilbert_degree + 1):
        mons = monomials(k)
        pts = _sample_exact(js, len(mons) + 24, rng)
        hilbert[k] = _rank_mod_p(_monomial_rows_mod_p(pts, mons).tolist())
        dims[k] = len(mons) - hilbert[k]
    hilbert[0] = 1
    ks = sorted(hilbert)
    second = [hilbert[k] - 2 * hilbert[k - 1] + hilbert[k - 2] for k in ks[2:]]
    degree = second[-1] if len(second) >= 2 and second[-1] == second[-2] else None
    design = [
        dict(
            kind=j.kind,
            h=str(j.h),
            a=str(j.a),
            c=str(j.c),
            alpha_half=tuple(map(str, j.alpha)),
            phi_half=tuple(map(str, j.phi)),
        )
        for j in js
    ]
    return Variety(
        equations, degree=degree, hilbert=dict(sorted(hilbert.items())), dims=dims, exact=True, design=design
    )


def _constraint_variety_float(chain: ChainLike, max_degree: int, seed: int) -> Variety:
    """Floating-point variant: SVD nullspaces on sampled poses, with residuals on fresh poses."""
    rng = np.random.default_rng(seed)

    def poses(count: int) -> NDArray[np.float64]:
        q = np.empty((count, 2))
        for i, p in enumerate(chain.pairs):
            lim = p.theta_limit or np.pi
            q[:, i] = rng.uniform(-0.98, 0.98, count) * lim
        S = chain.fk_study(q)
        return S / np.linalg.norm(S, axis=1, keepdims=True)

    equations, dims, hilbert, residual = [], {}, {}, 0.0
    prev = None
    for k in range(1, max_degree + 1):
        mons = monomials(k)
        E = np.array(mons)
        P = poses(len(mons) * 2)
        A = np.prod(P[:, None, :] ** E[None, :, :], axis=2)
        _, s, Vt = np.linalg.svd(A, full_matrices=True)
        s = np.concatenate([s, np.zeros(Vt.shape[0] - len(s))])
        null = Vt[s <= 1e-9 * s[0]]
        dims[k] = len(null)
        hilbert[k] = len(mons) - len(null)
        test = np.prod(poses(200)[:, None, :] ** E[None, :, :], axis=2)
        if len(null):
            residual = max(residual, float(np.max(np.abs(test @ null.T))))
        # new generators: directions of the nullspace outside x_j · (degree k−1 forms)
        if prev is not None and len(prev[1]):
            known = np.array(_shift(prev[1].tolist(), prev[0], mons), dtype=float)
            Q, _ = np.linalg.qr(known.T)
            rank = np.linalg.matrix_rank(known, tol=1e-9 * max(1.0, np.abs(known).max()))
            Q = Q[:, :rank]
            rest = null.T - Q @ (Q.T @ null.T)
            U, sv, _ = np.linalg.svd(rest, full_matrices=False)
            new = U[:, sv > 1e-7].T
        else:
            new = null
        equations += [
            sp.Poly.from_dict({m: float(c) for m, c in zip(mons, row) if abs(c) > 1e-14}, *VARS) for row in new
        ]
        prev = (mons, null)
    return Variety(equations, degree=None, hilbert=hilbert, dims=dims, exact=False, residual=residual)
