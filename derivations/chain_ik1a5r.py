"""The Raghavan–Roth equations of a six-joint chain with one sinusoidal A-pair, that pair's angle
hidden: the 1A5R inverse kinematics as an eigenproblem.

The loop A_1 … A_6 = T read from joint k (k = 1, 2, 3, the A-pair; apair.ik.elimination1a5r reads a chain
whose A-pair is joint 4, 5 or 6 from its end) is

    A_k A_{k+1} A_{k+2} · A_{k+3} = B · T · C,   B = A_{k−1}⁻¹ … A_1⁻¹,   C = A_6⁻¹ … A_{k+4}⁻¹,

and the third and fourth columns of A_{k+3}⁻¹ (an R-pair) are free of its angle: both sides' l
and p (docs of chain_ik6r) agree with the columns (l0, p0) of A_{k+3}⁻¹ carried by B T C. The 14
functions f = (l, p, p·p, p·l, p × l, (p·p) l − 2 (p·l) p) of a rigid motion g = (R, t) of (l, p)
are an affine map of f(l, p) (`transform`; Raghavan and Roth's invariance), so B T C's 14 functions
are built without ever squaring T's rotation (T stays a free 4 × 4 in the ring, no orthogonality
needed). With the A-pair's half angle (C, S) = (cos θ_k/2, sin θ_k/2) (its offset is h C and
ψ_k = θ_k + φ_k),

    P(C, S) · X_{k+1,k+2} = Q · X_right,

P on the nine monomials (1, C, …, C⁴, S, S C, …, S C³) (the remainders modulo C² + S² − 1) ⊗
(1, c, s)_{k+1} ⊗ (1, c, s)_{k+2}, a constant of the design, and Q on (1, c, s)_{r1} ⊗ (1, c, s)_{r2}
for the two joints r1 < r2 of B and C, a function of the pose. apair.ik.elimination1a5r solves it like the 6R
case (a 12 × 12 matrix polynomial of degree 8 in tan((θ_k − σ)/4)): 48 solutions and 48 spurious
eigenvalues at ±i.

`check_equations` verifies every split at random 1A5R poses in 40-digit arithmetic through the
DH product of docs/conventions.md §3 (mpmath), independently of the symbolic route.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .chain_ik import _mp_dh
from .chain_ik6r import _coefficients, _dh, _dh_inverse, _fourteen, _mul, _rx, _rz, _syms, _t
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik1a5r.py"
ROWS = 14
PARTS = (1, 2, 3)  # the A-pair's joint in the reading the equations take
A_BASIS = [(i, 0) for i in range(5)] + [(i, 1) for i in range(4)]  # C^i S^j


def split(k: int) -> tuple[tuple[int, int], int, tuple[int, int]]:
    """(the left pair k+1, k+2), the eliminated joint k+3, (the right pair r1 < r2) of split k."""
    return (k + 1, k + 2), k + 3, tuple(sorted(set(range(1, 7)) - {k, k + 1, k + 2, k + 3}))


def transform(R, t, F) -> list:
    """f(g·(l, p)) from F = f(l, p) for g = (R, t) (R a rotation): l → R l, p → R p + t, so
    p·p → p·p + 2 t·Rp + t·t, p·l → p·l + t·Rl, p × l → R(p × l) + t × Rl and
    (p·p) l − 2 (p·l) p → R[…] − 2 t × R(p × l) + (t·t) Rl − 2 (p·l) t − 2 (t·Rl) t."""
    rot = lambda v: [sum(R[r][c] * v[c] for c in range(3)) for r in range(3)]
    dot = lambda x, y: sum(a * b for a, b in zip(x, y))
    cross = lambda x, y: [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]
    l, p, pp, pl, cr, f4 = F[0:3], F[3:6], F[6], F[7], F[8:11], F[11:14]
    Rl, Rp, Rcr, Rf4 = rot(l), rot(p), rot(cr), rot(f4)
    tt, tRl = dot(t, t), dot(t, Rl)
    return (
        Rl
        + [x + y for x, y in zip(Rp, t)]
        + [pp + 2 * dot(t, Rp) + tt, pl + tRl]
        + [x + y for x, y in zip(Rcr, cross(t, Rl))]
        + [a - 2 * b + tt * c - 2 * pl * d - 2 * tRl * d for a, b, c, d in zip(Rf4, cross(t, Rcr), Rl, t)]
    )


def _a_pair(j, C, S, cphi, sphi, h):
    """A_k of the sinusoidal pair: Rz(θ + φ)·Tz(c + h C)·Tx(a)·Rx(α), θ = 2·atan2(S, C)."""
    cos2, sin2 = C * C - S * S, 2 * C * S
    c, s = cphi * cos2 - sphi * sin2, sphi * cos2 + cphi * sin2
    return _mul(_mul(_rz(c, s), _t(j["a"], j["d"] + h * C)), _rx(j["ca"], j["sa"]))


def _split_a(f, iC: int, iS: int, ring) -> list:
    """f as Σ C^i S^j · f_ij over A_BASIS, after checking that f is reduced and of degree ≤ 4."""
    out = [ring.zero] * len(A_BASIS)
    for monom, coeff in f.terms():
        key = (monom[iC], monom[iS])
        if key not in A_BASIS:
            raise AssertionError(f"ik1a5r: the A-pair's half angle enters an equation as C^{key[0]} S^{key[1]}")
        rest = list(monom)
        rest[iC] = rest[iS] = 0
        out[A_BASIS.index(key)] += ring({tuple(rest): coeff})
    return out


def equations(k: int):
    """(P, Q, pose, J, A): P[r][i][m] (i over A_BASIS, m over X_{k+1,k+2}) and Q[r][m] as
    expressions in the design symbols J[i] (keys c, s, a, ca, sa, d; joint k's c, s unused), the
    A-pair's A = {C, S, cphi, sphi, h} and the pose symbols (u, w for k = 3: T·(l0, p0); else T's
    twelve entries). Computed in the polynomial ring over Q, lex order, s before c, reduced modulo
    the circles of the R-pairs' angles, the twists, the A-pair's half angle and φ_k."""
    (m1, m2), e, (r1, r2) = split(k)
    J = {i: _syms(i) for i in range(1, 7)}
    A = {n: sp.Symbol(n, real=True) for n in ("S", "C", "sphi", "cphi", "h")}
    if k == 3:
        pose = list(sp.symbols("u0:3", real=True)) + list(sp.symbols("w0:3", real=True))
    else:
        pose = list(sp.symbols("T0:12", real=True))
    symbols = [A["S"], A["C"], A["sphi"], A["cphi"]]
    symbols += [J[i][x] for i in range(1, 7) for x in ("s", "c", "sa", "ca") if i != k or x in ("sa", "ca")]
    symbols += [J[i][x] for i in range(1, 7) for x in ("a", "d")] + [A["h"]] + pose
    ring, *gens = sp.ring(symbols, sp.QQ)
    G = dict(zip(symbols, gens))
    R = {i: {x: G[v] for x, v in J[i].items() if v in G} for i in J}
    circles = [G[A["S"]] ** 2 + G[A["C"]] ** 2 - 1, G[A["sphi"]] ** 2 + G[A["cphi"]] ** 2 - 1]
    circles += [G[J[i]["s"]] ** 2 + G[J[i]["c"]] ** 2 - 1 for i in range(1, 7) if i != k]
    circles += [G[J[i]["sa"]] ** 2 + G[J[i]["ca"]] ** 2 - 1 for i in range(1, 7)]
    Ak = _a_pair(R[k], G[A["C"]], G[A["S"]], G[A["cphi"]], G[A["sphi"]], G[A["h"]])
    left = _mul(_mul(Ak, _dh(R[m1])), _dh(R[m2]))
    FL = _fourteen([left[r][2] for r in range(3)], [left[r][3] for r in range(3)])
    # (l0, p0): A_e⁻¹'s third and fourth columns
    je = R[e]
    l0, p0 = [0, je["sa"], je["ca"]], [-je["a"], -je["d"] * je["sa"], -je["d"] * je["ca"]]
    pre = [[int(r == c) for c in range(4)] for r in range(4)]
    for i in range(k - 1, 0, -1):
        pre = _mul(pre, _dh_inverse(R[i]))
    if k == 3:  # C = I: T·(l0, p0) are the pose vectors, B carries them
        uw = [G[x] for x in pose]
        l = [sum(pre[r][c] * uw[c] for c in range(3)) for r in range(3)]
        p = [sum(pre[r][c] * uw[3 + c] for c in range(3)) + pre[r][3] for r in range(3)]
        FR = _fourteen(l, p)
    else:
        post = [[int(r == c) for c in range(4)] for r in range(4)]
        for i in range(6, k + 3, -1):
            post = _mul(post, _dh_inverse(R[i]))
        l = [sum(post[r][c] * l0[c] for c in range(3)) for r in range(3)]
        p = [sum(post[r][c] * p0[c] for c in range(3)) + post[r][3] for r in range(3)]
        Tg = [G[x] for x in pose]
        FR = transform([Tg[4 * r : 4 * r + 3] for r in range(3)], [Tg[4 * r + 3] for r in range(3)], _fourteen(l, p))
        if k > 1:
            FR = transform([row[:3] for row in pre[:3]], [row[3] for row in pre[:3]], FR)
    angle = lambda i: (G[J[i]["c"]], G[J[i]["s"]])
    iC, iS = ring.gens.index(G[A["C"]]), ring.gens.index(G[A["S"]])
    P, Q = [], []
    for eL, eR in zip(FL, FR):
        eL, eR = ring(eL).rem(circles), ring(eR).rem(circles)
        P.append([_coefficients(part, [angle(m1), angle(m2)], ring) for part in _split_a(eL, iC, iS, ring)])
        Q.append(_coefficients(eR, [angle(r1), angle(r2)], ring))
    return P, Q, pose, J, A


def spec(k: int) -> KernelSpec:
    """ik1a5r_equations_<k>(dh (6, 4), h (1,), T (4, 4)) -> P (14, 9, 9), Q (14, 9)."""
    P, Q, pose, J, A = equations(k)
    (m1, m2), e, (r1, r2) = split(k)
    dh = [sp.Symbol(f"{x}_{i}", real=True) for i in range(1, 7) for x in ("a", "alpha", "c", "phi")]
    h = sp.Symbol("h", real=True)
    Tm = sp.symbols("T0:16", real=True)
    sub = {A["h"]: h}
    steps = [(A["cphi"], sp.cos(dh[4 * k - 1])), (A["sphi"], sp.sin(dh[4 * k - 1]))]
    for i in range(1, 7):
        a, alpha, c, _phi = dh[4 * (i - 1) : 4 * i]
        sub[J[i]["a"]], sub[J[i]["d"]] = a, c
        steps += [(J[i]["ca"], sp.cos(alpha)), (J[i]["sa"], sp.sin(alpha))]
    if k == 3:
        col3 = (0, J[e]["sa"], J[e]["ca"])
        col4 = (-dh[4 * e - 4], -dh[4 * e - 2] * J[e]["sa"], -dh[4 * e - 2] * J[e]["ca"])
        Rt = [[Tm[4 * r + c] for c in range(3)] for r in range(3)]
        for r in range(3):
            steps.append((pose[r], sum(Rt[r][c] * col3[c] for c in range(3))))
        for r in range(3):
            steps.append((pose[3 + r], sum(Rt[r][c] * col4[c] for c in range(3)) + Tm[4 * r + 3]))
    else:
        sub.update(zip(pose, Tm[:12]))
    P_out = [sp.S(x).xreplace(sub) for row in P for part in row for x in part]
    Q_out = [sp.S(x).xreplace(sub) for row in Q for x in row]
    return KernelSpec(
        name=f"ik1a5r_equations_{k}",
        doc=(
            f"The Raghavan-Roth equations P(C, S) X{m1}{m2} = Q X{r1}{r2} of a six-joint chain whose joint {k} is "
            f"a sinusoidal A-pair (amplitude h; (C, S) its half angle; psi_i = theta_i + phi_i), joint {e} "
            f"eliminated: P (14 x 9 x 9) on (1, C, C^2, C^3, C^4, S, SC, SC^2, SC^3) x (1, c{m1}, s{m1}) x "
            f"(1, c{m2}, s{m2}) and Q (14 x 9) on (1, c{r1}, s{r1}) x (1, c{r2}, s{r2})."
        ),
        source=SOURCE,
        inputs=[
            Arg("dh", (6, 4), "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])", tuple(dh), design=True),
            Arg("h", (1,), f"joint {k}'s amplitude [m]", (h,), design=True),
            Arg("T", (4, 4), "the pose, row-major", tuple(Tm)),
        ],
        steps=steps,
        outputs=[
            Arg("P", (ROWS, 9, 9), "the left side's coefficients (design only)", exprs=tuple(P_out)),
            Arg("Q", (ROWS, 9), "the right side's coefficients", exprs=tuple(Q_out)),
        ],
    )


# ----------------------------------------------------------------------------- independent check
def check_equations(kernel: KernelSpec, k: int, samples: int = 3, digits: int = 40) -> float:
    """Largest |P(C, S) X − Q X_right| / (1 + |P X|) at random real poses T = A_1 … A_6 of chains
    whose joint k is a sinusoidal A-pair (mpmath DH product), the kernel evaluated in `digits`-digit
    arithmetic."""
    (m1, m2), _e, (r1, r2) = split(k)
    rng = random.Random(67 + k)
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
            h = mpmath.mpf(rng.uniform(0.05, 0.5))
            theta = [mpmath.mpf(rng.uniform(-6, 6)) for _ in range(6)]
            T = mpmath.eye(4)
            for i in range(6):
                d = h * mpmath.cos(theta[i] / 2) if i == k - 1 else 0
                T = T * _mp_dh(theta[i], d, *dh[i])
            env = {s: sp.Float(x, digits) for s, x in zip(kernel.inputs[0].symbols, [x for r in dh for x in r])}
            env[kernel.inputs[1].symbols[0]] = sp.Float(h, digits)
            env.update({s: sp.Float(T[j // 4, j % 4], digits) for j, s in enumerate(kernel.inputs[2].symbols)})
            for s, ex in kernel.steps:
                env[s] = sp.Float(sp.N(ex.xreplace(env), digits), digits)
            vals = [mpmath.mpf(sp.N(ex.xreplace(env), digits)) for a in kernel.outputs for ex in a.exprs]
            Pv, Qv = vals[: ROWS * 81], vals[ROWS * 81 :]
            cs = lambda i: [1, mpmath.cos(theta[i - 1] + dh[i - 1][3]), mpmath.sin(theta[i - 1] + dh[i - 1][3])]
            C, S = mpmath.cos(theta[k - 1] / 2), mpmath.sin(theta[k - 1] / 2)
            basis = [C**i * S**j for i, j in A_BASIS]
            XL = [x * y for x in cs(m1) for y in cs(m2)]
            XR = [x * y for x in cs(r1) for y in cs(r2)]
            for r in range(ROWS):
                lhs = sum(Pv[81 * r + 9 * i + m] * basis[i] * XL[m] for i in range(9) for m in range(9))
                rhs = sum(Qv[9 * r + m] * XR[m] for m in range(9))
                worst = max(worst, float(abs(lhs - rhs) / (1 + abs(lhs))))
    assert worst < 1e-30, f"ik1a5r_equations_{k}: the 14 equations fail at a 1A5R pose by {worst}"
    return worst


def derive(part=None):
    """The kernel of split `part` (1, 2, 3; None: all three), after the independent check."""
    if part is None:
        parts = [derive(k) for k in PARTS]
        return [], [s for _, specs, _ in parts for s in specs], {k: f for k, (_, _, f) in zip(PARTS, parts)}
    if part not in PARTS:
        raise ValueError(f"part: expected one of {PARTS}, got {part!r}")
    kernel = spec(part)
    return [], [kernel], {"equations_check": check_equations(kernel, part)}
