"""Equations of motion of nA-chains with leg inertia, n = 1..6 (docs/conventions.md §3-§4).

Generalised coordinates: the angles θ. Body j (j ≥ 1) is link j: it carries pair j's platform
and frame j. The legs of pair i are uniform slender rods from a base point a (on body i−1) to a
platform point b (on body i); a rod's kinetic energy (m/6)(|v_a|² + v_a·v_b + |v_b|²) is a point
mass m/3 at each end plus the coupling (m/6) v_a·v_b, and its potential energy is that of m/2 at
each end. Everything is assembled in the base frame from spatial quantities referred to the base
origin, so each term needs only the moments of a pair's leg end points, derived from the platform
geometry (derivations/apair_pair.py):

    T = ½ Σ_j V_jᵀ 𝕄_j V_j + Σ_i V_{i−1}ᵀ X_i V_i,   V_j = Σ_{k ≤ j} S_k θ'_k,
    S_k = (z_{k−1}, o_{k−1} × z_{k−1} + d'_k z_{k−1})   (the joint screw, pitch d'_k),

so M_kl = S_kᵀ 𝕄^c_{max(k,l)} S_l + S_kᵀ Y_{max(k+1,l)} S_l + S_lᵀ Y_{max(l+1,k)} S_k with composite
sums 𝕄^c_j = Σ_{j'≥j} 𝕄_j', Y_m = Σ_{i≥m} X_i (a CRBA with leg couplings). The inverse dynamics,
bias and gravity torques come from a Newton-Euler recursion with the same bodies and leg couplings
(`rnea`), and C from the Christoffel symbols of M by forward-mode differentiation of these steps
(derivations/autodiff.py), with d/dθ_k of the law values (d, d', d'') → (d', d'', ·). `check_bias`
proves the recursion equal to the Lagrangian Ṁθ' − ∇(T − V) at random points.
"""
from __future__ import annotations

import sympy as sp

from . import apair_pair
from .autodiff import directional, gradient
from .chain_kinematics import MAX_N, _Recorder, chain_inputs, frames
from .spec import Arg, KernelSpec

SOURCE = "derivations/chain_dynamics.py"
LINK_FIELDS = ("m", "cx", "cy", "cz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")
LEG_FIELDS = ("ml", "rb", "rp")


def leg_moments():
    """Moments of one pair's leg end points in its own frames, as functions of (r_b, r_p).

    Returns (Σ a aᵀ, Σ p pᵀ, Σ a pᵀ): base points a in the base frame, platform points p in the
    platform frame, paired leg by leg. Asserts the first moments Σ a, Σ p vanish (both point sets
    are symmetric about the axis) and that the second moments are invariant under Rz, which is
    what lets the assembly below use them in any frame with the same z axis.
    """
    legs = apair_pair.legs()
    A = [sp.Matrix(a) for a, _, _ in legs]
    P = [sp.Matrix(p) for _, p, _ in legs]
    simp = lambda m: m.applyfunc(lambda e: sp.nsimplify(sp.simplify(e)))
    assert simp(sum(A, sp.zeros(3, 1))) == sp.zeros(3, 1)
    assert simp(sum(P, sp.zeros(3, 1))) == sp.zeros(3, 1)
    Saa = simp(sum((a * a.T for a in A), sp.zeros(3, 3)))
    Spp = simp(sum((p * p.T for p in P), sp.zeros(3, 3)))
    Sap = simp(sum((a * p.T for a, p in zip(A, P)), sp.zeros(3, 3)))
    t = sp.Symbol("t", real=True)
    Rz = sp.Matrix([[sp.cos(t), -sp.sin(t), 0], [sp.sin(t), sp.cos(t), 0], [0, 0, 1]])
    for S in (Saa, Spp):
        assert simp(Rz * S * Rz.T - S) == sp.zeros(3, 3)
    return Saa, Spp, Sap, (apair_pair.r_b, apair_pair.r_p)


