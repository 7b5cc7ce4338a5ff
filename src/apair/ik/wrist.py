"""Every solution of a six-joint R-chain with a spherical wrist, in closed form (issue 42).

Where axes 4, 5 and 6 meet in one point (the families spherical-*, apair.ik.families: PUMA, KUKA,
ABB, Fanuc arms), that point's position depends on ψ_1, ψ_2, ψ_3 alone (ψ_i = θ_i + φ_i) and is
known from the pose. The derived kernel `ik_wrist_position6` (derivations/chain_ik_wrist.py) gives
it and the polynomial in t = tan(ψ_3/2) whose real roots are the solutions' ψ_3: Pieper's quartic,
or one of its two quadratics where axes 1 and 2 meet (a_1 = 0) or are parallel. For each root:

- u = Rz(ψ_2) p(ψ_3), the wrist point in frame 1, has u_x from r = a_1² + 2 a_1 u_x + |p|² and u_y
  from h = sin α_1 u_y + cos α_1 p_z (where a_1 = 0 or sin α_1 = 0, the other from
  u_x² + u_y² = p_x² + p_y², two signs); ψ_2 turns p onto u, ψ_1 turns frame 1's (a_1 + u_x,
  cos α_1 u_y − sin α_1 p_z) onto W's (x, y);
- the wrist: M = R_3ᵀ R_6 Rx(α_6)ᵀ = Rz(ψ_4) Rx(α_4) Rz(ψ_5) Rx(α_5) Rz(ψ_6), whose third column
  and row give cos ψ_5 (two signs of ψ_5), then ψ_4 and ψ_6 by their turns about z.

Every candidate is polished by Gauss-Newton steps and kept only where fk reproduces the pose
(apair.ik.poses.refine). A singular configuration (the wrist point on axis 1 or 2, axes 4 and 6 in
line) has a continuum of solutions: one member is returned for it (the free angle at 0, or the
wrist's ψ_4 at 0 with ψ_4 + ψ_6 or ψ_4 − ψ_6 fixed), and `Wrist.solve` says so in its note.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..frames import dh_matrix
from ..kernels import call, native_in_use
from .closed import DOUBLE, FLAT, SINGULAR, note, real_roots
from .families import Classification
from .poses import joint_periods, pose_error, refine, wrap

CONTINUUM = 1e-6  # a verified solution this close to axes 4 and 6 in line is one of their continuum


# the continua apair_ik_wrist flags, by bit
FLAGS = {
    1: "joints 4 and 6: axes 4 and 6 in line",
    2: "joint 1: the wrist point on axis 1",
    4: "joint 2: the wrist point on axis 2",
}


def applies(chain, family: Classification) -> bool:
    """Whether the closed form covers the chain: six R-pairs, a spherical wrist at joints 4-6."""
    f = family.family
    return (
        chain.n == 6
        and all(p.kind == "revolute" for p in chain.pairs)
        and f is not None
        and f.key.startswith("spherical-")
        and not f.reversed
    )


def _rotation(alpha: float, psi: float) -> NDArray[np.float64]:
    """Rz(ψ)·Rx(α): the rotation of one DH joint (apair.frames.dh_matrix's)."""
    return dh_matrix(0.0, alpha, 0.0, psi)[:3, :3]


class Wrist:
    """The closed form of one chain: its design read once."""

    code = 1  # the family in apair.h (APAIR_IK_WRIST)
    amplitude: NDArray[np.float64] | None = None  # (every joint an R-pair; apair.ik.wrist_apair: the amplitudes)
    flags = FLAGS  # the continua its C form flags, by bit

    def __init__(self, chain, scale: float) -> None:
        self.chain = chain
        self.dh = np.column_stack([chain.a, chain.alpha, chain.offset, chain.theta_offset]).astype(np.float64)
        self.scale = scale
        a, alpha, c = self.dh[:, 0], self.dh[:, 1], self.dh[:, 2]
        self.a1, self.ca1, self.sa1 = a[0], math.cos(alpha[0]), math.sin(alpha[0])
        self.case = "qa" if abs(self.a1) <= FLAT * scale else "qb" if abs(self.sa1) <= FLAT else "quartic"
        self.B2 = dh_matrix(a[1], alpha[1], c[1], 0.0)  # Tz(c_2)·Tx(a_2)·Rx(α_2)
        self.m3 = (dh_matrix(a[2], alpha[2], c[2], 0.0) @ np.array([0.0, 0.0, c[3], 1.0]))[:3]
        self.ca4, self.sa4 = math.cos(alpha[3]), math.sin(alpha[3])
        self.ca5, self.sa5 = math.cos(alpha[4]), math.sin(alpha[4])
        self.rx6t = _rotation(alpha[5], 0.0).T

    def solve(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], NDArray[np.float64], int, str]:
        """Every real solution (k, 6) at frame 6's pose Tm, verified to tol, their errors, the
        candidates examined and a note naming a continuum: in C (apair_ik_wrist) where the C
        backend is in use, else the same steps here."""
        native = native_in_use()
        if native is None:
            cands, free = self.candidates(Tm)
            q, err = refine(self.chain, cands, Tm, tol, self.scale)
            q, err, member = self._canonical(q, err, Tm, tol)
            return q, err, len(cands), note(free | member)
        q, err, found, cands, flags = native.ik_wrist(self.dh, self.scale, Tm.reshape(1, 4, 4), tol)
        if flags[0] < 0:
            raise ValueError("the position polynomial vanishes identically")
        k = int(found[0])
        return q[0, :k], err[0, :k], int(cands[0]), note({why for bit, why in FLAGS.items() if flags[0] & bit})

    def _canonical(self, q, err, Tm, tol) -> tuple[NDArray[np.float64], NDArray[np.float64], set[str]]:
        """A solution with axes 4 and 6 in line (K = Rx(α_4) Rz(ψ_5) Rx(α_5) keeps e_z, K_33 = s = ±1)
        is one of the continuum ψ_4 + s ψ_6 = const: replaced by its member with ψ_4 = 0 where that
        verifies, then merged."""
        phi = self.dh[:, 3]
        psi5 = q[:, 4] + phi[4]
        near = np.hypot(np.sin(psi5) * self.sa5, self.ca4 * np.cos(psi5) * self.sa5 + self.sa4 * self.ca5) <= CONTINUUM
        if not near.any():
            return q, err, set()
        s = np.where(self.ca4 * self.ca5 - self.sa4 * self.sa5 * np.cos(psi5) < 0, -1.0, 1.0)
        y = q.copy()
        y[:, 5] = q[:, 5] + s * (q[:, 3] + phi[3])
        y[:, 3] = -phi[3]
        y = wrap(y, joint_periods(self.chain))
        _, e2 = pose_error(self.chain, y, Tm, self.scale)
        take = near & (e2 <= tol)
        if not take.any():
            return q, err, set()
        q2, err2 = refine(self.chain, np.where(take[:, None], y, q), Tm, tol, self.scale)
        return q2, err2, {FLAGS[1]}

    def candidates(self, Tm: NDArray[np.float64]) -> tuple[NDArray[np.float64], set[str]]:
        """Candidate joint vectors (k, 6) at frame 6's pose Tm, and the continua met (FLAGS' texts)."""
        W, rh, quartic, qa, qb = call("ik_wrist_position6", self.dh, Tm)
        r, h = float(rh[0]), float(rh[1])
        big = r + self.scale**2  # the size of the terms: r, |p|², a_1² (and h², squared in the quartic)
        ref = {"quartic": big * big, "qa": big, "qb": math.sqrt(big)}[self.case]
        roots, at_infinity = real_roots({"quartic": quartic, "qa": qa, "qb": qb}[self.case], ref)
        psi3s = [2 * math.atan(t) for t in roots] + ([math.pi] if at_infinity else [])
        out: list[list[float]] = []
        free: set[str] = set()
        for psi3 in psi3s:
            m = _rotation(0.0, psi3) @ self.m3
            p = self.B2[:3, :3] @ m + self.B2[:3, 3]
            for psi1, psi2 in self._shoulder(W, r, h, p, free):
                R3 = self._r03(psi1, psi2, psi3)
                M = R3.T @ Tm[:3, :3] @ self.rx6t
                for psi456 in self._wrist(M, free):
                    out.append([psi1, psi2, psi3, *psi456])
        q = np.array(out, dtype=np.float64).reshape(-1, 6) - self.dh[:, 3]
        return q, free

    def _shoulder(self, W, r: float, h: float, p, free: set[str]) -> list[tuple[float, float]]:
        pxy2 = p[0] ** 2 + p[1] ** 2
        pp = pxy2 + p[2] ** 2
        a1, ca1, sa1 = self.a1, self.ca1, self.sa1
        pairs: list[tuple[float, float]] = []
        if self.case == "quartic":
            pairs.append(((r - a1 * a1 - pp) / (2 * a1), (h - ca1 * p[2]) / sa1))
        else:
            if self.case == "qa":
                known = (h - ca1 * p[2]) / sa1
            else:
                known = (r - a1 * a1 - pp) / (2 * a1)
            rest = pxy2 - known * known
            if rest < -1e-6 * (pxy2 + self.scale**2):
                return []
            # a double root (rest 0, rounded): sqrt would put both signs 1e-8 off it
            other = 0.0 if rest <= DOUBLE * (pxy2 + self.scale**2) else math.sqrt(rest)
            for sign in (1.0, -1.0) if other > 0 else (1.0,):
                pairs.append((sign * other, known) if self.case == "qa" else (known, sign * other))
        out = []
        tiny = (FLAT * self.scale) ** 2
        for ux, uy in pairs:
            if pxy2 <= tiny:
                free.add(FLAGS[4])
                psi2 = 0.0
            else:
                psi2 = math.atan2(uy, ux) - math.atan2(p[1], p[0])
            vx, vy = a1 + ux, ca1 * uy - sa1 * p[2]
            if W[0] ** 2 + W[1] ** 2 <= tiny and vx * vx + vy * vy <= tiny:
                free.add(FLAGS[2])
                psi1 = 0.0
            else:
                psi1 = math.atan2(W[1], W[0]) - math.atan2(vy, vx)
            out.append((psi1, psi2))
        return out

    def _r03(self, psi1: float, psi2: float, psi3: float) -> NDArray[np.float64]:
        d = self.dh
        A = dh_matrix(d[0, 0], d[0, 1], d[0, 2], psi1) @ dh_matrix(d[1, 0], d[1, 1], d[1, 2], psi2)
        return (A @ dh_matrix(d[2, 0], d[2, 1], d[2, 2], psi3))[:3, :3]

    def _wrist(self, M: NDArray[np.float64], free: set[str]) -> list[tuple[float, float, float]]:
        ca4, sa4, ca5, sa5 = self.ca4, self.sa4, self.ca5, self.sa5
        c5 = (ca4 * ca5 - M[2, 2]) / (sa4 * sa5)
        if abs(c5) > 1 + 1e-6:
            return []
        # |sin ψ_5| from |M e_z|'s (x, y) = |q|: exact near the wrist's singular ψ_5 (acos is not)
        qy0 = ca4 * max(-1.0, min(1.0, c5)) * sa5 + sa4 * ca5
        base = math.atan2(math.sqrt(max(0.0, M[0, 2] ** 2 + M[1, 2] ** 2 - qy0 * qy0)) / abs(sa5), c5)
        if base <= SINGULAR:
            base = 0.0
        elif base >= math.pi - SINGULAR:
            base = math.pi
        out = []
        for psi5 in (base, -base) if 0 < base < math.pi else (base,):
            s5, cs5 = math.sin(psi5), math.cos(psi5)
            qx, qy = s5 * sa5, -ca4 * cs5 * sa5 - sa4 * ca5
            if math.hypot(qx, qy) <= SINGULAR:
                free.add(FLAGS[1])
                N = (_rotation(self.dh[3, 1], 0.0) @ _rotation(self.dh[4, 1], psi5)).T @ M
                out.append((0.0, psi5, math.atan2(N[1, 0], N[0, 0])))
                continue
            psi4 = math.atan2(M[1, 2], M[0, 2]) - math.atan2(qy, qx)
            sx, sy = sa4 * s5, sa4 * cs5 * ca5 + ca4 * sa5
            psi6 = math.atan2(sy, sx) - math.atan2(M[2, 1], M[2, 0])
            out.append((psi4, psi5, psi6))
        return out
