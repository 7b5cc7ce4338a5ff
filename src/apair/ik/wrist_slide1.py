"""Every solution of a spherical-wrist arm with axes 2 and 3 parallel and a sinusoidal A-pair at
joint 1, in closed form (issue 42, part 3: PUMA-, KUKA-, ABB-, Fanuc-, Stäubli-like arms on a
sliding base joint).

The A-pair at joint 1 slides O_1 along axis 1 by d_1 = h cos(θ_1/2). Where axis 1 is at right angles
to axis 2 (cos α_1 = 0, every such arm), the wrist point W's height along the parallel axes 2 and 3
in frame 1 does not see the slide, and L(ψ_1) = 0 (ψ_i = θ_i + φ_i) is a quadratic in t = tan(ψ_1/2):
the derived kernel `ik_wrist_slide1_position6` (derivations/chain_ik_wrist_apair.py) gives it. Each
root has two representatives θ_1 in (−2π, 2π], whose slides have opposite signs; for each, O_1 is
known, and W's distance from axis 2, ρ² = E_0 + E_c cos ψ_3 + E_s sin ψ_3 (E_0, E_c, E_s read from
the elbow's plane at three angles), gives two elbows. Then ψ_2 turns the elbow's plane onto W − O_1
in frame 1, and the wrist's three angles follow as on the R-arm (apair.ik.wrist, two ψ_5): at most
16 solutions. Every candidate is polished by Gauss-Newton steps and kept only where fk reproduces
the pose (apair.ik.poses.refine). C twin: the family APAIR_IK_WRIST_SLIDES of
apair_ik_closed_init_apair (src/csrc/apair_ik_wrist.c).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..frames import dh_matrix
from ..kernels import call
from . import wrist_apair
from .closed import DOUBLE, FLAT, real_roots
from .families import Classification
from .poses import wrap
from .wrist import FLAGS
from .wrist_apair import WristAPairForm

KINDS = ["sinusoidal", "revolute", "revolute", "revolute", "revolute", "revolute"]


def applies(chain, family: Classification) -> bool:
    """Whether the closed form may cover the chain: six joints, a sinusoidal A-pair at joint 1 and
    R-pairs elsewhere, a spherical wrist at joints 4-6 (the rest is checked by WristSlide1)."""
    return wrist_apair.applies(chain, family, KINDS)


class WristSlide1(WristAPairForm):
    """The closed form of one chain: its design read once. ValueError where the design is not
    covered (axes 2 and 3 not parallel, cos α_1 ≠ 0, the elbow not read from ρ², axes 4, 5 or 5, 6
    parallel)."""

    code = 64  # the family in apair.h (APAIR_IK_WRIST_SLIDES: apair_ik_closed_init_apair, up to 32 rows)

    def __init__(self, chain, scale: float) -> None:
        super().__init__(chain, scale)
        if abs(math.sin(self.dh[1, 1])) > FLAT:
            raise ValueError("axes 2 and 3 are not parallel")
        if abs(self.ca1) > FLAT:
            raise ValueError("joint 1's slide moves the wrist point along axis 2 (cos alpha_1 != 0)")
        if abs(self.sa4 * self.sa5) <= FLAT:
            raise ValueError("axes 4, 5 or 5, 6 are parallel")
        r = [float(np.sum(self._elbow(k * math.pi / 2)[:2] ** 2)) for k in range(3)]  # |p_xy|² at 0, π/2, π
        self.E0, self.Ec = 0.5 * (r[0] + r[2]), 0.5 * (r[0] - r[2])
        self.Es = r[1] - self.E0
        if not math.hypot(self.Ec, self.Es) > FLAT * scale * scale:
            raise ValueError("the wrist point's distance from axis 2 does not move with the elbow")
        self.h = float(chain.pairs[0].amplitude)
        self.amplitude = np.array([self.h, 0.0, 0.0, 0.0, 0.0, 0.0])

    def candidates(self, Tm: NDArray[np.float64]) -> tuple[NDArray[np.float64], set[str]]:
        """Candidate joint vectors (k, 6) at frame 6's pose Tm, and the continua met (FLAGS' texts)."""
        W, _, quad = call("ik_wrist_slide1_position6", self.dh, Tm)
        roots, at_infinity = real_roots(quad, self.scale + float(np.linalg.norm(W)))
        psi1s = [2 * math.atan(t) for t in roots] + ([math.pi] if at_infinity else [])
        d = self.dh
        out: list[list[float]] = []
        free: set[str] = set()
        tiny = (FLAT * self.scale) ** 2
        K = math.hypot(self.Ec, self.Es)
        for psi1 in psi1s:
            theta = math.remainder(psi1 - d[0, 3], 2 * math.pi)
            for theta1 in (theta, theta - math.copysign(2 * math.pi, theta)):
                A1 = dh_matrix(d[0, 0], d[0, 1], d[0, 2] + self.h * math.cos(theta1 / 2), psi1)
                u = A1[:3, :3].T @ (W - A1[:3, 3])  # W − O_1 in frame 1
                x = (u[0] ** 2 + u[1] ** 2 - self.E0) / K  # cos(ψ_3 − β), β = atan2(E_s, E_c)
                if abs(x) > 1 + 1e-6:
                    continue
                beta, rest = math.atan2(self.Es, self.Ec), 1 - x * x
                turn = 0.0 if rest <= 4 * DOUBLE else math.acos(max(-1.0, min(1.0, x)))
                for psi3 in (beta + turn, beta - turn) if turn > 0 else (beta,):
                    p = self._elbow(psi3)
                    if p[0] ** 2 + p[1] ** 2 <= tiny:
                        free.add(FLAGS[4])
                        psi2 = 0.0
                    else:
                        psi2 = math.atan2(u[1], u[0]) - math.atan2(p[1], p[0])
                    M = self._r03(psi1, psi2, psi3).T @ Tm[:3, :3] @ self.rx6t
                    for psi456 in self._wrist(M, free):
                        q = wrap(np.array([psi1, psi2, psi3, *psi456]) - d[:, 3], 2 * np.pi)
                        q[0] = theta1
                        out.append(q.tolist())
        return np.array(out, dtype=np.float64).reshape(-1, 6), free
