"""Constraint varieties of 2-joint chains with the design left symbolic: their linear forms and quadrics.

Intrinsic form: P1(u1) · Tx(a) Rx(α) · P2(u2), base frame on joint 1, end frame on joint 2. The DH
offsets φ_i, c_i and the last link's a_2, α_2 are changes of frame (a pair's motion is a screw about z,
which commutes with Rz and Tz), acting on P^7 by a fixed linear map, so nothing is lost by leaving
them out. A sinusoidal A-pair enters as its rational quartic in u = tan(θ/4)
(`apair_pair.rational_motion`), an R-pair as (1, 0, 0, u) in u = tan(θ/2), the twist as (c, s, 0, 0)
with (c, s) = (cos α/2, sin α/2) up to a common factor (s/c = tan(α/2)).

Grading: x is of degree 1 in (c, s) and free of lengths; y is of degree 1 in (c, s) and of degree 1 in
the lengths (a, h1, h2). So a form Σ q_m(c, s, lengths) m(x, y) vanishes on the image for every design
exactly when each bihomogeneous part does: q_m of degree e in (c, s) and of degree w − deg_y(m) in the
lengths. For each (e, w) that is a linear system over Z (the coefficients in u1, u2 and the
parameters), solved exactly with FLINT. The generators kept are the solutions that lower gradings do
not already give by multiplication with c, s or a length (and, for quadrics, the linear generators
multiplied by a variable), searched over e ≤ 3, w ≤ 3, e + w ≤ 5.

Certificate: at a random rational design the generators span every linear form and quadric that
vanishes on that chain's image (their rank equals the nullity of the specialised system). Check: the
2R chain's image is a quadric surface in a 3-space (four linear forms, then only the Study quadric).
"""

from __future__ import annotations

import itertools
import math
import random
from fractions import Fraction

import flint
import sympy as sp

from . import apair_pair
from .quaternions import Quaternion, StudyPoint, rotation, study_symbols, translation
from .spec import Entry, PolynomialSet

SOURCE = "derivations/chain_variety.py"
u1, u2 = sp.symbols("u1 u2", real=True)
c_alpha, s_alpha = sp.symbols("c_alpha s_alpha", real=True)
a, h1, h2 = sp.symbols("a h1 h2", real=True)
_, _, VARS = study_symbols()
CHAINS = ("AA", "AR", "RA", "RR")
MAX_E, MAX_W, MAX_TOTAL = 3, 3, 5
SEED = 7


def joint(kind: str, u, h) -> StudyPoint:
    """A sinusoidal A-pair (its rational quartic, amplitude h) or an R-pair, in its parameter u."""
    if kind == "R":
        zero = sp.S(0)
        return StudyPoint(Quaternion(sp.S(1), zero, zero, u), Quaternion(zero, zero, zero, zero))
    p = [c.subs({apair_pair.u: u, apair_pair.h: h}) for c in apair_pair.rational_motion()]
    return StudyPoint(Quaternion(*p[:4]), Quaternion(*p[4:]))


