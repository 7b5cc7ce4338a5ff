"""Every solution of a UR-like six-joint chain with a sinusoidal A-pair at joint 3, in closed form
(issue 42, part 3).

Axes 2, 3 and 4 are parallel and the wrist is UR's (axes 4 ⟂ 5 ⟂ 6, a_4 = a_5 = 0, axes 5 and 6
meeting). On the R-arm (apair.ik.parallel) the slides along the parallel axes add up to a constant
and ψ_1 (ψ_i = θ_i + φ_i) comes from a quadratic; the A-pair's slide d_3 = h cos(θ_3/2) ties ψ_1 to
the elbow instead. The derived kernel `ik_parallel_apair_position6`
(derivations/chain_ik_parallel_apair.py) gives L_1(ψ_1) = P cos ψ_5, L_2(ψ_1) = cos α_2 d_3 and
G(ψ_1) sin ψ_5 = H(ψ_1) (the elbow's cos ψ_3 from frame 3's distance to axis 2 equated with the
pair's law), and their resultant in t = tan(ψ_1/2), of degree 12 (a quartic G = 0 where c_5 = 0). For
each real root ψ_5 = atan2(H/G, L_1/P), and ψ_6, the two elbows ψ_3, ψ_2 and ψ_4 follow as on the
R-arm; θ_3 is the angle of ψ_3 − φ_3 in (−2π, 2π] whose slide has the sign of cos α_2 L_2 (its twin
too where d_3 = 0, θ_3 = ±π). Every candidate is polished by Gauss-Newton steps and kept only where
fk reproduces the pose (apair.ik.poses.refine). The decomposition needs sin φ_3 = 0 (else cos θ_3
brings sin ψ_3 in); other designs go to the general solvers. C twin: apair_ik_parallel_apair
(src/csrc/apair_ik_parallel.c, beside the R-arm's steps it shares).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..kernels import call, native_in_use
from .closed import FLAT, note, real_roots
from .families import Classification
from .parallel import FLAGS, Parallel
from .poses import joint_periods, pose_error, refine, with_twins, wrap

MULTIPLE = 1e-4  # [rad] solutions this close to a singular one are copies of it (a multiple root's cluster)
KINDS = ["revolute", "revolute", "sinusoidal", "revolute", "revolute", "revolute"]


def applies(chain, family: Classification) -> bool:
    """Whether the closed form may cover the chain: six joints, a sinusoidal A-pair at joint 3 and
    R-pairs elsewhere, axes 2, 3 and 4 parallel (the design's wrist is checked by ParallelAPair)."""
    f = family.family
    return (
        chain.n == 6
        and [p.kind for p in chain.pairs] == KINDS
        and f is not None
        and f.key == "three-inner-parallel"
        and not f.reversed
    )


def one_per_multiple_root(chain, q: NDArray[np.float64], err: NDArray[np.float64]):
    """At a singular pose (a multiple root, e.g. the slide's top with the elbow stretched and axis
    6 parallel to axes 2-4) the roots come √eps apart and verify to tol as a cluster around the
    exact solution: the most accurate one stands for the others within MULTIPLE of it. (Two
    distinct solutions that close need a near-singular Jacobian between them, where tol cannot
    tell them apart.) As the C twins' apair_keep."""
    if len(q) <= 1:
        return q, err
    near = np.all(np.abs(wrap(q[:, None] - q[None], joint_periods(chain))) < MULTIPLE, axis=-1)
    np.fill_diagonal(near, False)
    if not near.any():
        return q, err
    kept: list[int] = []
    for k in np.argsort(err, kind="stable"):
        if not any(near[k, j] for j in kept):
            kept.append(int(k))
    keep = np.sort(np.array(kept))
    return q[keep], err[keep]


class APairForm(Parallel):
    """What the closed forms of UR arms with A-pairs share (ParallelAPair, and ParallelSlides in
    apair.ik.parallel_slides): the amplitudes per joint, and the solve over their C entry."""

    amplitude: NDArray[np.float64]

    def solve(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], NDArray[np.float64], int, str]:
        """Every real solution (k, 6) at frame 6's pose Tm, verified to tol, their errors, the
        candidates examined and a note naming a continuum: in C (apair_ik_parallel_apair, with the
        amplitudes) where the C backend is in use, else the same steps here."""
        native = native_in_use()
        if native is None:
            cands, free = self.candidates(Tm, tol)
            q, err = refine(self.chain, cands, Tm, tol, self.scale)
            q, err = one_per_multiple_root(self.chain, q, err)
            return q, err, len(cands), note(free)
        q, err, found, cands, flags = native.ik_parallel_apair(
            self.dh, self.amplitude, self.scale, Tm.reshape(1, 4, 4), tol
        )
        if flags[0] < 0:
            raise ValueError("the position polynomial vanishes identically")
        k = int(found[0])
        return q[0, :k], err[0, :k], int(cands[0]), note({why for bit, why in FLAGS.items() if flags[0] & bit})


