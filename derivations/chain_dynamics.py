"""Equations of motion of nA-chains with leg inertia, n = 1..7 (docs/conventions.md §3-§4).

Generalised coordinates: the joint variables q, entering through each joint's law values (cos(θ/2),
sin(θ/2), d, d', d'', derivatives in q) and its turning factor w = dθ/dq: q is the angle θ of an
R-, A- or H-pair (w = 1) and the slide d of a P-pair (w = 0, θ constant). Body j (j ≥ 1) is link j:
it carries pair j's platform and frame j.

Everything is computed in local link frames (Featherstone's formulation). Body i's coordinates are
Q_i = frame_{i-1} · Rz(θ_i + φ_i) · Tz(c_i + d_i): its origin lies on joint i's axis, so the joint
is a screw along z with the variable pitch d'_i, S_i = (w_i e_z, d'_i e_z), and frame i is the
constant Q_i · Tx(a_i) Rx(α_i). Parent to child is then four elementary motions (derivations/
spatial.py). The legs of pair i are uniform slender rods from base points a (on body i−1, in pair
i's base frame B_i = frame i−1, Σa = 0) to platform points b (on body i, b = Rz(θ_i) p + d_i e_z,
Σp = 0): a rod's kinetic energy (m/6)(|v_a|² + v_a·v_b + |v_b|²) is a point mass m/3 at each end
(folded into the bodies' constant inertias) plus the coupling (m/6) v_a·v_b, which needs only
K = Σ a bᵀ = Σ a pᵀ Rz(θ_i)ᵀ and Σb = 6 d_i e_z. In B_i the coupling is
(m/6) V_{i−1}ᵀ X V_i with X = [[tr K·1 − Kᵀ, 0], [−6 d_i [e_z]×, 6·1]], V_i = V_{i−1} + S_i θ'_i:
body i−1 carries the extra rigid-body inertia (m/3)·sym X = (2m, m d_i e_z, (m/3)(tr K·1 − sym K))
and column i of M the extra force (m/6) X S_i on body i−1.

- `Assembly`: the mass matrix by the composite-rigid-body algorithm with those two leg terms,
  and the potential energy (half of each rod's weight at each end) by a gravity recursion;
- `rnea`: inverse dynamics, bias and gravity torques by recursive Newton-Euler, each leg of pair i
  pushing body i at b with (m/6) times the acceleration of a and body i−1 at a with (m/6) times
  that of b (gravity as the base acceleration, so each end carries m/2 of the rod's weight);
- `christoffel`: C = ½(Ṁ + W − Wᵀ) by forward-mode differentiation of these steps;
- `check_bias`: at generation time, the recursion equals the Lagrangian Ṁθ' − ∇(T − V) with
  T = ½ θ'ᵀMθ', the gravity torques equal ∂V/∂θ, and the recursion at θ' = 0 gives M θ''.
"""

from __future__ import annotations

import sympy as sp

from . import apair_pair
from .autodiff import directional, gradient
from .chain_kinematics import MAX_N, _Recorder, chain_inputs, joint_trig, revolute, turning_arg
from .spatial import (
    Namer,
    add_inertia,
    apply_inertia,
    cross_force,
    cross_motion,
    force_to_parent,
    inertia_to_parent,
    motion_to_child,
    point_mass_inertia,
    rotation,
    skew,
)
from .spec import Arg, Call, KernelSpec

SOURCE = "derivations/chain_dynamics.py"
LINK_FIELDS = ("m", "cx", "cy", "cz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")
LEG_FIELDS = ("ml", "rb", "rp")
EZ = sp.Matrix([0, 0, 1])
ZERO3 = sp.zeros(3, 1)


