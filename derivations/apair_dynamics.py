"""The equation of motion of one A-pair with its legs, by Lagrange's equations (docs/conventions.md §4).

Vertical axis, gravity g along −z. The platform (mass m, centre of mass c and inertia I in the
platform frame) turns by θ and rises by d(θ); each leg is a uniform rod from a fixed base point to
a platform point (its end points from derivations/apair_pair.py), with kinetic energy
(m_l/6)|v_b|² (v_a = 0) and potential energy m_l g (a_z + b_z)/2. With T = ½ J(θ) θ'²:

    τ = J(θ) θ'' + ½ J'(θ) θ'² + G(θ),   G = dV/dθ.

The derivation works with the law values (d, d', d'') as symbols, then specialises to the
sinusoidal and the general pair. This route (explicit energies, sympy differentiation) shares
nothing with the chain recursion, and the tests compare the two for n = 1.
"""

from __future__ import annotations

import sympy as sp

from . import apair_pair
from .spec import Arg, Entry, KernelSpec, PolynomialSet

SOURCE = "derivations/apair_dynamics.py"

theta, t = apair_pair.theta, sp.Symbol("t", real=True)
d, dd, ddd = sp.symbols("d dd ddd", real=True)
qd, qdd = sp.symbols("qd qdd", real=True)
m, cx, cy, cz, Ixx, Iyy, Izz, Ixy, Ixz, Iyz = sp.symbols("m c_x c_y c_z I_xx I_yy I_zz I_xy I_xz I_yz", real=True)
m_l, g = sp.symbols("m_l g", real=True)
r_b, r_p, h, a, b = apair_pair.r_b, apair_pair.r_p, apair_pair.h, apair_pair.a, apair_pair.b


