"""Direct kinematics and geometric Jacobians of nA-chains, n = 1..7 (docs/conventions.md §3-§4).

A_i(θ_i) = Rz(θ_i + φ_i) · Tz(c_i + d_i) · Tx(a_i) · Rx(α_i), each factor built from its elementary
motion, both as a 4x4 matrix and as a Study point (dual-quaternion product). Each joint enters
through its law values (cos(θ_i/2), sin(θ_i/2), d_i, d'_i, d''_i), computed by the pair's law kernel
from one sincos of θ_i/2, so one chain kernel serves R-pairs (d ≡ 0), sinusoidal and general A-pairs
alike without a trigonometric call of its own: cos θ, sin θ follow by the double-angle formulas
and φ_i, α_i enter through their cos and sin, design constants that a batch computes once.

The chain product is written as a recursion of named steps (frame i = frame i-1 · A_i, with the
rotation applied one elementary factor at a time), so the expanded expression is never formed. The Jacobian uses the screw form of docs/conventions.md §4 on those
frames; `check_jacobian` proves it equal to the derivative of the forward kinematics
(chain rule through d_i(θ_i)) at random points in 50-digit arithmetic.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .autodiff import directional
from .quaternions import Quaternion, StudyPoint, rotation, translation
from .spec import Arg, Call, Entry, KernelSpec, PolynomialSet

SOURCE = "derivations/chain_kinematics.py"
MAX_N = 7


LAW_FIELDS = ("ch", "sh", "d", "dd", "ddd")
LAW_DOC = (
    "per joint (cos(theta_i/2), sin(theta_i/2), d_i [m], d'_i [m/rad], d''_i [m/rad^2]) from the pair's law kernel"
)


def joint_symbols(i: int) -> dict[str, sp.Symbol]:
    """Symbols of joint i (1-based): the angle (for reference derivations), the law values
    ch, sh = cos, sin(θ/2) and d, d', d'', and the DH constants."""
    names = ("theta",) + LAW_FIELDS + ("a", "alpha", "c", "phi", "w")
    return {k: sp.Symbol(f"{k}_{i}", real=True) for k in names}


TURNING_DOC = (
    "per joint w_i = d(theta_i)/dq_i: 1 where the joint variable q_i is the angle (R-, A- and H-pairs), "
    "0 where it is the slide d_i (P-pairs)"
)


def turning_arg(J: list[dict]) -> Arg:
    """The (n,) design input w of the kernels that differentiate in the joint variables (the
    Jacobian, the dynamics): joint i turns by w_i q'_i and slides by d'_i q'_i."""
    return Arg("turning", (len(J),), TURNING_DOC, tuple(j["w"] for j in J), design=True)


def chain_inputs(n: int) -> tuple[list[Arg], list[dict]]:
    """The two input arrays shared by every chain kernel: law (n, 5) and dh (n, 4)."""
    J = [joint_symbols(i) for i in range(1, n + 1)]
    return [
        Arg("law", (n, 5), LAW_DOC, tuple(j[k] for j in J for k in LAW_FIELDS)),
        Arg(
            "dh",
            (n, 4),
            "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])",
            tuple(j[k] for j in J for k in ("a", "alpha", "c", "phi")),
            design=True,
        ),
    ], J


# An R-pair's values of the generic kernels' per-joint inputs: its angle is the joint variable
# (w = 1), it does not slide (d and its derivatives d', d'', d''' = 0) and it has no legs (the
# dynamics' leg mass m_leg = 0)
REVOLUTE_VALUES = {"d": 0, "dd": 0, "ddd": 0, "dddd": 0, "w": 1, "ml": 0}


def revolute_name(name: str) -> str:
    """The name of kernel `name`'s form for chains of R-pairs: <family><n> -> <family>_revolute<n>."""
    family = name.rstrip("0123456789")
    return f"{family}_revolute{name[len(family) :]}"