def leg_moments():
    """Moments of one pair's leg end points in its own frames, as functions of (r_b, r_p).

    Returns (Σ a aᵀ, Σ p pᵀ, Σ a pᵀ): base points a in the base frame, platform points p in the
    platform frame, paired leg by leg. Asserts the first moments Σ a, Σ p vanish (both point sets
    are symmetric about the axis) and that the second moments are invariant under Rz, which is
    what lets the bodies take them in any frame with the same z axis.
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
    """law, qd, qdd, dh, links (n, 10), legs (n, 3), gravity (3) and their symbols."""
    kin, J = chain_inputs(n)
    law, dh = kin
    for i, j in enumerate(J, start=1):
        j.update({k: sp.Symbol(f"{k}_{i}", real=True) for k in ("qd", "qdd") + LINK_FIELDS + LEG_FIELDS})
    gvec = sp.symbols("g_x g_y g_z", real=True)
    args = {
        "law": law,
        "qd": Arg("qd", (n,), "joint velocities q'_i [rad/s; m/s for a slide]", tuple(j["qd"] for j in J)),
        "qdd": Arg("qdd", (n,), "joint accelerations q''_i [rad/s^2; m/s^2 for a slide]", tuple(j["qdd"] for j in J)),
        "dh": dh,
        "turning": turning_arg(J),
        "links": Arg(
            "links",
            (n, 10),
            "per link (mass [kg], com [m] in frame i (3), inertia about the com in "
            "frame i: Ixx, Iyy, Izz, Ixy, Ixz, Iyz [kg m^2])",
            tuple(j[k] for j in J for k in LINK_FIELDS),
            design=True,
        ),
        "legs": Arg(
            "legs",
            (n, 3),
            "per pair (leg mass [kg], r_b [m], r_p [m]); zeros for an R-pair",
            tuple(j[k] for j in J for k in LEG_FIELDS),
            design=True,
        ),
        "gravity": Arg("gravity", (3,), "gravity vector in the base frame [m/s^2]", gvec, design=True),
    }
    return args, J, sp.Matrix(gvec)


def _vee_antisym(N):
    """Σ_k a_k × c_k from N = Σ_k a_k c_kᵀ."""
    return sp.Matrix([N[1, 2] - N[2, 1], N[2, 0] - N[0, 2], N[0, 1] - N[1, 0]])


class Assembly:
    """The recorded computation of M(θ) and V(θ) for one chain length, and what the recursions share:
    the frame chains, joint screws, body inertias and leg terms."""

    def __init__(self, n: int):
        self.n = n
        self.args, self.J, self.g = dynamics_inputs(n)
        self.rec = rec = _Recorder()
        nm = Namer(rec, "")
        Saa, Spp, Sap, (rb0, rp0) = leg_moments()
        local = lambda S, j: S.subs({rb0: j["rb"], rp0: j["rp"]})
        J = self.J
        # frame chains: B_i -> Q_i ("inner", moves with joint i) and Q_i -> frame i = B_{i+1} ("outer")
        self.inner, self.outer, self.K = {}, {}, {}
        for i, j in enumerate(J, start=1):
            ct, st, cq, sq = joint_trig(j, rec, f"{i}")
            self.inner[i] = [("rz", cq, sq), ("tz", j["c"] + j["d"])]
            self.outer[i] = [("tx", j["a"]), ("rx", sp.cos(j["alpha"]), sp.sin(j["alpha"]))]
            # K = Σ a bᵀ of pair i in B_i: b = Rz(θ) p + d e_z and Σ a = 0
            self.K[i] = nm.mat3("K", local(Sap, j) * rotation("z", ct, st).T)
        # body inertias in Q_i (design constants): link i (given in frame i) and the m/3 point
        # masses of pair i+1's base ends (in frame i) moved through Q_i -> frame i; pair i's
        # platform ends in P_i = Q_i · Tz(−c_i) · Rz(−φ_i) (the Rz leaves their moments unchanged)
        self.bodies, self.weights = [], []
        for i, j in enumerate(J, start=1):
            c = sp.Matrix([j["cx"], j["cy"], j["cz"]])
            Ic = sp.Matrix(
                [[j["Ixx"], j["Ixy"], j["Ixz"]], [j["Ixy"], j["Iyy"], j["Iyz"]], [j["Ixz"], j["Iyz"], j["Izz"]]]
            )
            link = (j["m"], j["m"] * c, Ic + j["m"] * ((c.T * c)[0] * sp.eye(3) - c * c.T))
            parts_i, weight_i = [link], [(j["m"], j["m"] * c, None)]
            if i < n:
                nxt = J[i]
                parts_i.append(point_mass_inertia(2 * nxt["ml"], ZERO3, nxt["ml"] / 3 * local(Saa, nxt)))
                weight_i.append((3 * nxt["ml"], ZERO3, None))
            in_frame = add_inertia(*parts_i)
            body = inertia_to_parent(self.outer[i], in_frame, nm, "Ib")
            plat = inertia_to_parent(
                [("tz", -j["c"])], point_mass_inertia(2 * j["ml"], ZERO3, j["ml"] / 3 * local(Spp, j)), nm, "Ip"
            )
            self.bodies.append(self._named(nm, "B", add_inertia(body, plat)))
            wm = sum((w[0] for w in weight_i), sp.S(0))
            wh = sum((w[1] for w in weight_i), sp.zeros(3, 1))
            _, wh, _ = inertia_to_parent(self.outer[i], (wm, wh, None), nm, "Wh")
            _, ph, _ = inertia_to_parent([("tz", -j["c"])], (3 * j["ml"], ZERO3, None), nm, "Wp")
            self.weights.append((rec.name(f"Wm{i}", wm + 3 * j["ml"]), nm.vec("W", wh + ph)))
        # joint screws and the leg terms of pair i ≥ 2 (on body i−1, in B_i)
        self.S = [(j["w"] * EZ, j["dd"] * EZ) for j in J]
        self.coupling, self.cross = {}, {}
        for i in range(2, n + 1):
            j, K = J[i - 1], self.K[i]
            ml, trK = j["ml"], K.trace()
            self.coupling[i] = (2 * ml, ml * j["d"] * EZ, nm.sym3("Xs", ml / 3 * (trK * sp.eye(3) - (K + K.T) / 2)))
            self.cross[i] = (j["w"] * ml / 6 * (trK * sp.eye(3) - K.T) * EZ, ml * j["dd"] * EZ)

        # composite-rigid-body algorithm
        Ic = {n: self.bodies[n - 1]}
        for i in range(n, 1, -1):
            IB = inertia_to_parent(self.inner[i], Ic[i], nm, "Ci")
            IB = self._named(nm, "CB", add_inertia(IB, self.coupling[i]))
            Ic[i - 1] = self._named(
                nm, "Cc", add_inertia(self.bodies[i - 2], inertia_to_parent(self.outer[i - 1], IB, nm, "Co"))
            )
        M = sp.zeros(n, n)
        for i in range(1, n + 1):
            F = [nm.vec("Fn", x) for x in apply_inertia(Ic[i], self.S[i - 1])]
            M[i - 1, i - 1] = rec.name(f"M{i}{i}", self._project(i, F))
            if i == 1:
                continue
            FB = force_to_parent(self.inner[i], F, nm, "Fb")
            FB = [nm.vec("Fg", FB[0] + self.cross[i][0]), nm.vec("Fg", FB[1] + self.cross[i][1])]
            for k in range(i - 1, 0, -1):
                F = force_to_parent(self.outer[k], FB, nm, "Fo")
                M[k - 1, i - 1] = M[i - 1, k - 1] = rec.name(f"M{k}{i}", self._project(k, F))
                if k > 1:
                    FB = force_to_parent(self.inner[k], F, nm, "Fb")
        self.M = M

        # the potential energy (its own steps: they need the gravity input): gravity in body
        # coordinates and g·o_i along the chain
        self.vrec = vrec = _Recorder()
        nm = Namer(vrec, "")
        gv, g_dot_o, V = self.g, sp.S(0), sp.S(0)
        for i in range(1, n + 1):
            chain = (self.outer[i - 1] if i > 1 else []) + self.inner[i]
            for e in chain:
                if e[0] in ("rx", "rz"):
                    gv = nm.vec("gv", rotation(e[0][1], e[1], e[2]).T * gv)
                else:
                    g_dot_o = vrec.name(f"go{i}_{e[0]}", sp.expand(g_dot_o + e[1] * gv[{"tx": 0, "tz": 2}[e[0]]]))
            wm, wh = self.weights[i - 1]
            V = V - wm * g_dot_o - (gv.T * wh)[0]
        self.V = vrec.name("Vpot", sp.expand(V))

    def _named(self, nm, tag, inertia):
        m, h, Ib = inertia
        return self.rec.name(f"{tag}{nm.count + 1}m", sp.expand(m)), nm.vec(tag + "h", h), nm.sym3(tag, Ib)

    def _project(self, k, F):
        """S_kᵀ F for a force F = (n, f) in Q_k: w_k n_z + d'_k f_z."""
        j = self.J[k - 1]
        return j["w"] * F[0][2] + j["dd"] * F[1][2]

    def velocity_tangent(self) -> dict:
        """d/dt of the inputs along the motion: Σ_k θ'_k d/dθ_k."""
        tangent = {}
        for k, j in enumerate(self.J, start=1):
            for s, v in self.seeds(k).items():
                tangent[s] = tangent.get(s, 0) + v * j["qd"]
        return tangent

    def seeds(self, k: int) -> dict:
        """d/dq_k of the inputs: cos(θ/2) → −w sin(θ/2)/2, sin(θ/2) → w cos(θ/2)/2 (θ turns by
        w_k q_k) and, through the law, d → d', d' → d''."""
        j = self.J[k - 1]
        w = j["w"]
        return {j["ch"]: -w * j["sh"] / 2, j["sh"]: w * j["ch"] / 2, j["d"]: j["dd"], j["dd"]: j["ddd"]}

    def inputs(self, *names):
        return [self.args[nm] for nm in names]


