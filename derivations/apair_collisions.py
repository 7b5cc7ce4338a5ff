"""Leg and plate contacts of an A-pair, each as a polynomial in c = cos(θ/2), s = sin(θ/2) and d.

The platform points move by Rz(θ)·Tz(d) with cos θ = c² − s², sin θ = 2cs (apair_pair.legs gives
the end points). A leg is a cylinder of radius ρ/2 around the segment from its base point B to
its platform point P(θ), so two legs touch when their segments are ρ apart. That distance is
attained in one of three ways, and each gives a polynomial that vanishes at a touch:
- between the two lines, when the common perpendicular's feet lie in both segments:
  N² − ρ²|e_i × e_j|², with N = (B_j − B_i)·(e_i × e_j) and e = P − B;
- from an end point E to the other line, when the foot lies in that segment: |(E − B) × e|² − ρ²|e|²;
- between two end points: |E − F|² − ρ².
Plates of thickness τ (mid-planes at z = 0 and z = d) touch when d = τ.

The pair is threefold symmetric (Rz(120°) permutes the legs and commutes with the motion), so the
leg pairs (0, 1), (3, 4), (0, 3), (0, 4), (0, 5) stand for all fifteen. √3 appears in the
coordinates as the symbol q3. The runtime (apair.collisions) puts a design in exactly, removes d
(through d² = a + b cos θ) and q3 (through their norms), and isolates the real roots in
t = tan(θ/4) with FLINT; which of them are touches is decided there.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from . import apair_pair
from .spec import Entry, PolynomialSet

SOURCE = "derivations/apair_collisions.py"
c, s, d = sp.symbols("c s d", real=True)
rho, tau = sp.symbols("rho tau", positive=True)
q3 = sp.Symbol("q3", positive=True)  # √3
REPRESENTATIVES = ((0, 1), (3, 4), (0, 3), (0, 4), (0, 5))


def _vec(v):
    return sp.Matrix([sp.nsimplify(x) for x in v])


def leg_points():
    """[(B, P(θ))] of the six legs as column vectors in (c, s, d, r_b, r_p, q3)."""
    cos_t, sin_t = c**2 - s**2, 2 * c * s
    Rz = sp.Matrix([[cos_t, -sin_t, 0], [sin_t, cos_t, 0], [0, 0, 1]])
    out = []
    for base, plat, _ in apair_pair.legs():
        B = _vec(base).subs(sp.sqrt(3), q3)
        P = (Rz * _vec(plat) + sp.Matrix([0, 0, d])).subs(sp.sqrt(3), q3)
        out.append((B.applyfunc(sp.expand), P.applyfunc(sp.expand)))
    return out


def _reduce(expr):
    """Expanded, with q3² = 3."""
    p = sp.Poly(sp.expand(expr), q3)
    return sp.expand(sum(coef * (3 ** (k // 2)) * q3 ** (k % 2) for (k,), coef in p.terms()))


def pieces(i: int, j: int, legs) -> dict[str, sp.Expr]:
    """The contact polynomials of legs i and j (those that depend on θ)."""
    (Bi, Pi), (Bj, Pj) = legs[i], legs[j]
    ei, ej = Pi - Bi, Pj - Bj
    n = ei.cross(ej)
    out = {"lines": (Bj - Bi).dot(n) ** 2 - rho**2 * n.dot(n)}
    for one, other in ((i, j), (j, i)):
        B, P = legs[other]
        e = P - B
        for E, end in zip(legs[one], ("base", "platform")):
            w = (E - B).cross(e)
            out[f"{end}_{one}_line_{other}"] = w.dot(w) - rho**2 * e.dot(e)
    for E, ename in ((Bi, f"base_{i}"), (Pi, f"platform_{i}")):
        for F, fname in ((Bj, f"base_{j}"), (Pj, f"platform_{j}")):
            diff = E - F
            out[f"{ename}_{fname}"] = diff.dot(diff) - rho**2
    out = {k: _reduce(v) for k, v in out.items()}
    return {k: v for k, v in out.items() if not _constant_on_circle(v)}


def _constant_on_circle(expr) -> bool:
    """True when expr does not change along the motion (free of d, and constant where c² + s² = 1)."""
    rest = sp.rem(sp.expand(expr), c**2 + s**2 - 1, c)
    return d not in expr.free_symbols and not (sp.expand(rest).free_symbols & {c, s})


def _dot(u, v):
    return sum(x * y for x, y in zip(u, v))


def _check(legs, polys, rng: random.Random):
    """At a random design and angle, ρ² from the line and end-point pieces equals the distance
    computed directly (closest points from the normal equations, 30 digits)."""
    mpmath.mp.dps = 30
    r_b, r_p, d_, th = (
        sp.Rational(rng.randint(lo, hi), 100) for lo, hi in ((50, 200), (50, 200), (10, 100), (-300, 300))
    )
    vals = {apair_pair.r_b: r_b, apair_pair.r_p: r_p, d: d_, c: sp.cos(th / 2), s: sp.sin(th / 2), q3: sp.sqrt(3)}

    def num(v):
        return [mpmath.mpf(str(sp.N(x.subs(vals), 30))) for x in v]

    def root(G):  # ρ² where G = X − ρ² Y vanishes
        poly = sp.Poly(G.subs(vals), rho)
        return mpmath.mpf(str(sp.N(-poly.coeff_monomial(1) / poly.coeff_monomial(rho**2), 30)))

    for (i, j), ps in polys.items():
        (Bi, Pi), (Bj, Pj) = [(num(B), num(P)) for B, P in (legs[i], legs[j])]
        ei, ej = [p - b for p, b in zip(Pi, Bi)], [p - b for p, b in zip(Pj, Bj)]
        w = [x - y for x, y in zip(Bi, Bj)]
        a11, a12, a22 = _dot(ei, ei), -_dot(ei, ej), _dot(ej, ej)
        r1, r2 = -_dot(ei, w), _dot(ej, w)
        det = a11 * a22 - a12 * a12
        u, v = (r1 * a22 - a12 * r2) / det, (a11 * r2 - a12 * r1) / det
        gap = [x + u * y - v * z for x, y, z in zip(w, ei, ej)]
        assert abs(root(ps["lines"]) - _dot(gap, gap)) < 1e-20, (i, j)
        foot = _dot([x - y for x, y in zip(Pi, Bj)], ej) / a22  # platform point i onto line j
        off = [x - y - foot * z for x, y, z in zip(Pi, Bj, ej)]
        assert abs(root(ps[f"platform_{i}_line_{j}"]) - _dot(off, off)) < 1e-20, (i, j)


def derive():
    """The contact polynomials of every representative leg pair, and of the plates."""
    legs = leg_points()
    polys = {ij: pieces(*ij, legs) for ij in REPRESENTATIVES}
    _check(legs, polys, random.Random(5))
    entries = [
        Entry(f"legs_{i}_{j}_{name}", p, (c, s, d), f"legs {i} and {j}: {name.replace('_', ' ')}")
        for (i, j), ps in polys.items()
        for name, p in ps.items()
    ]
    entries.append(Entry("plates", d - tau, (c, s, d), "the plates' facing surfaces meet"))
    ps = PolynomialSet(
        name="apair_collisions",
        title="A-pair: leg and plate contacts",
        source=SOURCE,
        description=(
            "Each polynomial vanishes where two legs (cylinders of diameter rho around the leg "
            "segments) or the plates (thickness tau) touch, in c = cos(theta/2), s = sin(theta/2) "
            "and the translation d; q3 = sqrt(3). Leg pairs (0, 1), (3, 4), (0, 3), (0, 4), (0, 5) "
            "stand for all fifteen by the pair's threefold symmetry."
        ),
        entries=entries,
    )
    return [ps], [], {"pieces": {ij: sorted(p) for ij, p in polys.items()}}