def dynamics_inputs(n: int):
    """theta, qd, qdd, dh, law, links (n, 10), legs (n, 3), gravity (3) and their symbols."""
    kin, J = chain_inputs(n)
    theta, dh, law = kin
    for i, j in enumerate(J, start=1):
        j.update({k: sp.Symbol(f"{k}_{i}", real=True) for k in ("qd", "qdd") + LINK_FIELDS + LEG_FIELDS})
    gvec = sp.symbols("g_x g_y g_z", real=True)
    args = {
        "theta": theta,
        "qd": Arg("qd", (n,), "joint velocities theta'_i [rad/s]", tuple(j["qd"] for j in J)),
        "qdd": Arg("qdd", (n,), "joint accelerations theta''_i [rad/s^2]", tuple(j["qdd"] for j in J)),
        "dh": dh,
        "law": law,
        "links": Arg("links", (n, 10), "per link (mass [kg], com [m] in frame i (3), inertia about the com in "
                     "frame i: Ixx, Iyy, Izz, Ixy, Ixz, Iyz [kg m^2])", tuple(j[k] for j in J for k in LINK_FIELDS),
                     design=True),
        "legs": Arg("legs", (n, 3), "per pair (leg mass [kg], r_b [m], r_p [m]); zeros for an R-pair",
                    tuple(j[k] for j in J for k in LEG_FIELDS), design=True),
        "gravity": Arg("gravity", (3,), "gravity vector in the base frame [m/s^2]", gvec, design=True),
    }
    return args, J, sp.Matrix(gvec)


def _skew(v):
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


