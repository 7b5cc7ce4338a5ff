"""The inverse kinematics of n-joint chains as a homotopy system over the complex numbers.

Path tracking (apair.ik.homotopy, and the tracker apair_ik_track.c in src/csrc) continues the solutions of
fk(θ) = T from a generic complex pose to the user's pose, so it needs the equations at complex
joint values and complex poses, with their derivatives:

- Joint variables. Each joint's law values are taken at z = exp(iθ/2): the law kernels `ik_law_*`
  give (cos(θ/2), sin(θ/2), d, d') at a complex z, from the pair's law d(θ) (`apair_pair.LAWS`)
  with θ = −2i log z substituted: Laurent polynomials, no trigonometric call. (An A-pair's pose
  changes with θ + 2π, an R-pair's does not: the tracker identifies R-pair angles modulo 2π.)
  A P-pair's variable is its slide x itself (its angle held at 0, φ_i its fixed angle): its law
  values are (1, 0, x, 1), with the turning factor w = 0 (below), and F is linear in x.
- The target. A pose is (t, q): translation t ∈ C³ and rotation quaternion q ∈ C⁴ up to scale,
  both entering linearly, so that a straight line between two poses is a homotopy of poses and the
  solution set over all (t, q) is irreducible (monodromy can reach every solution).
- The system (`ik_system6`): F = [o(θ) − t ; vec(q̄ ⊗ x(θ))], with o the end frame's origin
  (`chain_kinematics.frames`, the recursion of the fk kernels) and x(θ) its rotation quaternion
  (the product of the joints' Rz((θ_i + φ_i)/2)·Rx(α_i/2), as in the fk_study kernels). The vector
  part of q̄ ⊗ x vanishes exactly when x ∝ q (q̄ ⊗ q = q·q is scalar), i.e. when the rotations
  agree: no other solutions (a random combination of the twelve equations q ⊗ e_k = (R e_k) ⊗ q
  would add a whole component of spurious ones).
- Derivatives. ∂F/∂θ_i = [v_i ; G ω_i] with [v_i; ω_i] the screw Jacobian's column i
  (`chain_kinematics.screw_jacobian`, pitch d'_i and the turning factor w_i included: 1 for an
  angle, 0 for a P-pair's slide, whose column is [z_{i−1}; 0]) and G_c = ½ vec(q̄ ⊗ e_c ⊗ x), since
  ∂x/∂θ_i = ½ (0, ω_i) ⊗ x. Fs = [−dt ; vec(dq̄ ⊗ x)] is the derivative along a direction (dt, dq).

Complex values are carried as (real, imaginary) pairs: every step is split into its real and
imaginary parts (`split_complex`), so the one emitter prints ordinary C and NumPy for them.
`check_system` compares F, ∂F/∂θ and Fs with an independent route (the 4×4 DH product in mpmath,
the quaternion from the rotation matrix, complex central differences) at random complex points.
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from .apair_pair import LAWS, h, theta
from .chain_kinematics import _Recorder, dh_study_half, frames, joint_symbols, screw_jacobian, turning_arg
from .quaternions import Quaternion
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_ik.py"
MAX_N = 6
LAW_FIELDS = ("ch", "sh", "d", "dd")  # cos(θ/2), sin(θ/2), d, d'
I = sp.I


# ----------------------------------------------------------------------------- complex splitting
def _parts(expr: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(real, imaginary) parts of an expression in real symbols, expanded."""
    e = sp.expand(expr, complex=False)
    if e.has(I):
        e = sp.expand(e)
    re, im = [], []
    for term in sp.Add.make_args(e):
        c = term.coeff(I) if term.has(I) else sp.S(0)
        if c != 0 and not c.has(I):
            im.append(c)
        else:
            re.append(term)
    re, im = sp.Add(*re), sp.Add(*im)
    assert not re.has(I) and not im.has(I), expr
    return re, im


def _reciprocal(x: sp.Expr, y: sp.Expr, rec: _Recorder, label: str) -> tuple[sp.Expr, sp.Expr]:
    """1/(x + iy) as (x, −y)/(x² + y²), the denominator once."""
    inv = rec.name(f"{label}_n", 1 / (x * x + y * y))
    return x * inv, -y * inv