def revolute(spec: KernelSpec, twins: dict[str, KernelSpec] | None = None) -> KernelSpec:
    """`spec`'s kernel for chains of R-pairs, named <family>_revolute<n>: its steps and outputs with
    REVOLUTE_VALUES put in, so that the slide, pitch and leg terms of the generic kernel drop out
    (a third of the mass matrix's operations). The inputs are the generic kernel's (the values it
    fixes are not read), so that a caller takes either with the same arguments; `twins` maps the
    kernels `spec` calls to their R-chain forms."""
    values = {}
    for a in spec.inputs:
        for s in a.symbols:
            field, _, joint = s.name.rpartition("_")
            if field in REVOLUTE_VALUES and joint.isdigit():
                values[s] = sp.S(REVOLUTE_VALUES[field])
    put = lambda e: sp.S(e).xreplace(values)
    twins = twins or {}
    return KernelSpec(
        name=revolute_name(spec.name),
        doc=f"{spec.doc} Chains of R-pairs only: reads neither the law's d, d', d'' (nor d''') nor turning or legs.",
        source=spec.source,
        inputs=spec.inputs,
        outputs=[Arg(a.name, a.shape, a.doc, exprs=tuple(put(e) for e in a.exprs)) for a in spec.outputs],
        steps=[(s, put(e)) for s, e in spec.steps],
        calls=[Call(twins[c.kernel.name], c.args, c.results) for c in spec.calls],
        wide=spec.wide,
    )


def at_angles(J: list[dict]) -> dict:
    """The law's trigonometric inputs as functions of the angles, for reference derivations."""
    out = {}
    for j in J:
        out[j["ch"]] = sp.cos(j["theta"] / 2)
        out[j["sh"]] = sp.sin(j["theta"] / 2)
    return out


def joint_trig(j: dict, rec: _Recorder, label: str) -> tuple[sp.Expr, sp.Expr, sp.Expr, sp.Expr]:
    """(cos θ, sin θ, cos(θ + φ), sin(θ + φ)) of joint j as steps, from the half-angle law values
    (or from cos θ, sin θ themselves where j has them: the inverse-kinematics system's inputs)."""
    if "ct" in j:
        ct, st = j["ct"], j["st"]
    else:
        ct = rec.name(f"ct{label}", j["ch"] ** 2 - j["sh"] ** 2)
        st = rec.name(f"st{label}", 2 * j["ch"] * j["sh"])
    cp, sp_ = sp.cos(j["phi"]), sp.sin(j["phi"])
    return ct, st, rec.name(f"cq{label}", ct * cp - st * sp_), rec.name(f"sq{label}", st * cp + ct * sp_)


def _rot(axis: int, angle) -> sp.Matrix:
    c, s = sp.cos(angle), sp.sin(angle)
    m = sp.eye(4)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _trans(axis: int, dist) -> sp.Matrix:
    m = sp.eye(4)
    m[axis, 3] = dist
    return m


def dh_matrix(j: dict) -> sp.Matrix:
    """A_i as the product of its four elementary motions (in the angle θ_i)."""
    return _rot(2, j["theta"] + j["phi"]) * _trans(2, j["c"] + j["d"]) * _trans(0, j["a"]) * _rot(0, j["alpha"])


def dh_study_half(j: dict) -> tuple[sp.Expr, sp.Expr]:
    """cos and sin of (θ_i + φ_i)/2 from the law values and φ_i/2."""
    cp, sp_ = sp.cos(j["phi"] / 2), sp.sin(j["phi"] / 2)
    return j["ch"] * cp - j["sh"] * sp_, j["sh"] * cp + j["ch"] * sp_


def dh_study(j: dict, half=None):
    """The Study point of A_i: the dual-quaternion product of the same four motions. `half`:
    (cos, sin) of (θ_i + φ_i)/2, by default from the law values (ch, sh) and φ_i/2."""
    if half is None:
        half = dh_study_half(j)
    half_a = j["alpha"] / 2
    return (
        rotation((0, 0, 1), *half)
        * translation((0, 0, j["c"] + j["d"]))
        * translation((j["a"], 0, 0))
        * rotation((1, 0, 0), sp.cos(half_a), sp.sin(half_a))
    )


class _Recorder:
    """Collects named steps; `name(prefix, expr)` returns a symbol, or the expr if it is trivial."""

    def __init__(self):
        self.steps: list[tuple[sp.Symbol, sp.Expr]] = []

    def name(self, label: str, expr) -> sp.Expr:
        expr = sp.S(expr)
        if expr.is_Atom or (expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1 and expr.args[1].is_Atom):
            return expr
        sym = sp.Symbol(label, real=True)
        self.steps.append((sym, expr))
        return sym