class Assembly:
    """The recorded computation of M(θ) and V(θ) for one chain length."""

    def __init__(self, n: int):
        self.n = n
        self.args, self.J, self.g = dynamics_inputs(n)
        self.rec = rec = _Recorder()
        F = frames(n, self.J, rec)
        Saa, Spp, Sap, (rb0, rp0) = leg_moments()
        vec = lambda label, v: sp.Matrix([rec.name(f"{label}_{k}", sp.expand(v[k])) for k in range(3)])
        z = [F[k][:3, 2] for k in range(n + 1)]
        o = [F[k][:3, 3] for k in range(n + 1)]
        R = [F[k][:3, :3] for k in range(n + 1)]

        # joint screws S_k = (w, v)
        self.S = []
        for k, j in enumerate(self.J, start=1):
            w = z[k - 1]
            v = vec(f"Sv{k}", o[k - 1].cross(w) + j["dd"] * w)
            self.S.append((w, v))

        def local(S, j):
            return S.subs({rb0: j["rb"], rp0: j["rp"]})

        # body spatial inertias about the base origin: (Θ 3x3, h 3, μ)
        bodies, oPs = [], {}
        self.bodies = bodies
        first_moment = sp.zeros(3, 1)  # Σ mass · position, for the potential energy
        for jx, j in enumerate(self.J, start=1):
            c = vec(f"com{jx}", o[jx] + R[jx] * sp.Matrix([j["cx"], j["cy"], j["cz"]]))
            I_loc = sp.Matrix([[j["Ixx"], j["Ixy"], j["Ixz"]], [j["Ixy"], j["Iyy"], j["Iyz"]], [j["Ixz"], j["Iyz"], j["Izz"]]])
            Theta = R[jx] * I_loc * R[jx].T + j["m"] * ((c.T * c)[0] * sp.eye(3) - c * c.T)
            h = j["m"] * c
            mu = j["m"]
            first_moment += j["m"] * c
            # platform ends of pair jx (on body jx): centre o_P = o_{jx-1} + d z_{jx-1}
            oP = oPs[jx] = vec(f"oP{jx}", o[jx - 1] + j["d"] * z[jx - 1])
            pts = [(oP, R[jx - 1] * local(Spp, j) * R[jx - 1].T, j["ml"])]
            # base ends of pair jx+1 (on body jx): centre o_jx
            if jx < n:
                nxt = self.J[jx]
                pts.append((o[jx], R[jx] * local(Saa, nxt) * R[jx].T, nxt["ml"]))
            for centre, second, ml in pts:
                # six points of mass ml/3 each: Σ p = 6 centre (first moments vanish locally)
                sum_ppT = 6 * centre * centre.T + second
                Theta += ml / 3 * (sum_ppT.trace() * sp.eye(3) - sum_ppT)
                h += ml / 3 * 6 * centre
                mu += 2 * ml
            bodies.append(self._name_inertia(f"B{jx}", Theta, h, mu))
        # the potential energy: links, and half of each leg's mass at each of its ends
        for i, j in enumerate(self.J, start=1):
            oP = oPs[i]
            first_moment += j["ml"] / 2 * (6 * o[i - 1] + 6 * oP)
        self.V = -(self.g.T * first_moment)[0]

        # leg couplings X_i between bodies i-1 and i (i ≥ 2); K_i = Σ a bᵀ also serves the RNEA
        X, self.legsum = {}, {}
        for i in range(1, n + 1):
            j = self.J[i - 1]
            oP = oPs[i]
            Rz = sp.Matrix([[sp.cos(j["theta"]), -sp.sin(j["theta"]), 0], [sp.sin(j["theta"]), sp.cos(j["theta"]), 0], [0, 0, 1]])
            # K = Σ a bᵀ with a = o + R α, b = o_P + R Rz p, Σα = Σp = 0
            K = 6 * o[i - 1] * oP.T + R[i - 1] * local(Sap, j) * Rz.T * R[i - 1].T
            K = sp.Matrix(3, 3, [rec.name(f"K{i}_{r}{c}", sp.expand(K[r, c])) for r in range(3) for c in range(3)])
            A, B = 6 * o[i - 1], 6 * oP
            self.legsum[i] = (A, B, K, j["ml"])
            if i == 1:
                continue  # body 0 does not move: no kinetic coupling
            top = (-(K.T - K.trace() * sp.eye(3))).row_join(_skew(A))
            bottom = (-_skew(B)).row_join(6 * sp.eye(3))
            X[i] = (j["ml"] / 6) * top.col_join(bottom)

        # composite sums and the mass matrix
        comp = [None] * (n + 2)
        acc = None
        for jx in range(n, 0, -1):
            Th, h, mu = bodies[jx - 1]
            acc = (Th, h, mu) if acc is None else self._name_inertia(f"C{jx}", acc[0] + Th, acc[1] + h, acc[2] + mu)
            comp[jx] = acc
        Y = [None] * (n + 2)
        accY = None
        for m in range(n, 1, -1):
            accY = X[m] if accY is None else accY + X[m]
            accY = sp.Matrix(6, 6, [rec.name(f"Y{m}_{r}{c}", sp.expand(accY[r, c])) for r in range(6) for c in range(6)])
            Y[m] = accY
        # M_kl = S_k · F, F = (𝕄^c_l + Y_l + Y_{l+1}ᵀ) S_l for k < l and (𝕄^c_l + Y_{l+1} + Y_{l+1}ᵀ) S_l for k = l
        zero6 = sp.zeros(6, 6)
        Yof = lambda m: Y[max(m, 2)] if max(m, 2) <= n else zero6  # Y_1 = Y_2: body 0 does not move
        M = sp.zeros(n, n)
        for l in range(1, n + 1):
            Sl = self._col(l)
            base = self._spatial(comp[l])
            off = base + Yof(l) + Yof(l + 1).T
            diag = base + Yof(l + 1) + Yof(l + 1).T
            F_off = sp.Matrix([rec.name(f"F{l}_{r}", sp.expand(v)) for r, v in enumerate(off * Sl)])
            F_diag = sp.Matrix([rec.name(f"Fd{l}_{r}", sp.expand(v)) for r, v in enumerate(diag * Sl)])
            for k in range(1, l + 1):
                e = (self._col(k).T * (F_diag if k == l else F_off))[0]
                M[k - 1, l - 1] = M[l - 1, k - 1] = rec.name(f"M{k}{l}", e)
        self.M = M
        self.z = z

    def _name_inertia(self, label, Theta, h, mu):
        rec = self.rec
        Th = sp.zeros(3, 3)
        for r in range(3):
            for c in range(r, 3):
                Th[r, c] = Th[c, r] = rec.name(f"{label}T{r}{c}", sp.expand(Theta[r, c]))
        hh = sp.Matrix([rec.name(f"{label}h{k}", sp.expand(h[k])) for k in range(3)])
        return Th, hh, rec.name(f"{label}m", sp.expand(mu))

    def _spatial(self, inertia):
        Th, h, mu = inertia
        return Th.row_join(_skew(h)).col_join(_skew(h).T.row_join(mu * sp.eye(3)))

    def _col(self, k):
        w, v = self.S[k - 1]
        return w.col_join(v)

    def velocity_tangent(self) -> dict:
        """d/dt of the inputs along the motion: θ_k → θ'_k, d_k → d'_k θ'_k, d'_k → d''_k θ'_k."""
        tangent = {}
        for k, j in enumerate(self.J, start=1):
            for s, v in self.seeds(k).items():
                tangent[s] = tangent.get(s, 0) + v * j["qd"]
        return tangent

    def seeds(self, k: int) -> dict:
        """d/dθ_k of the inputs: θ_k → 1 and, through the law, d_k → d'_k, d'_k → d''_k."""
        j = self.J[k - 1]
        return {j["theta"]: 1, j["d"]: j["dd"], j["dd"]: j["ddd"]}

    def inputs(self, *names):
        return [self.args[nm] for nm in names]