def split_complex(steps, outputs, parts: dict) -> tuple[list, list]:
    """Steps (symbol, complex expression) and outputs (complex expressions) in symbols that stand
    for complex values → the same over real symbols. parts: {complex symbol: (re, im)} for the
    inputs; each step symbol s becomes s_re, s_im (or stays one real symbol if its value is real).
    A reciprocal 1/s of a complex step is rewritten as conj(s)/|s|²."""
    parts = dict(parts)
    rec = _Recorder()

    def real_of(expr):
        # reciprocals of complex symbols first (the only division the system has)
        subs = {}
        for p in expr.atoms(sp.Pow):
            if p.exp.is_Integer and p.exp < 0 and p.base in parts:
                inv = sp.Symbol(f"{p.base.name}_inv")
                if inv not in parts:
                    parts[inv] = _reciprocal(*parts[p.base], rec, inv.name)
                subs[p] = inv**-p.exp
        expr = expr.xreplace(subs)
        return _parts(expr.xreplace({s: re + I * im for s, (re, im) in parts.items()}))

    for sym, expr in steps:
        re, im = real_of(expr)
        if im == 0:
            parts[sym] = (rec.name(sym.name, re), sp.S(0))
        else:
            parts[sym] = (rec.name(f"{sym.name}_re", re), rec.name(f"{sym.name}_im", im))
    out = [real_of(e) for e in outputs]
    return rec.steps, out


def _complex_arg(name: str, shape, doc: str, labels, design: bool = False):
    """An input of complex values as a real array (..., 2) of (re, im); returns the Arg and
    {complex placeholder: (re symbol, im symbol)} in row-major order."""
    parts, symbols, placeholders = {}, [], []
    for lab in labels:
        z = sp.Symbol(lab)
        re, im = sp.Symbol(f"{lab}_re", real=True), sp.Symbol(f"{lab}_im", real=True)
        parts[z] = (re, im)
        symbols += [re, im]
        placeholders.append(z)
    return (
        Arg(name, tuple(shape) + (2,), doc + " (real, imaginary)", tuple(symbols), design=design),
        parts,
        placeholders,
    )


def _complex_out(name: str, shape, doc: str, pairs) -> Arg:
    return Arg(name, tuple(shape) + (2,), doc + " (real, imaginary)", exprs=tuple(e for p in pairs for e in p))


# ----------------------------------------------------------------------------- joint laws
def law_in_variable(kind: str):
    """(cos(θ/2), sin(θ/2), d, d') of a pair as Laurent polynomials in z = exp(iθ/2), from the
    derived law d(θ) (LAWS) with θ = −2i log z."""
    z = sp.Symbol("v")
    th = -2 * I * sp.log(z)
    d_expr, _ = LAWS[kind]
    vals = [sp.cos(theta / 2), sp.sin(theta / 2), d_expr, sp.diff(d_expr, theta)]
    out = [sp.expand(sp.simplify(e.subs(theta, th).rewrite(sp.exp))) for e in vals]
    for e in out:
        assert not e.has(sp.log, sp.exp, sp.cos, sp.sin), (kind, e)
    # the same values on the angle route, at a complex point
    z0 = sp.Rational(3, 5) + I * sp.Rational(7, 10)
    for e, ref in zip(out, vals):
        num = complex(sp.N(e.subs({z: z0, h: sp.Rational(13, 10)}), 30))
        want = complex(sp.N(ref.subs({theta: th.subs(z, z0), h: sp.Rational(13, 10)}), 30))
        assert abs(num - want) < 1e-20, (kind, e)
    return z, out