def _through_law(asm: Assembly, grads: dict, k: int) -> sp.Expr:
    """d/dθ_k from partial derivatives: Σ_s ∂/∂s · ds/dθ_k over the seeds of joint k."""
    return sum((grads.get(s, 0) * v for s, v in asm.seeds(k).items()), sp.S(0))


def rnea(asm: Assembly, qd, qdd, gravity: bool, prefix: str):
    """Recursive Newton-Euler with the legs: τ = M qdd + C qd (+ g with gravity), as steps.

    Body i's velocity and acceleration are formed in B_i (where the joint adds S_i θ'_i,
    S_i θ''_i, (V_{i−1} ×m S_i) θ'_i and d''_i θ'_i² e_z) and moved to Q_i; forces come back the
    same way. The legs of pair i act in B_i: with point accelerations a_p = c + L p of a body
    (c the acceleration of its point at the origin, L = [α]× + [ω]×²), the six legs' forces need
    only Σa, Σb and K.
    """
    rec = _Recorder()
    nm = Namer(rec, prefix)
    n = asm.n
    add = lambda X, Y: (X[0] + Y[0], X[1] + Y[1])
    V = (ZERO3, ZERO3)
    A = (ZERO3, -asm.g if gravity else ZERO3)
    forces, legs = [], []
    for i, j in enumerate(asm.J, start=1):
        if i > 1:
            V = motion_to_child(asm.outer[i - 1], V, nm, "vb")
            A = motion_to_child(asm.outer[i - 1], A, nm, "ab")
        S = asm.S[i - 1]
        VB = (nm.vec("Vw", V[0] + S[0] * qd[i - 1]), nm.vec("Vv", V[1] + S[1] * qd[i - 1]))
        cm = cross_motion(V, S)
        AB = (
            nm.vec("Aw", A[0] + S[0] * qdd[i - 1] + cm[0] * qd[i - 1]),
            nm.vec("Av", A[1] + S[1] * qdd[i - 1] + cm[1] * qd[i - 1] + j["ddd"] * qd[i - 1] ** 2 * EZ),
        )
        # the legs of pair i, from the accelerations of their ends' bodies in B_i
        ml, K = j["ml"], asm.K[i]
        Sb = 6 * j["d"] * EZ
        c_prev = nm.vec("lc", A[1] + V[0].cross(V[1]))
        L_prev = nm.mat3("lL", skew(A[0]) + skew(V[0]) * skew(V[0]))
        c_i = nm.vec("lc", AB[1] + VB[0].cross(VB[1]))
        L_i = nm.mat3("lL", skew(AB[0]) + skew(VB[0]) * skew(VB[0]))
        on_i = (nm.vec("lnb", ml / 6 * (Sb.cross(c_prev) + _vee_antisym(K.T * L_prev.T))), nm.vec("lfb", ml * c_prev))
        on_prev = (nm.vec("lna", ml / 6 * _vee_antisym(K * L_i.T)), nm.vec("lfa", ml * (c_i + L_i * EZ * j["d"])))
        legs.append((on_i, on_prev))
        V = motion_to_child(asm.inner[i], VB, nm, "vq")
        A = motion_to_child(asm.inner[i], AB, nm, "aq")
        I = asm.bodies[i - 1]
        mom = [nm.vec("hv", x) for x in apply_inertia(I, V)]
        forces.append(add(apply_inertia(I, A), cross_force(V, mom)))
    tau = [None] * n
    carry = None
    for i in range(n, 0, -1):
        F = forces[i - 1] if carry is None else add(forces[i - 1], carry)
        F = (nm.vec("Ftn", F[0]), nm.vec("Ftf", F[1]))
        FB = force_to_parent(asm.inner[i], F, nm, "fb")
        FB = add(FB, legs[i - 1][0])
        FB = (nm.vec("FBn", FB[0]), nm.vec("FBf", FB[1]))
        tau[i - 1] = asm._project(i, FB)
        if i > 1:
            carry = force_to_parent(asm.outer[i - 1], add(FB, legs[i - 1][1]), nm, "fo")
    return rec.steps, tau