def _through_law(asm: Assembly, grads: dict, k: int) -> sp.Expr:
    """d/dθ_k from partial derivatives: ∂/∂θ_k + d'_k ∂/∂d_k + d''_k ∂/∂d'_k."""
    return sum((grads.get(s, 0) * v for s, v in asm.seeds(k).items()), sp.S(0))


def _cross_m(V, S):
    """Motion cross product (ω, v) ×m (w, u) = (ω × w, ω × u + v × w)."""
    w, v = V[:3, 0], V[3:, 0]
    return w.cross(S[:3, 0]).col_join(w.cross(S[3:, 0]) + v.cross(S[:3, 0]))


def _cross_f(V, F):
    """Force cross product (ω, v) ×f (n, f) = (ω × n + v × f, ω × f)."""
    w, v = V[:3, 0], V[3:, 0]
    return (w.cross(F[:3, 0]) + v.cross(F[3:, 0])).col_join(w.cross(F[3:, 0]))


def _vee_antisym(N):
    """Σ_k a_k × c_k from N = Σ_k a_k c_kᵀ."""
    return sp.Matrix([N[1, 2] - N[2, 1], N[2, 0] - N[0, 2], N[0, 1] - N[1, 0]])


def rnea(asm: Assembly, qd, qdd, gravity: bool, prefix: str):
    """Recursive Newton-Euler with the legs: τ = M qdd + C qd (+ g with gravity), as steps.

    Spatial vectors in the base frame about its origin. Gravity enters as the base acceleration
    (0, −g): a leg end then feels (m/3 + m/6) g = (m/2) g, the rod's weight split between its ends.
    A leg of pair i couples its ends' accelerations: (m/6) a_b acts at a (body i−1) and (m/6) a_a at
    b (body i); with a_p = c + L p for points of one body, the sums over the six legs need only
    Σa, Σb and K = Σ a bᵀ.
    """
    rec = _Recorder()
    n = asm.n
    name6 = lambda label, v: sp.Matrix([rec.name(f"{prefix}{label}_{k}", sp.expand(v[k])) for k in range(6)])
    name3 = lambda label, v: sp.Matrix([rec.name(f"{prefix}{label}_{k}", sp.expand(v[k])) for k in range(3)])
    V = [sp.zeros(6, 1)]
    A = [sp.zeros(3, 1).col_join(-asm.g if gravity else sp.zeros(3, 1))]
    for k, j in enumerate(asm.J, start=1):
        S = asm._col(k)
        V.append(name6(f"V{k}", V[-1] + S * qd[k - 1]))
        Sdot = _cross_m(V[k - 1], S) + sp.zeros(3, 1).col_join(j["ddd"] * qd[k - 1] * asm.z[k - 1])
        A.append(name6(f"A{k}", A[-1] + S * qdd[k - 1] + Sdot * qd[k - 1]))
    # point accelerations of body j: a_p = c_j + L_j p
    c = [name3(f"c{k}", A[k][3:, 0] + V[k][:3, 0].cross(V[k][3:, 0])) for k in range(n + 1)]
    Lmat = [sp.zeros(3, 3)]
    for k in range(1, n + 1):
        w, al = V[k][:3, 0], A[k][:3, 0]
        L = _skew(al) + _skew(w) * _skew(w)
        Lmat.append(sp.Matrix(3, 3, [rec.name(f"{prefix}L{k}_{r}{q}", sp.expand(L[r, q])) for r in range(3) for q in range(3)]))
    F = []
    for k in range(1, n + 1):
        Mk = asm._spatial(asm.bodies[k - 1])
        F.append(Mk * A[k] + _cross_f(V[k], Mk * V[k]))
    for i in range(1, n + 1):
        Asum, Bsum, K, ml = asm.legsum[i]
        # on body i (points b): (m/6) a_a, a_a = c_{i-1} + L_{i-1} a
        f_b = ml / 6 * (6 * c[i - 1] + Lmat[i - 1] * Asum)
        n_b = ml / 6 * (Bsum.cross(c[i - 1]) + _vee_antisym(K.T * Lmat[i - 1].T))
        F[i - 1] += n_b.col_join(f_b)
        if i >= 2:  # on body i-1 (points a): (m/6) a_b
            f_a = ml / 6 * (6 * c[i] + Lmat[i] * Bsum)
            n_a = ml / 6 * (Asum.cross(c[i]) + _vee_antisym(K * Lmat[i].T))
            F[i - 2] += n_a.col_join(f_a)
    tau = [None] * n
    acc = None
    for k in range(n, 0, -1):
        acc = F[k - 1] if acc is None else F[k - 1] + acc
        acc = name6(f"Fc{k}", acc)
        tau[k - 1] = (asm._col(k).T * acc)[0]
    return rec.steps, tau


