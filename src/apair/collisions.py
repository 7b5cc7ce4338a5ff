"""Collision limits of an A-pair: the collision-free range of θ around 0, found by root isolation.

The contact polynomials come from derivations/apair_collisions.py (`apair show apair_collisions`):
each vanishes where two legs (cylinders of diameter ρ = 2·leg_radius around the leg segments) or
the two plates (thickness τ) touch, in c = cos(θ/2), s = sin(θ/2), the translation d and q3 = √3.
For one design they are made univariate, exactly:

1. the design is put in as exact rationals (a float is a binary rational);
2. d goes: F = A + d·B with d² = a + b cos θ gives A² − d²B²;
3. c = (1 − t²)/(1 + t²), s = 2t/(1 + t²), t = tan(θ/4), and the powers of 1 + t² (never zero) are
   cleared;
4. √3 goes: F = F₀ + √3·F₁ gives F₀² − 3F₁².

Their real roots are isolated by FLINT (certified balls; real roots come out exactly real). Steps 2
and 4 add roots and a piece only counts inside its segments, so each root is a candidate: it is a
touch when the true clearance there (segment distances − ρ, plate gap d − τ) is zero. The limits
are the nearest touches on either side of θ = 0.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from fractions import Fraction
from functools import lru_cache
from typing import TYPE_CHECKING, NamedTuple, TypeVar, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    import flint  # an optional dependency, imported where it is used

    from ._typing import PairLike

# a pair, passed through (unit_pair makes it again by its own class)
P = TypeVar("P", bound="PairLike")

LEG_PAIRS = [(i, j) for i in range(6) for j in range(i + 1, 6)]
_TOUCH_RTOL = 1e-9  # |clearance| at a touch, relative to the pair's size


class CollisionLimits(NamedTuple):
    """The collision-free interval [theta_min, theta_max] and what touches first ("plates" or
    "legs i and j"); infinite limits when the pair turns freely."""

    theta_min: float
    theta_max: float
    what: str


@lru_cache(maxsize=1)
def _pieces() -> list[tuple[str, list[tuple[tuple[int, ...], Fraction]]]]:
    """[(label, [(exponents of c, s, d, q3, r_b, r_p, rho, tau), Fraction])] from the generated set."""
    import sympy as sp

    from . import polynomials

    out = []
    for label, expr in polynomials.load("apair_collisions").items():
        names = {str(x): x for x in expr.free_symbols}
        gens = [names.get(n, sp.Symbol(n)) for n in ("c", "s", "d", "q3", "r_b", "r_p", "rho", "tau")]
        terms = [(m, Fraction(int(k.p), int(k.q))) for m, k in sp.Poly(expr, *gens).terms()]
        out.append((label, terms))
    return out


def _tpoly(coeffs: Iterable[Fraction]) -> flint.fmpq_poly:
    import flint

    return flint.fmpq_poly([flint.fmpq(f.numerator, f.denominator) for f in coeffs])


class _Q3:
    """Polynomials in t over Q(√3), as a pair (P₀, P₁) meaning P₀ + √3·P₁."""

    def __init__(self, p0: flint.fmpq_poly, p1: flint.fmpq_poly | None = None) -> None:
        import flint

        self.p0, self.p1 = p0, p1 if p1 is not None else flint.fmpq_poly([])

    def __add__(self, o: _Q3) -> _Q3:
        return _Q3(self.p0 + o.p0, self.p1 + o.p1)

    def __sub__(self, o: _Q3) -> _Q3:
        return _Q3(self.p0 - o.p0, self.p1 - o.p1)

    def __mul__(self, o: _Q3 | flint.fmpq_poly) -> _Q3:
        if isinstance(o, _Q3):
            return _Q3(self.p0 * o.p0 + 3 * self.p1 * o.p1, self.p0 * o.p1 + self.p1 * o.p0)
        return _Q3(self.p0 * o, self.p1 * o)

    def norm(self) -> flint.fmpq_poly:
        """P₀² − 3P₁²: rational, vanishing wherever P₀ + √3·P₁ does (P₀ itself when P₁ = 0)."""
        if self.p1 == 0:
            return self.p0
        return self.p0 * self.p0 - 3 * self.p1 * self.p1


def contact_polynomials(
    r_b: float | Fraction,
    r_p: float | Fraction,
    a: float | Fraction,
    b: float | Fraction,
    rho: float | Fraction,
    tau: float | Fraction,
) -> list[tuple[str, flint.fmpq_poly]]:
    """[(label, fmpq_poly in t = tan(θ/4))] whose real roots contain every touch of this design."""
    import flint

    vals = [Fraction(v) for v in (r_b, r_p, rho, tau)]
    for name, v in zip(("r_b", "r_p"), vals):  # a zero radius would leave pieces with no term at all
        if not v > 0:
            raise ValueError(f"{name}: expected a radius > 0, got {float(v)!r}")
    a, b = Fraction(a), Fraction(b)
    one_t2 = flint.fmpq_poly([1, 0, 1])
    cn, sn = flint.fmpq_poly([1, 0, -1]), flint.fmpq_poly([0, 2])
    d2 = one_t2 * one_t2 * _tpoly([a]) + (cn * cn - sn * sn) * _tpoly([b])  # d² (1 + t²)², k = 2
    out = []
    for label, terms in _pieces():
        # collect A + d·B, each as {power of 1/(1 + t²): Q(√3)[t]}
        parts: dict[int, dict[int, _Q3]] = {0: {}, 1: {}}
        for (i, j, k, l, *p), coef in terms:
            value = coef * math.prod(v**e for v, e in zip(vals, p))
            if value == 0:
                continue
            if l >= 2:
                value *= 3 ** (l // 2)
            num = cn**i * sn**j * d2 ** (k // 2) * _tpoly([value])
            den = i + j + 2 * (k // 2)
            term = _Q3(num) if l % 2 == 0 else _Q3(flint.fmpq_poly([]), num)
            bucket = parts[k % 2]
            bucket[den] = bucket[den] + term if den in bucket else term
        A, kA = _combine(parts[0], one_t2)
        B, kB = _combine(parts[1], one_t2)
        G: _Q3 | None
        if B is None:
            G = A
        elif A is None:
            G = B
        else:  # A/(1+t²)^kA + d B/(1+t²)^kB = 0  ⇒  A² (1+t²)^(2kB+2) − d²(1+t²)² B² (1+t²)^(2kA)
            lhs = A * A * one_t2 ** (2 * kB + 2)
            rhs = B * B * d2 * one_t2 ** (2 * kA)
            G = lhs - rhs
        poly = cast(_Q3, G).norm()  # every piece has a term that no zero design value removes
        if poly != 0:
            out.append((label, poly))
    return out


def _combine(bucket: dict[int, _Q3], one_t2: flint.fmpq_poly) -> tuple[_Q3 | None, int]:
    if not bucket:
        return None, 0
    K = max(bucket)
    total: _Q3 | None = None
    for k, v in bucket.items():
        v = v * one_t2 ** (K - k)
        total = v if total is None else total + v
    return total, K


def real_roots_t(poly: flint.fmpq_poly) -> list[float]:
    """The real roots of a rational polynomial, isolated by FLINT and given to double precision."""
    import flint

    prec, flint.ctx.prec = flint.ctx.prec, 128  # balls far tighter than a double
    try:
        found = flint.fmpz_poly(poly.numer()).complex_roots()
    finally:
        flint.ctx.prec = prec
    real = [r if isinstance(r, flint.arb) else r.real for r, _ in found if isinstance(r, flint.arb) or r.imag.is_zero()]
    return [float(r.mid()) for r in real]


def segment_distance(P0: ArrayLike, P1: ArrayLike, Q0: ArrayLike, Q1: ArrayLike) -> NDArray[np.float64]:
    """Distance between segments P0P1 and Q0Q1, broadcasting over leading axes (…, 3); computed
    in units of the largest coordinate, so that no product over- or underflows at any scale."""
    unit = max(float(np.abs(x).max(initial=0.0)) for x in (P0, P1, Q0, Q1)) or 1.0
    P0, P1, Q0, Q1 = (np.asarray(x) / unit for x in (P0, P1, Q0, Q1))
    u, v, w = P1 - P0, Q1 - Q0, P0 - Q0
    a, b, c = np.sum(u * u, -1), np.sum(u * v, -1), np.sum(v * v, -1)
    d, e = np.sum(u * w, -1), np.sum(v * w, -1)
    den = a * c - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(den > 1e-14 * a * c, np.clip((b * e - c * d) / den, 0.0, 1.0), 0.0)
        t = (b * s + e) / c
        s = np.where(t < 0, np.clip(-d / a, 0.0, 1.0), np.where(t > 1, np.clip((b - d) / a, 0.0, 1.0), s))
        t = np.clip(t, 0.0, 1.0)
    gap = w + s[..., None] * u - t[..., None] * v
    return unit * np.linalg.norm(gap, axis=-1)


def clearances(pair: PairLike, theta: ArrayLike) -> tuple[NDArray[np.float64], float | NDArray[np.float64]]:
    """(…, 15) surface clearance of every leg pair (segment distance − 2·leg_radius) and (…) plate
    gap d − thickness, at the angles θ."""
    pts = pair.leg_endpoints(theta)
    i, j = np.array(LEG_PAIRS).T
    dist = segment_distance(pts[..., i, 0, :], pts[..., i, 1, :], pts[..., j, 0, :], pts[..., j, 1, :])
    return dist - 2 * pair.leg_radius, pair.translation(theta) - pair.thickness


def _rational(x: float) -> Fraction:
    """x (in units of the pair's size) as a rational within 1e-12·size: exact enough for a touch
    tolerance of 1e-9·size, and free of the huge denominators that tiny doubles (a leg radius of
    1e-300) would carry into the polynomials."""
    return Fraction(x).limit_denominator(10**12)


def _unit_length(x: float) -> float:
    """A length in units of the pair's size, put to 0 where it is below 1e-15 (the rationals of
    `_rational` round it to 0 anyway, and 1e-151 would be refused as a length)."""
    return x if x >= 1e-15 else 0.0


def unit_pair(pair: P) -> P:
    """The same pair (an APair, made by its own class) in units of its size r_b + r_p (collision
    angles do not depend on scale). Call `check_design` first: it bounds the radii's ratio, so that
    both unit radii are lengths the pair accepts."""
    s = pair.base_radius + pair.platform_radius
    L1 = None if pair.kind == "sinusoidal" else pair.leg_lengths[0] / s
    return type(pair)(
        pair.base_radius / s,
        pair.platform_radius / s,
        leg_length=L1,
        leg_radius=_unit_length(pair.leg_radius / s),
        thickness=_unit_length(pair.thickness / s),
    )


# The designs whose touches the tolerance _TOUCH_RTOL resolves (found by sweeps: a radius of 1e-9 of
# the size, or legs of 10^3.75 sizes, give wrong limits); anything beyond is refused, not guessed.
RATIO_MIN = 1e-6  # smallest radius / (r_b + r_p)
LEG_RATIO_MAX = 1e3  # largest leg_length / (r_b + r_p)


def check_design(pair: PairLike) -> None:
    """Refuses (ValueError naming the parameter, with the values the user gave) an A-pair whose
    collision limits do not exist or cannot be found: legs or plates that overlap at θ = 0 (the
    pair cannot move), or proportions (triangles too unequal, legs too long) that the touch
    tolerance cannot resolve. Cheap (no polynomials): chain files are checked with it on loading."""
    if pair.kind not in ("sinusoidal", "general"):  # a lower pair: no legs, no plates
        return
    _check_proportions(pair)
    pts = pair.leg_endpoints(0.0)
    i, j = np.array(LEG_PAIRS).T
    dist = segment_distance(pts[i, 0], pts[i, 1], pts[j, 0], pts[j, 1])
    k = int(np.argmin(dist))
    if dist[k] <= 2 * pair.leg_radius:
        raise ValueError(
            f"leg_radius: {pair.leg_radius!r} m is too large, legs {LEG_PAIRS[k][0] + 1} and {LEG_PAIRS[k][1] + 1} "
            f"overlap at theta = 0 (the pair cannot move); the largest radius is {dist[k] / 2:.6g} m"
        )
    d0 = pair.translation(0.0)
    if d0 <= pair.thickness:
        raise ValueError(
            f"thickness: {pair.thickness!r} m is not less than d(0) = {d0:.6g} m, "
            f"the plates overlap at theta = 0 (the pair cannot move)"
        )


def _check_proportions(pair: PairLike) -> None:
    """Refuses radii or a leg length outside RATIO_MIN, LEG_RATIO_MAX, naming the user's values."""
    radii = {"base_radius": pair.base_radius, "platform_radius": pair.platform_radius}
    size = sum(radii.values())
    for key, value in radii.items():
        other = "platform_radius" if key == "base_radius" else "base_radius"
        if value < RATIO_MIN * size:
            raise ValueError(
                f"{key}: {value!r} m against {other} = {radii[other]!r} m: the collision limits of triangles "
                f"this unequal (a radius below {RATIO_MIN:g} of their sum) cannot be resolved"
            )
    L1 = float(pair.leg_lengths[0])
    if pair.kind == "general" and L1 > LEG_RATIO_MAX * size:
        raise ValueError(
            f"leg_length: {L1!r} m is more than {LEG_RATIO_MAX:g} times base_radius + platform_radius "
            f"({size:.6g} m): the collision limits of legs this long cannot be resolved"
        )