class Chain:
    """The image of one 2-joint chain kind as integer polynomials in (u1, u2, c, s, lengths)."""

    def __init__(self, kinds: str):
        self.kinds = kinds
        self.lengths = [a] + [hs for k, hs in zip(kinds, (h1, h2)) if k == "A"]
        self.gens = (u1, u2, c_alpha, s_alpha, *self.lengths)
        link = translation((a, 0, 0)) * rotation((1, 0, 0), c_alpha, s_alpha)
        point = joint(kinds[0], u1, h1) * link * joint(kinds[1], u2, h2)
        polys = [sp.Poly(4 * c, *self.gens) for c in point.as_list()]  # projective: 4 clears the halves
        assert all(q.is_integer for p in polys for q in p.coeffs())
        assert sp.expand(point.study_quadric()) == 0
        for p, name in zip(polys, VARS):  # the grading the method relies on
            for m in p.monoms():
                assert sum(m[2:4]) == 1 and sum(m[4:]) == (1 if str(name)[0] == "y" else 0)
        self.image = polys
        self._powers: dict = {}

    def of_monomial(self, m: tuple[int, ...]) -> dict:
        """m(image) as {exponents: integer coefficient}."""
        if m not in self._powers:
            p = sp.Poly(1, *self.gens)
            for poly, e in zip(self.image, m):
                if e:
                    p = p * poly**e
            self._powers[m] = {k: int(v) for k, v in p.as_dict().items()}
        return self._powers[m]

    def unknowns(self, k: int, e: int, w: int) -> list[tuple]:
        """(form monomial, parameter exponents) of the bihomogeneous part (e, w) of degree-k forms."""
        out = []
        for m in monomials(k, 8):
            rest = w - sum(m[4:])
            if rest < 0:
                continue
            out += [(m, cs + ls) for cs in monomials(e, 2) for ls in monomials(rest, len(self.lengths))]
        return out

    def solutions(self, k: int, e: int, w: int) -> tuple[list, list[list[int]]]:
        """Columns and the canonical (RREF, primitive integer) basis of the forms vanishing identically."""
        cols = self.unknowns(k, e, w)
        rows: dict = {}
        entries = []
        for j, (m, shift) in enumerate(cols):
            for ex, v in self.of_monomial(m).items():
                key = ex[:2] + tuple(x + y for x, y in zip(ex[2:], shift))
                entries.append((rows.setdefault(key, len(rows)), j, v))
        if not cols:
            return cols, []
        M = flint.fmpz_mat(max(1, len(rows)), len(cols))
        for i, j, v in entries:
            M[i, j] = v
        X, nullity = M.nullspace()
        return cols, canonical([[X[i, r] for i in range(len(cols))] for r in range(nullity)])

    def specialised_nullity(self, k: int, values: dict) -> int:
        """Number of independent degree-k forms vanishing on the image of one rational design."""
        mons = monomials(k, 8)
        vals = [values[g] for g in self.gens[2:]]
        rows: dict = {}
        M_entries = []
        for j, m in enumerate(mons):
            for ex, v in self.of_monomial(m).items():
                i = rows.setdefault(ex[:2], len(rows))
                M_entries.append((i, j, v * math.prod(x**p for x, p in zip(vals, ex[2:]))))
        dense = [[Fraction(0)] * len(mons) for _ in rows]
        for i, j, v in M_entries:
            dense[i][j] += v
        den = math.lcm(*(x.denominator for r in dense for x in r))
        return len(mons) - flint.fmpz_mat([[int(x * den) for x in r] for r in dense]).rank()


def monomials(k: int, n: int) -> list[tuple[int, ...]]:
    """Exponent vectors of the degree-k monomials in n variables, in a fixed order."""
    out = []
    for combo in itertools.combinations_with_replacement(range(n), k):
        e = [0] * n
        for v in combo:
            e[v] += 1
        out.append(tuple(e))
    return out