def kinetic_energy(asm: Assembly, prefix: str):
    """T from the body velocities: ½ Σ V_iᵀ I_i V_i + Σ (m_i/6) V_{i−1}ᵀ X_i V_i (in B_i), as steps."""
    rec = _Recorder()
    nm = Namer(rec, prefix)
    V, T = (ZERO3, ZERO3), sp.S(0)
    for i, j in enumerate(asm.J, start=1):
        if i > 1:
            V = motion_to_child(asm.outer[i - 1], V, nm, "vb")
        S = asm.S[i - 1]
        VB = (nm.vec("Vw", V[0] + S[0] * j["qd"]), nm.vec("Vv", V[1] + S[1] * j["qd"]))
        if i > 1:
            K = asm.K[i]
            top = (K.trace() * sp.eye(3) - K.T) * VB[0]
            bottom = -6 * j["d"] * EZ.cross(VB[0]) + 6 * VB[1]
            T += j["ml"] / 6 * ((V[0].T * top)[0] + (V[1].T * bottom)[0])
        V = motion_to_child(asm.inner[i], VB, nm, "vq")
        mom = apply_inertia(asm.bodies[i - 1], V)
        T += ((V[0].T * mom[0])[0] + (V[1].T * mom[1])[0]) / 2
        T = rec.name(f"{prefix}T{i}", sp.expand(T))
    return rec.steps, T


