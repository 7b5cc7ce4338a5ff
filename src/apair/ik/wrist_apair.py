"""Every solution of a spherical-wrist arm with axes 2 and 3 parallel and a sinusoidal A-pair at
joint 3, in closed form (issue 42, part 3: PUMA-, KUKA-, ABB-, Fanuc-, Stäubli-like arms with a
sliding elbow).

On the R-arm (apair.ik.wrist) the wrist point W fixes ψ_1, ψ_2, ψ_3 (ψ_i = θ_i + φ_i) through
Pieper's quartic in ψ_3. Where axes 2 and 3 are parallel, W's height along them in frame 1 is a
constant, and the A-pair's slide d_3 = h cos(θ_3/2) along axis 3 adds to it: L(ψ_1) = cos α_2 d_3
ties ψ_1 to the elbow. The derived kernel `ik_wrist_apair_position6` (derivations/chain_ik_wrist_apair.py)
gives L, the elbow's κ cos ψ_3 (from the pair's law) and κ E_s sin ψ_3 (from W's distance to axis 2)
in t = tan(ψ_1/2), and their circle, a polynomial of degree 8. For each real root ψ_3 = atan2 of the
two (no square root), ψ_2 turns the elbow's plane onto W − O_1 in frame 1, and the wrist's three
angles follow as on the R-arm (two ψ_5): at most 16 solutions. θ_3 is the angle of ψ_3 − φ_3 in
(−2π, 2π] whose slide has the sign of cos α_2 L (its twin too where d_3 = 0, θ_3 = ±π). Every
candidate is polished by Gauss-Newton steps and kept only where fk reproduces the pose
(apair.ik.poses.refine). The decomposition needs sin φ_3 = 0 and 2 a_2 sin α_3 c_4 ≠ 0 (every such
arm on sale: the forearm c_4 at right angles to the elbow's axis); other designs go to the general
solvers. C twin: apair_ik_wrist_apair (src/csrc/apair_ik_wrist.c, beside the R-arm's steps).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..frames import dh_matrix
from ..kernels import call, native_in_use
from .closed import FLAT, note, real_roots
from .families import Classification
from .parallel_apair import one_per_multiple_root
from .poses import refine, with_twins, wrap
from .wrist import FLAGS, Wrist

KINDS = ["revolute", "revolute", "sinusoidal", "revolute", "revolute", "revolute"]


def applies(chain, family: Classification, kinds: list[str] = KINDS) -> bool:
    """Whether the closed form may cover the chain: six joints of these kinds (a sinusoidal A-pair at
    joint 3 and R-pairs elsewhere; apair.ik.wrist_slide1 passes its own), a spherical wrist at joints
    4-6 (axes 2 ∥ 3 is checked by the form)."""
    f = family.family
    return (
        chain.n == 6
        and [p.kind for p in chain.pairs] == kinds
        and f is not None
        and f.key.startswith("spherical-")
        and not f.reversed
    )


class WristAPairForm(Wrist):
    """What the closed forms of spherical-wrist arms with an A-pair share (WristAPair, and
    WristSlide1 in apair.ik.wrist_slide1): the amplitudes per joint, and the solve over their C entry."""

    amplitude: NDArray[np.float64]

    def _elbow(self, psi3: float) -> NDArray[np.float64]:
        """p(ψ_3): the wrist point in frame 1 before the turn ψ_2."""
        return self.B2[:3, :3] @ (dh_matrix(0.0, 0.0, 0.0, psi3)[:3, :3] @ self.m3) + self.B2[:3, 3]

    def solve(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], NDArray[np.float64], int, str]:
        """Every real solution (k, 6) at frame 6's pose Tm, verified to tol, their errors, the
        candidates examined and a note naming a continuum: in C (apair_ik_wrist_apair, with the
        amplitudes) where the C backend is in use, else the same steps here."""
        native = native_in_use()
        if native is None:
            cands, free = self.candidates(Tm)
            q, err = refine(self.chain, cands, Tm, tol, self.scale)
            q, err, member = self._canonical(q, err, Tm, tol)
            q, err = one_per_multiple_root(self.chain, q, err)
            return q, err, len(cands), note(free | member)
        q, err, found, cands, flags = native.ik_wrist_apair(
            self.dh, self.amplitude, self.scale, Tm.reshape(1, 4, 4), tol
        )
        if flags[0] < 0:
            raise ValueError("the position polynomial vanishes identically")
        k = int(found[0])
        return q[0, :k], err[0, :k], int(cands[0]), note({why for bit, why in FLAGS.items() if flags[0] & bit})


class WristAPair(WristAPairForm):
    """The closed form of one chain: its design read once. ValueError where the design is not
    covered (axes 2 and 3 not parallel, sin φ_3 ≠ 0, a_2 sin α_3 c_4 = 0, axes 4, 5 or 5, 6 parallel)."""

    code = 32  # the family in apair.h (APAIR_IK_WRIST_APAIR: apair_ik_closed_init_apair, up to 32 rows)

    def __init__(self, chain, scale: float) -> None:
        super().__init__(chain, scale)
        a, alpha, c, phi = self.dh.T
        if abs(math.sin(alpha[1])) > FLAT:
            raise ValueError("axes 2 and 3 are not parallel")
        if abs(math.sin(phi[2])) > FLAT:
            raise ValueError("joint 3's angle offset is not 0 or π")
        if abs(2 * a[1] * math.sin(alpha[2]) * c[3]) <= FLAT * scale * scale:
            raise ValueError("2 a_2 sin(alpha_3) c_4 = 0")
        if abs(self.sa4 * self.sa5) <= FLAT:
            raise ValueError("axes 4, 5 or 5, 6 are parallel")
        self.h = float(chain.pairs[2].amplitude)
        self.amplitude = np.array([0.0, 0.0, self.h, 0.0, 0.0, 0.0])
        self.law = np.array([self.h**2 / 2, self.h**2 / 2])  # d_3² = κ_0 + κ_1 cos θ_3
        self.ca2 = math.cos(alpha[1])

    def candidates(self, Tm: NDArray[np.float64]) -> tuple[NDArray[np.float64], set[str]]:
        """Candidate joint vectors (k, 6) at frame 6's pose Tm, and the continua met (FLAGS' texts)."""
        W, L, Es_, cs, poly = call("ik_wrist_apair_position6", self.dh, Tm, self.law)
        Es = float(Es_[0])
        C, S = cs.reshape(2, 5)
        big = self.scale + float(np.linalg.norm(W))
        size = abs(Es) * (big * big + self.law[1])  # the size of Es C and S
        roots, at_infinity = real_roots(poly, size * size)
        psi1s = [(2 * math.atan(t), t) for t in roots] + ([(math.pi, math.inf)] if at_infinity else [])
        d = self.dh
        out: list[list[float]] = []
        free: set[str] = set()
        tiny = (FLAT * self.scale) ** 2
        for psi1, t in psi1s:
            cv, sv = (
                (float(C[-1]), float(S[-1]))
                if math.isinf(t)
                else (float(np.polyval(C[::-1], t)), float(np.polyval(S[::-1], t)))
            )
            psi3 = math.atan2(sv / Es, cv)  # κ cos ψ_3 and κ sin ψ_3, times (1 + t²)²
            A1 = dh_matrix(d[0, 0], d[0, 1], d[0, 2], psi1)
            u = A1[:3, :3].T @ (W - A1[:3, 3])  # W − O_1 in frame 1
            p = self._elbow(psi3)
            if p[0] ** 2 + p[1] ** 2 <= tiny:
                free.add(FLAGS[4])
                psi2 = 0.0
            else:
                psi2 = math.atan2(u[1], u[0]) - math.atan2(p[1], p[0])
            M = self._r03(psi1, psi2, psi3).T @ Tm[:3, :3] @ self.rx6t
            cs1 = np.array([1.0, math.cos(psi1), math.sin(psi1)])
            d3 = self.ca2 * float(L @ cs1)
            for psi456 in self._wrist(M, free):
                q = wrap(np.array([psi1, psi2, psi3, *psi456]) - d[:, 3], 2 * np.pi)
                if math.cos(q[2] / 2) * d3 < 0:  # the representative whose slide has d_3's sign
                    q[2] -= math.copysign(2 * math.pi, q[2])
                out.append(q.tolist())
        return with_twins(self.chain, np.array(out, dtype=np.float64).reshape(-1, 6)), free