def frames(n: int, J: list[dict], rec: _Recorder) -> list[sp.Matrix]:
    """Frames 0..n as 4x4 matrices whose entries are step symbols (frame 0 = identity).

    R_i = R_{i-1} Rz(θ_i + φ_i) Rx(α_i) one factor at a time (U = R_{i-1} Rz first), and
    o_i = o_{i-1} + (c_i + d_i) z_{i-1} + a_i U e_x: 24 multiplications per joint."""
    out = [sp.eye(4)]
    for i, j in enumerate(J, start=1):
        _, _, cq, sq = joint_trig(j, rec, f"{i}")
        T = out[-1]
        R = [T[:3, k] for k in range(3)]
        U0 = [rec.name(f"U{i}_{r}0", sp.expand(R[0][r] * cq + R[1][r] * sq)) for r in range(3)]
        U1 = [rec.name(f"U{i}_{r}1", sp.expand(R[1][r] * cq - R[0][r] * sq)) for r in range(3)]
        ca, sa = sp.cos(j["alpha"]), sp.sin(j["alpha"])
        named = sp.eye(4)
        for r in range(3):
            named[r, 0] = U0[r]
            named[r, 1] = rec.name(f"T{i}_{r}1", sp.expand(U1[r] * ca + R[2][r] * sa))
            named[r, 2] = rec.name(f"T{i}_{r}2", sp.expand(R[2][r] * ca - U1[r] * sa))
            named[r, 3] = rec.name(f"T{i}_{r}3", sp.expand(T[r, 3] + (j["c"] + j["d"]) * R[2][r] + j["a"] * U0[r]))
        out.append(named)
    return out


def fk_spec(n: int) -> KernelSpec:
    inputs, J = chain_inputs(n)
    rec = _Recorder()
    T = frames(n, J, rec)[-1]
    return KernelSpec(
        name=f"fk{n}",
        doc=f"Forward kinematics of a {n}-joint chain: T = A_1 ... A_{n}, base frame -> frame {n}.",
        source=SOURCE,
        inputs=inputs,
        steps=rec.steps,
        outputs=[Arg("T", (4, 4), "homogeneous transform, row-major", exprs=tuple(T))],
    )


def fk_study_spec(n: int) -> KernelSpec:
    inputs, J = chain_inputs(n)
    rec = _Recorder()

    def joint(i, j):
        half = [rec.name(f"H{i}_{k}", e) for k, e in enumerate(dh_study_half(j))]
        return [rec.name(f"Q{i}_{k}", sp.expand(c)) for k, c in enumerate(dh_study(j, half).as_list())]

    comps = joint(1, J[0])
    for i, j in enumerate(J[1:], start=2):
        prev = [rec.name(f"S{i - 1}_{k}", c) for k, c in enumerate(comps)]
        joint_i = joint(i, j)
        P = StudyPoint(Quaternion(*prev[:4]), Quaternion(*prev[4:])) * StudyPoint(
            Quaternion(*joint_i[:4]), Quaternion(*joint_i[4:])
        )
        comps = [sp.expand(c) for c in P.as_list()]
    return KernelSpec(
        name=f"fk_study{n}",
        doc=(
            f"Study point (x0..x3, y0..y3) of a {n}-joint chain, the dual-quaternion product of the joints'; "
            "x is a unit quaternion, and (x, y) ~ (-x, -y)."
        ),
        source=SOURCE,
        inputs=inputs,
        steps=rec.steps,
        outputs=[Arg("study", (8,), "Study parameters (x0, x1, x2, x3, y0, y1, y2, y3)", exprs=tuple(comps))],
    )


def screw_jacobian(F: list[sp.Matrix], J: list[dict], turning: bool = True) -> sp.Matrix:
    """Columns [w_i z_{i-1} × (o_n − o_{i-1}) + d'_i z_{i-1}; w_i z_{i-1}] from the frames, with
    `turning` (else w_i = 1: every joint variable an angle)."""
    n = len(J)
    o_n = F[n][:3, 3]
    cols = []
    for i in range(1, n + 1):
        z = F[i - 1][:3, 2]
        o = F[i - 1][:3, 3]
        w = J[i - 1]["w"] if turning else 1
        v = w * z.cross(o_n - o) + J[i - 1]["dd"] * z
        cols.append(v.col_join(w * z))
    return sp.Matrix.hstack(*cols)


