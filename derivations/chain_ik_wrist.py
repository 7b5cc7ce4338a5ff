"""The position problem of six-joint R-chains with a spherical wrist (issue 42), Pieper's reduction.

Where axes 4, 5 and 6 meet in one point (a_4 = a_5 = 0 and c_5 = 0, apair.ik.families), that
point W is frame 4's origin, O_3 + c_4 z_3, whatever ψ_4, ψ_5, ψ_6 (ψ_i = θ_i + φ_i): its
position depends on ψ_1, ψ_2, ψ_3 alone, and it is known from the pose, W = O_6 − c_6 z_5 − a_6 x_6
with z_5 = R_6 (0, sin α_6, cos α_6) (A_6 = Rz(ψ_6)·Tz(c_6)·Tx(a_6)·Rx(α_6), docs/conventions.md §3).

With A_1 = Rz(ψ_1)·B_1, B_1 = Tz(c_1)·Tx(a_1)·Rx(α_1), and p(ψ_3) = Tz(c_2)·Tx(a_2)·Rx(α_2) ·
A_3(ψ_3) · (0, 0, c_4, 1) (the wrist point in frame 1 before the turn ψ_2), u = Rz(ψ_2) p:

    W − c_1 e_z = Rz(ψ_1) (a_1 + u_x,  cos α_1 u_y − sin α_1 u_z,  sin α_1 u_y + cos α_1 u_z),

and the turns about z leave |·| and the z component: with r = |W − c_1 e_z|², h = W_z − c_1 and
u_z = p_z, |u|² = |p|², u_x² + u_y² = p_x² + p_y²,

    (A)  r = a_1² + 2 a_1 u_x + |p|²,        (B)  h = sin α_1 u_y + cos α_1 p_z.

Eliminating u_x, u_y (a_1 ≠ 0, sin α_1 ≠ 0) gives Pieper's quartic in t = tan(ψ_3/2):

    E = sin²α_1 (r − a_1² − |p|²)² + 4 a_1² (h − cos α_1 p_z)² − 4 a_1² sin²α_1 (p_x² + p_y²) = 0

(times (1 + t²)²; p is linear in cos ψ_3, sin ψ_3, and so is |p|²). Where a_1 = 0 (axes 1 and 2
meet) E degenerates to the square of (A), which alone is a quadratic in t; where sin α_1 = 0 (1∥2)
(B) alone is. `ik_wrist_position6` gives W, r, h and the three polynomials' coefficients (lowest
degree first); apair.ik.wrist solves them, reads ψ_2 and ψ_1 from u and the wrist's three angles
from R_3ᵀ R_6, and verifies every solution through fk.

`check` evaluates the kernel in 40-digit arithmetic at the poses of random designs, and of designs
with a_1 = 0 and with α_1 = 0, built by the independent DH product (mpmath): W must be frame 4's
origin and the polynomials must vanish at tan(ψ_3/2) of the pose.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .chain_ik import _mp_dh, evaluate_real
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik_wrist.py"


def _rx(c, s):
    return sp.Matrix([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _t(x, z):
    return sp.Matrix([[1, 0, 0, x], [0, 1, 0, 0], [0, 0, 1, z], [0, 0, 0, 1]])


def spec() -> KernelSpec:
    """ik_wrist_position6(dh (6, 4) design, T (4, 4)) -> W (3), rh (2), quartic (5), qa (3), qb (3)."""
    dh = [sp.Symbol(f"{k}_{i}", real=True) for i in range(1, 7) for k in ("a", "alpha", "c", "phi")]
    J = {i: dict(zip(("a", "alpha", "c", "phi"), dh[4 * (i - 1) : 4 * i])) for i in range(1, 7)}
    Tm = sp.symbols("T0:16", real=True)
    t = sp.Symbol("t", real=True)
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(1, 7)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(1, 7)}
    steps = []
    for i in (1, 2, 3, 6):
        steps += [(ca[i], sp.cos(J[i]["alpha"])), (sa[i], sp.sin(J[i]["alpha"]))]
    R6 = sp.Matrix(3, 3, lambda r, k: Tm[4 * r + k])
    O6 = sp.Matrix([Tm[3], Tm[7], Tm[11]])
    # frame 5's z and origin from frame 6: A_6⁻¹ = Rx(−α_6)·Tx(−a_6)·Tz(−c_6)·Rz(−ψ_6)
    z5 = R6 * sp.Matrix([0, sa[6], ca[6]])
    W = O6 - J[6]["c"] * z5 - J[6]["a"] * R6[:, 0]
    Wn = sp.symbols("W0:3", real=True)
    steps += list(zip(Wn, W))
    r, h = sp.symbols("r h", real=True)
    steps += [(r, Wn[0] ** 2 + Wn[1] ** 2 + (Wn[2] - J[1]["c"]) ** 2), (h, Wn[2] - J[1]["c"])]
    # p(ψ_3) at cos ψ_3 = (1 − t²)/(1 + t²), sin ψ_3 = 2t/(1 + t²), times 1 + t²
    w, c3, s3 = 1 + t**2, 1 - t**2, 2 * t  # w cos ψ_3, w sin ψ_3
    ml = (_t(J[3]["a"], J[3]["c"]) * _rx(ca[3], sa[3]) * sp.Matrix([0, 0, J[4]["c"], 1]))[:3, 0]
    m = sp.Matrix([c3 * ml[0] - s3 * ml[1], s3 * ml[0] + c3 * ml[1], w * ml[2]])  # w A_3 (0, 0, c_4, 1)
    B2 = _t(J[2]["a"], J[2]["c"]) * _rx(ca[2], sa[2])
    P = B2[:3, :3] * m + w * B2[:3, 3]  # w p
    a1 = J[1]["a"]
    circle = {ca[i] ** 2: 1 - sa[i] ** 2 for i in (2, 3)}
    PP = sp.expand(sp.expand(P.dot(P)).subs(circle))  # w² |p|², divisible by w: |p|² is linear in cos, sin ψ_3
    pp_w, rem = sp.div(PP, w, t)
    assert rem == 0, "|p|² is not linear in (cos ψ_3, sin ψ_3)"
    A_eq = sp.expand((r - a1**2) * w - pp_w)  # w (r − a_1² − |p|²)
    B_eq = sp.expand(h * w - ca[1] * P[2])  # w (h − cos α_1 p_z)
    E = sp.expand(sa[1] ** 2 * A_eq**2 + 4 * a1**2 * B_eq**2 - 4 * a1**2 * sa[1] ** 2 * (P[0] ** 2 + P[1] ** 2))
    coeffs = lambda e, deg: [sp.factor_terms(sp.expand(e).coeff(t, k)) for k in range(deg + 1)]
    assert sp.degree(E, t) <= 4 and sp.degree(A_eq, t) <= 2 and sp.degree(B_eq, t) <= 2
    return KernelSpec(
        name="ik_wrist_position6",
        doc=(
            "The position problem of a 6R chain with a spherical wrist (axes 4, 5, 6 through one point): the "
            "wrist point W, r = |W - c1 e_z|^2, h = W_z - c1, and in t = tan((theta3 + phi3)/2), lowest degree "
            "first, Pieper's quartic and the quadratics (A) (for a1 = 0) and (B) (for sin(alpha1) = 0)."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("T", (4, 4), "frame 6's pose, row-major", tuple(Tm)),
        ],
        steps=steps,
        outputs=[
            Arg("W", (3,), "the wrist point [m]", exprs=tuple(Wn)),
            Arg("rh", (2,), "r = |W - c1 e_z|^2 [m^2], h = W_z - c1 [m]", exprs=(r, h)),
            Arg("quartic", (5,), "Pieper's quartic in t", exprs=tuple(coeffs(E, 4))),
            Arg("qa", (3,), "(1 + t^2)(r - a1^2 - |p|^2) in t", exprs=tuple(coeffs(A_eq, 2))),
            Arg("qb", (3,), "(1 + t^2)(h - cos(alpha1) p_z) in t", exprs=tuple(coeffs(B_eq, 2))),
        ],
    )


def check(kernel: KernelSpec, samples: int = 3, digits: int = 40) -> float:
    """Largest relative residual of W against frame 4's origin and of the polynomials at
    t = tan(ψ_3/2), at poses of random spherical-wrist designs (general, a_1 = 0, α_1 = 0) built
    by the mpmath DH product."""
    rng = random.Random(42)
    worst = 0.0
    with mpmath.workdps(digits):
        for case in ("general", "a1=0", "alpha1=0") * samples:
            dh = [[mpmath.mpf(rng.uniform(0.1, 1)), mpmath.mpf(rng.uniform(-3, 3)), mpmath.mpf(rng.uniform(-1, 1)),
                   mpmath.mpf(rng.uniform(-3, 3))] for _ in range(6)]  # fmt: skip
            dh[3][0] = dh[4][0] = dh[4][2] = mpmath.mpf(0)  # a_4 = a_5 = c_5 = 0: the wrist
            if case == "a1=0":
                dh[0][0] = mpmath.mpf(0)
            if case == "alpha1=0":
                dh[0][1] = mpmath.mpf(0)
            psi = [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(6)]
            frames = [mpmath.eye(4)]
            for i in range(6):
                frames.append(frames[-1] * _mp_dh(psi[i], 0, dh[i][0], dh[i][1], dh[i][2], 0))
            T = frames[6]
            out = evaluate_real(kernel, dh, T, digits=digits)
            W, quartic, qa, qb = out[:3], out[5:10], out[10:13], out[13:16]
            size = 1 + sum(abs(x) for row in dh for x in (row[0], row[2]))
            worst = max(worst, *(float(abs(W[k] - frames[4][k, 3]) / size) for k in range(3)))
            t = mpmath.tan(psi[2] / 2)
            value = lambda cs: sum(c * t**k for k, c in enumerate(cs))
            scale = lambda cs: sum(abs(c) * abs(t) ** k for k, c in enumerate(cs)) + 1
            polys = {"general": [quartic], "a1=0": [quartic, qa], "alpha1=0": [quartic, qb]}[case]
            for cs in polys:
                worst = max(worst, float(abs(value(cs)) / scale(cs)))
    assert worst < 1e-30, f"ik_wrist_position6: the wrist point or a polynomial fails at a pose by {worst}"
    return worst


def derive():
    """The wrist's position kernel, after the independent check."""
    kernel = spec()
    return [], [kernel], {"wrist_check": check(kernel)}