def lagrangian_bias(asm: Assembly):
    """The same bias by another route: Ṁθ' − ∇_θ(T − V), T = ½ θ'ᵀMθ' (forward + reverse mode)."""
    qd = sp.Matrix([j["qd"] for j in asm.J])
    f_steps, Mdot = directional(asm.rec.steps, list(asm.M), asm.velocity_tangent(), "dMt_")
    L = (qd.T * asm.M * qd)[0] / 2 - asm.V
    r_steps, grads = gradient(asm.rec.steps + asm.vrec.steps, L, "aL_")
    bias = sp.Matrix(asm.n, asm.n, Mdot) * qd - sp.Matrix([_through_law(asm, grads, k) for k in range(1, asm.n + 1)])
    return f_steps + r_steps, list(bias)


def christoffel(asm: Assembly):
    """C = ½(Ṁ + W − Wᵀ), W_ij = ∂(M u)_i/∂θ_j at u = θ': exactly C_ij = Σ_k Γ_ijk θ'_k with the
    Christoffel symbols Γ_ijk = ½(∂_k M_ij + ∂_j M_ik − ∂_i M_jk). Ṁ is one directional derivative
    of M; M u comes from the recursion (no velocity, no gravity, acceleration u) and is differentiated
    along each θ_j (d'' never needs differentiating: it enters only with θ'²)."""
    n = asm.n
    qd = [j["qd"] for j in asm.J]
    steps, Mdot = directional(asm.rec.steps, list(asm.M), asm.velocity_tangent(), "dMt_")
    Mdot = sp.Matrix(n, n, Mdot)
    mu_steps, Mu = rnea(asm, [0] * n, qd, gravity=False, prefix="mu_")
    third = {j["ddd"] for j in asm.J}
    assert not any(e.free_symbols & third for _, e in asm.rec.steps + mu_steps)
    steps += mu_steps
    W = sp.zeros(n, n)
    for jx in range(1, n + 1):
        new, dMu = directional(asm.rec.steps + mu_steps, Mu, asm.seeds(jx), f"dmu{jx}_")
        steps += new
        for i in range(n):
            W[i, jx - 1] = dMu[i]
    return steps, (Mdot + W - W.T) / 2