def lagrangian_bias(asm: Assembly):
    """The same bias by another route: Ṁθ' − ∇_θ(T − V), T = ½ θ'ᵀMθ' (forward + reverse mode)."""
    qd = sp.Matrix([j["qd"] for j in asm.J])
    f_steps, Mdot = directional(asm.rec.steps, list(asm.M), asm.velocity_tangent(), "dMt_")
    L = (qd.T * asm.M * qd)[0] / 2 - asm.V
    r_steps, grads = gradient(asm.rec.steps, L, "aL_")
    bias = sp.Matrix(asm.n, asm.n, Mdot) * qd - sp.Matrix([_through_law(asm, grads, k) for k in range(1, asm.n + 1)])
    return f_steps + r_steps, list(bias)


def christoffel(asm: Assembly):
    """C = ½(Ṁ + W − Wᵀ), W_ij = ∂(M u)_i/∂θ_j at u = θ': exactly C_ij = Σ_k Γ_ijk θ'_k with the
    Christoffel symbols Γ_ijk = ½(∂_k M_ij + ∂_j M_ik − ∂_i M_jk). Ṁ is one directional derivative
    of M; M u comes from the recursion (no velocity, no gravity, acceleration u) and is differentiated
    along each θ_j."""
    n = asm.n
    qd = [j["qd"] for j in asm.J]
    steps, Mdot = directional(asm.rec.steps, list(asm.M), asm.velocity_tangent(), "dMt_")
    Mdot = sp.Matrix(n, n, Mdot)
    mu_steps, Mu = rnea(asm, [0] * n, qd, gravity=False, prefix="mu_")
    steps += mu_steps
    W = sp.zeros(n, n)
    for jx in range(1, n + 1):
        new, dMu = directional(asm.rec.steps + mu_steps, Mu, asm.seeds(jx), f"dmu{jx}_")
        steps += new
        for i in range(n):
            W[i, jx - 1] = dMu[i]
    return steps, (Mdot + W - W.T) / 2