def law_spec(kind: str) -> KernelSpec:
    """Kernel: z = exp(iθ/2) (complex) [and h] → (cos(θ/2), sin(θ/2), d, d')."""
    z, exprs = law_in_variable(kind)
    arg, parts, _ = _complex_arg("v", (1,), "exp(i theta/2)", ["v"])
    inputs = [arg]
    if kind != "revolute":
        inputs.append(Arg("h", (1,), "amplitude h [m]", (h,)))
    steps, outs = split_complex([], exprs, parts)
    return KernelSpec(
        name=f"ik_law_{kind}",
        doc=(
            f"The {kind} pair's law at a complex angle, given as v = exp(i theta/2): cos(theta/2), "
            "sin(theta/2), d and d'."
        ),
        source=SOURCE,
        inputs=inputs,
        steps=steps,
        outputs=[_complex_out("law", (4,), "(cos(theta/2), sin(theta/2), d [m], d' [m/rad])", outs)],
    )


# ----------------------------------------------------------------------------- the system
def _skew(a) -> list[list[sp.Expr]]:
    """[a]×, the matrix of u ↦ a × u."""
    return [[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]]


def _pure_times(q: Quaternion) -> list[list[sp.Expr]]:
    """The 4 × 3 matrix of u ↦ (0, u) ⊗ q (linear in q)."""
    u = sp.symbols("u1:4")
    prod = (Quaternion.pure(u) * q).as_list()
    return [[sp.expand(c).coeff(u[k]) for k in range(3)] for c in prod]


def _times_axis(k: int) -> list[list[sp.Expr]]:
    """The 4 × 4 matrix of q ↦ q ⊗ e_k."""
    q = sp.symbols("w0:4")
    e = [0, 0, 0]
    e[k] = 1
    prod = (Quaternion(*q) * Quaternion.pure(e)).as_list()
    return [[sp.expand(c).coeff(q[m]) for m in range(4)] for c in prod]


def _vec_conj_times(q, x: Quaternion) -> list[sp.Expr]:
    """vec(q̄ ⊗ x) for a quaternion given as its four components q."""
    return (Quaternion(*q).conj() * x).vec()


def _rotation(J: list[dict], rec: _Recorder) -> Quaternion:
    """The end frame's rotation quaternion, one joint at a time:
    x_i = x_{i-1} ⊗ Rz((θ_i + φ_i)/2) ⊗ Rx(α_i/2), each x_i named."""
    x = Quaternion(sp.S(1), sp.S(0), sp.S(0), sp.S(0))
    for i, j in enumerate(J, start=1):
        c, s_ = (rec.name(f"H{i}_{k}", e) for k, e in enumerate(dh_study_half(j)))
        ca, sa = sp.cos(j["alpha"] / 2), sp.sin(j["alpha"] / 2)
        x = x * Quaternion(c, sp.S(0), sp.S(0), s_) * Quaternion(ca, sa, sp.S(0), sp.S(0))
        x = Quaternion(*[rec.name(f"X{i}_{k}", sp.expand(e)) for k, e in enumerate(x.as_list())])
    return x


def _residual(T: sp.Matrix, x: Quaternion, tsyms) -> list[sp.Expr]:
    """F = [o − t ; vec(q̄ ⊗ x)] for the end frame T, its quaternion x and the pose (t, q)."""
    return [T[k, 3] - tsyms[k] for k in range(3)] + [sp.expand(e) for e in _vec_conj_times(tsyms[3:], x)]


