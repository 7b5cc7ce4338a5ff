"""The first step of six-joint R-chains with three parallel inner axes (2∥3∥4, UR arms; issue 42).

Where axes 2, 3 and 4 are parallel (sin α_2 = sin α_3 = 0, apair.ik.families' three-inner-parallel),
N = A_2 A_3 A_4 A_5 (A_i = Rz(ψ_i)·Tz(c_i)·Tx(a_i)·Rx(α_i), ψ_i = θ_i + φ_i, docs/conventions.md §3)
turns its third row by ψ_2 + ψ_3 + ψ_4 about the common axis and so keeps it: with ε = cos α_2 cos α_3,

    N_33 = ε (cos α_4 cos α_5 − sin α_4 sin α_5 cos ψ_5),
    N_34 = c_2 + cos α_2 c_3 + ε (c_4 + cos α_4 c_5 + sin α_4 a_5 sin ψ_5),

functions of ψ_5 alone. Frame 1 sees them as z_1·z_5 and z_1·(O_5 − O_1), with z_1 = Rz(ψ_1) Rx(α_1) e_z =
(sin α_1 sin ψ_1, −sin α_1 cos ψ_1, cos α_1), z_1·O_1 = cos α_1 c_1, and from the pose
z_5 = R_6 (0, sin α_6, cos α_6), O_5 = O_6 − c_6 z_5 − a_6 x_6. So two equations, each linear in
(cos ψ_1, sin ψ_1) and in (cos ψ_5, sin ψ_5) with no product of the two (IK-Geo's subproblem 6):

    L_1(ψ_1) = z_1·z_5 − ε cos α_4 cos α_5                          = P cos ψ_5,   P = −ε sin α_4 sin α_5,
    L_2(ψ_1) = z_1·(O_5 − O_1) − c_2 − cos α_2 c_3 − ε (c_4 + cos α_4 c_5) = Q sin ψ_5,   Q = ε sin α_4 a_5.

Eliminating ψ_5, Q² L_1² + P² L_2² = P² Q², times (1 + t²)² a quartic in t = tan(ψ_1/2). Where a_5 = 0
(Q = 0, the UR arms) L_2 = 0 alone is a quadratic in t and cos ψ_5 = L_1/P gives two ψ_5; where axes 5
and 6 are parallel (P = 0) L_1 = 0 is, and sin ψ_5 = L_2/Q gives two. `ik_parallel_position6` gives
the coefficients of L_1 and L_2 in (1, cos ψ_1, sin ψ_1), P, Q and the three polynomials in t (lowest
degree first); apair.ik.parallel solves them and reads ψ_6, ψ_3, ψ_2 and ψ_4 in closed form.

`check` evaluates the kernel in 40-digit arithmetic at poses of random designs with α_2, α_3 in
{0, π} (general, a_5 = 0, α_5 = 0) built by the independent DH product (mpmath): L_1 and L_2 at the
pose's ψ_1 must be P cos ψ_5 and Q sin ψ_5, and the polynomials must vanish at tan(ψ_1/2).
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .chain_ik import _mp_dh, evaluate_real
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik_parallel.py"


def _dh(psi, a, ca, sa, c):
    """A_i = Rz(ψ)·Tz(c)·Tx(a)·Rx(α) with cos α, sin α as given (4 x 4)."""
    cp, sp_ = sp.cos(psi), sp.sin(psi)
    return sp.Matrix(
        [[cp, -sp_ * ca, sp_ * sa, a * cp], [sp_, cp * ca, -cp * sa, a * sp_], [0, sa, ca, c], [0, 0, 0, 1]]
    )


def third_row() -> tuple[sp.Expr, sp.Expr, dict]:
    """N_33 and N_34 of N = A_2 A_3 A_4 A_5 at sin α_2 = sin α_3 = 0, as functions of ψ_5: derived
    from the product (ψ_2, ψ_3, ψ_4 must drop out), with the symbols used."""
    psi = {i: sp.Symbol(f"psi{i}", real=True) for i in range(2, 6)}
    a = {i: sp.Symbol(f"a_{i}", real=True) for i in range(2, 6)}
    c = {i: sp.Symbol(f"c_{i}", real=True) for i in range(2, 6)}
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(2, 6)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(2, 6)}
    N = sp.eye(4)
    for i in range(2, 6):
        N = N * _dh(psi[i], a[i], ca[i], 0 if i in (2, 3) else sa[i], c[i])
    unit = {ca[2] ** 2: 1, ca[3] ** 2: 1}
    n33, n34 = (sp.expand(sp.expand(N[2, k]).subs(unit)) for k in (2, 3))
    for e in (n33, n34):
        assert not (e.free_symbols & {psi[2], psi[3], psi[4]}), "the third row of A_2 A_3 A_4 A_5 moves with ψ_2..ψ_4"
    return n33, n34, {"psi5": psi[5], "a": a, "c": c, "ca": ca, "sa": sa}


def spec() -> KernelSpec:
    """ik_parallel_position6(dh (6, 4), T (4, 4)) -> L (2, 3), PQ (2), quartic (5), qa (3), qb (3)."""
    dh = [sp.Symbol(f"{k}_{i}", real=True) for i in range(1, 7) for k in ("a", "alpha", "c", "phi")]
    J = {i: dict(zip(("a", "alpha", "c", "phi"), dh[4 * (i - 1) : 4 * i])) for i in range(1, 7)}
    Tm = sp.symbols("T0:16", real=True)
    t = sp.Symbol("t", real=True)
    n33, n34, s = third_row()
    psi5 = s["psi5"]
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(1, 7)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(1, 7)}
    steps = []
    for i in (1, 2, 3, 4, 5, 6):
        steps += [(ca[i], sp.cos(J[i]["alpha"])), (sa[i], sp.sin(J[i]["alpha"]))]
    # the third row in the kernel's symbols: split into its constant and its cos ψ_5, sin ψ_5 parts
    own = {s["a"][i]: J[i]["a"] for i in range(2, 6)} | {s["c"][i]: J[i]["c"] for i in range(2, 6)}
    own |= {s["ca"][i]: ca[i] for i in range(2, 6)} | {s["sa"][i]: sa[i] for i in range(2, 6)}
    n33, n34 = n33.xreplace(own), n34.xreplace(own)
    P = sp.factor_terms(n33.coeff(sp.cos(psi5)))
    Q = sp.factor_terms(n34.coeff(sp.sin(psi5)))
    k33 = sp.expand(n33 - P * sp.cos(psi5))
    k34 = sp.expand(n34 - Q * sp.sin(psi5))
    assert not (k33.free_symbols | k34.free_symbols) & {psi5}, "N_33, N_34 are not P cos ψ_5, Q sin ψ_5 plus constants"
    R6 = sp.Matrix(3, 3, lambda r, k: Tm[4 * r + k])
    O6 = sp.Matrix([Tm[3], Tm[7], Tm[11]])
    z5 = R6 * sp.Matrix([0, sa[6], ca[6]])
    O5 = O6 - J[6]["c"] * z5 - J[6]["a"] * R6[:, 0]
    Zn, On = sp.symbols("Z0:3", real=True), sp.symbols("O0:3", real=True)
    steps += list(zip(Zn, z5)) + list(zip(On, O5))
    # z_1·v = sin α_1 (sin ψ_1 v_x − cos ψ_1 v_y) + cos α_1 v_z: (1, cos ψ_1, sin ψ_1) coefficients
    lin = lambda v, const: (sp.expand(ca[1] * v[2] - const), sp.expand(-sa[1] * v[1]), sp.expand(sa[1] * v[0]))
    Ln = sp.symbols("l0:6", real=True)
    steps += list(zip(Ln, (*lin(Zn, k33), *lin(On, ca[1] * J[1]["c"] + k34))))
    L1, L2 = Ln[:3], Ln[3:]
    w, c1, s1 = 1 + t**2, 1 - t**2, 2 * t  # (1 + t²)(1, cos ψ_1, sin ψ_1)
    Lt1 = sp.expand(L1[0] * w + L1[1] * c1 + L1[2] * s1)
    Lt2 = sp.expand(L2[0] * w + L2[1] * c1 + L2[2] * s1)
    Ps, Qs = sp.symbols("P Q", real=True)
    steps += [(Ps, P), (Qs, Q)]
    E = sp.expand(Qs**2 * Lt1**2 + Ps**2 * Lt2**2 - Ps**2 * Qs**2 * w**2)
    coeffs = lambda e, deg: [sp.factor_terms(sp.expand(e).coeff(t, k)) for k in range(deg + 1)]
    assert sp.degree(E, t) <= 4 and sp.degree(Lt1, t) <= 2 and sp.degree(Lt2, t) <= 2
    return KernelSpec(
        name="ik_parallel_position6",
        doc=(
            "The first step of a 6R chain with axes 2, 3, 4 parallel: L1 = P cos(psi5) and L2 = Q sin(psi5), "
            "L1, L2 linear in (1, cos(psi1), sin(psi1)); in t = tan((theta1 + phi1)/2), lowest degree first, "
            "their quartic and the quadratics L1 (for P = 0) and L2 (for Q = 0), times powers of 1 + t^2."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("T", (4, 4), "frame 6's pose, row-major", tuple(Tm)),
        ],
        steps=steps,
        outputs=[
            Arg("L", (2, 3), "L1, L2: coefficients of (1, cos(psi1), sin(psi1))", exprs=Ln),
            Arg("PQ", (2,), "P, Q: L1 = P cos(psi5), L2 = Q sin(psi5)", exprs=(Ps, Qs)),
            Arg("quartic", (5,), "(1 + t^2)^2 (Q^2 L1^2 + P^2 L2^2 - P^2 Q^2) in t", exprs=tuple(coeffs(E, 4))),
            Arg("qa", (3,), "(1 + t^2) L1 in t", exprs=tuple(coeffs(Lt1, 2))),
            Arg("qb", (3,), "(1 + t^2) L2 in t", exprs=tuple(coeffs(Lt2, 2))),
        ],
    )


def check(kernel: KernelSpec, samples: int = 3, digits: int = 40) -> float:
    """Largest relative residual of L_1 − P cos ψ_5, L_2 − Q sin ψ_5 and of the polynomials at
    t = tan(ψ_1/2), at poses of random designs with axes 2, 3, 4 parallel (α_2, α_3 ∈ {0, π};
    general, a_5 = 0, α_5 = 0) built by the mpmath DH product. The case "slides" (cos α_1 =
    cos α_4 = 0, a_5 = 0: the UR arms) builds the pose with slides d_1, d_5 added to c_1 and c_5 and
    feeds the kernel the design without them: A-pairs at joints 1 and 5 leave the first step as it
    is (apair.ik.parallel_slides)."""
    rng = random.Random(42)
    worst = 0.0
    with mpmath.workdps(digits):
        for case in ("general", "a5=0", "alpha5=0", "slides") * samples:
            dh = [[mpmath.mpf(rng.uniform(0.1, 1)), mpmath.mpf(rng.uniform(-3, 3)), mpmath.mpf(rng.uniform(-1, 1)),
                   mpmath.mpf(rng.uniform(-3, 3))] for _ in range(6)]  # fmt: skip
            dh[1][1], dh[2][1] = mpmath.pi * rng.randint(0, 1), mpmath.pi * rng.randint(0, 1)  # 2∥3∥4
            if case == "a5=0":
                dh[4][0] = mpmath.mpf(0)
            if case == "alpha5=0":
                dh[4][1] = mpmath.mpf(0)
            slide = [mpmath.mpf(0)] * 6
            if case == "slides":
                dh[0][1], dh[3][1] = mpmath.pi / 2 * rng.choice((-1, 1)), mpmath.pi / 2 * rng.choice((-1, 1))
                dh[4][0] = mpmath.mpf(0)
                slide[0], slide[4] = mpmath.mpf(rng.uniform(-1, 1)), mpmath.mpf(rng.uniform(-1, 1))
            psi = [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(6)]
            T = mpmath.eye(4)
            for i in range(6):
                T = T * _mp_dh(psi[i], 0, dh[i][0], dh[i][1], dh[i][2] + slide[i], 0)
            out = evaluate_real(kernel, dh, T, digits=digits)
            L, (P, Q), quartic, qa, qb = out[:6], out[6:8], out[8:13], out[13:16], out[16:19]
            size = 1 + sum(abs(x) for row in dh for x in (row[0], row[2]))
            c1, s1 = mpmath.cos(psi[0]), mpmath.sin(psi[0])
            worst = max(worst, float(abs(L[0] + L[1] * c1 + L[2] * s1 - P * mpmath.cos(psi[4]))))
            worst = max(worst, float(abs(L[3] + L[4] * c1 + L[5] * s1 - Q * mpmath.sin(psi[4])) / size))
            t = mpmath.tan(psi[0] / 2)
            value = lambda cs: sum(c * t**k for k, c in enumerate(cs))
            scale = lambda cs: sum(abs(c) * abs(t) ** k for k, c in enumerate(cs)) + 1
            polys = {"general": [quartic], "a5=0": [quartic, qb], "alpha5=0": [quartic, qa], "slides": [quartic, qb]}[
                case
            ]
            for cs in polys:
                worst = max(worst, float(abs(value(cs)) / scale(cs)))
    assert worst < 1e-30, f"ik_parallel_position6: an equation fails at a pose by {worst}"
    return worst


def derive():
    """The three-parallel position kernel, after the independent check."""
    kernel = spec()
    return [], [kernel], {"parallel_check": check(kernel)}