def limits(pair: PairLike) -> CollisionLimits:
    """The collision-free interval around θ = 0 (see the module docstring), computed on the pair
    in units of its size, so that the answer is the same at every scale."""
    if pair.kind not in ("sinusoidal", "general"):  # a lower pair: nothing to collide
        return CollisionLimits(-math.inf, math.inf, "none")
    check_design(pair)
    end = pair.theta_limit  # the range end of the pair itself (the unit pair's differs by rounding)
    pair, size = unit_pair(pair), 1.0
    r_b, r_p = _rational(pair.base_radius), _rational(pair.platform_radius)
    if pair.kind == "sinusoidal":  # d² = a + b cos θ with a = b = r_b r_p, exactly
        a = b = r_b * r_p
    else:  # the design kernel's constants, as the runtime's d(θ) uses them
        a, b = _rational(pair.a), _rational(pair.b)
    roots: set[float] = set()
    for _, poly in contact_polynomials(r_b, r_p, a, b, _rational(2 * pair.leg_radius), _rational(pair.thickness)):
        roots.update(4 * math.atan(t) for t in real_roots_t(poly))
    lim = pair.theta_limit
    candidates = sorted(th for th in roots if th != 0 and (lim is None or abs(th) <= lim))
    upper = _first_touch([th for th in candidates if th > 0], pair, size)
    lower = _first_touch(sorted((th for th in candidates if th < 0), reverse=True), pair, size)
    if end is not None:  # a general pair with a < b: its motion ends at d = 0, the plates coplanar
        upper = (min(upper[0], end), upper[1]) if upper else (end, "plates")
        lower = (max(lower[0], -end), lower[1]) if lower else (-end, "plates")
    if upper is None and lower is None:
        return CollisionLimits(-math.inf, math.inf, "none")
    theta_max, what_max = upper if upper is not None else (math.inf, "none")
    theta_min, what_min = lower if lower is not None else (-math.inf, "none")
    return CollisionLimits(theta_min, theta_max, what_max if theta_max <= -theta_min else what_min)


def _first_touch(ordered: Sequence[float], pair: PairLike, size: float) -> tuple[float, str] | None:
    """The first candidate (in the given order) where the clearance is zero, and what touches."""
    if not ordered:
        return None
    all_legs, all_plates = clearances(pair, np.array(ordered))
    for th, legs, plate in zip(ordered, all_legs, cast(NDArray[np.float64], all_plates)):  # θ is 1-D here
        k = int(np.argmin(legs))
        if min(legs[k], plate) < -_TOUCH_RTOL * size:
            raise RuntimeError(f"collision limits: overlap at theta = {th!r} with no touch before it")
        if abs(legs[k]) <= _TOUCH_RTOL * size:
            return th, "legs {} and {}".format(*(i + 1 for i in LEG_PAIRS[k]))
        if abs(plate) <= _TOUCH_RTOL * size:
            return th, "plates"
    return None
