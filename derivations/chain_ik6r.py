"""The Raghavan–Roth equations of the 6R inverse kinematics, for an eigenvalue solver.

A 6R chain (docs/conventions.md §3, d_i ≡ 0) reaches T when, with ψ_i = θ_i + φ_i,

    A_3 A_4 A_5 = A_2⁻¹ A_1⁻¹ T A_6⁻¹.

The third and fourth columns of A_6⁻¹ do not depend on ψ_6, so both sides' third and fourth
columns, l (a direction) and p (a point), are free of ψ_6. Raghavan and Roth (1993) add eight
combinations that keep the same monomials: p·p, p·l, p × l and (p·p) l − 2 (p·l) p. These 14
equations are, after reduction by cos² + sin² = 1,

    P(ψ_3) · X45 = Q · X12,

X45 = (1, c4, s4) ⊗ (1, c5, s5) and X12 = (1, c1, s1) ⊗ (1, c2, s2) (c_i, s_i = cos ψ_i, sin ψ_i),
with P linear in (1, c3, s3): `ik6r_equations` gives P (14, 3, 9), a constant of the design, and Q
(14, 9), which depends on the pose through u = R_T · A_6⁻¹ e_z and w = T · A_6⁻¹ e_4 alone.
apair.ik.elimination6r eliminates X12's eight non-constant monomials (six combinations of the 14 rows),
substitutes half-angles and solves the resulting 12 × 12 quadratic matrix polynomial in
tan(ψ_3/2) as a 24 × 24 eigenproblem: 16 solutions and 8 spurious ones at tan(ψ_3/2) = ±i.

The derivation itself checks that every equation reduces to those monomials (the multilinearity
the method rests on), and `check_equations` verifies them at random 6R poses in 40-digit
arithmetic, through the DH product of docs/conventions.md §3 (mpmath), independently of the
symbolic route.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .chain_ik import _mp_dh, evaluate_real
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik6r.py"
ROWS = 14


def _syms(i: int) -> dict[str, sp.Symbol]:
    return {k: sp.Symbol(f"{k}{i}", real=True) for k in ("s", "c", "sa", "ca", "a", "d")}


def _mul(A, B):
    """The product of two 4 × 4 matrices (lists of ring elements)."""
    return [[sum(A[r][k] * B[k][col] for k in range(4)) for col in range(4)] for r in range(4)]


def _rz(c, s):
    return [[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]


def _rx(c, s):
    return [[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]]


def _t(x, z):
    return [[1, 0, 0, x], [0, 1, 0, 0], [0, 0, 1, z], [0, 0, 0, 1]]


def _dh(j):
    """A_i = Rz(ψ)·Tz(c)·Tx(a)·Rx(α)."""
    return _mul(_mul(_rz(j["c"], j["s"]), _t(j["a"], j["d"])), _rx(j["ca"], j["sa"]))


def _dh_inverse(j):
    """A_i⁻¹ = Rx(−α)·Tx(−a)·Tz(−c)·Rz(−ψ)."""
    return _mul(_mul(_rx(j["ca"], -j["sa"]), _t(-j["a"], -j["d"])), _rz(j["c"], -j["s"]))


def _fourteen(l, p) -> list:
    """l, p, p·p, p·l, p × l, (p·p) l − 2 (p·l) p."""
    pp, pl = sum(x * x for x in p), sum(x * y for x, y in zip(p, l))
    cross = [p[1] * l[2] - p[2] * l[1], p[2] * l[0] - p[0] * l[2], p[0] * l[1] - p[1] * l[0]]
    return list(l) + list(p) + [pp, pl] + cross + [pp * x - 2 * pl * y for x, y in zip(l, p)]


def _coefficients(f, bases, ring) -> list[sp.Expr]:
    """The coefficients of the ring element f in the tensor basis ⊗_k (1, c_k, s_k) (row-major),
    after checking that f is multilinear in it (the Raghavan–Roth property)."""
    where = {ring.gens.index(g): (k, slot) for k, (c, s) in enumerate(bases) for g, slot in ((c, 1), (s, 2))}
    out = [ring.zero] * 3 ** len(bases)
    for monom, coeff in f.terms():
        digits, rest = [0] * len(bases), list(monom)
        for g, (k, slot) in where.items():
            if monom[g]:
                if monom[g] > 1 or digits[k]:
                    raise AssertionError(f"ik6r: an equation is not multilinear in {bases[k]}: {monom}")
                digits[k], rest[g] = slot, 0
        pos = 0
        for d in digits:
            pos = 3 * pos + d
        out[pos] += ring({tuple(rest): coeff})
    return [sp.factor_terms(e.as_expr()) for e in out]


def equations():
    """(P, Q, u, w, J): P[r][k][m] and Q[r][m] as expressions in the design symbols J[i] (i = 1..6,
    keys c, s, a, ca, sa, d) and the pose vectors u, w (3 symbols each). Computed in the
    polynomial ring over Q in all of them (lex order, s_i before c_i), reduced modulo
    s_i² + c_i² − 1 (joint angles and twists alike)."""
    J = {i: _syms(i) for i in range(1, 7)}
    u = sp.symbols("u0:3", real=True)
    w = sp.symbols("w0:3", real=True)
    symbols = [J[i][k] for i in range(1, 7) for k in ("s", "c", "sa", "ca")]
    symbols += [J[i][k] for i in range(1, 7) for k in ("a", "d")] + list(u) + list(w)
    ring, *gens = sp.ring(symbols, sp.QQ)
    G = dict(zip(symbols, gens))
    R = {i: {k: G[v] for k, v in J[i].items()} for i in J}
    circles = [G[J[i]["s"]] ** 2 + G[J[i]["c"]] ** 2 - 1 for i in range(1, 7)]
    circles += [G[J[i]["sa"]] ** 2 + G[J[i]["ca"]] ** 2 - 1 for i in range(1, 7)]
    left = _mul(_mul(_dh(R[3]), _dh(R[4])), _dh(R[5]))
    right = _mul(_dh_inverse(R[2]), _dh_inverse(R[1]))
    lL, pL = [left[r][2] for r in range(3)], [left[r][3] for r in range(3)]
    lR = [sum(right[r][k] * G[u[k]] for k in range(3)) for r in range(3)]
    pR = [sum(right[r][k] * G[w[k]] for k in range(3)) + right[r][3] for r in range(3)]
    angle = lambda i: (J[i]["c"], J[i]["s"])
    gen = lambda pair: tuple(G[x] for x in pair)
    P, Q = [], []
    for eL, eR in zip(_fourteen(lL, pL), _fourteen(lR, pR)):
        eL, eR = ring(eL).rem(circles), ring(eR).rem(circles)
        coeffs = _coefficients(eL, [gen(angle(3)), gen(angle(4)), gen(angle(5))], ring)  # (1, c3, s3) ⊗ X45
        P.append([coeffs[9 * k : 9 * k + 9] for k in range(3)])
        Q.append(_coefficients(eR, [gen(angle(1)), gen(angle(2))], ring))
    return P, Q, u, w, J


def spec() -> KernelSpec:
    """ik6r_equations(dh (6, 4) design, T (4, 4)) -> P (14, 3, 9), Q (14, 9)."""
    P, Q, u, w, J = equations()
    dh = [sp.Symbol(f"{k}_{i}", real=True) for i in range(1, 7) for k in ("a", "alpha", "c", "phi")]
    Tm = sp.symbols("T0:16", real=True)
    steps = []
    sub = {}
    for i in range(1, 7):
        a, alpha, c, _phi = dh[4 * (i - 1) : 4 * i]
        sub[J[i]["a"]], sub[J[i]["d"]] = a, c
        steps += [(J[i]["ca"], sp.cos(alpha)), (J[i]["sa"], sp.sin(alpha))]
    # A_6⁻¹'s third and fourth columns: (0, sin α6, cos α6, 0) and (−a6, −c6 sin α6, −c6 cos α6, 1)
    col3 = (0, J[6]["sa"], J[6]["ca"])
    col4 = (-dh[20], -dh[22] * J[6]["sa"], -dh[22] * J[6]["ca"])
    R = [[Tm[4 * r + k] for k in range(3)] for r in range(3)]
    for r in range(3):
        steps.append((u[r], sum(R[r][k] * col3[k] for k in range(3))))
    for r in range(3):
        steps.append((w[r], sum(R[r][k] * col4[k] for k in range(3)) + Tm[4 * r + 3]))
    P_out = [sp.S(e).xreplace(sub) for row in P for part in row for e in part]
    Q_out = [sp.S(e).xreplace(sub) for row in Q for e in row]
    return KernelSpec(
        name="ik6r_equations",
        doc=(
            "The Raghavan-Roth equations P(psi_3) X45 = Q X12 of a 6R chain at the pose T (psi_i = theta_i + "
            "phi_i): P (14 x 3 x 9) on (1, c3, s3) x (1, c4, s4) x (1, c5, s5) and Q (14 x 9) on "
            "(1, c1, s1) x (1, c2, s2)."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("T", (4, 4), "the pose, row-major", tuple(Tm)),
        ],
        steps=steps,
        outputs=[
            Arg("P", (ROWS, 3, 9), "the left side's coefficients (design only)", exprs=tuple(P_out)),
            Arg("Q", (ROWS, 9), "the right side's coefficients", exprs=tuple(Q_out)),
        ],
    )


# ----------------------------------------------------------------------------- independent check
def check_equations(kernel: KernelSpec, samples: int = 3, digits: int = 40) -> float:
    """Largest |P(ψ3) X45 − Q X12| / (1 + |P(ψ3) X45|) at random real 6R poses T = A_1 … A_6 (mpmath
    DH product), the kernel's steps and outputs evaluated in `digits`-digit arithmetic."""
    rng = random.Random(61)
    worst = 0.0
    with mpmath.workdps(digits):
        for _ in range(samples):
            dh = [
                [
                    mpmath.mpf(rng.uniform(-1, 1)),
                    mpmath.mpf(rng.uniform(-3, 3)),
                    mpmath.mpf(rng.uniform(-1, 1)),
                    mpmath.mpf(rng.uniform(-3, 3)),
                ]
                for _ in range(6)
            ]
            psi = [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(6)]
            T = mpmath.eye(4)
            for i in range(6):
                T = T * _mp_dh(psi[i], 0, dh[i][0], dh[i][1], dh[i][2], 0)  # ψ_i = θ_i + φ_i
            vals = evaluate_real(kernel, dh, T, digits=digits)
            Pv, Qv = vals[: ROWS * 27], vals[ROWS * 27 :]
            cs = lambda i: [1, mpmath.cos(psi[i]), mpmath.sin(psi[i])]
            X45 = [x * y for x in cs(3) for y in cs(4)]
            X12 = [x * y for x in cs(0) for y in cs(1)]
            t3 = cs(2)
            for r in range(ROWS):
                lhs = sum(Pv[27 * r + 9 * k + m] * t3[k] * X45[m] for k in range(3) for m in range(9))
                rhs = sum(Qv[9 * r + m] * X12[m] for m in range(9))
                worst = max(worst, float(abs(lhs - rhs) / (1 + abs(lhs))))
    assert worst < 1e-30, f"ik6r_equations: the 14 equations fail at a 6R pose by {worst}"
    return worst


def derive():
    """The 6R equations' kernel, after the independent check."""
    kernel = spec()
    return [], [kernel], {"equations_check": check_equations(kernel)}