def system_spec(n: int) -> KernelSpec:
    """ik_system{n}: F, ∂F/∂θ and the derivative along a direction of poses (module docstring)."""
    labels = [f"{f}_{i}" for i in range(1, n + 1) for f in LAW_FIELDS]
    law_arg, parts, law_syms = _complex_arg(
        "law", (n, 4), "per joint (cos(theta_i/2), sin(theta_i/2), d_i [m], d'_i [m/rad])", labels
    )
    tgt_arg, tparts, tsyms = _complex_arg(
        "target",
        (7,),
        "pose (t [m], q): translation and rotation quaternion up to scale",
        ["t1", "t2", "t3", "q0", "q1", "q2", "q3"],
    )
    dir_arg, dparts, dsyms = _complex_arg(
        "direction",
        (7,),
        "a direction (dt, dq) in the same coordinates",
        ["dt1", "dt2", "dt3", "dq0", "dq1", "dq2", "dq3"],
    )
    parts.update(tparts)
    parts.update(dparts)
    J = []
    for i in range(1, n + 1):
        j = joint_symbols(i)
        j.update({f: law_syms[4 * (i - 1) + k] for k, f in enumerate(LAW_FIELDS)})
        J.append(j)
    dh_arg = Arg(
        "dh",
        (n, 4),
        "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])",
        tuple(j[k] for j in J for k in ("a", "alpha", "c", "phi")),
        design=True,
    )
    rec = _Recorder()
    F = frames(n, J, rec)
    Jm = screw_jacobian(F, J)
    T = F[n]
    x = _rotation(J, rec)
    q, dq = tsyms[3:], dsyms[3:]
    # G[c] = ½ vec(q̄ ⊗ e_c ⊗ x): the rotation residual's derivative along axis c
    G = []
    for c in range(3):
        e = [0, 0, 0]
        e[c] = 1
        G.append(
            [
                rec.name(f"G{c}_{r}", sp.expand(v / 2))
                for r, v in enumerate((Quaternion(*q).conj() * Quaternion.pure(e) * x).vec())
            ]
        )
    F_out = _residual(T, x, tsyms)
    J_out = []
    for r in range(6):
        for i in range(n):
            J_out.append(Jm[r, i] if r < 3 else sp.expand(sum(G[c][r - 3] * Jm[3 + c, i] for c in range(3))))
    Fs_out = [-dsyms[k] for k in range(3)] + [sp.expand(e) for e in _vec_conj_times(dq, x)]
    steps, outs = split_complex(rec.steps, F_out + J_out + Fs_out, parts)
    nF, nJ = 6, 6 * n
    return KernelSpec(
        name=f"ik_system{n}",
        doc=(
            f"The inverse-kinematics homotopy system of a {n}-joint chain at complex law values and a complex "
            "pose (t, q): F = [o - t; vec(conj(q) x)] (zero exactly where fk = (t, q)), dF/dtheta (6 x n) and "
            "the derivative of F along a direction (dt, dq) of poses."
        ),
        source=SOURCE,
        inputs=[law_arg, tgt_arg, dir_arg, dh_arg, turning_arg(J)],
        steps=steps,
        outputs=[
            _complex_out("F", (6,), "residual", outs[:nF]),
            _complex_out("dF", (6, n), "derivative in the joint angles, row-major", outs[nF : nF + nJ]),
            _complex_out("dFs", (6,), "derivative along the direction", outs[nF + nJ :]),
        ],
    )


def residual_spec(n: int) -> KernelSpec:
    """ik_residual{n}: F of ik_system{n} alone, from z_i = exp(iθ_i/2) and the amplitudes h_i
    (the sinusoidal law; h = 0 is an R-pair's) and the slides x_i added to d_i (a P-pair: z_i = 1,
    h_i = 0, x_i its variable), also emitted in extended precision (`wide`).

    Far out in the complex (|Im θ| ≈ 10) the terms of F that cancel are exp(2|Im θ|) larger than
    F: in double precision Newton's method stalls at about 1e-5. The tracker's corrector takes F
    from the wide version there and the Jacobian from ik_system6 (a Jacobian with a relative error
    far below 1 still converges), so that such paths are tracked and their endpoints refined."""
    zr, law_r = law_in_variable("revolute")
    zs, law_s = law_in_variable("sinusoidal")
    assert all(sp.expand(a - b.subs({h: 0, zs: zr})) == 0 for a, b in zip(law_r, law_s)), (
        "an R-pair's law is the sinusoidal law with h = 0"
    )
    v_arg, parts, vsyms = _complex_arg("v", (n,), "per joint exp(i theta_i/2)", [f"v_{i}" for i in range(1, n + 1)])
    slide_arg, sparts, ssyms = _complex_arg(
        "slide",
        (n,),
        "per joint a slide added to d_i [m] (a P-pair's variable, its v = 1; 0 otherwise)",
        [f"x_{i}" for i in range(1, n + 1)],
    )
    parts.update(sparts)
    hs = tuple(sp.Symbol(f"h_{i}", real=True) for i in range(1, n + 1))
    h_arg = Arg("h", (n,), "per joint the amplitude h_i of a sinusoidal A-pair, 0 for an R-pair [m]", hs, design=True)
    tgt_arg, tparts, tsyms = _complex_arg(
        "target",
        (7,),
        "pose (t [m], q): translation and rotation quaternion up to scale",
        ["t1", "t2", "t3", "q0", "q1", "q2", "q3"],
    )
    parts.update(tparts)
    rec = _Recorder()
    J = []
    for i in range(1, n + 1):
        j = joint_symbols(i)
        sub = {zs: vsyms[i - 1], h: hs[i - 1]}
        for f, e in zip(("ch", "sh", "d"), law_s):
            j[f] = rec.name(f"L{i}_{f}", sp.expand(e.xreplace(sub) + (ssyms[i - 1] if f == "d" else 0)))
        J.append(j)
    dh_arg = Arg(
        "dh",
        (n, 4),
        "per joint (a_i [m], alpha_i [rad], c_i [m], phi_i [rad])",
        tuple(j[k] for j in J for k in ("a", "alpha", "c", "phi")),
        design=True,
    )
    T = frames(n, J, rec)[n]
    steps, outs = split_complex(rec.steps, _residual(T, _rotation(J, rec), tsyms), parts)
    return KernelSpec(
        name=f"ik_residual{n}",
        doc=(
            f"The residual F of ik_system{n} at z_i = exp(i theta_i/2) (the laws included) and the P-pairs' "
            "slides, also in extended precision for the tracker's corrector far out in the complex."
        ),
        source=SOURCE,
        inputs=[v_arg, slide_arg, h_arg, tgt_arg, dh_arg],
        steps=steps,
        outputs=[_complex_out("F", (6,), "residual", outs)],
        wide=True,
    )


