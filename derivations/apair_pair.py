"""The A-pair derived from its Griffis-Duffy platform (docs/conventions.md §2).

1. The six leg constraints of the GDP as quadrics in the Study parameters, computed from the
   Euclidean sphere condition |R p + t − b|² = L² through the kinematic mapping.
2. The self-motion: on the 3-space x1 = x2 = y1 = y2 = 0 the six quadrics collapse to one relation
   exactly when L1² − L2² = ¾(r_b² − r_p²); on Rz(θ)Tz(d) it reads d² = a + b cos θ. The sinusoidal
   case a = b gives d = h cos(θ/2), h = √(2 r_b r_p), and a rational quartic in u = tan(θ/4).
3. A numerical certificate that the platform's mobility along the motion is one (rank 5).

Every closed form that reaches generated code (the pair laws d, d', d'' and the leg end points)
is taken from these computations, and each step asserts what it claims.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from .quaternions import rotation, study_symbols, transform_point_homogeneous, translation
from .spec import Arg, Entry, KernelSpec, PolynomialSet

SOURCE = "derivations/apair_pair.py"

r_b, r_p, L1, L2 = sp.symbols("r_b r_p L1 L2", positive=True)
theta = sp.Symbol("theta", real=True)
d = sp.Symbol("d", real=True)
a, b, h = sp.symbols("a b h", real=True)
u = sp.Symbol("u", real=True)


def _polar(r, angle):
    return (r * sp.cos(angle), r * sp.sin(angle), sp.S(0))


def triangles():
    """Base/platform vertices and edge midpoints, k = 0, 1, 2 (each in its own frame)."""
    k3 = [2 * sp.pi * k / 3 for k in range(3)]
    return {
        "base_vertex": [_polar(r_b, t) for t in k3],
        "base_midpoint": [_polar(r_b / 2, sp.pi / 3 + t) for t in k3],
        "platform_vertex": [_polar(r_p, sp.pi / 3 + t) for t in k3],
        "platform_midpoint": [_polar(r_p / 2, t) for t in k3],
    }


def legs():
    """The six legs as (base point, platform point, length): vertex k ↔ midpoint k."""
    tri = triangles()
    out = [(tri["base_vertex"][k], tri["platform_midpoint"][k], L1) for k in range(3)]
    out += [(tri["base_midpoint"][k], tri["platform_vertex"][k], L2) for k in range(3)]
    return out


def leg_quadric(base_point, platform_point, length):
    """The sphere condition of one leg as a quadric G in (x, y).

    F = |x|⁴(|R p + t − b|² − L²) is a quartic; F + 4(x·y)² is divisible by |x|², and the quotient G
    is the leg's quadric: on the Study quadric x·y = 0, F = |x|² G.
    """
    x, y, gens = study_symbols()
    n = sp.expand(x.norm2())
    moved = transform_point_homogeneous(x, y, platform_point)
    F = sp.expand(sum((m - n * sp.S(bc)) ** 2 for m, bc in zip(moved, base_point)) - length**2 * n**2)
    q, r = sp.div(sp.expand(F + 4 * x.dot(y) ** 2), n, *gens)
    assert r == 0, "the sphere condition must factor through |x|² on the Study quadric"
    return sp.expand(q)


def pair_study_point(angle, shift):
    """Study point of the platform frame Rz(angle)·Tz(shift) relative to the base frame."""
    return rotation((0, 0, 1), sp.cos(angle / 2), sp.sin(angle / 2)) * translation((0, 0, shift))


SINUSOIDAL_LAW = h * sp.cos(theta / 2)  # d(θ) of a sinusoidal pair, proved in `derive`


def rational_motion(law=SINUSOIDAL_LAW) -> list[sp.Expr]:
    """The sinusoidal pair's Study point as polynomials in u = tan(θ/4) (times (1 + u²)², of degree ≤ 4).

    `law` is d(θ), by default the sinusoidal law that `derive` proves. Each step is asserted: the
    rotation part is the rational parametrisation of Rz(θ), the point is on the Study quadric.
    """
    cu, su = (1 - u**2) / (1 + u**2), 2 * u / (1 + u**2)
    Pu = pair_study_point(theta, law)
    rational = [sp.factor(sp.expand_trig(c.subs(theta, 4 * sp.atan(u))).rewrite(sp.cos)) for c in Pu.as_list()]
    rational = [sp.factor(sp.simplify(c)) for c in rational]
    denom = (1 + u**2) ** 2
    rational = [sp.factor(sp.cancel(c * denom)) for c in rational]
    x_check = [sp.cancel(c - e) for c, e in zip(rational[:4], [cu * denom, 0, 0, su * denom])]
    assert all(v == 0 for v in x_check)
    assert all(sp.Poly(c, u).degree() <= 4 for c in rational if c != 0)
    assert sp.expand(sum(p * q for p, q in zip(rational[:4], rational[4:]))) == 0
    return rational


def derive():
    """Run the whole A-pair derivation; returns (polynomial sets, kernel specs, facts)."""
    x, y, gens = study_symbols()
    x0, x1, x2, x3, y0, y1, y2, y3 = gens
    G = [leg_quadric(*leg) for leg in legs()]

    # --- the self-motion on the 3-space x1 = x2 = y1 = y2 = 0 -------------------------------
    on_space = {x1: 0, x2: 0, y1: 0, y2: 0}
    R = [sp.expand(g.xreplace(on_space)) for g in G]
    assert R[0] == R[1] == R[2] and R[3] == R[4] == R[5], "legs of one kind must agree on the 3-space"
    difference = sp.factor(R[0] - R[3])
    consistency = sp.solve(sp.Eq(R[0] - R[3], 0), L1**2)  # the two kinds coincide iff this holds
    assert len(consistency) == 1
    L1_sq = consistency[0]
    assert sp.expand(L1_sq - L2**2 - sp.Rational(3, 4) * (r_b**2 - r_p**2)) == 0

    # The one relation, written as 4(y0² + y3²) = A x0² + B x3², and the pair constants a, b.
    relation = R[0]
    rel_poly = sp.Poly(relation, x0, x3, y0, y3)
    assert rel_poly.coeff_monomial(y0**2) == 4 and rel_poly.coeff_monomial(y3**2) == 4
    A = -rel_poly.coeff_monomial(x0**2)
    B = -rel_poly.coeff_monomial(x3**2)
    assert set(rel_poly.monoms()) == {(2, 0, 0, 0), (0, 2, 0, 0), (0, 0, 2, 0), (0, 0, 0, 2)}
    a_expr = sp.expand((A + B) / 2)
    b_expr = sp.factor((A - B) / 2)
    a_expr2 = sp.expand(a_expr.subs(L1**2, L1_sq))
    assert b_expr == r_b * r_p
    assert sp.expand(a_expr - (L1**2 - r_b**2 - r_p**2 / 4)) == 0
    assert sp.expand(a_expr2 - (L2**2 - r_p**2 - r_b**2 / 4)) == 0
    pair_quadric = sp.expand(4 * (y0**2 + y3**2) - (a + b) * x0**2 - (a - b) * x3**2)
    assert sp.expand(pair_quadric.subs({a: a_expr, b: b_expr}) - relation) == 0

    # --- the law d(θ): put the pair's Study point Rz(θ)Tz(d) into the relation ---------------
    P = pair_study_point(theta, d)
    p_list = [sp.expand(c) for c in P.as_list()]
    assert p_list[1] == p_list[2] == p_list[5] == p_list[6] == 0, "Rz·Tz lies in the 3-space"
    assert sp.simplify(P.study_quadric()) == 0
    on_curve = pair_quadric.xreplace(dict(zip(gens, p_list)))
    D = sp.Symbol("D")  # d², the relation is linear in it
    lin = sp.Poly(sp.expand(on_curve).subs(d**2, D), D)
    assert lin.degree() == 1
    c1, c0 = lin.all_coeffs()
    d_sq = sp.simplify(sp.trigsimp(-c0 / c1))
    assert sp.simplify(d_sq - (a + b * sp.cos(theta))) == 0
    d_sq = a + b * sp.cos(theta)  # the simplified form just proved equal

    # General pair: d = +√(a + b cos θ); angle range when a < b.
    d_general = sp.sqrt(d_sq)
    theta_max_general = sp.acos(-a / b)

    # Sinusoidal pair: a = b, solved for L1; then d² = 2b cos²(θ/2) and d = h cos(θ/2).
    sinus_L1 = sp.solve(sp.Eq(a_expr, b_expr), L1)
    assert len(sinus_L1) == 1
    sinus_L1 = sp.factor(sinus_L1[0])
    d_sq_sinus = sp.trigsimp(d_sq.subs(a, b))
    h_expr = sp.sqrt(2 * b_expr)
    half = sp.cos(theta / 2)
    assert sp.simplify(d_sq_sinus - (sp.sqrt(2 * b) * half) ** 2) == 0
    d_sinus = SINUSOIDAL_LAW  # h·cos(θ/2): the branch through d(0) = +h, continued analytically
    assert sp.simplify((d_sinus.subs(h, sp.sqrt(2 * b))) ** 2 - d_sq_sinus) == 0 and d_sinus == h * half

    # The rational quartic of the sinusoidal pair in u = tan(θ/4) (homogeneous, one common factor).
    rational = rational_motion(d_sinus)
    # --- mobility: the six leg lines have rank 5 along the motion ------------------------------
    mobility = mobility_certificate()

    # --- laws and their derivatives, for the kernels ---------------------------------------------
    assert LAWS["sinusoidal"][0] == d_sinus and LAWS["general"][0] == d_general
    specs = law_specs() + law_d3_specs()
    specs.append(legs_spec())
    L2_sq = sp.expand(L1**2 - L1_sq + L2**2)  # L2² from the consistency condition
    specs += design_specs(a_expr, b_expr, L2_sq, sinus_L1, h_expr)

    gdp = PolynomialSet(
        name="gdp_legs",
        title="Griffis-Duffy platform: the six leg constraints in Study parameters",
        source=SOURCE,
        description=(
            "Sphere condition |R p + t - b|^2 = L^2 of each leg, mapped to the Study parameters "
            "(x0:x1:x2:x3:y0:y1:y2:y3); quadrics, valid on the Study quadric."
        ),
        entries=[Entry("study_quadric", sp.expand(x.dot(y)), tuple(gens), "the Study quadric")]
        + [
            Entry(
                f"leg_{k}",
                g,
                tuple(gens),
                f"{'base vertex' if k < 3 else 'base midpoint'} {k % 3} - "
                f"{'platform midpoint' if k < 3 else 'platform vertex'} {k % 3}, "
                f"length {'L1' if k < 3 else 'L2'}",
            )
            for k, g in enumerate(G)
        ],
    )
    motion = PolynomialSet(
        name="apair_motion",
        title="The A-pair: self-motion of the Griffis-Duffy platform",
        source=SOURCE,
        description=(
            "On the 3-space x1 = x2 = y1 = y2 = 0 the six leg quadrics reduce to one relation when "
            "the leg lengths are consistent; a, b are the pair's constants."
        ),
        entries=[
            Entry("restricted_leg_L1", R[0], (x0, x3, y0, y3), "legs 0, 1, 2 on the 3-space (identical)"),
            Entry("restricted_leg_L2", R[3], (x0, x3, y0, y3), "legs 3, 4, 5 on the 3-space (identical)"),
            Entry("kinds_difference", difference, (x0, x3), "leg_L1 - leg_L2: zero iff the lengths are consistent"),
            Entry("consistency", L1**2 - L2**2, (), "required leg-length relation", rhs=sp.factor(L1_sq - L2**2)),
            Entry("a", a, (), "pair constant", rhs=a_expr),
            Entry("a_alt", a, (), "the same constant in L2", rhs=a_expr2),
            Entry("b", b, (), "pair constant", rhs=b_expr),
            Entry("pair_quadric", pair_quadric, (x0, x3, y0, y3), "with x0 y0 + x3 y3 = 0: the pair's curve"),
            Entry("study_quadric", x0 * y0 + x3 * y3, (x0, x3, y0, y3), "the Study quadric on the 3-space"),
            Entry("law", d**2, (), "Rz(theta)Tz(d) put into the pair quadric", rhs=d_sq),
            Entry("law_general", d, (), "general pair; |theta| <= acos(-a/b) when a < b", rhs=d_general),
            Entry("theta_max_general", sp.Symbol("theta_max"), (), "range of a pair with a < b", rhs=theta_max_general),
            Entry("sinusoidal_L1", L1, (), "a = b", rhs=sinus_L1),
            Entry("sinusoidal_amplitude", h, (), "h = sqrt(2 b)", rhs=h_expr),
            Entry("law_sinusoidal", d, (), "a = b: d(theta) = h cos(theta/2)", rhs=d_sinus),
            Entry("pitch_sinusoidal", sp.Symbol("dd"), (), "d'(theta)", rhs=sp.diff(d_sinus, theta)),
        ]
        + [
            Entry(f"rational_{n}", c, (u,), "sinusoidal pair, u = tan(theta/4), times (1+u^2)^2")
            for n, c in zip(["x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3"], rational)
        ],
    )
    facts = {
        "d_squared": d_sq,
        "amplitude": h_expr,
        "sinusoidal_L1": sinus_L1,
        "consistency": sp.Eq(L1**2 - L2**2, sp.factor(L1_sq - L2**2)),
        "mobility": mobility,
    }
    return [gdp, motion], specs, facts


# d(θ) of each kind and the law kernel's inputs: the forms derive() proves from the pair's quadric,
# and the helical pair, of which the A-pair is the generalisation: d = pitch·θ (c_i, the joint's
# constant offset, is in the chain's DH row).
pitch = sp.Symbol("pitch", real=True)
LAWS = {
    "revolute": (sp.S(0), (theta,)),
    "sinusoidal": (SINUSOIDAL_LAW, (theta, h)),
    "general": (sp.sqrt(a + b * sp.cos(theta)), (theta, a, b)),
    "helical": (pitch * theta, (theta, pitch)),
}
# The prismatic pair, the helical pair's limit of infinite pitch: its joint variable is the slide
# d itself, its angle the constant φ_i of the DH row; as a law of its variable q = d, the angle
# is 0 (cos, sin of 0/2 = 1, 0) and d(q) = q.
PRISMATIC_LAW = d


def law_specs() -> list[KernelSpec]:
    """The law kernels of every kind (derive() checks the A-pairs' LAWS against the derivation)."""
    return [law_spec(kind, expr, args) for kind, (expr, args) in LAWS.items()] + [prismatic_law_spec()]


def prismatic_law_spec() -> KernelSpec:
    """Kernel: the slide q -> (cos(0/2), sin(0/2), d, d', d'') = (1, 0, q, 1, 0) of a prismatic pair,
    the law values in its own variable q = d (the chain kernels take the derivatives in each
    joint's variable and, for a prismatic joint, no turning: see derivations/chain_kinematics.py)."""
    derivs = [sp.diff(PRISMATIC_LAW, d, k) for k in range(3)]
    return KernelSpec(
        name="law_prismatic",
        doc=(
            "The prismatic pair's law values at the slide d: cos(0/2), sin(0/2) (its angle is the "
            "constant phi of its DH row), d and its first two derivatives in d, as the chain kernels take them."
        ),
        source=SOURCE,
        inputs=[Arg("d", (1,), "joint slide [m]", (d,))],
        outputs=[
            Arg(
                "law",
                (5,),
                "(cos(0/2), sin(0/2), d [m], dd/dd = 1, 0)",
                exprs=(sp.cos(sp.S(0)), sp.sin(sp.S(0))) + tuple(derivs),
            )
        ],
        steps=[],
    )


def law_spec(kind: str, d_expr: sp.Expr, args) -> KernelSpec:
    """Kernel: (θ, pair constants) -> (cos(θ/2), sin(θ/2), d, d', d'') of one pair.

    d, d', d'' are differentiated symbolically in θ and then written in C = cos(θ/2), S = sin(θ/2)
    (θ = 2u, expand_trig), so the kernel makes one sincos-able pair of calls and the chain kernels
    none: they take cos θ = C² − S², sin θ = 2CS. For the general pair d² = a + b(C² − S²) is
    formed in that order, which `APair.theta_limit` repeats in Python to find the last double of
    the range.
    """
    inputs, steps, outs, (C, S) = _law_derivatives(kind, d_expr, args, (0, 1, 2))
    return KernelSpec(
        name=f"law_{kind}",
        doc=(
            f"The {kind} pair's law values at theta: cos(theta/2), sin(theta/2), d(theta) and its first two "
            "derivatives, as the chain kernels take them."
        ),
        source=SOURCE,
        inputs=inputs,
        outputs=[
            Arg(
                "law",
                (5,),
                "(cos(theta/2), sin(theta/2), d [m], d' [m/rad], d'' [m/rad^2])",
                exprs=(C, S) + tuple(outs),
            )
        ],
        steps=steps,
    )


def law_d3_specs() -> list[KernelSpec]:
    """Kernels (θ, pair constants) -> d'''(θ), the law's third derivative, of every kind.

    Only the derivative kernels of the chain dynamics take it (∂τ/∂θ of the term d'' θ'² e_z). It
    is a kernel of its own, from the same expressions in the same half-angle form, so that the law
    kernels, and every chain kernel's law input, keep their width.
    """
    out = []
    for kind, (d_expr, args) in LAWS.items():
        inputs, steps, outs, _ = _law_derivatives(kind, d_expr, args, (3,))
        out.append(
            KernelSpec(
                name=f"law_{kind}_d3",
                doc=f"The {kind} pair's d'''(theta), the third derivative of its law, as the derivative "
                "kernels of the chain dynamics take it.",
                source=SOURCE,
                inputs=inputs,
                outputs=[Arg("dddd", (1,), "d''' [m/rad^3]", exprs=tuple(outs))],
                steps=steps,
            )
        )
    out.append(
        KernelSpec(
            name="law_prismatic_d3",
            doc="The prismatic pair's d''' in its slide d (zero: d(d) = d), as the derivative kernels of the "
            "chain dynamics take it.",
            source=SOURCE,
            inputs=[Arg("d", (1,), "joint slide [m]", (d,))],
            outputs=[Arg("dddd", (1,), "d''' (0)", exprs=(sp.diff(PRISMATIC_LAW, d, 3),))],
            steps=[],
        )
    )
    return out


def _law_derivatives(kind: str, d_expr: sp.Expr, args, orders: tuple[int, ...]):
    """(inputs, steps, the derivatives of d_expr(θ) of the given orders in C = cos(θ/2),
    S = sin(θ/2), (C, S)) of one kind's law kernel (see law_spec)."""
    names = {theta: "theta", h: "h", a: "a", b: "b", pitch: "pitch"}
    inputs = [
        Arg(names[s], (1,), doc, (s,))
        for s, doc in zip(
            args,
            {
                "revolute": ["joint angle [rad]"],
                "helical": ["joint angle [rad]", "pitch [m/rad]: d = pitch theta"],
                "sinusoidal": ["joint angle [rad]", "amplitude h = sqrt(2 r_b r_p) [m]"],
                "general": [
                    "joint angle [rad], a + b cos(theta) >= 0",
                    "pair constant a [m^2]",
                    "pair constant b = r_b r_p [m^2]",
                ],
            }[kind],
        )
    ]
    u = sp.Symbol("u", real=True)
    C, S = sp.Symbol("C_half", real=True), sp.Symbol("S_half", real=True)

    def in_half(e, *extra):
        """e(θ) in C, S: θ = 2u, the double-angle formulas, then cos u → C, sin u → S."""
        e = sp.expand_trig(e.subs(theta, 2 * u)).subs({sp.cos(u): C, sp.sin(u): S})
        assert e.free_symbols <= {C, S, h, a, b, *extra}, e
        return sp.factor(e)

    derivs = [sp.simplify(sp.diff(d_expr, theta, k) if k else d_expr) for k in orders]
    steps = [(C, sp.cos(theta / 2)), (S, sp.sin(theta / 2))]
    if kind == "general":
        # d = √(a + b cos θ) as one step, the radicand formed as a + b(C² − S²), shared by d', d''
        cos_t, gap, dsym = (sp.Symbol(nm, real=True) for nm in ("cos_theta", "gap", "d_general"))
        steps += [(cos_t, C**2 - S**2), (gap, a + b * cos_t), (dsym, sp.sqrt(gap))]
        outs = [in_half(e.subs(sp.sqrt(a + b * sp.cos(theta)), dsym), dsym) for e in derivs]
        # the same values on the angle route, at a rational point
        vals = {theta: sp.Rational(7, 10), a: sp.Rational(3, 10), b: sp.Rational(11, 10)}
        env = {C: sp.cos(vals[theta] / 2), S: sp.sin(vals[theta] / 2)}
        env[dsym] = sp.sqrt(vals[a] + vals[b] * (env[C] ** 2 - env[S] ** 2))
        for e, ref in zip(outs, derivs):
            assert abs(sp.N(e.subs(env).subs(vals) - ref.subs(vals), 30)) < 1e-25
    elif kind == "revolute":
        outs = [sp.S(0) for _ in orders]
    elif kind == "helical":  # d = pitch·θ is linear in θ itself, not a function of its half angles
        outs = derivs
        assert outs == [[pitch * theta, pitch, sp.S(0), sp.S(0)][k] for k in orders], outs
    else:
        outs = [in_half(e) for e in derivs]
    return inputs, steps, outs, (C, S)


def design_specs(a_expr, b_expr, L2_sq, sinus_L1, h_expr) -> list[KernelSpec]:
    """Kernels: a pair's derived constants from its radii (and L1 for a general pair)."""
    radii = Arg("radii", (2,), "(r_b, r_p) circumradii of base and platform triangles [m]", (r_b, r_p))
    sin_sub = {L1: sinus_L1}
    return [
        KernelSpec(
            name="design_sinusoidal",
            doc="Constants of the sinusoidal pair (a = b) with the given radii.",
            source=SOURCE,
            inputs=[radii],
            outputs=[
                Arg(
                    "design",
                    (5,),
                    "(L1 [m], L2 [m], a [m^2], b [m^2], h [m])",
                    exprs=(sinus_L1, sp.sqrt(sp.factor(L2_sq.subs(sin_sub))), a_expr.subs(sin_sub), b_expr, h_expr),
                )
            ],
        ),
        KernelSpec(
            name="design_general",
            doc="Constants of the general pair with leg length L1; L2^2 <= 0 or a + b <= 0 admit no pose.",
            source=SOURCE,
            inputs=[radii, Arg("leg_length", (1,), "L1, the base-vertex legs' length [m]", (L1,))],
            outputs=[
                Arg(
                    "design",
                    (4,),
                    "(L2^2 [m^2], a [m^2], b [m^2], a + b [m^2])",
                    exprs=(L2_sq, a_expr, b_expr, a_expr + b_expr),
                )
            ],
        ),
    ]


def legs_spec() -> KernelSpec:
    """Kernel: leg end points in the pair's base frame, for a given θ and translation d."""
    pts = []
    P = pair_study_point(theta, d)
    for base_point, platform_point, _ in legs():
        xq, yq = P.x, P.y
        moved = transform_point_homogeneous(xq, yq, platform_point)  # |x|² = 1 here
        moved = [sp.simplify(m) for m in moved]
        pts.extend(list(base_point) + moved)
    return KernelSpec(
        name="pair_legs",
        doc="End points of the six legs, base frame: [leg][base point, platform point][xyz].",
        source=SOURCE,
        inputs=[
            Arg("theta", (1,), "joint angle [rad]", (theta,)),
            Arg("d", (1,), "translation d(theta) along the axis [m]", (d,)),
            Arg("radii", (2,), "(r_b, r_p) circumradii of base and platform triangles [m]", (r_b, r_p)),
        ],
        outputs=[Arg("points", (6, 2, 3), "leg end points [m]", exprs=tuple(pts))],
    )


def mobility_certificate(samples: int = 8, digits: int = 40) -> list[tuple[float, float]]:
    """Singular values of the 6x6 leg-line matrix at random poses of random pairs.

    Each leg is the line through its end points (Plücker coordinates: direction, moment); the
    platform's instantaneous mobility is 6 − rank. Returns (σ5/σ1, σ6/σ1) per sample and asserts
    rank 5: σ6 at the working precision, σ5 well away from it.
    """
    import random

    rng = random.Random(20261123)
    out = []
    spec = legs_spec()
    pts_exprs = spec.outputs[0].exprs
    fn = sp.lambdify((theta, d, r_b, r_p), pts_exprs, modules="mpmath")
    with mpmath.workdps(digits):
        for i in range(samples):
            rb, rp = mpmath.mpf(rng.uniform(0.5, 2.0)), mpmath.mpf(rng.uniform(0.5, 2.0))
            bb = rb * rp
            if i % 2 == 0:
                aa = bb  # sinusoidal
            else:
                aa = bb * mpmath.mpf(rng.uniform(-0.8, 2.0))  # general
            lim = mpmath.pi if aa >= bb else mpmath.acos(-aa / bb)
            th = mpmath.mpf(rng.uniform(-0.9, 0.9)) * lim
            dv = mpmath.sqrt(aa + bb * mpmath.cos(th))
            p = fn(th, dv, rb, rp)
            rows = []
            for k in range(6):
                bp = [p[6 * k + j] for j in range(3)]
                pp = [p[6 * k + 3 + j] for j in range(3)]
                u_ = [pp[j] - bp[j] for j in range(3)]
                m_ = [bp[1] * u_[2] - bp[2] * u_[1], bp[2] * u_[0] - bp[0] * u_[2], bp[0] * u_[1] - bp[1] * u_[0]]
                rows.append(u_ + m_)
            s = mpmath.svd_r(mpmath.matrix(rows), compute_uv=False)
            s = sorted([abs(v) for v in s], reverse=True)
            r5, r6 = s[4] / s[0], s[5] / s[0]
            assert r6 < mpmath.mpf(10) ** (-(digits - 8)), f"sample {i}: sixth singular value {r6}"
            assert r5 > mpmath.mpf(10) ** -6, f"sample {i}: fifth singular value {r5}"
            out.append((float(r5), float(r6)))
    return out