def check_bias(n: int, samples: int = 2, digits: int = 30) -> float:
    """Max over random points of |RNEA bias − Lagrangian bias|, |RNEA gravity − ∂V/∂θ| and
    |RNEA(θ' = 0, no gravity) − M θ''| and |T from the velocities − ½ θ'ᵀMθ'|; the law's half
    angles are those of a random θ."""
    import random

    import mpmath

    asm = Assembly(n)
    qd = [j["qd"] for j in asm.J]
    qdd = [j["qdd"] for j in asm.J]
    r_steps, r_bias = rnea(asm, qd, [0] * n, gravity=True, prefix="r_")
    l_steps, l_bias = lagrangian_bias(asm)
    g_steps, r_g = rnea(asm, [0] * n, [0] * n, gravity=True, prefix="rg_")
    v_steps, grads = gradient(asm.rec.steps + asm.vrec.steps, asm.V, "aV_")
    l_g = [_through_law(asm, grads, k) for k in range(1, n + 1)]
    a_steps, r_Ma = rnea(asm, [0] * n, qdd, gravity=False, prefix="ra_")
    Ma = list(asm.M * sp.Matrix(qdd))
    t_steps, T = kinetic_energy(asm, "T_")
    qdm = sp.Matrix(qd)
    steps = asm.rec.steps + asm.vrec.steps + r_steps + l_steps + g_steps + v_steps + a_steps + t_steps
    diffs = [a - b for a, b in zip(r_bias + r_g + r_Ma + [T], l_bias + l_g + Ma + [(qdm.T * asm.M * qdm)[0] / 2])]
    rng = random.Random(100 + n)
    worst = mpmath.mpf(0)
    inputs = [s for a in asm.args.values() for s in a.symbols]
    with mpmath.workdps(digits):
        for _ in range(samples):
            env = {s: mpmath.mpf(rng.uniform(-1, 1)) for s in inputs}
            for j in asm.J:
                th = mpmath.mpf(rng.uniform(-6, 6))
                env[j["ch"]], env[j["sh"]] = mpmath.cos(th / 2), mpmath.sin(th / 2)
            for sym, e in steps:
                env[sym] = sp.lambdify(sorted(e.free_symbols, key=str), e, "mpmath")(
                    *[env[v] for v in sorted(e.free_symbols, key=str)]
                )
            for d in diffs:
                val = sp.lambdify(sorted(d.free_symbols, key=str), d, "mpmath")(
                    *[env[v] for v in sorted(d.free_symbols, key=str)]
                )
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
            L[i, j] = rec.name(
                f"{prefix}L{i}{j}", (M[i, j] - sum((L[i, k] * L[j, k] for k in range(j)), sp.S(0))) * inv
            )
        L[j, j] = inv  # below, only 1/L_jj is needed
    y = [None] * n
    for i in range(n):
        y[i] = rec.name(f"{prefix}y{i}", (rhs[i] - sum((L[i, k] * y[k] for k in range(i)), sp.S(0))) * L[i, i])
    x = [None] * n
    for i in reversed(range(n)):
        x[i] = rec.name(f"{prefix}x{i}", (y[i] - sum((L[k, i] * x[k] for k in range(i + 1, n)), sp.S(0))) * L[i, i])
    return rec.steps, x