# ----------------------------------------------------------------------------- independent check
def _mp_dh(theta_i, d_i, a, alpha, c, phi):
    """A_i = Rz(θ + φ)·Tz(c + d)·Tx(a)·Rx(α) (docs/conventions.md §3) as an mpmath matrix."""
    ct, st = mpmath.cos(theta_i + phi), mpmath.sin(theta_i + phi)
    ca, sa = mpmath.cos(alpha), mpmath.sin(alpha)
    return mpmath.matrix(
        [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, c + d_i], [0, 0, 0, 1]]
    )


def evaluate_real(kernel: KernelSpec, dh, T, *rest, digits: int) -> list:
    """A real-valued kernel spec in `digits`-digit arithmetic at mpmath inputs: dh rows, the 4×4 pose
    T, then the further inputs' flat values in order; its outputs, flat."""
    values = [[x for row in dh for x in row], [T[k // 4, k % 4] for k in range(16)], *rest]
    env = {}
    for arg, vals in zip(kernel.inputs, values):
        env.update({s: sp.Float(x, digits) for s, x in zip(arg.symbols, vals)})
    for s, e in kernel.steps:
        env[s] = sp.Float(sp.N(e.xreplace(env), digits), digits)
    return [mpmath.mpf(sp.N(e.xreplace(env), digits)) for a in kernel.outputs for e in a.exprs]


def _mp_qmul(x, y):
    return [
        x[0] * y[0] - x[1] * y[1] - x[2] * y[2] - x[3] * y[3],
        x[0] * y[1] + x[1] * y[0] + x[2] * y[3] - x[3] * y[2],
        x[0] * y[2] - x[1] * y[3] + x[2] * y[0] + x[3] * y[1],
        x[0] * y[3] + x[1] * y[2] - x[2] * y[1] + x[3] * y[0],
    ]


def _mp_quaternion(R):
    """The unit quaternion of a (complex) rotation matrix, sign fixed by its largest component."""
    w = [
        1 + R[0, 0] + R[1, 1] + R[2, 2],
        1 + R[0, 0] - R[1, 1] - R[2, 2],
        1 - R[0, 0] + R[1, 1] - R[2, 2],
        1 - R[0, 0] - R[1, 1] + R[2, 2],
    ]
    k = max(range(4), key=lambda m: abs(w[m]))
    s = mpmath.sqrt(w[k]) * 2
    if k == 0:
        return [s / 4, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    if k == 1:
        return [(R[2, 1] - R[1, 2]) / s, s / 4, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    if k == 2:
        return [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, s / 4, (R[1, 2] + R[2, 1]) / s]
    return [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, s / 4]


def _mp_system(joints, dh, target, x_sign=None):
    """F by the 4×4 DH product and the quaternion of its rotation in mpmath; joints: per joint
    (θ_i, d_i) (an A-pair's d = h cos(θ/2), a P-pair's θ = 0 and d = x); x_sign: a quaternion whose
    sign the result's is aligned with (q and −q are one rotation)."""
    T = mpmath.eye(4)
    for (th, d), row in zip(joints, dh):
        T = T * _mp_dh(th, d, *row)
    x = _mp_quaternion(T)
    if x_sign is not None:
        dot = sum(a * b for a, b in zip(x, x_sign))
        if abs(dot + 1) < abs(dot - 1):
            x = [-a for a in x]
    qc = [target[3], -target[4], -target[5], -target[6]]
    vec = _mp_qmul(qc, x)[1:]
    return [T[k, 3] - target[k] for k in range(3)] + vec, x


def _mp_joints(values, kinds, hs):
    """(θ_i, d_i) per joint from its variable: an angle (A- or R-pair, d = h cos(θ/2)) or a P-pair's
    slide x (θ = 0, d = x)."""
    return [(0, v) if k == "P" else (v, hh * mpmath.cos(v / 2)) for v, k, hh in zip(values, kinds, hs)]


KINDS = "APR"  # the joints of the checks, in turn: A-, P-, R-pair, ...


def _evaluate(spec: KernelSpec, values: dict, dh, digits: int):
    """A complex-valued kernel spec at mpmath inputs (values: {input name: complex values, or for
    the real input h real values}, dh rows): its outputs as complex numbers, and the quaternion x
    of the end frame (steps X{n}_k) it computed."""
    env = {}
    for a in spec.inputs:
        if a.name == "dh":
            env.update({s: sp.Float(x, digits) for s, x in zip(a.symbols, [x for row in dh for x in row])})
        elif a.name in ("h", "turning"):
            env.update({s: sp.Float(mpmath.re(x), digits) for s, x in zip(a.symbols, values[a.name])})
        else:
            for k, z in enumerate(values[a.name]):
                env[a.symbols[2 * k]] = sp.Float(z.real, digits)
                env[a.symbols[2 * k + 1]] = sp.Float(z.imag, digits)
    for s, e in spec.steps:
        env[s] = sp.N(e.xreplace(env), digits)
    flat = [mpmath.mpmathify(sp.N(e.xreplace(env), digits)) for a in spec.outputs for e in a.exprs]
    n = next(a for a in spec.inputs if a.name == "dh").shape[0]
    # the kernel's quaternion sign: the half-angle product's (the matrix route's is aligned with it)
    x = [
        mpmath.mpmathify(sp.N(sp.Symbol(f"X{n}_{k}_re", real=True).xreplace(env), digits))
        + 1j * mpmath.mpmathify(sp.N(sp.Symbol(f"X{n}_{k}_im", real=True).xreplace(env), digits))
        for k in range(4)
    ]
    return [flat[2 * k] + 1j * flat[2 * k + 1] for k in range(len(flat) // 2)], x


def check_residual(n: int = 3, digits: int = 30) -> float:
    """Max difference between ik_residual{n} and the independent route (the 4×4 DH product) at
    a random complex point with the joints A-, P- and R-pairs in turn (KINDS)."""
    spec = residual_spec(n)
    rng = random.Random(200 + n)
    kinds = [KINDS[i % 3] for i in range(n)]
    with mpmath.workdps(digits):
        th = [mpmath.mpc(rng.uniform(-3, 3), rng.uniform(-2, 2)) for _ in range(n)]
        hs = [rng.uniform(0.2, 1.0) if k == "A" else 0.0 for k in kinds]
        dh = [
            [
                mpmath.mpf(rng.uniform(-1, 1)),
                mpmath.mpf(rng.uniform(-2, 2)),
                mpmath.mpf(rng.uniform(-1, 1)),
                mpmath.mpf(rng.uniform(-2, 2)),
            ]
            for _ in range(n)
        ]
        target = [mpmath.mpc(rng.uniform(-1, 1), rng.uniform(-1, 1)) for _ in range(7)]
        v = [1 if k == "P" else mpmath.exp(1j * t / 2) for t, k in zip(th, kinds)]
        slide = [t if k == "P" else 0 for t, k in zip(th, kinds)]
        got, x_kernel = _evaluate(spec, {"v": v, "slide": slide, "h": hs, "target": target}, dh, digits)
        F, _ = _mp_system(_mp_joints(th, kinds, hs), dh, target, x_kernel)
        worst = max(abs(g - f) for g, f in zip(got, F))
    assert worst < 1e-15, f"ik_residual{n} differs from the DH route by {worst}"
    return float(worst)


def check_system(n: int = 3, digits: int = 30) -> float:
    """Max difference between the kernel's expressions and the independent route at a random
    complex point: F, dF/dθ (central differences of the DH product) and dFs (F is linear in the
    pose, so F(p + dp) − F(p)), with the joints A-, P- and R-pairs in turn (KINDS)."""
    spec = system_spec(n)
    rng = random.Random(100 + n)
    kinds = [KINDS[i % 3] for i in range(n)]

    def cplx():
        return mpmath.mpc(rng.uniform(-1, 1), rng.uniform(-1, 1))

    with mpmath.workdps(digits):
        th = [cplx() for _ in range(n)]
        hs = [rng.uniform(0.2, 1.0) if k == "A" else 0.0 for k in kinds]
        dh = [
            [
                mpmath.mpf(rng.uniform(-1, 1)),
                mpmath.mpf(rng.uniform(-2, 2)),
                mpmath.mpf(rng.uniform(-1, 1)),
                mpmath.mpf(rng.uniform(-2, 2)),
            ]
            for _ in range(n)
        ]
        target, direction = [cplx() for _ in range(7)], [cplx() for _ in range(7)]
        law = [
            x
            for t, hh, k in zip(th, hs, kinds)
            for x in (
                (1, 0, t, 1)
                if k == "P"
                else (mpmath.cos(t / 2), mpmath.sin(t / 2), hh * mpmath.cos(t / 2), -hh / 2 * mpmath.sin(t / 2))
            )
        ]
        turning = [0 if k == "P" else 1 for k in kinds]
        values = {"law": law, "target": target, "direction": direction, "turning": turning}
        got, x_kernel = _evaluate(spec, values, dh, digits)

        def system(values, target, x_sign):
            return _mp_system(_mp_joints(values, kinds, hs), dh, target, x_sign)

        F, x = system(th, target, x_kernel)
        worst = max(abs(a - b) for a, b in zip(x, x_kernel))
        worst = max([worst] + [abs(g - f) for g, f in zip(got[:6], F)])
        eps = mpmath.mpf(10) ** -10
        for i in range(n):
            up, dn = list(th), list(th)
            up[i] += eps
            dn[i] -= eps
            Fu, Fd = system(up, target, x)[0], system(dn, target, x)[0]
            worst = max([worst] + [abs(got[6 + r * n + i] - (Fu[r] - Fd[r]) / (2 * eps)) for r in range(6)])
        shifted = [a + b for a, b in zip(target, direction)]
        Fs = [a - b for a, b in zip(system(th, shifted, x)[0], F)]
        worst = max([worst] + [abs(g - f) for g, f in zip(got[6 + 6 * n :], Fs)])
    assert worst < 1e-15, f"ik_system{n} differs from the DH route by {worst}"
    return float(worst)


def derive():
    """The law kernels at exp(iθ/2), ik_system6 and ik_residual6 (a shorter chain is tracked with
    virtual joints added, see apair.ik.homotopy), after the independent checks on n = 1 and 3."""
    checks = {n: check_system(n) for n in (1, 3)}
    checks.update({f"residual{n}": check_residual(n) for n in (1, 3)})
    specs = [law_spec("revolute"), law_spec("sinusoidal"), system_spec(MAX_N), residual_spec(MAX_N)]
    return [], specs, {"system_check": checks}
