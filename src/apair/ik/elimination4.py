"""Inverse kinematics of 1 to 4 joints by kinematic mapping: every real solution, each verified.

Joint i moves as A_i(u) = P_i(u)·K_i: P_i(u) = Rz(φ_i)·Tz(c_i)·(pair point) lies in the pair
subalgebra spanned by 1, k, ε, εk (rotations about and translations along z) and is polynomial in
its parameter (the derived rational quartic of `apair_motion` in u = tan(θ/4) for a sinusoidal
A-pair, (1, 0, 0, u) with u = tan(θ/2) for an R-pair); K_i = Tx(a_i)·Rx(α_i) is constant. Each
parameter is shifted by a random angle (a Möbius substitution) so that no solution sits at u = ∞.

- 1 joint: T·K_1⁻¹ must be proportional to P_1(u): univariate.
- 2 joints: A_1(u_1)A_2(u_2) = T ⇔ K_1⁻¹·P̃_1(u_1)·T·K_2⁻¹ lies in the pair subalgebra (its
  components x1, x2, y1, y2 vanish: four polynomials in u_1 with common roots) and is proportional
  to P_2(u_2) (polynomials in u_2): two univariate problems.
- 3 and 4 joints: the left half's (joints 1, 2) constraint variety, evaluated on the right part's
  parametrised image W(u_3, u_4) = T·(A_3A_4)~, must vanish. Its quadrics are found by SVD on
  sampled points of the half (`_half_quadrics`). Their images Q(W(u_3, u_4)) have bidegree
  (8, 8), less the factors 1 + u² they carry at every pose (found once per design and divided
  out): the quadric in x alone (the spherical two-joint condition) gives f of bidegree (4, 4), a
  quadric without a yy block g of bidegree (6, 6) (for A-pairs), random combinations (8, 8).
  Their resultant in u_4 has degree 48 in u_3, 16 of its roots spurious: at u_3 = ±i and where
  u_4 = ±i, g is a multiple of f, and g − a·f, divided by 1 + u², removes them (`deflate`:
  bidegree (4, 4), 32 roots). The resultant is never expanded: the Sylvester matrix in u_4, whose
  rows have degree 4 in u_3, is linearised by rows into a 32 × 32 eigenvalue problem. At each
  real eigenvalue u_3 the Sylvester matrix's null vector (1, u_4, u_4², …) gives u_4, and the
  pair is kept if every quadric of the left half vanishes on its image (`_screen`; undecided
  ones get the common roots u_4 of all quadrics, `_right_pairs`); the left half is then solved
  for W(u_3, u_4) as above. The usual path of every step is in generated C (apair_ik4_pencil,
  apair_ik4_screen, apair_ik4_left) where the kernels are installed, NumPy otherwise.

Special designs (twists of 0 and 90°, zero lengths: what robots are built from) make parts of this
degenerate, and each has its own remedy:
- the rotation condition holds on the whole image (parallel axes, as in examples/4a_chain.toml),
  or f and g share a curve: other combinations of the quadrics take their place, the pair with
  the smallest resultant first (parallel axes give every image more factors 1 + u²: the
  example's pair has bidegrees (4, 4), a 32 × 32 problem; undivided, the factors made every
  pencil singular); where every pair shares a curve, the u_3 are the eigenvalues of the singular
  pencil's regular part (a random rank completion, apair.ik.pencil.hidden_variable);
- at some u_3 every u_4 satisfies f (or g): each u_3 gets the common roots u_4 of *all* the
  left half's quadrics (`_right_pairs`), not of f and g alone;
- joints 1 and 2 on one axis (a_1 = α_1 = 0): u_1 and u_2 come together from a bivariate
  system (`_solve_coaxial`);
- what still degenerates is solved on the reversed chain (K_n·T̃ = Π P̃ K̃, the halves swapped);
  where both orientations fail, a batched Levenberg-Marquardt search from 64 seeds finds the
  solutions, and the answer says that it is not certified complete (`Solution.certified`;
  apair.ik.solver, apair.ik.local); where they find nothing for a pose within reach, the search
  checks that "none", which stands (certified) unless it finds a solution. A curve of solutions
  (two R-pairs on one axis) is refused with a ValueError.

Counting the complex solutions (`full=True`) keeps the real path as it is and adds the complex
roots u_3 with Im u_3 >= 0 (the pose is real: the others give the conjugates), screened as the
real ones are (`_complex_pairs`); most of their images are proven to have no left-half solution
by one singular value each (apair.ik.pencil.no_common_root), so the count costs about as much as
the real answer.

Every real candidate is checked with the chain's own fk kernel, refined by up to two Gauss-Newton
steps where it is not already accurate to 1e-3·tol, and kept only if fk(q) reproduces T to `tol`
(largest entry of the 4×4 difference, its translations in units of the chain's length scale,
apair.ik.poses.length_scale); duplicates are merged (apair.ik.poses.refine). The elimination
itself works on the design and the target in units of that scale, so it is the same problem at
every scale. Angles are
returned in (−2π, 2π] for A-pairs (their motion has period 4π) and (−π, π] for R-pairs. General
(non-sinusoidal) A-pairs have an elliptic, not rational, motion and are not supported.

Chains of 5 and 6 joints are solved by the eliminations of apair.ik.elimination6r and
apair.ik.elimination1a5r or by parameter homotopy (apair.ik.homotopy), and `ik_local`
(apair.ik.local) is a Levenberg-Marquardt search from seeds in C for any chain.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from ..kernels import native_in_use
from ..study import conjugate, multiply
from .joints import chain_joints, curve_minors, evaluate, left_matrix, on_curve, right_matrix
from .pencil import (
    DEFLATE_TOL,
    LEAD_COND,
    NO_ROOT,
    PROBE,
    ROOT_RTOL,
    Degenerate,
    bezout_of,
    common_roots,
    common_roots_many,
    deflate,
    eigenvalues,
    hidden_variable,
    isotropic_factors,
    isotropic_quotient,
    no_common_root,
    null_vectors,
    polished,
    product_map,
    relres_many,
    shifted,
    sylvester_at,
    two_roots,
    unique_roots,
)
from .poses import wrap

_Pair = tuple[np.ndarray, np.ndarray] | None  # the two images eliminated (None: a singular pencil's regular part)
OUTSIDE = [1, 2, 5, 6]  # components that vanish on the pair subalgebra
INSIDE = [0, 3, 4, 7]  # the subalgebra's components: 1, k, ε, εk
REAL_TOL = 1e-6  # |Im u| / (1 + |u|) under which a root is taken as real
CAND_TOL = 1e-4  # the same for an intermediate root (multiple roots lose half their digits)
SCREEN_TOL = (1e-8, 1e-8, 1e-6)  # the screen: Vandermonde null vector; accept; reject (see _screen)
_SCREEN_TOL = np.array(SCREEN_TOL)
# apair_ik4_left: ROOT_RTOL; a single null vector's rank gap; its Vandermonde test; no root at all
# (NO_ROOT, as unique_roots)
LEFT_TOL = np.array([ROOT_RTOL, 1e-6, 1e-8, NO_ROOT])


class Elimination:
    """The elimination for one orientation of the chain (forward or reversed, see chain_joints)."""

    def __init__(self, chain, scale: float, reverse: bool, seed: int):
        n = chain.n
        self.chain, self.scale, self.reverse = chain, scale, reverse
        self.rng = np.random.default_rng(seed)
        deltas = self.rng.uniform(-np.pi, np.pi, n)
        self.joints, self.pre = chain_joints(chain, scale, deltas, reverse)
        self.theta_map = (
            np.array([2.0 if j.kind == "revolute" else 4.0 for j in self.joints]),
            np.array([j.delta for j in self.joints]),
        )
        j1 = self.joints[0]
        if n >= 2:  # Z(u_1) = K_1⁻¹·P̃_1(u_1)·W·K_2⁻¹ = Σ u_1^m Zmap[m] W
            right = right_matrix(self.joints[1].Kinv)
            self.Zmap = np.stack([left_matrix(j1.Kinv) @ left_matrix(c) @ right for c in conjugate(j1.P)])
        if n == 3:
            self.image = conjugate(self.joints[2].A)  # W(u_3) = T·Ã_3(u_3)
        if n == 4:
            j3, j4 = self.joints[2:]
            self.image = conjugate(multiply(j3.A[:, None, :], j4.A[None, :, :]))
        if n >= 3:
            Q, Qx = self._half_quadrics()
            if len(Qx) == 0:
                raise AssertionError("no quadric in x vanishes on the rotations of a two-joint chain")
            self.Q = Q
            self.Qx = np.tensordot(self.rng.standard_normal(len(Qx)), Qx, 1)
            Qx8 = np.zeros((8, 8))
            Qx8[:4, :4] = self.Qx
            combinations = [Qx8] + list(np.tensordot(self.rng.standard_normal((3, len(Q))), Q, 1))
            xy = _without_yy(Q, Qx8)
            self.combinations = np.array(combinations + ([xy] if xy is not None else []))  # (4 or 5, 8, 8)
        if n == 4:  # the factors 1 + u² of the images at a random pose (not on the chain's image)
            x, y = self.rng.standard_normal((2, 4))
            x /= np.linalg.norm(x)
            pose = np.concatenate([x, y - (x @ y) * x])  # on the Study quadric
            images = self._quadric_images(self.image @ left_matrix(pose).T)
            self.factors = [isotropic_factors(g) for g in images]
            divided = [isotropic_quotient(g, k) for g, k in zip(images, self.factors)]
            self.shapes = [d.shape for d in divided]
            # per pair, whether g(±i, ·) is a multiple of f(±i, ·), and then g(·, ±i) one of
            # f(·, ±i): the spurious roots at u_3 = ±i and at u_4 = ±i (`deflate`), removed where
            # that holds at the pose too
            self.deflatable = {}
            for a, b in self._tries(True):
                f, g = divided[a + 1], divided[b + 1]
                du = deflate(f, g)
                dv = deflate(f.T, (g if du is None else du).T)
                self.deflatable[a, b] = (du is not None, dv is not None)

    def _half_quadrics(self):
        """Quadrics through the left half's poses (all, and in x alone) by SVD on sampled points."""
        j1, j2 = self.joints[:2]
        u = np.tan(self.rng.uniform(-np.pi / 2, np.pi / 2, (2, 160)))
        pts = multiply(evaluate(j1.A, u[0]), evaluate(j2.A, u[1]))
        pts /= np.linalg.norm(pts, axis=1, keepdims=True)
        return _quadric_forms(pts), _quadric_forms(pts[:, :4])

    def candidates(self, target: np.ndarray, count_complex: bool) -> list[np.ndarray]:
        """Complex parameter vectors (in this elimination's joint order) for a unit target."""
        if self.pre is not None:
            target = multiply(self.pre, conjugate(target))
        n = self.chain.n
        return self._solve_left(target, n) if n <= 2 else self._solve_right(target, count_complex)

    def angles(self, real: np.ndarray) -> np.ndarray:
        """Joint angles (k, n) in the chain's order from real parameter vectors (k, n)."""
        if len(real) == 0:
            return np.zeros((0, self.chain.n))
        k, delta = self.theta_map  # θ = k·arctan(u) + δ, k = 2 (R-pair) or 4: Joint.parameter inverted
        q = wrap(k * np.arctan(np.real(real)) + delta, np.pi * k)
        return q[:, ::-1] if self.reverse else q

    def _solve_left(self, W: np.ndarray, n: int) -> list[np.ndarray]:
        """Parameters (u_1[, u_2]) with A_1 (A_2) ∝ W, complex; W may be complex."""
        j1 = self.joints[0]
        if n == 1:
            return [np.array([u]) for u in on_curve(j1, multiply(W, j1.Kinv), self.rng)]
        return self._solve_left_many(W[None])[0]

    def _solve_left_many(self, Ws: np.ndarray) -> list[list[np.ndarray]]:
        """Parameters (u_1, u_2) with A_1 A_2 ∝ W for each row of Ws (R, 8): the usual single
        solution of a real W in C (apair_ik4_left, the first step of _solve_left_general) where
        the kernels are installed, every other row by _solve_left_general."""
        native = native_in_use()
        if np.iscomplexobj(Ws) and len(Ws):
            return self._solve_left_complex(Ws)
        if native is None or len(Ws) == 0:
            return self._solve_left_general(Ws)
        j2 = self.joints[1]
        joint = np.array([j2.kind == "revolute", j2.delta, j2.offset, j2.sign], float)
        status, u1, u2, ok = native.ik4_left(Ws, self.Zmap, j2.P, joint, LEFT_TOL)
        out = [[np.array([x, y]) for y, good in zip(ys, oks) if good] for x, ys, oks in zip(u1, u2, ok)]
        rest = np.flatnonzero(status == 1)  # 2: no root u_1 at all
        for r, sols in zip(rest, self._solve_left_general(Ws[rest])):
            out[r] = sols
        return out

    def _solve_left_complex(self, Ws: np.ndarray) -> list[list[np.ndarray]]:
        """_solve_left_general for complex rows (the count of the complex solutions), the rows
        proven to have no root u_1 at all (no_common_root, as _solve_left_general's test, which
        does not apply where joints 1 and 2 share an axis) first left out: most of them, there."""
        Zc = np.einsum("mab,rb->rma", self.Zmap, Ws)
        outside = Zc[:, :, OUTSIDE]
        coaxial = np.abs(outside).max(axis=(1, 2)) <= 1e-10 * np.abs(Zc).max(axis=(1, 2))
        polys = np.swapaxes(outside, 1, 2)
        rows = np.flatnonzero(coaxial | ~no_common_root(shifted(polys, polys.shape[2] - 2)))
        out: list[list[np.ndarray]] = [[] for _ in range(len(Ws))]
        for r, sols in zip(rows, self._solve_left_general(Ws[rows]) if len(rows) else []):
            out[r] = sols
        return out

    def _solve_left_general(self, Ws: np.ndarray) -> list[list[np.ndarray]]:
        """Parameters (u_1, u_2) with A_1 A_2 ∝ W for each row of Ws (R, 8), complex: the common
        roots of all rows at once."""
        if len(Ws) == 0:
            return []
        Zc = np.einsum("mab,rb->rma", self.Zmap, Ws)  # (R, D1+1, 8)
        outside = Zc[:, :, OUTSIDE]
        coaxial = np.abs(outside).max(axis=(1, 2)) <= 1e-10 * np.abs(Zc).max(axis=(1, 2))
        out: list = [self._solve_coaxial(Zc[r]) if coaxial[r] else [] for r in range(len(Ws))]
        rows = np.flatnonzero(~coaxial)
        # the usual case, one (u_1, u_2) per W, from two null vectors; the rest by eigenvalues
        polys = np.swapaxes(outside[rows], 1, 2)  # (R, 4, D1+1)
        M = shifted(polys, polys.shape[2] - 2)
        if not np.iscomplexobj(Ws):
            u1, one, none = unique_roots(M)  # as apair_ik4_left does
            Z = np.einsum("km,kma->ka", u1[:, None] ** np.arange(Zc.shape[1]), Zc[rows])
            u2 = self.joints[1].parameters_of(Z)  # (R, 1 or 2), each tested
            ok = np.stack(
                [
                    relres_many(np.swapaxes(curve_minors(self.joints[1].P, Z), 1, 2), u2[:, j]) <= ROOT_RTOL
                    for j in range(u2.shape[1])
                ],
                1,
            )
            one &= ok.any(axis=1)
            for r, x, ys, oks in zip(rows[one], u1[one], u2[one], ok[one]):
                out[r] = [np.array([x, y]) for y, good in zip(ys, oks) if good]
        else:  # (complex W: for the count of complex solutions, most with no root u_1 at all)
            one, none = np.zeros(len(rows), bool), no_common_root(M)
        rows = rows[~one & ~none]
        if len(rows) == 0:
            return out
        u1s = common_roots_many(np.swapaxes(outside[rows], 1, 2), self.rng)
        if any(u is None for u in u1s):
            raise Degenerate("every polynomial vanishes identically")
        owner = np.concatenate([np.full(len(u), r) for r, u in zip(rows, u1s)] + [np.zeros(0, int)]).astype(int)
        u1 = np.concatenate(list(u1s) + [np.zeros(0, complex)])
        if len(u1) == 0:
            return out
        Z = np.einsum("km,kma->ka", u1[:, None] ** np.arange(Zc.shape[1]), Zc[owner])  # (K, 8)
        u2s = common_roots_many(np.swapaxes(curve_minors(self.joints[1].P, Z), 1, 2), self.rng)
        if any(u is None for u in u2s):
            raise Degenerate("every polynomial vanishes identically")
        for r, x, u2 in zip(owner, u1, u2s):
            out[r] += [np.array([x, y]) for y in u2]
        return out

    def _solve_coaxial(self, Zc: np.ndarray) -> list[np.ndarray]:
        """Joints 1 and 2 on one axis (a_1 = 0, α_1 = 0): Z(u_1) lies in the pair subalgebra for
        every u_1, so u_1 and u_2 come together from Z(u_1) ∝ P_2(u_2): the 2×2 minors of the
        subalgebra components are bivariate; two random combinations are eliminated (hidden
        variable u_1), and each u_1 gets the common roots u_2 of all minors. Two R-pairs on one
        axis have a curve of solutions (the resultant vanishes identically): Degenerate."""
        P2 = self.joints[1].P
        a, b = np.array([(a, b) for i, a in enumerate(INSIDE) for b in INSIDE[i + 1 :]]).T
        minors = (Zc[:, None, a] * P2[None, :, b] - Zc[:, None, b] * P2[None, :, a]).transpose(2, 0, 1)
        f, g = (np.tensordot(self.rng.standard_normal(len(minors)), minors, 1) for _ in range(2))
        out = []
        for u1 in hidden_variable(f, g, self.rng):
            row = np.einsum("kij,i->kj", minors, u1 ** np.arange(len(Zc)))
            try:
                out += [np.array([u1, u2]) for u2 in common_roots(row, self.rng)]
            except Degenerate:
                continue
        return out

    def _quadric_images(
        self, C: np.ndarray, factors: list[tuple[int, int]] | None = None
    ) -> np.ndarray | list[np.ndarray]:
        """Coefficients (u_3^i u_4^j) of Q(W(u_3, u_4)) for the rotation quadric Qx (first: f), three
        random combinations Q of the left half's quadrics and the one without a yy block (last,
        where there is one), from one FFT of W, each divided by
        the factors 1 + u² it has at every pose (`factors`, found once per design: f has two of
        each at least, since W's rotation part carries (1 + u_3²)(1 + u_4²))."""
        s = (2 * C.shape[0] - 1, 2 * C.shape[1] - 1)
        F = np.fft.fft2(C, s=s, axes=(0, 1)).reshape(-1, 8)
        values = np.einsum("qpb,pb->qp", F @ self.combinations, F)  # (q, s0·s1)
        images = np.real(np.fft.ifft2(values.reshape((-1,) + s), axes=(-2, -1)))
        if factors is None:
            return images
        return [isotropic_quotient(g, k) for g, k in zip(images, factors)]

    def _resultant_roots(self, C: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray] | None]:
        """Every u_3 at which two conditions on W(u_3, u_4) have a common root u_4: the rotation
        condition f (bidegree (4, 4)) with a combination g of the quadrics (the one without a yy
        block first: bidegree (6, 6), 48 roots, 32 once deflated, `deflate`), else (where f
        vanishes on the whole image, or f and g share a curve, as special designs make them) other
        combinations, until the
        resultant is not identically zero; where every pair shares a curve, the regular part of
        the first pair's pencil. The pair with the fewest roots is tried first (special designs
        give the images more factors 1 + u²: two parallel axes halve their bidegrees). Returns
        the roots and the pair eliminated (None for a singular pencil's regular part)."""
        native = native_in_use()
        # the first pair that the loop below would not skip for a row constant in u_3, in C
        a, b = next(
            (ab for ab in self._tries(True) if min(self.shapes[ab[0] + 1][0], self.shapes[ab[1] + 1][0]) >= 2), (0, 0)
        )
        if native is not None and a < b and not np.iscomplexobj(C):
            du, dv = self.deflatable[a, b]
            out = native.ik4_pencil(
                C,
                self.combinations[a + 1],
                self._factor_array(a + 1),
                self.combinations[b + 1],
                self._factor_array(b + 1),
                LEAD_COND,
                int(du) + 2 * int(dv),
                DEFLATE_TOL,
            )
            if out is not None:
                f, g, M = out
                return eigenvalues(M), (f, g)
        f, *g = self._quadric_images(C, self.factors)

        def poly(k: int) -> np.ndarray:  # −1: f; 0, 1, 2: random combinations; 3: without yy
            return f if k < 0 else g[k]

        tries = self._tries(np.abs(f).max() > 1e-12 * np.abs(C).max() ** 2 * np.abs(self.Qx).max())
        for a, b in tries:
            pa, pb = poly(a), poly(b)
            du, dv = self.deflatable[a, b]
            deflated = deflate(pa, pb) if du else None
            pb = pb if deflated is None else deflated
            deflated = deflate(pa.T, pb.T) if dv else None
            pb = pb if deflated is None else deflated.T
            try:
                return hidden_variable(pa, pb, self.rng, singular_ok=False), (pa, pb)
            except Degenerate:
                continue
        # every pair shares a curve
        return hidden_variable(poly(tries[0][0]), poly(tries[0][1]), self.rng), None

    def _tries(self, with_f: bool) -> list[tuple[int, int]]:
        """The pairs of images to eliminate (−1: f; k ≥ 0: the k-th other), fewest roots first."""
        tries = [(0, 1), (1, 2)]
        if with_f:
            tries = [(-1, k) for k in range(len(self.combinations) - 1)] + tries
        return sorted(tries, key=lambda ab: bezout_of(self.shapes[ab[0] + 1], self.shapes[ab[1] + 1]))

    def _factor_array(self, k: int) -> np.ndarray:
        return np.array(self.factors[k], np.int32)

    def _screen(
        self, u3s: np.ndarray, pair: tuple[np.ndarray, np.ndarray] | None, C: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The real u_3 sorted by two steps of inverse iteration: the Sylvester matrix of the
        eliminated pair `pair` is singular at each u_3, and where its null vector comes out as
        (1, u_4, u_4², …) (one common root u_4), the left half's quadrics on W(u_3, u_4) accept the
        pair (relative residual ≤ 1e-8) or reject u_3 (> 1e-6: most of the resultant's roots are
        not common roots of the other quadrics). Where the null space is two-dimensional, each of
        its two roots u_4 is polished by Newton and tested alike. Returns the accepted pairs (r, 2),
        their images (r, 8), and the u_3 left undecided (a residual in between, or a null space
        that says neither) for _right_pairs."""
        none = np.zeros((0, 2)), np.zeros((0, 8)), u3s
        if pair is None or len(u3s) == 0 or np.iscomplexobj(C) or np.iscomplexobj(pair[0]):
            return none
        vand_tol, accept_tol, reject_tol = SCREEN_TOL
        native = native_in_use()
        if native is not None:  # in C (apair_ik4_screen), the same steps
            N = pair[0].shape[1] + pair[1].shape[1] - 2
            status, u4, W, rel, two, two_ok, W2, rel2 = native.ik4_screen(
                u3s, C, pair[0], pair[1], self.Q, PROBE[:N], _SCREEN_TOL
            )
            vandermonde = status <= 2
            rows = np.flatnonzero(~vandermonde)
            known, real = status[rows] == 3, two_ok[rows].astype(bool)
            a, b, W2, rel2 = two[rows, :, 0], two[rows, :, 1], W2[rows], rel2[rows]
        else:
            x = null_vectors(sylvester_at(*pair, u3s))
            solved = np.isfinite(x).all(axis=1)
            u4 = np.sum(x[:, :-1] * x[:, 1:], axis=1) / np.maximum(np.sum(x[:, :-1] ** 2, axis=1), 1e-300)
            vandermonde = solved & (np.linalg.norm(x[:, 1:] - u4[:, None] * x[:, :-1], axis=1) <= vand_tol)
            u4 = np.where(solved, u4, 0.0)
            W, rel = self._on_quadrics(u3s, u4, C)
            rows = np.flatnonzero(~vandermonde)
            # two roots u_4: each real one polished on the eliminated pair
            v = two_roots(sylvester_at(*pair, u3s[rows]))
            known = np.isfinite(v).all(axis=1)
            real = known[:, None] & (np.abs(v.imag) <= 1e-2 * (1 + np.abs(v)))
            a, b = np.zeros(real.shape), np.zeros(real.shape)
            a[real], b[real] = polished(*pair, np.repeat(u3s[rows], 2)[real.ravel()], v.real[real])
            W2, rel2 = np.zeros(real.shape + (8,)), np.zeros(real.shape)
            W2[real], rel2[real] = self._on_quadrics(a[real], b[real], C)
        accept, reject = vandermonde & (rel <= accept_tol), vandermonde & ~(rel <= reject_tol)
        pairs, images = np.stack([u3s[accept], u4[accept]], 1), W[accept]
        if len(rows) == 0:
            return pairs, images, u3s[~(accept | reject)]
        # a u_3 with two roots is decided where both real ones are (complex ones are no solutions);
        # a null space that says neither leaves it undecided
        good, bad = real & (rel2 <= accept_tol), real & ~(rel2 <= reject_tol)
        undecided = ~known | np.any(real & ~(good | bad), axis=1)
        reject[rows[~undecided]] = True
        pairs = np.concatenate([pairs, np.stack([a[good], b[good]], 1)])
        images = np.concatenate([images, W2[good]])
        return pairs, images, u3s[~(accept | reject)]

    def _on_quadrics(self, u3: np.ndarray, u4: np.ndarray, C: np.ndarray):
        """The images W(u_3, u_4) (r, 8) and the left half's largest quadric on each, relative to |W|²."""
        Cu = (u3[:, None] ** np.arange(C.shape[0]) @ C.reshape(C.shape[0], -1)).reshape(len(u3), C.shape[1], 8)
        W = (u4[:, None, None] ** np.arange(C.shape[1])[None, None, :] @ Cu)[:, 0]
        size = np.maximum(np.sum(np.abs(W) ** 2, axis=1), 1e-300)
        return W, np.abs(np.sum((W @ self.Q) * W, axis=-1)).max(axis=0) / size

    def _right_pairs(self, u3s: np.ndarray, C: np.ndarray, real: bool) -> tuple[np.ndarray, np.ndarray]:
        """For each u_3, the u_4 where every quadric of the left half vanishes on W(u_3, u_4) (their
        common roots: complete even where f or g alone vanishes for all u_4 at that u_3); the
        pairs (r, 2) and their images W (r, 8). A u_3 at which all of them vanish for every u_4
        (a curve of candidates, never a solution of a full-rank pose) is skipped."""
        if len(u3s) == 0:
            return np.zeros((0, 2)), np.zeros((0, 8))
        Cu = np.einsum("ri,ija->rja", u3s[:, None] ** np.arange(C.shape[0]), C)  # (R, D4+1, 8)
        outer = (Cu[:, None] @ self.Q) @ np.swapaxes(Cu, 1, 2)[:, None]  # (R, k, D4+1, D4+1)
        D = Cu.shape[1]
        polys = outer.reshape(outer.shape[:2] + (D * D,)) @ product_map(D, D)
        owners, roots = [np.zeros(0, int)], [np.zeros(0, complex if not real else float)]
        for r, u4s in enumerate(common_roots_many(polys, self.rng)):
            if u4s is None:  # every quadric vanishes for all u4 at this u3
                continue
            if real:
                u4s = u4s[np.abs(u4s.imag) <= CAND_TOL * (1 + np.abs(u4s))].real
            owners.append(np.full(len(u4s), r))
            roots.append(u4s)
        owner, u4 = np.concatenate(owners), np.concatenate(roots)
        if len(u4) == 0:
            return np.zeros((0, 2)), np.zeros((0, 8))
        images = np.einsum("kj,kja->ka", u4[:, None] ** np.arange(D), Cu[owner])
        return np.stack([u3s[owner], u4], 1), images

    def _solve_right(self, T: np.ndarray, count_complex: bool) -> list[np.ndarray]:
        """Candidates for 3 and 4 joints: the right part's parameters from the left half's quadrics
        on the image W = T·(A_3 A_4)~, then the left half for each W."""
        LT = left_matrix(T)
        C = self.image @ LT.T
        rights: np.ndarray | list[np.ndarray]
        images: np.ndarray | list[np.ndarray]
        if self.chain.n == 3:
            G = np.einsum("ma,qab,kb->qmk", C, self.Q, C)
            G = G.reshape(len(G), -1) @ product_map(*G.shape[1:])
            rights = [np.array([u3]) for u3 in common_roots(G, self.rng)]
            images = [(r[0] ** np.arange(len(C))) @ C for r in rights]
        else:
            u3s, pair = self._resultant_roots(C)
            rights, images = _with_cluster_means(*self._real_pairs(u3s, pair, C), C)
            if count_complex:
                more = self._with_left(*_with_cluster_means(*self._complex_pairs(u3s, pair, C), C))
                mirrored = [v.conj() for v in more if v[2].imag > CAND_TOL * (1 + abs(v[2]))]
                return self._with_left(rights, images) + more + mirrored
        return self._with_left(rights, images)

    def _with_left(self, rights, images) -> list[np.ndarray]:
        """The parameter vectors (u_1, u_2, right…) of the left half solved for each image."""
        out = []
        for right, lefts in zip(rights, self._solve_left_many(np.asarray(images).reshape(-1, 8))):
            out += [np.concatenate([left, right]) for left in lefts]
        return out

    def _real_pairs(self, u3s: np.ndarray, pair: _Pair, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The real pairs (u_3, u_4) of 4 joints and their images: the real roots u_3 (and the mean
        of every two close ones) screened (`_screen`), the undecided by `_right_pairs`."""
        # a mean within CAND_TOL of the real axis has both roots within 2·CAND_TOL of it
        u3s = _with_means(u3s[np.abs(u3s.imag) <= 2 * CAND_TOL * (1 + np.abs(u3s))])
        u3s = u3s[np.abs(u3s.imag) <= CAND_TOL * (1 + np.abs(u3s))].real
        rights, images, rest = self._screen(u3s, pair, C)
        if len(rest):
            more, more_images = self._right_pairs(rest, C, real=True)
            rights, images = np.concatenate([rights, more]), np.concatenate([images, more_images])
        return rights, images

    def _complex_pairs(self, u3s: np.ndarray, pair: _Pair, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The pairs (u_3, u_4), not both real, on whose image every quadric of the left half
        vanishes, and their images (r, 8), complex: what the count of the complex solutions adds
        to `_real_pairs`. Every root u_3 off the isotropic points is screened as `_screen` screens
        the real ones, in complex arithmetic: a Vandermonde null vector of the eliminated pair's
        Sylvester matrix gives its one common root u_4, which the quadrics accept or reject; the
        rest (two or more roots u_4, but for a real u_3 with two real ones, or a residual in
        between) get the common roots of all quadrics (`_right_pairs`). Isotropic pairs are
        dropped. The pose is real, so the solutions at the conjugate of a root u_3 are the
        conjugates of those at u_3: only the roots with Im u_3 >= 0 (to CAND_TOL) are taken, and the
        caller adds the conjugates (and the means of close pairs, for a double root's accuracy)."""
        u3s = u3s[~_isotropic(u3s) & (u3s.imag >= -CAND_TOL * (1 + np.abs(u3s)))].astype(complex)
        rest = u3s
        pairs, images = np.zeros((0, 2), complex), np.zeros((0, 8), complex)
        if pair is not None and len(u3s):
            x = null_vectors(sylvester_at(*pair, u3s))
            solved = np.isfinite(x).all(axis=1)
            x = np.where(solved[:, None], x, 0)
            u4 = np.sum(x[:, :-1].conj() * x[:, 1:], axis=1) / np.maximum(
                np.sum(np.abs(x[:, :-1]) ** 2, axis=1), 1e-300
            )
            vandermonde = solved & (np.linalg.norm(x[:, 1:] - u4[:, None] * x[:, :-1], axis=1) <= SCREEN_TOL[0])
            W, rel = self._on_quadrics(u3s, u4, C)
            accept = vandermonde & (rel <= SCREEN_TOL[1])
            pairs, images = np.stack([u3s[accept], u4[accept]], 1), W[accept]
            undecided = ~accept & ~(vandermonde & ~(rel <= SCREEN_TOL[2]))
            # a real u_3 whose two roots u_4 are real (an A-pair's θ and θ + 2π) is _real_pairs' alone
            rows = np.flatnonzero(undecided & ~vandermonde & (np.abs(u3s.imag) <= CAND_TOL * (1 + np.abs(u3s))))
            if len(rows):
                two = two_roots(sylvester_at(*pair, u3s[rows].real))
                undecided[rows[np.all(np.abs(two.imag) <= CAND_TOL * (1 + np.abs(two)), axis=1)]] = False
            rest = u3s[undecided]
        if len(rest):
            more, more_images = self._right_pairs(rest, C, real=False)
            pairs, images = np.concatenate([pairs, more]), np.concatenate([images, more_images])
        real = np.all(np.abs(pairs.imag) <= CAND_TOL * (1 + np.abs(pairs)), axis=1)
        keep = ~real & ~_isotropic(pairs[:, 1])
        return pairs[keep], images[keep]


# ----------------------------------------------------------------------------- helpers
def _isotropic(u: np.ndarray) -> np.ndarray:
    """Where a parameter is at an isotropic point u = ±i (a joint's rotation part vanishes: never a
    displacement), to the tolerance apair.ik.solver drops such candidates with."""
    return np.abs(1 + u * u) <= 1e-3 * (1 + np.abs(u) ** 2)


def _close_pairs(x: np.ndarray) -> tuple[np.ndarray, ...]:
    """Indices i < j of the rows of x (r, m) that agree to CAND_TOL in every entry."""
    i, j = _upper(len(x))
    close = np.all(np.abs(x[i] - x[j]) <= CAND_TOL * (1 + np.abs(x[i])), axis=-1)
    return i[close], j[close]


@cache
def _upper(r: int) -> tuple[np.ndarray, np.ndarray]:
    """The index pairs i < j of r rows, row by row."""
    return np.triu_indices(r, 1)


def _with_means(u: np.ndarray) -> np.ndarray:
    """The roots u (r,) and the mean of every two that agree to CAND_TOL: a double root comes out
    as two simple roots (or a complex pair) about √ε apart, too inaccurate for what is solved from
    it, while their mean is accurate to about ε (the sum of roots is a smooth function of the
    coefficients). At a pose where the left half's surface crosses itself (an A-pair at ±π) the
    resultant has such a double root. The roots themselves are kept, and means at the isotropic
    points u = ±i (never a displacement) are not added."""
    i, j = _close_pairs(u[:, None])
    means = (u[i] + u[j]) / 2
    means = means[np.abs(1 + means * means) > 1e-3 * (1 + np.abs(means) ** 2)]
    return np.concatenate([u, means]) if len(means) else u


def _with_cluster_means(pairs: np.ndarray, images: np.ndarray, C: np.ndarray):
    """The pairs (u_3, u_4) and their images, plus the mean of every two pairs that agree to
    CAND_TOL: a double root (special poses square the resultant) comes out as two simple roots
    about √ε apart, too inaccurate for the left half, while their mean is accurate to about ε.
    Candidates are kept as they are, so two close genuine solutions are not merged (verification
    and deduplication decide)."""
    if len(pairs) < 2:
        return pairs, images
    i, j = _close_pairs(pairs)
    if len(i) == 0:
        return pairs, images
    means = (pairs[i] + pairs[j]) / 2
    Cu = np.einsum("ri,ija->rja", means[:, 0:1] ** np.arange(C.shape[0]), C)
    extra = np.einsum("rj,rja->ra", means[:, 1:2] ** np.arange(C.shape[1]), Cu)
    return np.concatenate([pairs, means]), np.concatenate([images, extra])


def _without_yy(Q: np.ndarray, Qx8: np.ndarray) -> np.ndarray | None:
    """A quadric of the span of Q (k, 8, 8) without a yy block, orthogonal (Frobenius) to the
    rotation quadric Qx8 and to the Study quadric x·y (both are in that subspace: the Study
    quadric vanishes on every image, and a large Qx part would make its image nearly a
    multiple of f, the resultant's roots inaccurate); None where there is no such quadric.
    Its image carries the factor (1 + u_3²)(1 + u_4²), so it has bidegree (6, 6), not (8, 8),
    and its resultant with f has 48 roots, not 64."""
    _, sv, Vt = np.linalg.svd(Q[:, 4:, 4:].reshape(len(Q), -1).T)
    sv = np.concatenate([sv, np.zeros(len(Q) - len(sv))])
    null = Vt[sv <= 1e-10 * max(sv[0], 1e-300)]
    if len(null) == 0:
        return None
    basis = np.tensordot(null, Q, 1).reshape(len(null), -1).T  # (64, m)
    study = np.zeros((8, 8))
    study[:4, 4:] = study[4:, :4] = np.eye(4)
    known = np.stack([Qx8.ravel(), study.ravel()], 1)
    _, sv, Vt = np.linalg.svd(known.T @ basis)
    sv = np.concatenate([sv, np.zeros(basis.shape[1] - len(sv))])
    if sv[-1] > 1e-8 * max(sv[0], 1e-300):  # every combination has a Qx or Study part
        return None
    xy = (basis @ Vt[-1]).reshape(8, 8)
    return xy / np.linalg.norm(xy)


def _quadric_forms(pts: np.ndarray) -> np.ndarray:
    """Symmetric matrices (k, d, d) of the quadratic forms vanishing on the points (N, d)."""
    d = pts.shape[1]
    i, j = np.triu_indices(d)
    A = pts[:, i] * pts[:, j]
    _, s, Vt = np.linalg.svd(A)
    s = np.concatenate([s, np.zeros(Vt.shape[0] - len(s))])
    null = Vt[s <= 1e-10 * s[0]]
    Q = np.zeros((len(null), d, d))
    Q[:, i, j] = null
    return (Q + np.swapaxes(Q, 1, 2)) / 2