def specs_for(n: int) -> list[KernelSpec]:
    """The dynamics kernels of the n-joint chain. Forward dynamics, bias and energy call the mass
    matrix and inverse dynamics kernels (`Call`) rather than repeat their code: the bias is the
    inverse dynamics at θ'' = 0, forward dynamics solves M θ'' = τ − bias by Cholesky, and the
    kinetic energy is ½ θ'ᵀMθ'. The mass matrix, inverse and forward dynamics also come in their
    forms for chains of R-pairs (chain_kinematics.revolute), which the runtime takes for them."""
    asm = Assembly(n)
    base = list(asm.rec.steps)
    qd = [j["qd"] for j in asm.J]
    qdd = [j["qdd"] for j in asm.J]
    g_steps, g = rnea(asm, [0] * n, [0] * n, gravity=True, prefix="g_")
    i_steps, tau = rnea(asm, qd, qdd, gravity=True, prefix="id_")
    c_steps, C = christoffel(asm)
    kin = ("law", "dh", "turning")
    body = ("links", "legs")
    mass = KernelSpec(
        f"mass_matrix{n}",
        f"Mass matrix M(theta) ({n} x {n}) of a {n}-joint chain, legs included.",
        SOURCE,
        asm.inputs(*kin, *body),
        [Arg("M", (n, n), "mass matrix, row-major", exprs=tuple(asm.M))],
        base,
    )
    inverse = KernelSpec(
        f"inverse_dynamics{n}",
        f"Joint torques tau = M theta'' + C theta' + g ({n}) of a {n}-joint chain.",
        SOURCE,
        asm.inputs("law", "qd", "qdd", "dh", "turning", *body, "gravity"),
        [Arg("tau", (n,), "joint torques [N m]", exprs=tuple(tau))],
        base + i_steps,
    )
    M_r = sp.Matrix(n, n, [sp.Symbol(f"rM{k}", real=True) for k in range(n * n)])
    b_r = [sp.Symbol(f"rb{k}", real=True) for k in range(n)]
    call_M = lambda *names: Call(mass, names, tuple(M_r))
    call_bias = Call(inverse, ("law", "qd", None, "dh", "turning", "links", "legs", "gravity"), tuple(b_r))
    taus = [sp.Symbol(f"tau_{k}", real=True) for k in range(1, n + 1)]
    f_steps, qdd_fd = cholesky_solve(M_r, [t - b for t, b in zip(taus, b_r)], "fd_")
    tau_arg = Arg("tau", (n,), "joint torques tau_i [N m]", tuple(taus))
    qdm = sp.Matrix(qd)
    T = sp.expand((qdm.T * M_r * qdm)[0] / 2)
    forward = KernelSpec(
        f"forward_dynamics{n}",
        f"Joint accelerations theta'' = M^-1 (tau - C theta' - g) ({n}) of a "
        f"{n}-joint chain, by Cholesky (NaN where M is not positive definite).",
        SOURCE,
        asm.inputs("law", "qd") + [tau_arg] + asm.inputs("dh", "turning", *body, "gravity"),
        [Arg("qdd", (n,), "joint accelerations [rad/s^2]", exprs=tuple(qdd_fd))],
        f_steps,
        calls=[call_M("law", "dh", "turning", "links", "legs"), call_bias],
    )
    # the hot kernels' forms for chains of R-pairs (no slide, pitch or leg terms)
    twins = {k.name: revolute(k) for k in (mass, inverse)}
    return [
        mass,
        KernelSpec(
            f"gravity{n}",
            f"Gravity torques g(theta) = dV/dtheta ({n}) of a {n}-joint chain.",
            SOURCE,
            asm.inputs(*kin, *body, "gravity"),
            [Arg("g", (n,), "gravity torques [N m]", exprs=tuple(g))],
            base + g_steps,
        ),
        KernelSpec(
            f"coriolis{n}",
            f"Coriolis matrix C(theta, theta') ({n} x {n}, Christoffel form) of a {n}-joint chain.",
            SOURCE,
            asm.inputs("law", "qd", "dh", "turning", *body),
            [Arg("C", (n, n), "C such that dM/dt - 2C is skew-symmetric, row-major", exprs=tuple(C))],
            base + c_steps,
        ),
        KernelSpec(
            f"bias{n}",
            f"Bias C(theta, theta') theta' + g(theta) ({n}) of a {n}-joint chain.",
            SOURCE,
            asm.inputs("law", "qd", "dh", "turning", *body, "gravity"),
            [Arg("bias", (n,), "bias torques [N m]", exprs=tuple(b_r))],
            calls=[Call(inverse, ("law", "qd", None, "dh", "turning", "links", "legs", "gravity"), tuple(b_r))],
        ),
        inverse,
        forward,
        KernelSpec(
            f"energy{n}",
            f"Kinetic and potential energy (T, V) of a {n}-joint chain.",
            SOURCE,
            asm.inputs("law", "qd", "dh", "turning", *body, "gravity"),
            [Arg("energy", (2,), "(T, V) [J]", exprs=(T, asm.V))],
            base + asm.vrec.steps,
            calls=[call_M("law", "dh", "turning", "links", "legs")],
        ),
        *twins.values(),
        revolute(forward, twins),
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
