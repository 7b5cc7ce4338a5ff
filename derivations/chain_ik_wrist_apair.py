"""The position problem of spherical-wrist arms with axes 2 and 3 parallel and an A-pair at joint 3,
or at joint 1 (issue 42, part 3: PUMA-, KUKA-, ABB-, Fanuc-, Stäubli-like arms with a sliding elbow
or base).

Where axes 4, 5 and 6 meet in W (a_4 = a_5 = c_5 = 0), W is known from the pose, W = O_6 − c_6 z_5 −
a_6 x_6 (derivations/chain_ik_wrist.py), and lies at (0, 0, c_4) in frame 3. Where axes 2 and 3 are
parallel (sin α_2 = 0), frame 1 sees W − O_1 = Rz(ψ_2) p(ψ_3) (ψ_i = θ_i + φ_i), p = Tz(c_2) Tx(a_2)
Rx(α_2) A_3(ψ_3) (0, 0, c_4), whose third component and the length of whose first two are derived
below from the product:

    z_1·(W − O_1) = c_2 + cos α_2 c_3 + cos α_2 cos α_3 c_4          (no ψ_2, ψ_3),
    |W − O_1|² − (z_1·(W − O_1))² = E_0 + E_c cos ψ_3 + E_s sin ψ_3,
    E_0 = a_2² + a_3² + sin² α_3 c_4²,  E_c = 2 a_2 a_3,  E_s = 2 a_2 sin α_3 c_4.

An A-pair at joint 3 slides by d_3(θ_3) along axis 3 (c_3 → c_3 + d_3), so with z_1 = (sin α_1 sin ψ_1,
−sin α_1 cos ψ_1, cos α_1) and O_1 = (a_1 cos ψ_1, a_1 sin ψ_1, c_1) (z_1·O_1 = cos α_1 c_1),

    L(ψ_1) = z_1·W − cos α_1 c_1 − c_2 − cos α_2 c_3 − cos α_2 cos α_3 c_4 = cos α_2 d_3,

linear in (cos ψ_1, sin ψ_1): the slide ties ψ_1 to the elbow. The pair's law d_3² = κ_0 + κ_1 cos θ_3
(sinusoidal: κ_0 = κ_1 = h²/2; cos θ_3 = cos φ_3 cos ψ_3 where sin φ_3 = 0) gives the elbow's cosine,
and the plane of the parallel axes its sine, both of degree 2 in (cos ψ_1, sin ψ_1):

    C̃ = κ_1 cos ψ_3 = cos φ_3 (L² − κ_0),   S̃ = κ_1 E_s sin ψ_3 = κ_1 (ρ² − E_0) − E_c C̃,

with ρ² = |W − O_1|² − (z_1·(W − O_1))². So E_s² C̃² + S̃² = E_s² κ_1², of degree 4 in (cos ψ_1,
sin ψ_1): a polynomial of degree 8 in t = tan(ψ_1/2) (times (1 + t²)⁴). Each real root gives ψ_1,
then ψ_3 = atan2(S̃/E_s, C̃) with no square root, ψ_2 from W − O_1 in frame 1, and the wrist's three
angles as on the R-arm (two ψ_5): at most 8 × 2 = 16 solutions, and θ_3's representative in
(−2π, 2π] is the one whose slide has the sign of cos α_2 L. `ik_wrist_apair_position6` gives W,
L in (1, cos ψ_1, sin ψ_1), E_s, C̃ and S̃ in t and the polynomial (lowest degree first);
apair.ik.wrist_apair solves it. Where E_s = 0 (sin α_3 c_4 = 0: the forearm along the elbow's
axis direction) the elbow's sine is not read this way, and the general solvers answer.

An A-pair at joint 1 slides O_1 along axis 1 by d_1(θ_1); where axis 1 is at right angles to axis 2
(cos α_1 = 0, every such arm) L does not see it: with joint 3 an R-pair, L(ψ_1) = 0 is a quadratic
in t whose roots give ψ_1 first (`ik_wrist_slide1_position6`: W, L and the quadratic). Each ψ_1 has
two representatives θ_1 in (−2π, 2π] with slides of opposite signs; for each, O_1 is known, ρ² =
E_0 + E_c cos ψ_3 + E_s sin ψ_3 gives two elbows, then ψ_2 and the wrist as above: at most
2 × 2 × 2 × 2 = 16 solutions (apair.ik.wrist_slide1).

`check` evaluates the kernel in 40-digit arithmetic at poses of random such designs (α_2 ∈ {0, π},
φ_3 ∈ {0, π}; a_1 = 0 and α_1 = ±π/2 among them) built by the independent DH product with the pair's
slide (mpmath): W must be frame 4's origin, L − cos α_2 d_3, C̃ − κ_1 cos ψ_3, S̃ − κ_1 E_s sin ψ_3 and
the polynomial at t = tan(ψ_1/2) must vanish.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .chain_ik import _mp_dh, evaluate_real
from .chain_ik_parallel import _dh
from .chain_ik_parallel_apair import _product, in_t
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik_wrist_apair.py"


def elbow_plane() -> tuple[sp.Expr, sp.Expr, sp.Expr, sp.Expr, dict]:
    """From p = A_2(ψ_2) A_3(ψ_3) (0, 0, c_4) at sin α_2 = 0: its third component (checked free of
    ψ_2, ψ_3) and E_0, E_c, E_s of |p_xy|² = E_0 + E_c cos ψ_3 + E_s sin ψ_3 (checked free of ψ_2),
    with the symbols used."""
    psi2, psi3 = sp.symbols("psi2 psi3", real=True)
    a2, a3, c2, c3, c4, ca2, ca3, sa3 = sp.symbols("a_2 a_3 c_2 c_3 c_4 ca2 ca3 sa3", real=True)
    p = _dh(psi2, a2, ca2, 0, c2) * _dh(psi3, a3, ca3, sa3, c3) * sp.Matrix([0, 0, c4, 1])
    unit = {ca2**2: 1, sa3**2: 1 - ca3**2}
    z = sp.expand(p[2]).subs(unit)
    assert not z.free_symbols & {psi2, psi3}, "the wrist point's height along the parallel axes moves with ψ_2, ψ_3"
    rho2 = sp.expand(sp.expand(p[0] ** 2 + p[1] ** 2).subs(unit))
    rho2 = sp.expand(sp.trigsimp(rho2))
    assert not rho2.free_symbols & {psi2}, "the wrist point's distance from axis 2 moves with ψ_2"
    Ec, Es = rho2.coeff(sp.cos(psi3)), rho2.coeff(sp.sin(psi3))
    E0 = sp.expand(rho2 - Ec * sp.cos(psi3) - Es * sp.sin(psi3))
    assert not (E0.free_symbols | Ec.free_symbols | Es.free_symbols) & {psi3}, "|p_xy|² is not E_0 + E_c cos + E_s sin"
    names = {"a2": a2, "a3": a3, "c2": c2, "c3": c3, "c4": c4, "ca2": ca2, "ca3": ca3, "sa3": sa3}
    return z, sp.factor_terms(E0), sp.factor_terms(Ec), sp.factor_terms(Es), names


def spec() -> KernelSpec:
    """ik_wrist_apair_position6(dh (6, 4), T (4, 4), law (2)) -> W (3), L (3), Es (1), cs (2, 5),
    poly (9)."""
    dh = [sp.Symbol(f"{k}_{i}", real=True) for i in range(1, 7) for k in ("a", "alpha", "c", "phi")]
    J = {i: dict(zip(("a", "alpha", "c", "phi"), dh[4 * (i - 1) : 4 * i])) for i in range(1, 7)}
    Tm = sp.symbols("T0:16", real=True)
    law = sp.symbols("kappa0 kappa1", real=True)
    t, c1, s1 = sp.symbols("t cpsi1 spsi1", real=True)
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(1, 7)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(1, 7)}
    steps = []
    for i in (1, 2, 3, 6):
        steps += [(ca[i], sp.cos(J[i]["alpha"])), (sa[i], sp.sin(J[i]["alpha"]))]
    cphi3 = sp.Symbol("cphi3", real=True)
    steps.append((cphi3, sp.cos(J[3]["phi"])))
    z, E0, Ec, Es, s = elbow_plane()
    own = {s["a2"]: J[2]["a"], s["a3"]: J[3]["a"], s["c2"]: J[2]["c"], s["c3"]: J[3]["c"], s["c4"]: J[4]["c"]}
    own |= {s["ca2"]: ca[2], s["ca3"]: ca[3], s["sa3"]: sa[3]}
    z, E0, Ec, Es = (sp.expand(e.xreplace(own)) for e in (z, E0, Ec, Es))
    d3 = sp.Symbol("d3", real=True)
    assert sp.expand(z.xreplace({J[3]["c"]: J[3]["c"] + d3}) - z) == ca[2] * d3, "the slide enters as cos α_2 d_3"
    # the pose: the wrist point W (frame 4's origin) from frame 6
    R6 = sp.Matrix(3, 3, lambda r, k: Tm[4 * r + k])
    O6 = sp.Matrix([Tm[3], Tm[7], Tm[11]])
    Wn = sp.symbols("W0:3", real=True)
    steps += list(zip(Wn, O6 - J[6]["c"] * R6 * sp.Matrix([0, sa[6], ca[6]]) - J[6]["a"] * R6[:, 0]))
    W = sp.Matrix(Wn)
    z1 = sp.Matrix([sa[1] * s1, -sa[1] * c1, ca[1]])
    O1 = sp.Matrix([J[1]["a"] * c1, J[1]["a"] * s1, J[1]["c"]])
    u = W - O1
    zu = sp.expand(z1.dot(u))
    assert sp.Poly(zu, c1, s1).total_degree() <= 1, "z_1·(W − O_1) is not linear in (cos ψ_1, sin ψ_1)"
    L = zu - z
    lin = lambda e: [sp.expand(e).subs({c1: 0, s1: 0}), sp.expand(e).coeff(c1), sp.expand(e).coeff(s1)]
    Ln = sp.symbols("l0:3", real=True)
    steps += list(zip(Ln, lin(L)))
    Lc = Ln[0] + Ln[1] * c1 + Ln[2] * s1
    assert sp.expand(Lc.xreplace(dict(steps[-3:])) - L) == 0, "L is not linear in (cos ψ_1, sin ψ_1)"
    Esn = sp.Symbol("Es", real=True)
    steps.append((Esn, Es))
    # ρ² = |u|² − (z_1·u)², of degree 2 (|z_1| = 1 is used: (z_1·u)² is not reduced by c1² + s1² = 1)
    rho2 = u.dot(u) - zu**2
    C = cphi3 * (Lc**2 - law[0])  # κ_1 cos ψ_3 (cos² α_2 = 1: d_3² = L²)
    S = law[1] * (rho2 - E0) - Ec * C  # κ_1 E_s sin ψ_3
    cn, sn = sp.symbols("cc0:5", real=True), sp.symbols("ss0:5", real=True)
    steps += list(zip(cn, in_t(C, c1, s1, t, 2))) + list(zip(sn, in_t(S, c1, s1, t, 2)))
    w = [1, 0, 1]
    w2 = _product(w, w)
    lhs = [sp.expand(Esn**2 * x + y) for x, y in zip(_product(list(cn), list(cn)), _product(list(sn), list(sn)))]
    poly = [sp.expand(p - Esn**2 * law[1] ** 2 * q) for p, q in zip(lhs, _product(w2, w2))]
    assert len(poly) == 9
    return KernelSpec(
        name="ik_wrist_apair_position6",
        doc=(
            "The position problem of a 6-joint chain with a spherical wrist, axes 2 and 3 parallel and an A-pair "
            "at joint 3 (d3^2 = kappa0 + kappa1 cos(theta3)): the wrist point W, L = cos(alpha2) d3 linear in "
            "(1, cos(psi1), sin(psi1)), Es, and in t = tan((theta1 + phi1)/2), lowest degree first, "
            "(1 + t^2)^2 kappa1 cos(psi3), (1 + t^2)^2 kappa1 Es sin(psi3) and their circle, of degree 8."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("T", (4, 4), "frame 6's pose, row-major", tuple(Tm)),
            Arg("law", (2,), "kappa0, kappa1: joint 3's d^2 = kappa0 + kappa1 cos(theta)", tuple(law), design=True),
        ],
        steps=steps,
        outputs=[
            Arg("W", (3,), "the wrist point (frame 4's origin)", exprs=Wn),
            Arg("L", (3,), "L = cos(alpha2) d3: coefficients of (1, cos(psi1), sin(psi1))", exprs=Ln),
            Arg("Es", (1,), "2 a2 sin(alpha3) c4", exprs=(Esn,)),
            Arg(
                "cs", (2, 5), "(1 + t^2)^2 kappa1 cos(psi3) and (1 + t^2)^2 kappa1 Es sin(psi3) in t", exprs=(*cn, *sn)
            ),
            Arg("poly", (9,), "(1 + t^2)^4 (Es^2 C^2 + S^2 - Es^2 kappa1^2) in t", exprs=tuple(poly)),
        ],
    )


def check(kernel: KernelSpec, samples: int = 3, digits: int = 40) -> float:
    """Largest relative residual of W − O_4, L − cos α_2 d_3, C̃ − κ_1 cos ψ_3, S̃ − κ_1 E_s sin ψ_3 and
    of the polynomial at t = tan(ψ_1/2), at poses of random spherical-wrist designs with α_2 ∈ {0, π},
    φ_3 ∈ {0, π} and a sinusoidal A-pair at joint 3 (κ_0 = κ_1 = h²/2), a_1 = 0 and α_1 = ±π/2
    among them, built by the mpmath DH product."""
    rng = random.Random(11)
    worst = 0.0
    with mpmath.workdps(digits):
        for case in ("general", "a1=0", "alpha1=90") * samples:
            dh = [[mpmath.mpf(rng.uniform(0.1, 1)), mpmath.mpf(rng.uniform(-3, 3)), mpmath.mpf(rng.uniform(-1, 1)),
                   mpmath.mpf(rng.uniform(-3, 3))] for _ in range(6)]  # fmt: skip
            dh[1][1] = mpmath.pi * rng.randint(0, 1)  # 2∥3
            dh[3][0] = dh[4][0] = dh[4][2] = mpmath.mpf(0)  # 4, 5, 6 meet
            dh[2][3] = mpmath.pi * rng.randint(0, 1)
            if case == "a1=0":
                dh[0][0] = mpmath.mpf(0)
            if case == "alpha1=90":
                dh[0][1] = mpmath.pi / 2 * rng.choice((-1, 1))
            h = mpmath.mpf(rng.uniform(0.05, 0.5))
            theta = [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(6)]
            theta[2] = mpmath.mpf(rng.uniform(-6, 6))
            slide = [0, 0, h * mpmath.cos(theta[2] / 2), 0, 0, 0]
            T, O4 = mpmath.eye(4), None
            for i in range(6):
                T = T * _mp_dh(theta[i], slide[i], dh[i][0], dh[i][1], dh[i][2], dh[i][3])
                if i == 3:
                    O4 = [T[r, 3] for r in range(3)]
            law = [h**2 / 2, h**2 / 2]
            out = evaluate_real(kernel, dh, T, law, digits=digits)
            W, L, Es, C, S, poly = out[:3], out[3:6], out[6], out[7:12], out[12:17], out[17:26]
            size = 1 + sum(abs(x) for row in dh for x in (row[0], row[2])) + h
            worst = max(worst, float(max(abs(a - b) for a, b in zip(W, O4)) / size))
            psi1, psi3 = theta[0] + dh[0][3], theta[2] + dh[2][3]
            c1, s1 = mpmath.cos(psi1), mpmath.sin(psi1)
            worst = max(worst, float(abs(L[0] + L[1] * c1 + L[2] * s1 - mpmath.cos(dh[1][1]) * slide[2]) / size))
            t = mpmath.tan(psi1 / 2)
            value = lambda cs: sum(c * t**k for k, c in enumerate(cs))
            scale = lambda cs: sum(abs(c) * abs(t) ** k for k, c in enumerate(cs)) + size**4
            w2 = (1 + t * t) ** 2
            worst = max(worst, float(abs(value(C) - law[1] * mpmath.cos(psi3) * w2) / scale(C)))
            worst = max(worst, float(abs(value(S) - law[1] * Es * mpmath.sin(psi3) * w2) / scale(S)))
            worst = max(worst, float(abs(value(poly)) / scale(poly)))
    assert worst < 1e-30, f"ik_wrist_apair_position6: an equation fails at a pose by {worst}"
    return worst


def spec_slide1() -> KernelSpec:
    """ik_wrist_slide1_position6(dh (6, 4), T (4, 4)) -> W (3), L (3), quadratic (3): the first step of
    a spherical-wrist arm with axes 2 and 3 parallel whose joint 1 slides (cos α_1 = 0)."""
    dh = [sp.Symbol(f"{k}_{i}", real=True) for i in range(1, 7) for k in ("a", "alpha", "c", "phi")]
    J = {i: dict(zip(("a", "alpha", "c", "phi"), dh[4 * (i - 1) : 4 * i])) for i in range(1, 7)}
    Tm = sp.symbols("T0:16", real=True)
    t, c1, s1 = sp.symbols("t cpsi1 spsi1", real=True)
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(1, 7)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(1, 7)}
    steps = []
    for i in (1, 2, 3, 6):
        steps += [(ca[i], sp.cos(J[i]["alpha"])), (sa[i], sp.sin(J[i]["alpha"]))]
    z, _, _, _, s = elbow_plane()
    own = {s["a2"]: J[2]["a"], s["a3"]: J[3]["a"], s["c2"]: J[2]["c"], s["c3"]: J[3]["c"], s["c4"]: J[4]["c"]}
    z = sp.expand(z.xreplace(own | {s["ca2"]: ca[2], s["ca3"]: ca[3], s["sa3"]: sa[3]}))
    R6 = sp.Matrix(3, 3, lambda r, k: Tm[4 * r + k])
    O6 = sp.Matrix([Tm[3], Tm[7], Tm[11]])
    Wn = sp.symbols("W0:3", real=True)
    steps += list(zip(Wn, O6 - J[6]["c"] * R6 * sp.Matrix([0, sa[6], ca[6]]) - J[6]["a"] * R6[:, 0]))
    z1 = sp.Matrix([sa[1] * s1, -sa[1] * c1, ca[1]])
    d1 = sp.Symbol("d1", real=True)
    O1 = sp.Matrix([J[1]["a"] * c1, J[1]["a"] * s1, J[1]["c"] + d1])
    L = sp.expand(z1.dot(sp.Matrix(Wn) - O1) - z)
    assert L.coeff(d1) == -ca[1], "joint 1's slide enters L other than as cos α_1 d_1"
    L = L.subs(d1, 0)  # where cos α_1 = 0 it does not enter
    lin = [L.subs({c1: 0, s1: 0}), L.coeff(c1), L.coeff(s1)]
    assert sp.expand(lin[0] + lin[1] * c1 + lin[2] * s1 - L) == 0, "L is not linear in (cos ψ_1, sin ψ_1)"
    Ln = sp.symbols("l0:3", real=True)
    steps += list(zip(Ln, lin))
    quad = in_t(Ln[0] + Ln[1] * c1 + Ln[2] * s1, c1, s1, t, 1)
    return KernelSpec(
        name="ik_wrist_slide1_position6",
        doc=(
            "The first step of a 6-joint chain with a spherical wrist, axes 2 and 3 parallel and an A-pair at "
            "joint 1 (cos(alpha1) = 0): the wrist point W, L (its height along axes 2 and 3 less the design's) "
            "linear in (1, cos(psi1), sin(psi1)) and (1 + t^2) L in t = tan((theta1 + phi1)/2), lowest degree first."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("T", (4, 4), "frame 6's pose, row-major", tuple(Tm)),
        ],
        steps=steps,
        outputs=[
            Arg("W", (3,), "the wrist point (frame 4's origin)", exprs=Wn),
            Arg("L", (3,), "L: coefficients of (1, cos(psi1), sin(psi1))", exprs=Ln),
            Arg("quadratic", (3,), "(1 + t^2) L in t", exprs=tuple(quad)),
        ],
    )


def check_slide1(kernel: KernelSpec, samples: int = 4, digits: int = 40) -> float:
    """Largest relative residual of W − O_4, L and the quadratic at t = tan(ψ_1/2), at poses of random
    spherical-wrist designs with α_2 ∈ {0, π} and cos α_1 = 0 built by the mpmath DH product with a
    slide d_1 at joint 1 (the kernel gets the design without it)."""
    rng = random.Random(13)
    worst = 0.0
    with mpmath.workdps(digits):
        for _ in range(samples):
            dh = [[mpmath.mpf(rng.uniform(0.1, 1)), mpmath.mpf(rng.uniform(-3, 3)), mpmath.mpf(rng.uniform(-1, 1)),
                   mpmath.mpf(rng.uniform(-3, 3))] for _ in range(6)]  # fmt: skip
            dh[0][1] = mpmath.pi / 2 * rng.choice((-1, 1))
            dh[1][1] = mpmath.pi * rng.randint(0, 1)  # 2∥3
            dh[3][0] = dh[4][0] = dh[4][2] = mpmath.mpf(0)  # 4, 5, 6 meet
            theta = [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(6)]
            slide = [mpmath.mpf(rng.uniform(-0.5, 0.5)), 0, 0, 0, 0, 0]
            T, O4 = mpmath.eye(4), None
            for i in range(6):
                T = T * _mp_dh(theta[i], slide[i], dh[i][0], dh[i][1], dh[i][2], dh[i][3])
                if i == 3:
                    O4 = [T[r, 3] for r in range(3)]
            out = evaluate_real(kernel, dh, T, digits=digits)
            W, L, quad = out[:3], out[3:6], out[6:9]
            size = 1 + sum(abs(x) for row in dh for x in (row[0], row[2]))
            worst = max(worst, float(max(abs(a - b) for a, b in zip(W, O4)) / size))
            psi1 = theta[0] + dh[0][3]
            worst = max(worst, float(abs(L[0] + L[1] * mpmath.cos(psi1) + L[2] * mpmath.sin(psi1)) / size))
            t = mpmath.tan(psi1 / 2)
            value = sum(c * t**k for k, c in enumerate(quad))
            worst = max(worst, float(abs(value) / (sum(abs(c) * abs(t) ** k for k, c in enumerate(quad)) + size)))
    assert worst < 1e-30, f"ik_wrist_slide1_position6: an equation fails at a pose by {worst}"
    return worst


def derive():
    """The spherical-wrist A-pair position kernels (joint 3, joint 1), after the independent checks."""
    kernel, slide1 = spec(), spec_slide1()
    return [], [kernel, slide1], {"wrist_apair_check": check(kernel), "wrist_slide1_check": check_slide1(slide1)}
