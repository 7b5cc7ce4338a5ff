"""Every solution of a six-joint R-chain with axes 1, 2 and 3 parallel and axes 5 and 6 meeting, in
closed form (issue 42; the family three-parallel-two-intersecting, apair.ik.families).

Where sin α_1 = sin α_2 = 0, the joints 1-3 turn about one direction, so the third row of
M = A_1 A_2 A_3 A_4 depends on ψ_4 alone (ψ_i = θ_i + φ_i). Where a_5 = 0, axes 5 and 6 meet in W,
read off the pose, and W = M (0, 0, c_5). The derived kernel `ik_three_parallel6`
(derivations/chain_ik_three_parallel.py) gives W, the equation A cos ψ_4 + B sin ψ_4 = C of W's height
along the parallel axes (IK-Geo's subproblem 4: two ψ_4), the third row u(ψ_4) of M's rotation and
g, the third row of R_6 Rx(α_6)ᵀ. Then:

- u Rz(ψ_5) Rx(α_5) Rz(ψ_6) = g: its third entry, sin α_5 (u_x sin ψ_5 − u_y cos ψ_5) = g_z − cos α_5 u_z,
  gives two ψ_5, and ψ_6 turns (g_x, g_y) onto the first two entries of v = u Rz(ψ_5) Rx(α_5)
  (subproblem 2);
- N = A_1 A_2 A_3 = T (A_4 A_5 A_6)⁻¹ has the rotation Rz(S) Rx(α_1 + α_2 + α_3), S = ψ_1 + cos α_1 ψ_2 +
  cos α_1 cos α_2 ψ_3, and frame 3's origin less a_3 (cos S, sin S) is P = a_1 e(ψ_1) + a_2 e(ψ_1 + γ),
  γ = cos α_1 ψ_2: cos γ = (|P|² − a_1² − a_2²)/(2 a_1 a_2) (two elbows), ψ_1 by atan2, ψ_3 from S.

Where axis 5 or axis 6 is parallel to axes 1-3 (four parallel joints, a self-motion) that joint is
free: P runs on a circle as it turns, and the member with the elbow mid-range (cos γ = 0) is taken
where the circle reaches it, else the nearest; where axes 1 and 3 are one line ψ_1 is free (0 is
taken). `note` names the continuum. Every candidate is polished by Gauss-Newton steps and kept only
where fk reproduces the pose (apair.ik.poses.refine); C twin: src/csrc/apair_ik_three_parallel.c.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..frames import dh_matrix, inverse
from ..kernels import call, native_in_use
from .closed import DOUBLE, FLAT, SINGULAR, note
from .families import Classification
from .poses import refine

# the continua apair_ik_three_parallel flags, by bit
FLAGS = {
    1: "joints 1, 2, 3 and 5: axis 5 parallel to axes 1, 2 and 3",
    2: "joints 1, 2, 3 and 6: axis 6 parallel to axes 1, 2 and 3",
    4: "joints 1 and 3: axes 1 and 3 on one line",
}


def applies(chain, family: Classification) -> bool:
    """Whether the closed form covers the chain: six R-pairs, axes 1, 2, 3 parallel, 5 and 6 meeting."""
    f = family.family
    return (
        chain.n == 6
        and all(p.kind == "revolute" for p in chain.pairs)
        and f is not None
        and f.key == "three-parallel-two-intersecting"
        and not f.reversed
    )


def _lin_trig(a: float, b: float, c: float, ref: float) -> list[float] | None:
    """x with a cos x + b sin x = c (0, 1 where tangent, or 2); None where a = b = 0 against ref."""
    r = math.hypot(a, b)
    if not r > FLAT * ref:
        return None
    k = c / r
    if not abs(k) <= 1 + 1e-6:
        return []
    base, d = math.atan2(b, a), math.acos(max(-1.0, min(1.0, k)))
    if d <= SINGULAR:
        return [base]
    if d >= math.pi - SINGULAR:
        return [base + math.pi]
    return [base + d, base - d]


class ThreeParallel:
    """The closed form of one chain: its design read once."""

    code = 3  # the family in apair.h (APAIR_IK_THREE_PARALLEL)
    amplitude = None  # (every joint an R-pair)
    flags = FLAGS  # the continua its C form flags, by bit

    def __init__(self, chain, scale: float) -> None:
        self.chain = chain
        self.dh = np.column_stack([chain.a, chain.alpha, chain.offset, chain.theta_offset]).astype(np.float64)
        self.scale = scale
        a, alpha, c = self.dh[:, 0], self.dh[:, 1], self.dh[:, 2]
        self.ca, self.sa = np.cos(alpha), np.sin(alpha)
        self.e1, self.e12 = float(self.ca[0]), float(self.ca[0] * self.ca[1])
        flat = FLAT * scale
        if abs(a[0]) <= flat or abs(a[1]) <= flat:
            raise ValueError("two of axes 1, 2, 3 are one line")
        if math.hypot(c[4] * self.sa[3], a[3]) * abs(self.sa[2]) <= flat:
            raise ValueError("joint 4 does not move the point where axes 5 and 6 meet along axis 1")

    def solve(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], NDArray[np.float64], int, str]:
        """Every real solution (k, 6) at frame 6's pose Tm, verified to tol, their errors, the
        candidates examined and a note naming a continuum: in C (apair_ik_three_parallel) where the
        C backend is in use, else the same steps here."""
        native = native_in_use()
        if native is None:
            cands, free = self.candidates(Tm)
            q, err = refine(self.chain, cands, Tm, tol, self.scale)
            verified = free if len(q) else set()
            return q, err, len(cands), note(verified)
        q, err, found, cands, flags = native.ik_three_parallel(self.dh, self.scale, Tm.reshape(1, 4, 4), tol)
        k = int(found[0])
        return q[0, :k], err[0, :k], int(cands[0]), note({why for bit, why in FLAGS.items() if flags[0] & bit})

    def candidates(self, Tm: NDArray[np.float64]) -> tuple[NDArray[np.float64], set[str]]:
        """Candidate joint vectors (k, 6) at frame 6's pose Tm, and the continua met (FLAGS' texts)."""
        _, F4, U, g = call("ik_three_parallel6", self.dh, Tm)
        U = U.reshape(3, 3)
        ca5, sa5 = float(self.ca[4]), float(self.sa[4])
        out: list[list[float]] = []
        free: set[str] = set()
        for psi4 in _lin_trig(float(F4[0]), float(F4[1]), float(F4[2]), self.scale) or []:
            u = U @ np.array([1.0, math.cos(psi4), math.sin(psi4)])
            psi5s = _lin_trig(-sa5 * u[1], sa5 * u[0], float(g[2]) - ca5 * u[2], 1.0)
            for psi5 in psi5s if psi5s is not None else [None]:
                psi = [psi4, 0.0 if psi5 is None else psi5, 0.0]
                c5, s5 = math.cos(psi[1]), math.sin(psi[1])
                vx, vy = u[0] * c5 + u[1] * s5, (-u[0] * s5 + u[1] * c5) * ca5 + u[2] * sa5
                if psi5 is not None and math.hypot(vx, vy) <= SINGULAR:  # axis 6 parallel to axes 1-3
                    psi[2] = self._free_member(Tm, psi, 2)
                    free.add(FLAGS[2])
                else:
                    psi[2] = math.atan2(g[0] * vy - g[1] * vx, g[0] * vx + g[1] * vy)
                if psi5 is None:  # axis 5 parallel to axes 1-3: ψ_5 free (v, so ψ_6, does not move with it)
                    psi[1] = self._free_member(Tm, psi, 1)
                    free.add(FLAGS[1])
                out += self._elbows(Tm, psi, free)
        return np.array(out, dtype=np.float64).reshape(-1, 6) - self.dh[:, 3], free

    def _planar(self, Tm, psi456) -> tuple[float, NDArray[np.float64]]:
        """S and P (the module's docstring) at ψ_4, ψ_5, ψ_6."""
        d = self.dh
        M = np.eye(4)
        for i, x in zip((3, 4, 5), psi456):
            M = M @ dh_matrix(d[i, 0], d[i, 1], d[i, 2], x)
        N = Tm @ inverse(M)
        S = math.atan2(N[1, 0], N[0, 0])
        return S, N[:2, 3] - d[2, 0] * np.array([math.cos(S), math.sin(S)])

    def _free_member(self, Tm, psi456: list[float], which: int) -> float:
        """The free joint's value with the elbow mid-range (|P|² = a_1² + a_2²) where P's circle
        reaches it, else the nearest."""
        r = []
        for k in range(3):
            psi456[which] = k * math.pi / 2
            r.append(float(np.sum(self._planar(Tm, psi456)[1] ** 2)))
        A, B = 0.5 * (r[0] + r[2]), 0.5 * (r[0] - r[2])
        C = r[1] - A
        K = math.hypot(B, C)
        mid = self.dh[0, 0] ** 2 + self.dh[1, 0] ** 2
        if not K > FLAT * mid:
            return 0.0
        return math.atan2(C, B) + math.acos(max(-1.0, min(1.0, (mid - A) / K)))

    def _elbows(self, Tm, psi456: list[float], free: set[str]) -> list[list[float]]:
        """[ψ_1 … ψ_6] per elbow of the planar problem left by ψ_4, ψ_5, ψ_6."""
        S, P = self._planar(Tm, psi456)
        a1, a2 = self.dh[0, 0], self.dh[1, 0]
        rho2 = float(P @ P)
        c = (rho2 - a1 * a1 - a2 * a2) / (2 * a1 * a2)
        if abs(c) > 1 + 1e-6:
            return []
        rest = 1 - c * c
        s = 0.0 if rest <= DOUBLE * 4 else math.sqrt(max(0.0, rest))
        out = []
        for sign in (1.0, -1.0) if s > 0 else (1.0,):
            gamma = math.atan2(sign * s, c)
            if rho2 <= (FLAT * self.scale) ** 2:
                free.add(FLAGS[4])
                psi1 = 0.0
            else:
                psi1 = math.atan2(P[1], P[0]) - math.atan2(a2 * math.sin(gamma), a1 + a2 * math.cos(gamma))
            out.append([psi1, self.e1 * gamma, self.e12 * (S - psi1 - gamma), *psi456])
        return out
