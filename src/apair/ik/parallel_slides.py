"""Every solution of a UR-like six-joint chain with sinusoidal A-pairs at joint 1 and/or joint 5, in
closed form (issue 42, part 3).

Axes 2, 3 and 4 are parallel (apair.ik.parallel). An A-pair at joint 1 slides along axis 1 and one at
joint 5 along axis 5; where those axes are at right angles to the parallel axes (cos α_1 = 0 for
joint 1, cos α_4 = 0 for joint 5, as on every UR arm) the slides have no component along them, so the
R-arm's two equations L_1(ψ_1) = P cos ψ_5 and L_2(ψ_1) = Q sin ψ_5 (`ik_parallel_position6`,
derivations/chain_ik_parallel.py, whose check covers designs with these slides) do not see them: ψ_1
and ψ_5 (ψ_i = θ_i + φ_i) come as on the R-arm. An A-pair's angle has period 4π (its slide
h cos(θ/2) changes sign at θ + 2π), so each such ψ has two representatives θ in (−2π, 2π], with
slides of opposite signs; for each, ψ_6, the two elbows ψ_3, ψ_2 and ψ_4 follow as on the R-arm with
c_1 + d_1 and c_5 + d_5: at most 8 × 2 × 2 = 32 solutions. Every candidate is polished by
Gauss-Newton steps and kept only where fk (with the pairs' laws) reproduces the pose
(apair.ik.poses.refine). Other slides (cos α_1 ≠ 0, cos α_4 ≠ 0, A-pairs at joints 2, 4, 6) move the
parallel axes' offsets and go to the general solvers (joint 3: apair.ik.parallel_apair). C twin:
apair_ik_parallel_apair with those amplitudes (src/csrc/apair_ik_parallel.c).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..kernels import call
from .closed import FLAT, real_roots
from .families import Classification
from .parallel import FLAGS
from .parallel_apair import APairForm
from .poses import refine

SLIDING = (0, 4)  # the joints (from 0) whose A-pairs this form takes


def applies(chain, family: Classification) -> bool:
    """Whether the closed form may cover the chain: six joints, sinusoidal A-pairs at joint 1 and/or 5
    and R-pairs elsewhere, axes 2, 3 and 4 parallel (the twists are checked by ParallelSlides)."""
    f = family.family
    kinds = [p.kind for p in chain.pairs]
    return (
        chain.n == 6
        and any(kinds[i] == "sinusoidal" for i in SLIDING)
        and all(k == "revolute" or (i in SLIDING and k == "sinusoidal") for i, k in enumerate(kinds))
        and f is not None
        and f.key == "three-inner-parallel"
        and not f.reversed
    )


class ParallelSlides(APairForm):
    """The closed form of one chain: its design read once. ValueError where a pair's slide is not at
    right angles to the parallel axes (cos α_1 ≠ 0 with an A-pair at joint 1, cos α_4 ≠ 0 at joint 5)."""

    code = 16  # the family in apair.h (APAIR_IK_PARALLEL_SLIDES: apair_ik_closed_init_apair, up to 32 solutions)

    def __init__(self, chain, scale: float) -> None:
        super().__init__(chain, scale)
        self.h = np.array([p.amplitude if p.kind == "sinusoidal" else 0.0 for p in chain.pairs])
        self.amplitude = self.h
        if self.h[0] > 0 and abs(self.ca[0]) > FLAT:
            raise ValueError("joint 1's slide has a component along the parallel axes (cos alpha_1 != 0)")
        if self.h[4] > 0 and abs(self.ca[3]) > FLAT:
            raise ValueError("joint 5's slide has a component along the parallel axes (cos alpha_4 != 0)")

    def _thetas(self, psi: float, i: int) -> list[tuple[float, float]]:
        """(θ, c_i + d_i(θ)) for joint i (from 0) at ψ: θ = ψ − φ in (−π, π], and for an A-pair also
        its other representative in (−2π, 2π] (the slide's other sign)."""
        theta = math.remainder(psi - self.dh[i, 3], 2 * math.pi)
        c, h = float(self.dh[i, 2]), float(self.h[i])
        if h == 0.0:
            return [(theta, c)]
        other = theta - math.copysign(2 * math.pi, theta)
        return [(t, c + h * math.cos(t / 2)) for t in (theta, other)]

    def candidates(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], set[str]]:
        """Candidate joint vectors (k, 6) at frame 6's pose Tm, and the continua met (FLAGS' texts)."""
        L, PQ, quartic, qa, qb = call("ik_parallel_position6", self.dh, Tm)
        L1, L2 = L.reshape(2, 3)
        P, Q = float(PQ[0]), float(PQ[1])
        big = self.scale + float(np.linalg.norm(Tm[:3, 3]))
        ref = {"quartic": (big * P) ** 2 + Q**2, "qa": 1.0, "qb": big}[self.case]  # as Parallel.candidates
        roots, at_infinity = real_roots({"quartic": quartic, "qa": qa, "qb": qb}[self.case], ref)
        psi1s = [2 * math.atan(t) for t in roots] + ([math.pi] if at_infinity else [])
        z5 = Tm[:3, :3] @ np.array([0.0, self.sa[5], self.ca[5]])
        out: list[list[float]] = []
        free: set[str] = set()
        dh = self.dh.copy()
        for psi1 in psi1s:
            cs1 = np.array([1.0, math.cos(psi1), math.sin(psi1)])
            z1 = np.array([self.sa[0] * cs1[2], -self.sa[0] * cs1[1], self.ca[0]])
            for psi5 in self._psi5(float(L1 @ cs1), float(L2 @ cs1), P, Q, z1, z5):
                psi6 = self._psi6(psi5, z1, Tm)
                for theta1, dh[0, 2] in self._thetas(psi1, 0):
                    for theta5, dh[4, 2] in self._thetas(psi5, 4):
                        if psi6 is None:  # ψ_6 free: the member with the elbow mid-range
                            found = self._inner(psi1, psi5, self._free_psi6(psi1, psi5, Tm, dh), Tm, free, dh=dh)
                        else:
                            found = self._inner(psi1, psi5, psi6, Tm, free, dh=dh)
                        q = np.array(found, dtype=np.float64).reshape(-1, 6) - self.dh[:, 3]
                        q[:, 0], q[:, 4] = theta1, theta5
                        if psi6 is None and len(refine(self.chain, q, Tm, tol, self.scale)[0]):
                            free.add(FLAGS[1])
                        out += q.tolist()
        return np.array(out, dtype=np.float64).reshape(-1, 6), free