class ParallelAPair(APairForm):
    """The closed form of one chain: its design read once. ValueError where the design is not
    covered (a wrist other than UR's, sin φ_3 ≠ 0, a_2 a_3 = 0)."""

    code = 8  # the family in apair.h (APAIR_IK_PARALLEL_APAIR: apair_ik_closed_init_apair, up to 24 solutions)

    def __init__(self, chain, scale: float) -> None:
        super().__init__(chain, scale)
        a, ca = self.dh[:, 0], self.ca
        if max(abs(ca[3]), abs(ca[4])) > FLAT or max(abs(a[3]), abs(a[4])) > FLAT * scale:
            raise ValueError("the wrist is not UR's (axes 4, 5, 6 at right angles, a_4 = a_5 = 0)")
        if abs(math.sin(self.dh[2, 3])) > FLAT:
            raise ValueError("joint 3's angle offset is not 0 or π")
        if min(abs(a[1]), abs(a[2])) <= FLAT * scale:
            raise ValueError("a_2 a_3 = 0")
        self.h = float(chain.pairs[2].amplitude)
        self.amplitude = np.array([0.0, 0.0, self.h, 0.0, 0.0, 0.0])
        self.law = np.array([self.h**2 / 2, self.h**2 / 2])  # d_3² = κ_0 + κ_1 cos θ_3
        self.case = "g" if abs(self.dh[4, 2]) <= FLAT * scale else "poly"  # c_5 = 0: H ≡ 0

    def candidates(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], set[str]]:
        """Candidate joint vectors (k, 6) at frame 6's pose Tm, and the continua met (FLAGS' texts)."""
        L, P_, gh, poly = call("ik_parallel_apair_position6", self.dh, Tm, self.law)
        L1, L2 = L.reshape(2, 3)
        P = float(P_[0])
        g, h = gh.reshape(2, 5)
        a2, a3 = abs(self.dh[1, 0]), abs(self.dh[2, 0])
        big = self.scale + float(np.linalg.norm(Tm[:3, 3]))
        gref = big * big * (2 * a2 * a3 + self.h**2)  # the size of G's terms
        roots, at_infinity = real_roots(g if self.case == "g" else poly, gref if self.case == "g" else gref * gref)
        psi1s = [(2 * math.atan(t), t) for t in roots] + ([(math.pi, math.inf)] if at_infinity else [])
        z5 = Tm[:3, :3] @ np.array([0.0, self.sa[5], self.ca[5]])
        out: list[list[float]] = []
        free: set[str] = set()
        for psi1, t in psi1s:
            cs1 = np.array([1.0, math.cos(psi1), math.sin(psi1)])
            c5 = float(L1 @ cs1) / P
            if abs(c5) > 1 + 1e-6:
                continue
            c5 = max(-1.0, min(1.0, c5))
            z1 = np.array([self.sa[0] * cs1[2], -self.sa[0] * cs1[1], self.ca[0]])
            l2 = float(L2 @ cs1)
            s5 = float(np.linalg.norm(np.cross(z1, z5)))  # |sin ψ_5| = |z_3 × z_5|, exact near ψ_5 = 0 too
            for psi5 in self._psi5_of(c5, s5, g, h, t):
                psi6 = self._psi6(psi5, z1, Tm)
                found: list[list[float]] = []
                if psi6 is not None:
                    found = self._elbows(psi1, psi5, psi6, Tm, free, l2)
                elif (pinned := self._pinned_psi6(psi1, psi5, Tm, l2)) is not None:
                    for psi6 in pinned:
                        found += self._elbows(psi1, psi5, psi6, Tm, free, l2)
                else:  # ψ_6 free: the member with the elbow mid-range (as the C twin, apair_elbows)
                    found = self._elbows(psi1, psi5, self._free_psi6(psi1, psi5, Tm), Tm, free, l2)
                    if len(refine(self.chain, self._angles(found, l2), Tm, tol, self.scale)[0]):
                        free.add(FLAGS[1])
                out += self._angles(found, l2).tolist()
        return np.array(out, dtype=np.float64).reshape(-1, 6), free

    def _psi5_of(self, c5: float, s5: float, g, h, t: float) -> list[float]:
        """ψ_5 at a root: |sin ψ_5| = s5, with the sign of H/G (H/G itself loses digits where G and
        H nearly vanish: a near-double root), or both signs where G vanishes with H (c_5 = 0, or the
        arm's wrist singularity)."""
        if math.isinf(t):  # ψ_1 = π: the leading coefficients
            gv, hv, size = float(g[-1]), float(h[-1]), float(np.max(np.abs(g)) + np.max(np.abs(h)))
        else:
            powers = t ** np.arange(5)
            gv, hv = float(g @ powers), float(h @ powers)
            size = float((np.abs(g) + np.abs(h)) @ np.abs(powers))
        if self.case == "poly" and abs(gv) > 1e-6 * size:
            return [] if abs(hv / gv) > 1 + 1e-6 else [math.atan2(math.copysign(s5, hv / gv), c5)]
        base = math.acos(c5)
        return [0.0] if base <= 1e-7 else [math.pi] if base >= math.pi - 1e-7 else [base, -base]

    def _elbows(self, psi1: float, psi5: float, psi6: float, Tm, free: set[str], l2: float) -> list[list[float]]:
        """The two elbows of apair.ik.parallel, or the one stretched (folded) elbow where that
        reproduces the pose better: near ψ_3 = 0 with θ_3 = 0 the slide's top and the elbow's
        stretch meet (a near-double root in ψ_1, known to 1e-12), and the elbows' sin ψ_3 = ±1e-6
        from cos ψ_3's error would be two spurious solutions of error 1e-11."""
        found = self._inner(psi1, psi5, psi6, Tm, free)
        if len(found) != 2 or abs(math.sin(found[0][2])) > 1e-4:
            return found
        one = self._inner(psi1, psi5, psi6, Tm, free, stretched=1.0)
        errors = [pose_error(self.chain, self._angles(x, l2), Tm, self.scale)[1].min() for x in (found, one)]
        return one if errors[1] <= errors[0] else found

    def _pinned_psi6(self, psi1: float, psi5: float, Tm, l2: float) -> list[float] | None:
        """Where axis 6 is parallel to axes 2-4 (ψ_6 drops out of the wrist), frame 3's origin runs on
        a circle as ψ_6 turns, ρ² = A + B cos ψ_6 + C sin ψ_6; on the R-arm that is a self-motion, but
        the pair's slide pins the elbow (κ_1 cos φ_3 cos ψ_3 = L_2² − κ_0) and so ρ: the ψ_6 where
        the circle meets it (isolated solutions), or None where the circle is a point."""
        a2, a3 = self.dh[1, 0], self.dh[2, 0]
        c3 = (l2 * l2 - self.law[0]) / (self.law[1] * math.cos(self.dh[2, 3]))
        if abs(c3) > 1 + 1e-6:
            return []
        A, B, C = self._circle(psi1, psi5, Tm)
        K = math.hypot(B, C)
        if not K > FLAT * (a2 * a2 + a3 * a3):
            return None
        x = (a2 * a2 + a3 * a3 + 2 * a2 * a3 * max(-1.0, min(1.0, c3)) - A) / K
        if abs(x) > 1 + 1e-6:
            return []
        base, turn = math.atan2(C, B), math.acos(max(-1.0, min(1.0, x)))
        return [base] if turn <= 1e-7 else [base + turn, base - turn]

    def _angles(self, psis: list[list[float]], l2: float) -> NDArray[np.float64]:
        """Joint vectors from [ψ_1 … ψ_6]: θ_3 the angle of ψ_3 − φ_3 in (−2π, 2π] whose slide
        h cos(θ_3/2) has the sign of d_3 = cos α_2 L_2, with its twin where d_3 is near 0."""
        q = wrap(np.array(psis, dtype=np.float64).reshape(-1, 6) - self.dh[:, 3], 2 * np.pi)
        d3 = self.ca[1] * l2
        flip = np.cos(q[:, 2] / 2) * d3 < 0
        q[flip, 2] -= np.copysign(2 * np.pi, q[flip, 2])
        return with_twins(self.chain, q)
