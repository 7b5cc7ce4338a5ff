"""Spatial vectors and rigid-body inertias moved between frames one elementary motion at a time.

A frame chain is a list of elementary motions, each ("rx" | "rz", cos, sin) or ("tx" | "tz", t):
child = parent · e. Motion vectors (ω, v), v the velocity of the body point at the frame origin,
go from parent to child coordinates; force vectors (n, f), n the moment about the origin, and
rigid-body inertias (m, h, Ī) (mass, first moment, rotational inertia about the origin) go from
child to parent. Applying the factors one at a time keeps each step a few multiplications (a
rotation about a coordinate axis touches two components, a translation along one touches few),
which is what makes the body-frame recursions of derivations/chain_dynamics.py cheap. Every result
is named by the recorder, so a recursion stays linear in size.
"""

from __future__ import annotations

import sympy as sp


def rotation(axis: str, c, s) -> sp.Matrix:
    """The 3x3 rotation about x or z with cosine c and sine s."""
    if axis == "x":
        return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def offset(e) -> sp.Matrix:
    """The translation vector of an elementary translation."""
    k = {"tx": 0, "tz": 2}[e[0]]
    p = sp.zeros(3, 1)
    p[k] = e[1]
    return p


def skew(v) -> sp.Matrix:
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


class Namer:
    """Names vectors and matrices as recorder steps with unique labels `{prefix}{tag}{k}_{i}`."""

    def __init__(self, rec, prefix: str):
        self.rec, self.prefix, self.count = rec, prefix, 0

    def vec(self, tag: str, v) -> sp.Matrix:
        self.count += 1
        return sp.Matrix([self.rec.name(f"{self.prefix}{tag}{self.count}_{i}", sp.expand(x)) for i, x in enumerate(v)])

    def sym3(self, tag: str, M) -> sp.Matrix:
        self.count += 1
        out = sp.zeros(3, 3)
        for r in range(3):
            for c in range(r, 3):
                out[r, c] = out[c, r] = self.rec.name(f"{self.prefix}{tag}{self.count}_{r}{c}", sp.expand(M[r, c]))
        return out

    def mat3(self, tag: str, M) -> sp.Matrix:
        self.count += 1
        return sp.Matrix(
            3,
            3,
            [
                self.rec.name(f"{self.prefix}{tag}{self.count}_{r}{c}", sp.expand(M[r, c]))
                for r in range(3)
                for c in range(3)
            ],
        )


def motion_to_child(chain, V, nm: Namer, tag: str = "v"):
    """A motion vector (ω, v) in parent coordinates, in the coordinates of parent · chain."""
    w, v = V
    for e in chain:
        if e[0] in ("rx", "rz"):
            Rt = rotation(e[0][1], e[1], e[2]).T
            w, v = nm.vec(tag + "w", Rt * w), nm.vec(tag, Rt * v)
        else:
            v = nm.vec(tag, v + w.cross(offset(e)))
    return w, v


def force_to_parent(chain, F, nm: Namer, tag: str = "f"):
    """A force vector (n, f) in the coordinates of parent · chain, in parent coordinates."""
    n, f = F
    for e in reversed(chain):
        if e[0] in ("rx", "rz"):
            R = rotation(e[0][1], e[1], e[2])
            n, f = nm.vec(tag + "n", R * n), nm.vec(tag, R * f)
        else:
            n = nm.vec(tag + "n", n + offset(e).cross(f))
    return n, f


def inertia_to_parent(chain, inertia, nm: Namer, tag: str = "I"):
    """A rigid-body inertia (m, h, Ī) in the coordinates of parent · chain, in parent coordinates
    (Ī may be None: then only mass and first moment are moved, as for a potential energy)."""
    m, h, Ib = inertia
    for e in reversed(chain):
        if e[0] in ("rx", "rz"):
            R = rotation(e[0][1], e[1], e[2])
            h = nm.vec(tag + "h", R * h)
            if Ib is not None:
                Ib = nm.sym3(tag, R * Ib * R.T)
        else:
            p = offset(e)
            if Ib is not None:
                Ib = nm.sym3(
                    tag,
                    Ib + m * ((p.T * p)[0] * sp.eye(3) - p * p.T) + 2 * (p.T * h)[0] * sp.eye(3) - p * h.T - h * p.T,
                )
            h = nm.vec(tag + "h", h + m * p)
    return m, h, Ib


def apply_inertia(inertia, V):
    """The momentum (Ī ω + h × v, m v − h × ω) of a rigid-body inertia moving with V = (ω, v)."""
    m, h, Ib = inertia
    w, v = V
    return Ib * w + h.cross(v), m * v - h.cross(w)


def cross_motion(V, U):
    """(ω, v) ×m (w, u) = (ω × w, ω × u + v × w)."""
    return V[0].cross(U[0]), V[0].cross(U[1]) + V[1].cross(U[0])


def cross_force(V, F):
    """(ω, v) ×f (n, f) = (ω × n + v × f, ω × f)."""
    return V[0].cross(F[0]) + V[1].cross(F[1]), V[0].cross(F[1])


def point_mass_inertia(mass, first, second) -> tuple:
    """Inertia (m, h, Ī) of point masses with total `mass`, first moment `first` (Σ m p) and second
    moment `second` (Σ m p pᵀ): Ī = tr(second) I − second."""
    return mass, first, second.trace() * sp.eye(3) - second


def add_inertia(*inertias):
    m = sum((i[0] for i in inertias), sp.S(0))
    h = sum((i[1] for i in inertias), sp.zeros(3, 1))
    Ib = sum((i[2] for i in inertias), sp.zeros(3, 3))
    return m, h, Ib
