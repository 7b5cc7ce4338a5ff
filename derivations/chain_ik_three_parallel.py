"""The first steps of six-joint R-chains with axes 1, 2 and 3 parallel and axes 5 and 6 meeting
(apair.ik.families' three-parallel-two-intersecting; issue 42).

Where sin α_1 = sin α_2 = 0, M = A_1 A_2 A_3 A_4 (A_i = Rz(ψ_i)·Tz(c_i)·Tx(a_i)·Rx(α_i), ψ_i = θ_i + φ_i,
docs/conventions.md §3) turns its third row by ψ_1 ± ψ_2 ± ψ_3 about the common axis and so keeps it:
that row depends on ψ_4 alone. Where a_5 = 0, axes 5 and 6 meet in frame 5's origin
W = O_6 − c_6 z_5 − a_6 x_6 (z_5 = R_6 (0, sin α_6, cos α_6): read off the pose, whatever ψ_6), and
W = M (0, 0, c_5). So

    W_z = M_31 0 + M_32 0 + M_33 c_5 + M_34 = k + A cos ψ_4 + B sin ψ_4       (IK-Geo's subproblem 4),

two ψ_4, and the third row u(ψ_4) of M's rotation must satisfy u Rz(ψ_5) Rx(α_5) Rz(ψ_6) = g, the
third row of R_6 Rx(α_6)ᵀ: its third entry is one equation in ψ_5 (two), its first two turn by ψ_6
(subproblem 2). `ik_three_parallel6` gives W, (A, B, W_z − k), u's coefficients in (1, cos ψ_4,
sin ψ_4) and g; apair.ik.three_parallel reads ψ_4, ψ_5, ψ_6, then ψ_1 + cos α_1 ψ_2 + cos α_1 cos α_2 ψ_3
from M's rotation and the planar elbow in closed form.

`check` evaluates the kernel in 40-digit arithmetic at poses of random designs with α_1, α_2 in
{0, π} and a_5 = 0 built by the independent DH product (mpmath): the ψ_4 equation and u(ψ_4) at the
pose's ψ_4 must hold, and u Rz(ψ_5) Rx(α_5) Rz(ψ_6) must be g.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .chain_ik import _mp_dh, evaluate_real
from .chain_ik_parallel import _dh
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik_three_parallel.py"


def third_row() -> tuple[list[sp.Expr], dict]:
    """The third row of M = A_1 A_2 A_3 A_4 at sin α_1 = sin α_2 = 0 (rotation, then translation),
    derived from the product (ψ_1, ψ_2, ψ_3 must drop out), with the symbols used."""
    psi = {i: sp.Symbol(f"psi{i}", real=True) for i in range(1, 5)}
    a = {i: sp.Symbol(f"a_{i}", real=True) for i in range(1, 5)}
    c = {i: sp.Symbol(f"c_{i}", real=True) for i in range(1, 5)}
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(1, 5)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(1, 5)}
    M = sp.eye(4)
    for i in range(1, 5):
        M = M * _dh(psi[i], a[i], ca[i], 0 if i in (1, 2) else sa[i], c[i])
    unit = {ca[1] ** 2: 1, ca[2] ** 2: 1}
    row = [sp.expand(sp.expand(M[2, k]).subs(unit)) for k in range(4)]
    for e in row:
        assert not (e.free_symbols & {psi[1], psi[2], psi[3]}), "the third row of A_1 A_2 A_3 A_4 moves with ψ_1..ψ_3"
    return row, {"psi4": psi[4], "a": a, "c": c, "ca": ca, "sa": sa}


def spec() -> KernelSpec:
    """ik_three_parallel6(dh (6, 4), T (4, 4)) -> W (3), F4 (3), U (3, 3), g (3)."""
    dh = [sp.Symbol(f"{k}_{i}", real=True) for i in range(1, 7) for k in ("a", "alpha", "c", "phi")]
    J = {i: dict(zip(("a", "alpha", "c", "phi"), dh[4 * (i - 1) : 4 * i])) for i in range(1, 7)}
    Tm = sp.symbols("T0:16", real=True)
    row, s = third_row()
    psi4 = s["psi4"]
    ca = {i: sp.Symbol(f"ca{i}", real=True) for i in range(1, 7)}
    sa = {i: sp.Symbol(f"sa{i}", real=True) for i in range(1, 7)}
    steps = []
    for i in (1, 2, 3, 4, 6):
        steps += [(ca[i], sp.cos(J[i]["alpha"])), (sa[i], sp.sin(J[i]["alpha"]))]
    own = {s["a"][i]: J[i]["a"] for i in range(1, 5)} | {s["c"][i]: J[i]["c"] for i in range(1, 5)}
    own |= {s["ca"][i]: ca[i] for i in range(1, 5)} | {s["sa"][i]: sa[i] for i in range(1, 5)}
    row = [e.xreplace(own) for e in row]
    split = lambda e: (  # (1, cos ψ_4, sin ψ_4) parts
        sp.expand(e.subs({sp.cos(psi4): 0, sp.sin(psi4): 0})),
        sp.factor_terms(sp.expand(e).coeff(sp.cos(psi4))),
        sp.factor_terms(sp.expand(e).coeff(sp.sin(psi4))),
    )
    U = [split(e) for e in row[:3]]
    for e, (k, cc, ss) in zip(row[:3], U):
        assert sp.expand(k + cc * sp.cos(psi4) + ss * sp.sin(psi4) - e) == 0, "u is not linear in cos ψ_4, sin ψ_4"
    k, A, B = split(sp.expand(row[2] * J[5]["c"] + row[3]))
    R6 = sp.Matrix(3, 3, lambda r, q: Tm[4 * r + q])
    O6 = sp.Matrix([Tm[3], Tm[7], Tm[11]])
    z5 = R6 * sp.Matrix([0, sa[6], ca[6]])
    W = O6 - J[6]["c"] * z5 - J[6]["a"] * R6[:, 0]
    Wn = sp.symbols("W0:3", real=True)
    steps += list(zip(Wn, W))
    g = (R6 * sp.Matrix([[1, 0, 0], [0, ca[6], sa[6]], [0, -sa[6], ca[6]]]))[2, :]  # third row of R_6 Rx(α_6)ᵀ
    return KernelSpec(
        name="ik_three_parallel6",
        doc=(
            "The first steps of a 6R chain with axes 1, 2, 3 parallel and axes 5, 6 meeting (a5 = 0): W, the "
            "point where axes 5 and 6 meet; A cos(psi4) + B sin(psi4) = C from W_z; the third row u of the "
            "rotation of A1 A2 A3 A4, linear in (1, cos(psi4), sin(psi4)); g, the third row of R6 Rx(alpha6)^T."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("T", (4, 4), "frame 6's pose, row-major", tuple(Tm)),
        ],
        steps=steps,
        outputs=[
            Arg("W", (3,), "the point where axes 5 and 6 meet [m]", exprs=Wn),
            Arg("F4", (3,), "A, B, C: A cos(psi4) + B sin(psi4) = C", exprs=(A, B, sp.expand(Wn[2] - k))),
            Arg(
                "U",
                (3, 3),
                "u_k = U[k][0] + U[k][1] cos(psi4) + U[k][2] sin(psi4)",
                exprs=tuple(x for r in U for x in r),
            ),
            Arg("g", (3,), "the third row of R6 Rx(alpha6)^T", exprs=tuple(g)),
        ],
    )


def check(kernel: KernelSpec, samples: int = 4, digits: int = 40) -> float:
    """Largest residual of the ψ_4 equation (relative to the design's size), of u(ψ_4) against the
    product's third row and of u Rz(ψ_5) Rx(α_5) Rz(ψ_6) − g, at poses of random designs with
    α_1, α_2 ∈ {0, π} and a_5 = 0 built by the mpmath DH product."""
    rng = random.Random(43)
    worst = 0.0
    with mpmath.workdps(digits):
        for _ in range(samples):
            dh = [[mpmath.mpf(rng.uniform(0.1, 1)), mpmath.mpf(rng.uniform(-3, 3)), mpmath.mpf(rng.uniform(-1, 1)),
                   mpmath.mpf(rng.uniform(-3, 3))] for _ in range(6)]  # fmt: skip
            dh[0][1], dh[1][1] = mpmath.pi * rng.randint(0, 1), mpmath.pi * rng.randint(0, 1)  # 1∥2∥3
            dh[4][0] = mpmath.mpf(0)  # 5∩6
            psi = [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(6)]
            A = [_mp_dh(psi[i], 0, dh[i][0], dh[i][1], dh[i][2], 0) for i in range(6)]
            T = A[0] * A[1] * A[2] * A[3] * A[4] * A[5]
            M = A[0] * A[1] * A[2] * A[3]
            out = evaluate_real(kernel, dh, T, digits=digits)
            W, (fa, fb, fc), U, g = out[:3], out[3:6], out[6:15], out[15:18]
            size = 1 + sum(abs(x) for row in dh for x in (row[0], row[2]))
            c4, s4 = mpmath.cos(psi[3]), mpmath.sin(psi[3])
            worst = max(worst, float(abs(fa * c4 + fb * s4 - fc) / size))
            u = [U[3 * k] + U[3 * k + 1] * c4 + U[3 * k + 2] * s4 for k in range(3)]
            worst = max(worst, max(float(abs(u[k] - M[2, k])) for k in range(3)))
            W5 = A[0] * A[1] * A[2] * A[3] * A[4]
            worst = max(worst, max(float(abs(W[k] - W5[k, 3]) / size) for k in range(3)))
            R = mpmath.matrix(3, 3)
            for r in range(3):
                for q in range(3):
                    R[r, q] = (A[4] * A[5])[r, q]
            a6 = dh[5][1]
            Rx6t = mpmath.matrix([[1, 0, 0], [0, mpmath.cos(a6), mpmath.sin(a6)], [0, -mpmath.sin(a6), mpmath.cos(a6)]])
            lhs = mpmath.matrix([u]) * R * Rx6t
            worst = max(worst, max(float(abs(lhs[0, k] - g[k])) for k in range(3)))
    assert worst < 1e-30, f"ik_three_parallel6: an equation fails at a pose by {worst}"
    return worst


def derive():
    """The three-parallel-two-intersecting kernel, after the independent check."""
    kernel = spec()
    return [], [kernel], {"three_parallel_check": check(kernel)}