def jacobian_spec(n: int) -> KernelSpec:
    inputs, J = chain_inputs(n)
    rec = _Recorder()
    F = frames(n, J, rec)
    Jm = screw_jacobian(F, J)
    return KernelSpec(
        name=f"jacobian{n}",
        doc=(
            f"Geometric Jacobian (6 x {n}, base frame, rows [v; omega], v the velocity of the origin of "
            f"frame {n}) of a {n}-joint chain in the joint variables: column i turns by w_i and slides "
            "by d'_i along z_(i-1)."
        ),
        source=SOURCE,
        inputs=inputs + [turning_arg(J)],
        steps=rec.steps,
        outputs=[Arg("J", (6, n), "Jacobian, row-major", exprs=tuple(Jm))],
    )


def jacobian_dot_spec(n: int) -> KernelSpec:
    """J̇ = dJ/dt along q' (6 × n): the Jacobian's steps differentiated forward along the velocity
    (autodiff.directional): each joint's law values move by q'_i times their derivatives in q_i
    (cos(θ/2) → −w sin(θ/2)/2, sin(θ/2) → w cos(θ/2)/2, d → d', d' → d''). J̇q' is the bias of the
    tool's acceleration, a = J q'' + J̇ q', which operational-space control needs."""
    inputs, J = chain_inputs(n)
    qd = Arg(
        "qd",
        (n,),
        "joint velocities q'_i [rad/s; m/s for a slide]",
        tuple(sp.Symbol(f"qd_{i}", real=True) for i in range(1, n + 1)),
    )
    rec = _Recorder()
    Jm = screw_jacobian(frames(n, J, rec), J)
    tangent: dict = {}
    for j, v in zip(J, qd.symbols):
        w = j["w"]
        for sym, rate in (
            (j["ch"], -w * j["sh"] / 2),
            (j["sh"], w * j["ch"] / 2),
            (j["d"], j["dd"]),
            (j["dd"], j["ddd"]),
        ):
            tangent[sym] = tangent.get(sym, 0) + rate * v
    steps, Jdot = directional(rec.steps, list(Jm), tangent, "dJ_")
    return KernelSpec(
        name=f"jacobian_dot{n}",
        doc=(
            f"Time derivative of the geometric Jacobian (6 x {n}, base frame, rows [v; omega]) of a {n}-joint "
            "chain moving at q': dJ/dt, with J of jacobian{n}."
        ),
        source=SOURCE,
        inputs=[inputs[0], qd, inputs[1], turning_arg(J)],
        steps=rec.steps + steps,
        outputs=[Arg("Jdot", (6, n), "dJ/dt, row-major", exprs=tuple(Jdot))],
    )


def check_jacobian(n: int, samples: int = 3, digits: int = 50) -> float:
    """Max |screw Jacobian − derivative of FK| over random points, in `digits`-digit arithmetic.

    The derivative is taken on the fully expanded FK in the angles θ_i and slides d_i, with
    d/dq_i = w_i ∂/∂θ_i + d'_i ∂/∂d_i (θ_i = w_i q_i, d_i = d_i(q_i)), and the angular part from the
    skew matrix (∂R/∂q_i) Rᵀ: an independent route to the same columns (which come from the
    half-angle law values), for any turning factors w_i.
    """
    _, J = chain_inputs(n)
    T = sp.eye(4)
    for j in J:
        T = T * dh_matrix(j)
    R = T[:3, :3]
    cols = []
    for j in J:
        dT = j["w"] * T.diff(j["theta"]) + j["dd"] * T.diff(j["d"])
        W = dT[:3, :3] * R.T
        cols.append(dT[:3, 3].col_join(sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])))
    J_diff = sp.Matrix.hstack(*cols)
    rec = _Recorder()
    F = frames(n, J, rec)
    env = {}
    for s, e in rec.steps:
        env[s] = e.xreplace(env)
    J_screw = screw_jacobian(F, J).xreplace(env).xreplace(at_angles(J))
    syms = sorted(J_diff.free_symbols | J_screw.free_symbols, key=str)
    f = sp.lambdify(syms, J_diff - J_screw, modules="mpmath")
    rng = random.Random(n)
    worst = mpmath.mpf(0)
    with mpmath.workdps(digits):
        for _ in range(samples):
            vals = [mpmath.mpf(rng.uniform(-2, 2)) for _ in syms]
            worst = max(worst, max(abs(v) for v in f(*vals)))
    assert worst < mpmath.mpf(10) ** (-(digits - 10)), f"screw Jacobian != dFK/dtheta for n={n}: {worst}"
    return float(worst)


