"""The first step of UR-like six-joint chains with an A-pair at joint 3 (issue 42, part 3).

Where axes 2, 3 and 4 are parallel (sin α_2 = sin α_3 = 0) and the wrist is UR's (cos α_4 =
cos α_5 = 0, a_4 = a_5 = 0: axes 4 ⟂ 5 ⟂ 6, axes 5 and 6 meeting), the R-arm's first step
(derivations/chain_ik_parallel.py) reads ψ_1 from L_2(ψ_1) = 0 alone: the slides along the parallel
axes add up to a constant. An A-pair at joint 3 slides by d_3(θ_3) along its axis, so with
N = A_2 A_3 A_4 A_5 as there (c_3 → c_3 + d_3)

    L_1(ψ_1) = z_1·z_5 = P cos ψ_5,   P = −ε sin α_4 sin α_5 = ±1,   ε = cos α_2 cos α_3,
    L_2(ψ_1) = z_1·(O_5 − O_1) − c_2 − cos α_2 c_3 − ε c_4 = cos α_2 d_3,

and the slide ties ψ_1 to the elbow. The slide does not move frame 3's origin O_3 in the plane of
the parallel axes, where its distance ρ from axis 2 gives cos ψ_3 = (ρ² − a_2² − a_3²)/(2 a_2 a_3).
From frame 4, z_3 × z_5 = −sin α_4 sin α_5 sin ψ_5 z_4 (derived below), and O_3 = O_5 − c_5 z_4 − c_4 z_3,
so with v = O_5 − O_1 − c_4 z_3 (z_3 = ε z_1, z_4 ⟂ z_1, |z_4| = 1):

    ρ² = |v|² − (z_1·v)² + c_5² − 2 c_5 v·z_4 = R_0(ψ_1) + R_1(ψ_1)/sin ψ_5.

The pair's law d_3² = κ_0 + κ_1 cos θ_3 (a sinusoidal pair: κ_0 = κ_1 = h²/2; cos θ_3 = cos φ_3
cos ψ_3 where sin φ_3 = 0) then reads G(ψ_1) sin ψ_5 = H(ψ_1) with

    G = 2 a_2 a_3 (L_2² − κ_0) − κ_1 cos φ_3 (R_0 − a_2² − a_3²),   H = κ_1 cos φ_3 R_1,

and sin² ψ_5 = 1 − L_1² eliminates ψ_5: G² (1 − L_1²) = H², of degree 6 in (cos ψ_1, sin ψ_1), a
polynomial of degree 12 in t = tan(ψ_1/2) (times (1 + t²)⁶). Where c_5 = 0 (H ≡ 0) it is G² (1 − L_1²),
and G = 0, a quartic, gives the ψ_1 of both ψ_5. `ik_parallel_apair_position6` gives L_1, L_2 in
(1, cos ψ_1, sin ψ_1), P, G and H in t and the polynomial; apair.ik.parallel_apair solves it and
reads ψ_5 = atan2(H/G, P L_1), then ψ_6, ψ_3, ψ_2 and ψ_4 as the R-arm's closed form does.

`check` evaluates the kernel in 40-digit arithmetic at poses of random such designs (α_2, α_3 ∈
{0, π}, α_4, α_5 ∈ {±π/2}, φ_3 ∈ {0, π}, c_5 = 0 too) built by the independent DH product with
the pair's slide (mpmath): L_1 − P cos ψ_5, L_2 − cos α_2 d_3, G sin ψ_5 − H and the polynomial at
t = tan(ψ_1/2) must vanish.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .chain_ik import _mp_dh, evaluate_real
from .chain_ik_parallel import _dh, third_row
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik_parallel_apair.py"


def frame4() -> sp.Expr:
    """K with z_4 = K (z_3 × z_5)/sin ψ_5, derived in frame 4 at cos α_4 = cos α_5 = 0 (z_3 =
    Rx(α_4)ᵀ e_z, z_5 = Rz(ψ_5) Rx(α_5) e_z there), after checking that O_5 − O_3 = c_4 z_3 + c_5 z_4
    at a_4 = a_5 = 0."""
    psi4, psi5, sa4, sa5, c4, c5 = sp.symbols("psi4 psi5 sa4 sa5 c4 c5", real=True)
    A4, A5 = _dh(psi4, 0, 0, sa4, c4), _dh(psi5, 0, 0, sa5, c5)
    z3 = A4[:3, :3].T * sp.Matrix([0, 0, 1])  # in frame 4
    z5 = A5[:3, :3] * sp.Matrix([0, 0, 1])
    cross = z3.cross(z5)
    assert cross[0] == 0 and cross[1] == 0, "z_3 × z_5 is not along z_4"
    k = sp.factor(cross[2] / sp.sin(psi5))
    assert not k.free_symbols & {psi4, psi5}, "z_3 × z_5 is not sin ψ_5 times a constant"
    offset = (A4 * A5)[:3, 3]  # O_5 − O_3 in frame 3
    expected = c4 * sp.Matrix([0, 0, 1]) + c5 * (A4[:3, :3] * sp.Matrix([0, 0, 1]))
    assert sp.simplify(offset - expected) == sp.zeros(3, 1), "O_5 − O_3 is not c_4 z_3 + c_5 z_4"
    unit = {sa4**2: 1, sa5**2: 1}
    return sp.expand(1 / k).subs(unit), sa4, sa5  # 1/k = k for k = ±1


def in_t(e: sp.Expr, c1: sp.Symbol, s1: sp.Symbol, t: sp.Symbol, deg: int) -> list[sp.Expr]:
    """(1 + t²)^deg e(cos ψ_1 = c1, sin ψ_1 = s1) as coefficients in t = tan(ψ_1/2), lowest first,
    for e of total degree ≤ deg in (c1, s1)."""
    w = 1 + t**2
    poly = sp.Poly(sp.expand(e), c1, s1)
    assert poly.total_degree() <= deg, f"degree {poly.total_degree()} in (cos ψ_1, sin ψ_1), expected ≤ {deg}"
    out = sp.Integer(0)
    for (i, j), coeff in poly.terms():
        out += coeff * (1 - t**2) ** i * (2 * t) ** j * w ** (deg - i - j)
    out = sp.expand(out)
    return [sp.factor_terms(out.coeff(t, k)) for k in range(2 * deg + 1)]


def _product(x: list, y: list) -> list:
    """Coefficients (lowest first) of the product of two polynomials."""
    out = [sp.Integer(0)] * (len(x) + len(y) - 1)
    for i, a in enumerate(x):
        for j, b in enumerate(y):
            out[i + j] += a * b
    return out


def spec() -> KernelSpec:
    """ik_parallel_apair_position6(dh (6, 4), T (4, 4), law (2)) -> L (2, 3), P (1), gh (2, 5),
    poly (13)."""
    dh = [sp.Symbol(f"{k}_{i}", real=True) for i in range(1, 7) for k in ("a", "alpha", "c", "phi")]
    J = {i: dict(zip(("a", "alpha", "c", "phi"), dh[4 * (i - 1) : 4 * i])) for i in range(1, 7)}
    Tm = sp.symbols("T0:16", real=True)
    law = sp.symbols("kappa0 kappa1", real=True)
    t, c1, s1 = sp.symbols("t cpsi1 spsi1", real=True)
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(1, 7)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(1, 7)}
    steps = []
    for i in (1, 2, 3, 4, 5, 6):
        steps += [(ca[i], sp.cos(J[i]["alpha"])), (sa[i], sp.sin(J[i]["alpha"]))]
    cphi3 = sp.Symbol("cphi3", real=True)
    steps.append((cphi3, sp.cos(J[3]["phi"])))
    # the third row of A_2 A_3 A_4 A_5 with joint 3's slide d_3, at the UR wrist
    n33, n34, s = third_row()
    d3 = sp.Symbol("d3", real=True)
    ur = {s["ca"][4]: 0, s["ca"][5]: 0, s["a"][4]: 0, s["a"][5]: 0}
    own = {s["a"][i]: J[i]["a"] for i in range(2, 6)} | {s["c"][i]: J[i]["c"] for i in range(2, 6)}
    own |= {s["ca"][i]: ca[i] for i in range(2, 6)} | {s["sa"][i]: sa[i] for i in range(2, 6)}
    n33 = sp.expand(n33.xreplace(ur).xreplace(own))
    n34 = sp.expand(n34.xreplace({s["c"][3]: s["c"][3] + d3}).xreplace(ur).xreplace(own))
    psi5 = s["psi5"]
    P = sp.factor_terms(n33.coeff(sp.cos(psi5)))
    D3 = n34.coeff(d3)
    assert sp.expand(n33 - P * sp.cos(psi5)) == 0, "N_33 is not P cos ψ_5 at the UR wrist"
    assert D3 == ca[2] and not (n34.free_symbols & {psi5}), "N_34 is not its constant plus cos α_2 d_3"
    k34 = sp.expand(n34 - D3 * d3)
    K, sa4, sa5 = frame4()
    K = K.xreplace({sa4: sa[4], sa5: sa[5]})
    # the pose: z_5 and O_5 (axes 5 and 6 meet there) from frame 6
    R6 = sp.Matrix(3, 3, lambda r, k: Tm[4 * r + k])
    O6 = sp.Matrix([Tm[3], Tm[7], Tm[11]])
    z5 = R6 * sp.Matrix([0, sa[6], ca[6]])
    O5 = O6 - J[6]["c"] * z5 - J[6]["a"] * R6[:, 0]
    Zn, On = sp.symbols("Z0:3", real=True), sp.symbols("O0:3", real=True)
    steps += list(zip(Zn, z5)) + list(zip(On, O5))
    Z, O = sp.Matrix(Zn), sp.Matrix(On)
    z1 = sp.Matrix([sa[1] * s1, -sa[1] * c1, ca[1]])
    O1 = sp.Matrix([J[1]["a"] * c1, J[1]["a"] * s1, J[1]["c"]])
    L1 = z1.dot(Z)
    L2 = z1.dot(O) - ca[1] * J[1]["c"] - k34  # z_1·O_1 = cos α_1 c_1
    eps = ca[2] * ca[3]
    # v = u − c_4 ε z_1 with u = O_5 − O_1: |v|² − (z_1·v)² = |u|² − (z_1·u)² (|z_1| = 1, ε² = 1) and
    # v·z_4 = u·z_4 (z_4 ⟂ z_1), written so that each stays of degree 2 in (cos ψ_1, sin ψ_1)
    u = O - O1
    zu = sp.expand(z1.dot(u))
    assert sp.Poly(zu, c1, s1).total_degree() <= 1, "z_1·(O_5 − O_1) is not linear in (cos ψ_1, sin ψ_1)"
    R0 = u.dot(u) - zu**2 + J[5]["c"] ** 2
    R1 = -2 * J[5]["c"] * K * eps * u.dot(z1.cross(Z))  # −2 c_5 v·z_4 = R_1/sin ψ_5
    a2, a3 = J[2]["a"], J[3]["a"]
    H = law[1] * cphi3 * R1
    # d_3² = L_2² (cos² α_2 = 1): G = 2 a_2 a_3 (L_2² − κ_0) − κ_1 cos φ_3 (R_0 − a_2² − a_3²)
    lin = lambda e: [sp.expand(e).subs({c1: 0, s1: 0}), sp.expand(e).coeff(c1), sp.expand(e).coeff(s1)]
    Ln = sp.symbols("l0:6", real=True)
    steps += list(zip(Ln, (*lin(L1), *lin(L2))))
    Lc = lambda k0: Ln[k0] + Ln[k0 + 1] * c1 + Ln[k0 + 2] * s1
    values = dict(steps[-6:])
    for k0, e in ((0, L1), (3, L2)):
        assert sp.expand(Lc(k0).xreplace(values) - e) == 0, "L_1, L_2 are not linear in (cos ψ_1, sin ψ_1)"
    gn, hn = sp.symbols("g0:5", real=True), sp.symbols("h0:5", real=True)
    G = 2 * a2 * a3 * (Lc(3) ** 2 - law[0]) - law[1] * cphi3 * (R0 - a2**2 - a3**2)  # L_2 by its step symbols
    steps += list(zip(gn, in_t(G, c1, s1, t, 2))) + list(zip(hn, in_t(H, c1, s1, t, 2)))
    la = in_t(Lc(0), c1, s1, t, 1)  # (1 + t²) L_1
    w = [1, 0, 1]
    w2 = _product(w, w)
    poly = [sp.expand(x) for x in _product(_product(list(gn), list(gn)), [p - q for p, q in zip(w2, _product(la, la))])]
    hh = _product(_product(list(hn), list(hn)), w2)
    poly = [sp.expand(p - q) for p, q in zip(poly, hh)]
    assert len(poly) == 13
    Ps = sp.Symbol("P", real=True)
    steps.append((Ps, P))
    return KernelSpec(
        name="ik_parallel_apair_position6",
        doc=(
            "The first step of a UR-like 6-joint chain (axes 2, 3, 4 parallel, UR's wrist) with an A-pair at "
            "joint 3 (d3^2 = kappa0 + kappa1 cos(theta3)): L1 = P cos(psi5) and L2 = cos(alpha2) d3, linear in "
            "(1, cos(psi1), sin(psi1)); G sin(psi5) = H; in t = tan((theta1 + phi1)/2), lowest degree first, "
            "(1 + t^2)^2 G and H and the polynomial (1 + t^2)^6 (G^2 (1 - L1^2) - H^2) of degree 12."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("T", (4, 4), "frame 6's pose, row-major", tuple(Tm)),
            Arg("law", (2,), "kappa0, kappa1: joint 3's d^2 = kappa0 + kappa1 cos(theta)", tuple(law), design=True),
        ],
        steps=steps,
        outputs=[
            Arg("L", (2, 3), "L1, L2: coefficients of (1, cos(psi1), sin(psi1))", exprs=Ln),
            Arg("P", (1,), "L1 = P cos(psi5)", exprs=(Ps,)),
            Arg("gh", (2, 5), "(1 + t^2)^2 G and (1 + t^2)^2 H in t", exprs=(*gn, *hn)),
            Arg("poly", (13,), "(1 + t^2)^6 (G^2 (1 - L1^2) - H^2) in t", exprs=tuple(poly)),
        ],
    )


def check(kernel: KernelSpec, samples: int = 3, digits: int = 40) -> float:
    """Largest relative residual of L_1 − P cos ψ_5, L_2 − cos α_2 d_3, G sin ψ_5 − H and of the
    polynomial at t = tan(ψ_1/2), at poses of random UR-like designs with a sinusoidal A-pair at
    joint 3 (κ_0 = κ_1 = h²/2), c_5 = 0 among them, built by the mpmath DH product."""
    rng = random.Random(7)
    worst = 0.0
    with mpmath.workdps(digits):
        for case in ("general", "c5=0") * samples:
            dh = [[mpmath.mpf(rng.uniform(0.1, 1)), mpmath.mpf(rng.uniform(-3, 3)), mpmath.mpf(rng.uniform(-1, 1)),
                   mpmath.mpf(rng.uniform(-3, 3))] for _ in range(6)]  # fmt: skip
            dh[1][1], dh[2][1] = mpmath.pi * rng.randint(0, 1), mpmath.pi * rng.randint(0, 1)  # 2∥3∥4
            dh[3][1], dh[4][1] = mpmath.pi / 2 * rng.choice((-1, 1)), mpmath.pi / 2 * rng.choice((-1, 1))
            dh[3][0] = dh[4][0] = mpmath.mpf(0)
            dh[2][3] = mpmath.pi * rng.randint(0, 1)
            if case == "c5=0":
                dh[4][2] = mpmath.mpf(0)
            h = mpmath.mpf(rng.uniform(0.05, 0.5))
            theta = [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(6)]
            theta[2] = mpmath.mpf(rng.uniform(-6, 6))
            slide = [0, 0, h * mpmath.cos(theta[2] / 2), 0, 0, 0]
            T = mpmath.eye(4)
            for i in range(6):
                T = T * _mp_dh(theta[i], slide[i], dh[i][0], dh[i][1], dh[i][2], dh[i][3])
            law = [h**2 / 2, h**2 / 2]
            out = evaluate_real(kernel, dh, T, law, digits=digits)
            L, P, g, hh, poly = out[:6], out[6], out[7:12], out[12:17], out[17:30]
            psi1, psi5 = theta[0] + dh[0][3], theta[4] + dh[4][3]
            size = 1 + sum(abs(x) for row in dh for x in (row[0], row[2])) + h
            c1, s1 = mpmath.cos(psi1), mpmath.sin(psi1)
            worst = max(worst, float(abs(L[0] + L[1] * c1 + L[2] * s1 - P * mpmath.cos(psi5))))
            worst = max(worst, float(abs(L[3] + L[4] * c1 + L[5] * s1 - mpmath.cos(dh[1][1]) * slide[2]) / size))
            t = mpmath.tan(psi1 / 2)
            value = lambda cs: sum(c * t**k for k, c in enumerate(cs))
            scale = lambda cs: sum(abs(c) * abs(t) ** k for k, c in enumerate(cs)) + 1
            gt, ht = value(g), value(hh)
            worst = max(worst, float(abs(gt * mpmath.sin(psi5) - ht) / (scale(g) + scale(hh))))
            worst = max(worst, float(abs(value(poly)) / scale(poly)))
            if case == "c5=0":
                worst = max(worst, float(max(abs(x) for x in hh)) / size**4)
    assert worst < 1e-30, f"ik_parallel_apair_position6: an equation fails at a pose by {worst}"
    return worst


def derive():
    """The A-pair-at-joint-3 position kernel, after the independent check."""
    kernel = spec()
    return [], [kernel], {"parallel_apair_check": check(kernel)}
