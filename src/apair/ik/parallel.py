"""Every solution of a six-joint R-chain with three parallel inner axes, in closed form (issue 42).

Where axes 2, 3 and 4 are parallel (the family three-inner-parallel, apair.ik.families: the UR
arms), the third row of A_2 A_3 A_4 A_5 depends on ψ_5 alone (ψ_i = θ_i + φ_i), and frame 1 sees it
as z_1·z_5 and z_1·(O_5 − O_1), known from the pose once ψ_1 is. The derived kernel
`ik_parallel_position6` (derivations/chain_ik_parallel.py) gives the two equations L_1(ψ_1) =
P cos ψ_5 and L_2(ψ_1) = Q sin ψ_5 and the polynomial in t = tan(ψ_1/2) whose real roots are the
solutions' ψ_1: a quartic, or L_2's quadratic where a_5 = 0 (UR: two ψ_5 from cos ψ_5 = L_1/P), or
L_1's where axes 5 and 6 are parallel (two ψ_5 from sin ψ_5 = L_2/Q). For each (ψ_1, ψ_5):

- ψ_6 turns w = the third row of Rz(ψ_5) Rx(α_5) seen from frame 4 onto z_1ᵀ R_6 Rx(α_6)ᵀ (the
  third row of A_2…A_6's rotation); where w is along z (axis 6 parallel to axes 2-4, the arm's wrist
  singularity) ψ_6 is free: the member with the elbow mid-range (cos ψ_3 = 0) is taken where the
  continuum reaches it, else the nearest (exact where the continuum shrinks to one stretched arm);
- frame 3's origin O_3 = A_1⁻¹ T A_6⁻¹ A_5⁻¹ (0, 0, 0) less (a_4, c_4 sin α_4, c_4 cos α_4) in frame 4
  lies in the plane of the parallel axes at distance ρ from axis 2: cos ψ_3 = (ρ² − a_2² − a_3²)/(2 a_2
  a_3) (two elbows), ψ_2 turns (a_2 + a_3 cos ψ_3, cos α_2 a_3 sin ψ_3) onto O_3, and ψ_4 closes the
  rotation about the parallel axes.

Every candidate is polished by Gauss-Newton steps and kept only where fk reproduces the pose
(apair.ik.poses.refine); C twin: src/csrc/apair_ik_parallel.c.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..frames import dh_matrix
from ..kernels import call, native_in_use
from .closed import DOUBLE, FLAT, SINGULAR, note, real_roots
from .families import Classification
from .poses import refine

# the continua apair_ik_parallel flags, by bit
FLAGS = {
    1: "joints 2, 3, 4 and 6: axis 6 parallel to axes 2, 3 and 4",
    2: "joints 2 and 4: axes 2 and 4 on one line",
}


def applies(chain, family: Classification) -> bool:
    """Whether the closed form covers the chain: six R-pairs, axes 2, 3 and 4 parallel."""
    f = family.family
    return (
        chain.n == 6
        and all(p.kind == "revolute" for p in chain.pairs)
        and f is not None
        and f.key == "three-inner-parallel"
        and not f.reversed
    )


class Parallel:
    """The closed form of one chain: its design read once."""

    code = 2  # the family in apair.h (APAIR_IK_PARALLEL)
    amplitude: NDArray[np.float64] | None = None  # the A-pairs' amplitudes (apair.ik.parallel_apair, parallel_slides)
    flags = FLAGS  # the continua its C form flags, by bit

    def __init__(self, chain, scale: float) -> None:
        self.chain = chain
        self.dh = np.column_stack([chain.a, chain.alpha, chain.offset, chain.theta_offset]).astype(np.float64)
        self.scale = scale
        a, alpha, c = self.dh[:, 0], self.dh[:, 1], self.dh[:, 2]
        ca, sa = np.cos(alpha), np.sin(alpha)
        self.ca, self.sa = ca, sa
        P, Q = -ca[1] * ca[2] * sa[3] * sa[4], ca[1] * ca[2] * sa[3] * a[4]
        if abs(P) <= FLAT and abs(Q) <= FLAT * scale:
            raise ValueError("axes 5 and 6 are one line")
        self.case = "qb" if abs(Q) <= FLAT * scale else "qa" if abs(P) <= FLAT else "quartic"
        self.o3 = np.array([a[3], c[3] * sa[3], c[3] * ca[3]])  # O_4 − O_3 in frame 4

    def solve(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], NDArray[np.float64], int, str]:
        """Every real solution (k, 6) at frame 6's pose Tm, verified to tol, their errors, the
        candidates examined and a note naming a continuum: in C (apair_ik_parallel) where the C
        backend is in use, else the same steps here."""
        native = native_in_use()
        if native is None:
            cands, free = self.candidates(Tm, tol)
            q, err = refine(self.chain, cands, Tm, tol, self.scale)
            return q, err, len(cands), note(free)
        q, err, found, cands, flags = native.ik_parallel(self.dh, self.scale, Tm.reshape(1, 4, 4), tol)
        if flags[0] < 0:
            raise ValueError("the position polynomial vanishes identically")
        k = int(found[0])
        return q[0, :k], err[0, :k], int(cands[0]), note({why for bit, why in FLAGS.items() if flags[0] & bit})

    def candidates(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], set[str]]:
        """Candidate joint vectors (k, 6) at frame 6's pose Tm, and the continua met (FLAGS' texts:
        a free ψ_6 where its member verifies to tol)."""
        L, PQ, quartic, qa, qb = call("ik_parallel_position6", self.dh, Tm)
        L1, L2 = L.reshape(2, 3)
        P, Q = float(PQ[0]), float(PQ[1])
        big = self.scale + float(np.linalg.norm(Tm[:3, 3]))  # the size of L_2's terms
        ref = {"quartic": (big * P) ** 2 + Q**2, "qa": 1.0, "qb": big}[self.case]  # as apair_ik_parallel.c
        roots, at_infinity = real_roots({"quartic": quartic, "qa": qa, "qb": qb}[self.case], ref)
        psi1s = [2 * math.atan(t) for t in roots] + ([math.pi] if at_infinity else [])
        z5 = Tm[:3, :3] @ np.array([0.0, self.sa[5], self.ca[5]])
        out: list[list[float]] = []
        free: set[str] = set()
        for psi1 in psi1s:
            cs1 = np.array([1.0, math.cos(psi1), math.sin(psi1)])
            l1, l2 = float(L1 @ cs1), float(L2 @ cs1)
            z1 = np.array([self.sa[0] * cs1[2], -self.sa[0] * cs1[1], self.ca[0]])
            for psi5 in self._psi5(l1, l2, P, Q, z1, z5):
                psi6 = self._psi6(psi5, z1, Tm)
                if psi6 is None:  # ψ_6 free: the member with the elbow mid-range
                    found = self._inner(psi1, psi5, self._free_psi6(psi1, psi5, Tm), Tm, free)
                    if len(refine(self.chain, np.array(found).reshape(-1, 6) - self.dh[:, 3], Tm, tol, self.scale)[0]):
                        free.add(FLAGS[1])
                    out += found
                else:
                    out += self._inner(psi1, psi5, psi6, Tm, free)
        q = np.array(out, dtype=np.float64).reshape(-1, 6) - self.dh[:, 3]
        return q, free

    def _psi5(self, l1: float, l2: float, P: float, Q: float, z1, z5) -> list[float]:
        if self.case == "quartic":
            return [math.atan2(l2 / Q, l1 / P)]
        if self.case == "qb":  # cos ψ_5 = L_1/P; |sin ψ_5| from |z_1 × z_5|² = w_x² + w_y² (exact near ψ_5 = 0)
            c5 = l1 / P
            if abs(c5) > 1 + 1e-6:
                return []
            ca4, sa4, ca5, sa5 = self.ca[3], self.sa[3], self.ca[4], self.sa[4]
            wy = sa4 * max(-1.0, min(1.0, c5)) * ca5 + ca4 * sa5
            s5 = math.sqrt(max(0.0, float(np.sum(np.cross(z1, z5) ** 2)) - wy * wy)) / abs(sa4)
            base = math.atan2(s5, c5)
        else:  # sin ψ_5 = L_2/Q: ψ_5 and π − ψ_5
            s5 = l2 / Q
            if abs(s5) > 1 + 1e-6:
                return []
            base = math.asin(max(-1.0, min(1.0, s5)))
            if abs(abs(base) - math.pi / 2) <= SINGULAR:
                return [math.copysign(math.pi / 2, base)]
            return [base, math.pi - base]
        if base <= SINGULAR:
            return [0.0]
        if base >= math.pi - SINGULAR:
            return [math.pi]
        return [base, -base]

    def _psi6(self, psi5: float, z1, Tm) -> float | None:
        """ψ_6 turning w (the third row of Rz(ψ_5) Rx(α_5), seen from frame 4) onto v = (z_1ᵀ R_6
        Rx(α_6)ᵀ); None where w is along z (axis 6 parallel to axes 2-4: ψ_6 free)."""
        ca4, sa4, ca5, sa5 = self.ca[3], self.sa[3], self.ca[4], self.sa[4]
        s5, c5 = math.sin(psi5), math.cos(psi5)
        wx, wy = sa4 * s5, sa4 * c5 * ca5 + ca4 * sa5
        if math.hypot(wx, wy) <= SINGULAR:
            return None
        v = z1 @ Tm[:3, :3] @ dh_matrix(0.0, self.dh[5, 1], 0.0, 0.0)[:3, :3].T
        eps = self.ca[1] * self.ca[2]  # the third row of A_2 A_3 A_4 A_5 A_6 is ε w Rz(ψ_6) Rx(α_6)
        vx, vy = eps * v[0], eps * v[1]
        return math.atan2(wy * vx - wx * vy, wx * vx + wy * vy)

    def _free_psi6(self, psi1: float, psi5: float, Tm, dh: NDArray[np.float64] | None = None) -> float:
        """Where ψ_6 is free, frame 3's origin runs on a circle as ψ_6 turns, ρ² = A + B cos ψ_6 +
        C sin ψ_6: the member with the elbow at cos ψ_3 = 0 (ρ² = a_2² + a_3²) where the circle
        reaches it, else the nearest."""
        A, B, C = self._circle(psi1, psi5, Tm, dh)
        K = math.hypot(B, C)
        mid = self.dh[1, 0] ** 2 + self.dh[2, 0] ** 2
        if not K > FLAT * mid:
            return 0.0
        return math.atan2(C, B) + math.acos(max(-1.0, min(1.0, (mid - A) / K)))

    def _circle(
        self, psi1: float, psi5: float, Tm, dh: NDArray[np.float64] | None = None
    ) -> tuple[float, float, float]:
        """(A, B, C) of ρ² = A + B cos ψ_6 + C sin ψ_6, frame 3's distance from axis 2 as ψ_6 turns."""
        r = [float(np.sum(self._frame3(psi1, psi5, k * math.pi / 2, Tm, dh)[1] ** 2)) for k in range(3)]
        A, B = 0.5 * (r[0] + r[2]), 0.5 * (r[0] - r[2])
        return A, B, r[1] - A

    def _frame3(
        self, psi1: float, psi5: float, psi6: float, Tm, dh: NDArray[np.float64] | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """N = A_2 A_3 A_4 and frame 3's origin's (x, y) in frame 1 (`dh`: the design with the
        A-pairs' slides added to c_1 and c_5, apair.ik.parallel_slides; default the chain's)."""
        d = self.dh if dh is None else dh
        A1 = dh_matrix(d[0, 0], d[0, 1], d[0, 2], psi1)
        A5 = dh_matrix(d[4, 0], d[4, 1], d[4, 2], psi5)
        A6 = dh_matrix(d[5, 0], d[5, 1], d[5, 2], psi6)
        N = np.linalg.solve(A1, Tm @ np.linalg.inv(A6) @ np.linalg.inv(A5))
        return N, (N[:3, 3] - N[:3, :3] @ self.o3)[:2]

    def _inner(
        self,
        psi1: float,
        psi5: float,
        psi6: float,
        Tm,
        free: set[str],
        stretched: float = DOUBLE * 4,
        dh: NDArray[np.float64] | None = None,
    ) -> list[list[float]]:
        """ψ_2, ψ_3, ψ_4 of the planar 3R problem left by ψ_1, ψ_5, ψ_6: [ψ_1 … ψ_6] per elbow (one,
        the stretched or folded elbow, where sin² ψ_3 ≤ `stretched`; `dh` as _frame3's)."""
        d = self.dh
        N, O3 = self._frame3(psi1, psi5, psi6, Tm, dh)
        a2, a3 = d[1, 0], d[2, 0]
        rho2 = O3[0] ** 2 + O3[1] ** 2
        c3 = (rho2 - a2 * a2 - a3 * a3) / (2 * a2 * a3)
        if abs(c3) > 1 + 1e-6:
            return []
        rest = 1 - c3 * c3
        s3 = 0.0 if rest <= stretched else math.sqrt(max(0.0, rest))
        out = []
        for sign in (1.0, -1.0) if s3 > 0 else (1.0,):
            psi3 = math.atan2(sign * s3, c3)
            if rho2 <= (FLAT * self.scale) ** 2:
                free.add(FLAGS[2])
                psi2 = 0.0
            else:
                psi2 = math.atan2(O3[1], O3[0]) - math.atan2(self.ca[1] * a3 * math.sin(psi3), a2 + a3 * math.cos(psi3))
            R3 = (dh_matrix(a2, d[1, 1], d[1, 2], psi2) @ dh_matrix(a3, d[2, 1], d[2, 2], psi3))[:3, :3]
            M = R3.T @ N[:3, :3]  # Rz(ψ_4) Rx(α_4)
            out.append([psi1, psi2, psi3, math.atan2(M[1, 0], M[0, 0]), psi5, psi6])
        return out