def check_bias(n: int, samples: int = 2, digits: int = 30) -> float:
    """Max |RNEA bias − Lagrangian bias| and |RNEA gravity − ∂V/∂θ| at random points."""
    import random

    import mpmath

    asm = Assembly(n)
    qd = [j["qd"] for j in asm.J]
    r_steps, r_bias = rnea(asm, qd, [0] * n, gravity=True, prefix="r_")
    l_steps, l_bias = lagrangian_bias(asm)
    g_steps, r_g = rnea(asm, [0] * n, [0] * n, gravity=True, prefix="rg_")
    v_steps, grads = gradient(asm.rec.steps, asm.V, "aV_")
    l_g = [_through_law(asm, grads, k) for k in range(1, n + 1)]
    steps = asm.rec.steps + r_steps + l_steps + g_steps + v_steps
    diffs = [a - b for a, b in zip(r_bias + r_g, l_bias + l_g)]
    rng = random.Random(100 + n)
    worst = mpmath.mpf(0)
    inputs = [s for a in asm.args.values() for s in a.symbols]
    with mpmath.workdps(digits):
        for _ in range(samples):
            env = {s: mpmath.mpf(rng.uniform(-1, 1)) for s in inputs}
            for sym, e in steps:
                env[sym] = sp.lambdify(sorted(e.free_symbols, key=str), e, "mpmath")(
                    *[env[v] for v in sorted(e.free_symbols, key=str)])
            for d in diffs:
                val = sp.lambdify(sorted(d.free_symbols, key=str), d, "mpmath")(*[env[v] for v in sorted(d.free_symbols, key=str)])
                worst = max(worst, abs(val))
    assert worst < mpmath.mpf(10) ** (-(digits - 8)), f"RNEA and Lagrangian disagree for n={n}: {worst}"
    return float(worst)


def cholesky_solve(M: sp.Matrix, rhs: list, prefix: str):
    """Steps of x = M⁻¹ rhs by Cholesky, M = L Lᵀ, and forward and back substitution.

    Straight-line code for a symmetric positive definite M; where M is not, a square root of a
    negative number gives NaN (the runtime turns that into an error). Returns (steps, x).
    """
    rec = _Recorder()
    n = M.shape[0]
    L = sp.zeros(n, n)
    for j in range(n):
        L[j, j] = rec.name(f"{prefix}L{j}{j}", sp.sqrt(M[j, j] - sum((L[j, k] ** 2 for k in range(j)), sp.S(0))))
        inv = rec.name(f"{prefix}iL{j}", 1 / L[j, j])
        for i in range(j + 1, n):
            L[i, j] = rec.name(f"{prefix}L{i}{j}", (M[i, j] - sum((L[i, k] * L[j, k] for k in range(j)), sp.S(0))) * inv)
        L[j, j] = inv  # below, only 1/L_jj is needed
    y = [None] * n
    for i in range(n):
        y[i] = rec.name(f"{prefix}y{i}", (rhs[i] - sum((L[i, k] * y[k] for k in range(i)), sp.S(0))) * L[i, i])
    x = [None] * n
    for i in reversed(range(n)):
        x[i] = rec.name(f"{prefix}x{i}", (y[i] - sum((L[k, i] * x[k] for k in range(i + 1, n)), sp.S(0))) * L[i, i])
    return rec.steps, x


