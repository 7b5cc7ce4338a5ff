"""What the closed-form solvers of six-joint chains share (apair.ik.wrist, apair.ik.parallel,
apair.ik.three_parallel, apair.ik.parallel_apair): the tolerances, the real roots of their univariate
polynomials and the note that names a continuum. Their C twins share src/csrc/apair_ik_closed.h."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

ROOT_IMAG = 1e-4  # a root with |Im t| <= ROOT_IMAG (1 + |t|) is a candidate (then verified)
SINGULAR = 1e-7  # [rad] an angle this close to 0 or π (at a double root) is taken as there
FLAT = 1e-9  # relative size below which a length, a twist's sine or a coefficient counts as zero
DOUBLE = 1e-14  # a squared sine within this (relative) of 0: one root, not two
TANGENT = 1e-8  # a critical point where the polynomial is this close to 0 (relative) is a (double) root
SPLIT = 1e-6  # two real roots of a quadratic this far apart (relative) are two, not a split double root


def real_roots(coeffs: NDArray[np.float64], ref: float) -> tuple[list[float], bool]:
    """Real roots t of Σ c_k t^k (lowest degree first), near-real ones included, and whether the
    degree drops (a root at t = ∞, the angle π). Raises ValueError where every coefficient vanishes
    against `ref`, the size of its terms (the angle then moves nothing the polynomial sees)."""
    size = float(np.max(np.abs(coeffs)))
    if not size > FLAT * ref:
        raise ValueError("the position polynomial vanishes identically")
    c = coeffs / size
    nz = np.nonzero(np.abs(c) > FLAT)[0]
    top = int(nz[-1])
    at_infinity = top < len(c) - 1
    if top == 0:
        return [], at_infinity
    poly = c[: top + 1][::-1]
    t = np.roots(poly)
    real = t[np.abs(t.imag) <= ROOT_IMAG * (1 + np.abs(t))].real
    roots = _polish(poly, real).tolist()
    # a critical point where the polynomial (nearly) vanishes: a double root, exact where the two
    # roots come sqrt(eps) off it (as the C twin, apair_ik_closed.h); a quadratic's by its
    # discriminant, and not between two real roots SPLIT apart (two solutions: the point between them
    # nearly verifies, to 3e-11 on a PUMA's pose with roots 1.7e-5 apart)
    if top == 2:
        c2, c1, c0 = poly
        disc = c1 * c1 - 4 * c2 * c0
        mid = -c1 / (2 * c2)
        split = disc >= 0 and len(real) == 2 and abs(real[1] - real[0]) > SPLIT * (1 + abs(mid))
        if abs(disc) <= TANGENT * (c1 * c1 + abs(4 * c2 * c0) + c2 * c2) and not split:
            roots.append(float(mid))
    elif top > 2:  # ... and not between two real roots each SPLIT from it, in the intervals beside it
        x = np.roots(np.polyder(poly))
        x = np.sort(x[np.abs(x.imag) <= ROOT_IMAG * (1 + np.abs(x))].real)
        near = np.abs(np.polyval(poly, x)) <= TANGENT * np.maximum(1.0, np.polyval(np.abs(poly), np.abs(x)))
        edges = np.concatenate([[-np.inf], x, [np.inf]])
        for m in np.flatnonzero(near):
            c, split = x[m], SPLIT * (1 + abs(x[m]))
            below = [r for r in real if edges[m] < r < c]
            above = [r for r in real if c < r < edges[m + 2]]
            if not (below and above and c - max(below) > split and min(above) - c > split):
                roots.append(float(c))
    return roots, at_infinity


def _polish(poly: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """Newton steps on simple roots while they shrink |p| (as the C twin's bracketed Newton): the
    companion matrix's eigenvalues come some 1e-14 off, which a stretched elbow's cos ψ_3 = ±1
    turns into a spurious pair of elbows 1e-6 apart. Each root stops at its first step that does
    not shrink |p|."""
    dpoly = np.polyder(poly)
    x = np.array(x, dtype=np.float64)
    px = np.abs(np.polyval(poly, x))
    going = np.ones(len(x), dtype=bool)
    for _ in range(3):
        d = np.polyval(dpoly, x)
        going &= (d != 0.0) & (px != 0.0)
        if not going.any():
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(going, x - np.polyval(poly, x) / np.where(going, d, 1.0), x)
        py = np.abs(np.polyval(poly, y))
        going &= py < px
        x, px = np.where(going, y, x), np.where(going, py, px)
    return x


def note(free: set[str]) -> str:
    """The note of an answer with continua (FLAGS' texts): one member of each is given."""
    return f"a continuum of solutions ({', '.join(sorted(free))}): one member is given" if free else ""