def joint_polynomials() -> PolynomialSet:
    """The single DH joint, as a matrix and as a Study point, for reading."""
    j = joint_symbols(1)
    A = dh_matrix(j)
    half_t = (j["theta"] + j["phi"]) / 2
    P = dh_study(j, (sp.cos(half_t), sp.sin(half_t)))
    comps = [sp.factor(sp.expand(c)) for c in P.as_list()]
    names = ["x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3"]
    return PolynomialSet(
        name="dh_joint",
        title="One joint of an A-chain: Rz(theta+phi) Tz(c+d) Tx(a) Rx(alpha)",
        source=SOURCE,
        description="d is the pair's law value d(theta) (0 for an R-pair, h cos(theta/2) for a sinusoidal A-pair).",
        entries=[Entry(f"A[{r},{c}]", A[r, c], ()) for r in range(3) for c in range(4)]
        + [Entry(f"study_{nm}", e, ()) for nm, e in zip(names, comps)],
    )


def chain_study_polynomials(n: int = 2) -> PolynomialSet:
    """The Study point of an n-joint chain, expanded in the half-angle variables of its joints.

    With C_i, S_i = cos, sin((θ_i + φ_i)/2), K_i, L_i = cos, sin(α_i/2) and D_i = c_i + d_i(θ_i),
    each component is a polynomial; its degrees and term counts are what constraint varieties and
    inverse kinematics work with.
    """
    _, J = chain_inputs(n)
    subs, gens = {}, []
    P = None
    for i, j in enumerate(J, start=1):
        C, S, K, L, D = sp.symbols(f"C_{i} S_{i} K_{i} L_{i} D_{i}", real=True)
        gens += [C, S, K, L, j["a"], D]
        half_t, half_a = (j["theta"] + j["phi"]) / 2, j["alpha"] / 2
        subs.update({sp.cos(half_t): C, sp.sin(half_t): S, sp.cos(half_a): K, sp.sin(half_a): L})
        Q = dh_study(j, (sp.cos(half_t), sp.sin(half_t)))
        Q = StudyPoint(
            Quaternion(*[sp.expand(c).xreplace(subs).subs(j["c"] + j["d"], D) for c in Q.x.as_list()]),
            Quaternion(*[sp.expand(sp.expand(c).xreplace(subs).subs(j["c"], D - j["d"])) for c in Q.y.as_list()]),
        )
        P = Q if P is None else P * Q
    names = ["x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3"]
    comps = [sp.expand(c) for c in P.as_list()]
    for c in comps:
        assert c.free_symbols <= set(gens), c.free_symbols - set(gens)
    return PolynomialSet(
        name=f"chain{n}_study",
        title=f"Study point of a {n}-joint A-chain in half-angle variables",
        source=SOURCE,
        description=(
            "C_i, S_i = cos, sin((theta_i + phi_i)/2); K_i, L_i = cos, sin(alpha_i/2); "
            "D_i = c_i + d_i(theta_i) (d_i = h_i cos(theta_i/2) for a sinusoidal pair)."
        ),
        entries=[Entry(nm, c, tuple(gens)) for nm, c in zip(names, comps)],
    )


def derive():
    """All chain-kinematics kernels for n = 1..MAX_N, after checking the Jacobian route."""
    checks = {n: check_jacobian(n) for n in (1, 2, 3)}
    specs = []
    for n in range(1, MAX_N + 1):
        fk, jacobian = fk_spec(n), jacobian_spec(n)
        specs += [fk, fk_study_spec(n), jacobian, jacobian_dot_spec(n), revolute(fk), revolute(jacobian)]
    return [joint_polynomials(), chain_study_polynomials(2)], specs, {"jacobian_check": checks}