def specs_for(n: int) -> list[KernelSpec]:
    asm = Assembly(n)
    base = list(asm.rec.steps)
    qd = [j["qd"] for j in asm.J]
    qdd = [j["qdd"] for j in asm.J]
    g_steps, g = rnea(asm, [0] * n, [0] * n, gravity=True, prefix="g_")
    b_steps, bias = rnea(asm, qd, [0] * n, gravity=True, prefix="b_")
    i_steps, tau = rnea(asm, qd, qdd, gravity=True, prefix="id_")
    c_steps, C = christoffel(asm)
    taus = [sp.Symbol(f"tau_{k}", real=True) for k in range(1, n + 1)]
    f_steps, qdd_fd = cholesky_solve(asm.M, [t - b for t, b in zip(taus, bias)], "fd_")
    tau_arg = Arg("tau", (n,), "joint torques tau_i [N m]", tuple(taus))
    qdm = sp.Matrix(qd)
    kin = ("theta", "dh", "law")
    body = ("links", "legs")
    T = (qdm.T * asm.M * qdm)[0] / 2
    return [
        KernelSpec(f"mass_matrix{n}", f"Mass matrix M(theta) ({n} x {n}) of a {n}-joint chain, legs included.",
                   SOURCE, asm.inputs(*kin, *body), [Arg("M", (n, n), "mass matrix, row-major", exprs=tuple(asm.M))], base),
        KernelSpec(f"gravity{n}", f"Gravity torques g(theta) = dV/dtheta ({n}) of a {n}-joint chain.",
                   SOURCE, asm.inputs(*kin, *body, "gravity"), [Arg("g", (n,), "gravity torques [N m]", exprs=tuple(g))],
                   base + g_steps),
        KernelSpec(f"coriolis{n}", f"Coriolis matrix C(theta, theta') ({n} x {n}, Christoffel form) of a {n}-joint chain.",
                   SOURCE, asm.inputs("theta", "qd", "dh", "law", *body),
                   [Arg("C", (n, n), "C such that dM/dt - 2C is skew-symmetric, row-major", exprs=tuple(C))],
                   base + c_steps),
        KernelSpec(f"bias{n}", f"Bias C(theta, theta') theta' + g(theta) ({n}) of a {n}-joint chain.",
                   SOURCE, asm.inputs("theta", "qd", "dh", "law", *body, "gravity"),
                   [Arg("bias", (n,), "bias torques [N m]", exprs=tuple(bias))], base + b_steps),
        KernelSpec(f"inverse_dynamics{n}", f"Joint torques tau = M theta'' + C theta' + g ({n}) of a {n}-joint chain.",
                   SOURCE, asm.inputs("theta", "qd", "qdd", "dh", "law", *body, "gravity"),
                   [Arg("tau", (n,), "joint torques [N m]", exprs=tuple(tau))], base + i_steps),
        KernelSpec(f"forward_dynamics{n}", f"Joint accelerations theta'' = M^-1 (tau - C theta' - g) ({n}) of a "
                   f"{n}-joint chain, by Cholesky (NaN where M is not positive definite).",
                   SOURCE, asm.inputs("theta", "qd") + [tau_arg] + asm.inputs("dh", "law", *body, "gravity"),
                   [Arg("qdd", (n,), "joint accelerations [rad/s^2]", exprs=tuple(qdd_fd))],
                   base + b_steps + f_steps),
        KernelSpec(f"energy{n}", f"Kinetic and potential energy (T, V) of a {n}-joint chain.",
                   SOURCE, asm.inputs("theta", "qd", "dh", "law", *body, "gravity"),
                   [Arg("energy", (2,), "(T, V) [J]", exprs=(T, asm.V))], base),
    ]


PARTS = ("check",) + tuple(range(1, MAX_N + 1))  # codegen runs these as parallel jobs


def derive(part=None):
    """(sets, specs, facts) of one part, or of all: "check" proves the RNEA bias and gravity equal
    to the Lagrangian ones for n = 1..3; a number n gives the kernels of the n-joint chain."""
    if part is None:
        parts = [derive(p) for p in PARTS]
        return [], [s for _, specs, _ in parts for s in specs], parts[0][2]
    if part == "check":
        return [], [], {"bias_check": {n: check_bias(n) for n in (1, 2, 3)}}
    if part not in PARTS:
        raise ValueError(f"part: expected one of {PARTS}, got {part!r}")
    return [], specs_for(part), {}