def derive():
    th = sp.Function("theta")(t)
    D = sp.Function("D")  # d as a function of θ
    law_subs = lambda e: (
        e.subs(sp.Derivative(D(theta), (theta, 2)), ddd).subs(sp.Derivative(D(theta), theta), dd).subs(D(theta), d)
    )

    def rz(x):
        return sp.Matrix([[sp.cos(x), -sp.sin(x), 0], [sp.sin(x), sp.cos(x), 0], [0, 0, 1]])

    # platform: position of the centre of mass and angular velocity
    R = rz(th)
    com = R * sp.Matrix([cx, cy, cz]) + sp.Matrix([0, 0, D(th)])
    v = com.diff(t)
    omega = sp.Matrix([0, 0, th.diff(t)])
    I = sp.Matrix([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])
    T_platform = (m * v.dot(v) + omega.dot(R * I * R.T * omega)) / 2
    V_platform = m * g * com[2]

    # legs: end points from the A-pair derivation, the platform point moving with (θ, d(θ))
    pts = apair_pair.legs_spec().outputs[0].exprs
    T_legs, V_legs = 0, 0
    for k in range(6):
        base = sp.Matrix(pts[6 * k : 6 * k + 3])
        tip = sp.Matrix(pts[6 * k + 3 : 6 * k + 6]).subs({apair_pair.theta: th, apair_pair.d: D(th)})
        vb = tip.diff(t)
        T_legs += m_l / 6 * vb.dot(vb)
        V_legs += m_l * g * (base[2] + tip[2]) / 2

    qdot = th.diff(t)
    to_q = lambda e: law_subs(sp.expand(e).subs(sp.Derivative(th, (t, 2)), qdd).subs(qdot, qd).subs(th, theta))
    parts = {}
    for label, T, V in (("platform", T_platform, V_platform), ("legs", T_legs, V_legs)):
        L = T - V
        eom = sp.diff(L.diff(qdot), t) - L.diff(th)
        J = sp.simplify(to_q(2 * T / qdot**2))
        Vq = sp.simplify(to_q(V))
        tau = sp.expand(to_q(eom))
        # split τ into J θ'' + (½ J') θ'² + G and check each piece
        J_from_tau = sp.simplify(tau.coeff(qdd))
        half_dJ = sp.simplify(tau.coeff(qd, 2))
        G = sp.simplify(tau.subs({qd: 0, qdd: 0}))
        assert sp.simplify(J_from_tau - J) == 0
        assert sp.simplify(tau - (J * qdd + half_dJ * qd**2 + G)) == 0
        dJ = sp.diff(J.subs({d: D(theta), dd: sp.Derivative(D(theta), theta)}), theta)
        dJ = (
            dJ.subs(sp.Derivative(D(theta), (theta, 2)), ddd).subs(sp.Derivative(D(theta), theta), dd).subs(D(theta), d)
        )
        assert sp.simplify(half_dJ - dJ / 2) == 0, "the velocity term must be ½ J'(θ) θ'²"
        dV = sp.diff(Vq.subs(d, D(theta)), theta).subs(sp.Derivative(D(theta), theta), dd)
        assert sp.simplify(G - dV) == 0
        parts[label] = (J, half_dJ, G, sp.simplify(to_q(T)), Vq)

    J = sum(p[0] for p in parts.values())
    half_dJ = sum(p[1] for p in parts.values())
    G = sum(p[2] for p in parts.values())
    laws = {"sinusoidal": h * sp.cos(theta / 2), "general": sp.sqrt(a + b * sp.cos(theta))}
    entries = []
    for label, (Jp, _hp, Gp, Tp, Vp) in parts.items():
        entries += [
            Entry(f"T_{label}", sp.Symbol(f"T_{label}"), (), f"kinetic energy of the {label}", rhs=Tp),
            Entry(f"V_{label}", sp.Symbol(f"V_{label}"), (), f"potential energy of the {label}", rhs=Vp),
            Entry(f"J_{label}", sp.Symbol(f"J_{label}"), (), f"{label}: generalised inertia J(theta)", rhs=Jp),
            Entry(f"G_{label}", sp.Symbol(f"G_{label}"), (), f"{label}: gravity term dV/dtheta", rhs=Gp),
        ]
    entries += [
        Entry(
            "equation",
            sp.Symbol("tau"),
            (),
            "d, dd, ddd: the law d(theta) and its derivatives",
            rhs=sp.collect(sp.expand(J * qdd + half_dJ * qd**2 + G), [qdd, qd]),
        ),
    ]
    for kind, law in laws.items():
        sub = {ddd: sp.diff(law, theta, 2), dd: sp.diff(law, theta), d: law}
        for name, e in (("J", J), ("half_dJ", half_dJ), ("G", G)):
            entries.append(
                Entry(f"{name}_{kind}", sp.Symbol(name), (), f"{kind} pair", rhs=sp.simplify(e.xreplace(sub)))
            )

    spec = KernelSpec(
        name="pair_dynamics",
        doc=(
            "One A-pair with a vertical axis (gravity g along -z): (tau, J, J'/2, G) with "
            "tau = J theta'' + (J'/2) theta'^2 + G."
        ),
        source=SOURCE,
        inputs=[
            Arg("theta", (1,), "joint angle [rad]", (theta,)),
            Arg("qd", (1,), "theta' [rad/s]", (qd,)),
            Arg("qdd", (1,), "theta'' [rad/s^2]", (qdd,)),
            Arg("law", (3,), "(d, d', d'') of the pair at theta", (d, dd, ddd)),
            Arg(
                "platform",
                (5,),
                "platform mass [kg], centre of mass (x, y, z) in the platform frame [m], "
                "I_zz about the centre of mass [kg m^2]",
                (m, cx, cy, cz, Izz),
            ),
            Arg("legs", (3,), "(leg mass [kg], r_b [m], r_p [m])", (m_l, r_b, r_p)),
            Arg("g", (1,), "gravitational acceleration [m/s^2] (acting along -z)", (g,)),
        ],
        outputs=[
            Arg(
                "terms",
                (4,),
                "(tau [N m], J [kg m^2], J'/2 [kg m^2/rad], G [N m])",
                exprs=(J * qdd + half_dJ * qd**2 + G, J, half_dJ, G),
            )
        ],
    )
    ps = PolynomialSet(
        name="apair_dynamics",
        title="Equation of motion of one A-pair with its six legs",
        source=SOURCE,
        description=(
            "tau = J(theta) theta'' + (1/2) J'(theta) theta'^2 + G(theta); vertical axis, gravity g "
            "along -z; platform mass m, centre of mass c, inertia I; legs: uniform rods of mass m_l."
        ),
        entries=entries,
    )
    return [ps], [spec], {"J": J, "half_dJ": half_dJ, "G": G}