def canonical(vectors) -> list[list[int]]:
    """The RREF basis of the span of integer vectors, each row scaled to primitive integers."""
    if not vectors:
        return []
    R, rank = flint.fmpq_mat([[flint.fmpq(int(v)) for v in row] for row in vectors]).rref()
    out = []
    for r in range(rank):
        vals = [Fraction(int(R[r, c].p), int(R[r, c].q)) for c in range(R.ncols())]
        den = math.lcm(*(v.denominator for v in vals))
        ints = [int(v * den) for v in vals]
        g = math.gcd(*ints)
        out.append([v // g for v in ints])
    return out


def _rank(vectors: list[dict], cols: list) -> int:
    if not vectors:
        return 0
    index = {c: i for i, c in enumerate(cols)}
    M = flint.fmpz_mat(len(vectors), len(cols))
    for r, v in enumerate(vectors):
        for key, c in v.items():
            M[r, index[key]] = c
    return M.rank()


def _times_parameter(v: dict, idx: int) -> dict:
    out = {}
    for (m, shift), c in v.items():
        s = list(shift)
        s[idx] += 1
        out[(m, tuple(s))] = c
    return out


def _times_variable(v: dict, j: int) -> dict:
    out = {}
    for (m, shift), c in v.items():
        mm = list(m)
        mm[j] += 1
        out[(tuple(mm), shift)] = out.get((tuple(mm), shift), 0) + c
    return out


def generators(chain: Chain) -> dict[int, list[tuple[tuple[int, int], dict]]]:
    """{form degree: [((e, w), form as {(monomial, parameter exponents): coefficient})]}."""
    found: dict = {1: [], 2: []}
    sols: dict = {}
    for k in (1, 2):
        for total in range(MAX_TOTAL + 1):
            for e in range(min(total, MAX_E) + 1):
                w = total - e
                if w > MAX_W:
                    continue
                cols, basis = chain.solutions(k, e, w)
                vecs = [{c: v for c, v in zip(cols, row) if v} for row in basis]
                sols[k, e, w] = vecs
                known = []
                if e > 0:
                    known += [_times_parameter(v, i) for v in sols[k, e - 1, w] for i in (0, 1)]
                if w > 0:
                    known += [_times_parameter(v, 2 + i) for v in sols[k, e, w - 1] for i in range(len(chain.lengths))]
                if k == 2:  # x_j · (linear forms of grading (e, w)), y_j · (those of (e, w − 1))
                    known += [_times_variable(v, j) for v in sols.get((1, e, w), []) for j in range(4)]
                    known += [_times_variable(v, j) for v in sols.get((1, e, w - 1), []) for j in range(4, 8)]
                base = _rank(known, cols)
                kept: list = []
                for v in vecs:
                    if base + len(kept) == len(vecs):
                        break
                    if _rank(known + kept + [v], cols) > base + len(kept):
                        kept.append(v)
                found[k] += [((e, w), v) for v in kept]
    return found


def as_expr(form: dict, chain: Chain) -> sp.Expr:
    params = chain.gens[2:]
    return sp.Add(
        *(
            c * sp.Mul(*(g**p for g, p in zip(VARS, m))) * sp.Mul(*(g**p for g, p in zip(params, shift)))
            for (m, shift), c in form.items()
        )
    )


def certify(chain: Chain, found: dict, rng: random.Random) -> tuple[dict[int, int], dict[int, list[bool]]]:
    """At a random rational design: the generators span all vanishing forms of degree 1 and 2.

    Returns the dimensions there and, per generator, whether it is needed at a generic design (it
    adds to the span of those before it and, for quadrics, of the linear forms times a variable);
    the others are needed only at special designs (e.g. a = 0).
    """
    values = {g: Fraction(rng.randint(1, 30), rng.randint(1, 30)) for g in chain.gens[2:]}
    subs = {g: sp.Rational(v.numerator, v.denominator) for g, v in values.items()}
    dims = {k: chain.specialised_nullity(k, values) for k in (1, 2)}
    lin = [sp.Poly(as_expr(f, chain).subs(subs), *VARS) for _, f in found[1]]
    quad = [sp.Poly(as_expr(f, chain).subs(subs), *VARS) for _, f in found[2]]
    generic = {}
    for k, polys, start in ((1, lin, []), (2, quad, [sp.Poly(g * l.as_expr(), *VARS) for l in lin for g in VARS])):
        mons = monomials(k, 8)
        rows = [[p.coeff_monomial(m) for m in mons] for p in start]
        rank = sp.Matrix(rows).rank() if rows else 0
        generic[k] = []
        for p in polys:
            rows.append([p.coeff_monomial(m) for m in mons])
            new = sp.Matrix(rows).rank()
            generic[k].append(new > rank)
            rank = new
        assert rank == dims[k], f"{chain.kinds}: generators of degree {k} span {rank} of {dims[k]}"
    return dims, generic


def derive():
    """The symbolic linear forms and quadrics of the AA, AR, RA and RR chains; (sets, specs, facts)."""
    rng = random.Random(SEED)
    entries, facts = [], {}
    for kinds in CHAINS:
        chain = Chain(kinds)
        found = generators(chain)
        dims, generic = certify(chain, found, rng)
        facts[kinds] = {"dims": dims, "generic": {k: sum(v) for k, v in generic.items()}}
        for k, name in ((1, "L"), (2, "Q")):
            for i, (((e, w), form), gen) in enumerate(zip(found[k], generic[k])):
                expr = sp.expand(as_expr(form, chain))
                entries.append(
                    Entry(
                        f"{kinds}_{name}{i}",
                        expr,
                        tuple(VARS),
                        f"{kinds}; degree {e} in (c_alpha, s_alpha), {w} in lengths and y; "
                        + ("generic" if gen else "special designs only"),
                    )
                )
        facts[kinds]["summary"] = (
            f"{kinds}: {len(found[1])} linear forms and {len(found[2])} quadrics "
            f"({sum(generic[1])} and {sum(generic[2])} needed at a generic design), "
            f"spanning {dims[1]} linear forms and {dims[2]} quadrics there"
        )
    rr = facts["RR"]  # 2R: a quadric surface in a 3-space, the 3-space cut out by 4 linear forms
    assert rr["dims"] == {1: 4, 2: 8 * 4 - 6 + 1} and rr["generic"] == {1: 4, 2: 1}, rr
    assert facts["AA"]["dims"][1] == 0
    description = (
        "Generators of the linear forms and quadrics vanishing on every pose of the 2-joint chain "
        "P1(u1)·Tx(a)Rx(alpha)·P2(u2) (A = sinusoidal A-pair of amplitude h_i, R = revolute), with the "
        "design symbolic: (c_alpha, s_alpha) = (cos(alpha/2), sin(alpha/2)) up to a factor, a the link "
        "length. Valid for every design; at a generic design they span all such forms. "
        + "; ".join(facts[k]["summary"] for k in CHAINS)
        + "."
    )
    ps = PolynomialSet(
        name="chain_variety_symbolic",
        title="Constraint varieties of 2-joint chains with symbolic design: linear forms and quadrics",
        source=SOURCE,
        description=description,
        entries=entries,
    )
    return [ps], [], facts
