"""The joints as the 4-joint elimination sees them (apair.ik.elimination4): joint i moves as
A_i(u) = P_i(u)·K_i, P_i(u) a polynomial curve in its shifted parameter u in the pair subalgebra
(rotations about and translations along z), K_i = Tx(a_i)·Rx(α_i) constant; the chain's joints
forward or reversed (`chain_joints`), and the Study products as 8×8 matrices.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cache

import numpy as np

from ..study import conjugate, multiply
from .pencil import common_roots
from .poses import wrap


def _mobius(coeffs: np.ndarray, tau: float) -> np.ndarray:
    """(D+1, ...) coefficients of p(u) → those of (1 − τv)^D p((v + τ)/(1 − τv))."""
    P = np.polynomial.polynomial
    D = coeffs.shape[0] - 1
    out = np.zeros_like(coeffs)
    for m in range(D + 1):
        w = P.polymul(P.polypow([tau, 1.0], m), P.polypow([1.0, -tau], D - m))
        out[: len(w)] += np.multiply.outer(w, coeffs[m])
    return out


@cache
def _quartic() -> np.ndarray:
    """(5, 8, 2): the coefficient of u^m h^k in component j of the sinusoidal pair's Study point,
    read from the derived set `apair_motion` (entries rational_x0 … rational_y3)."""
    import sympy as sp

    from .. import polynomials

    eqs = polynomials.load("apair_motion")
    out = np.zeros((5, 8, 2))
    for j, name in enumerate(("x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3")):
        expr = sp.expand(eqs[f"rational_{name}"])
        syms = {s.name: s for s in expr.free_symbols}
        poly = sp.Poly(expr, syms.get("u", sp.Symbol("u")), syms.get("h", sp.Symbol("h")))
        for (m, k), c in poly.terms():
            out[m, j, k] = float(c)
    return out


def _rot(axis: int, angle: float) -> np.ndarray:
    p = np.zeros(8)
    p[0], p[1 + axis] = math.cos(angle / 2), math.sin(angle / 2)
    return p


def _trans(axis: int, dist: float) -> np.ndarray:
    p = np.zeros(8)
    p[0], p[5 + axis] = 1.0, dist / 2
    return p


@dataclass
class Joint:
    """Joint i in a shifted parameter u: P(u) (D+1, 8); the constant K and K⁻¹; and the map θ → u."""

    kind: str
    delta: float
    P: np.ndarray
    K: np.ndarray
    Kinv: np.ndarray
    A: np.ndarray = field(init=False)

    def __post_init__(self):
        self.A = multiply(self.P, self.K)
        # P's rotation is about z by the angle sign·θ + offset (sign −1 for a reversed chain)
        a = self._rotation(self.parameter(np.array([0.0, 1.0])))
        self.sign = float(np.round(wrap(a[1] - a[0], 2 * np.pi)))
        self.offset = a[0]

    def parameter(self, theta):
        return np.tan((theta - self.delta) / (2 if self.kind == "revolute" else 4))

    def _rotation(self, u) -> np.ndarray:
        x = evaluate(self.P, u)
        return 2 * np.arctan2(x[:, 3], x[:, 0])

    def parameters_of(self, Z: np.ndarray) -> np.ndarray:
        """(R, 1) for an R-pair, (R, 2) for an A-pair: the parameters u whose rotation is that of
        the points Z (R, 8) in the pair subalgebra (an A-pair's two angles θ and θ + 2π share it;
        which of them has P(u) ∝ Z is for the caller to test)."""
        theta = (2 * np.arctan2(Z[:, 3].real, Z[:, 0].real) - self.offset) / self.sign
        if self.kind == "revolute":
            return self.parameter(theta)[:, None]
        return self.parameter(np.stack([theta, theta + 2 * np.pi], 1))


def _pair_curve(chain, i: int, scale: float, delta: float) -> np.ndarray:
    """P_i(u) (D+1, 8) = Rz(φ_i)·Tz(c_i)·(pair point in the parameter shifted by delta)."""
    pair = chain.pairs[i]
    if pair.kind == "revolute":
        tau = math.tan(delta / 2)
        base = np.zeros((2, 8))
        base[0, 0] = base[1, 3] = 1.0  # the rotation quaternion (1, 0, 0, tan(θ/2)), projectively
    else:
        tau = math.tan(delta / 4)
        base = _quartic() @ np.array([1.0, pair.amplitude / scale])
    P = _mobius(base, tau)
    return multiply(multiply(_rot(2, chain.theta_offset[i]), _trans(2, chain.offset[i] / scale)), P)


def _link(chain, i: int, scale: float) -> np.ndarray:
    """K_i = Tx(a_i)·Rx(α_i), the joint's constant part."""
    return multiply(_trans(0, chain.a[i] / scale), _rot(0, chain.alpha[i]))


def _make_joint(kind: str, delta: float, P: np.ndarray, K: np.ndarray) -> Joint:
    return Joint(kind, delta, P, K, conjugate(K))


def chain_joints(chain, scale: float, deltas, reverse: bool):
    """The joints as the elimination sees them, and the map of the target pose.

    Forward: A_i = P_i(u)·K_i, target T. Reversed: T = Π P_i K_i gives K_n·T̃ = Π_j P'_j K'_j
    with P'_j = P̃_{n+1−j} (still in the pair subalgebra, in the same parameter) and
    K'_j = K̃_{n−j}, K'_n = 1: the same problem with the chain's halves swapped, which is
    regular where the forward split degenerates (e.g. where joints 1 and 2 are parallel)."""
    n = chain.n
    kinds = [p.kind for p in chain.pairs]
    P = [_pair_curve(chain, i, scale, deltas[i]) for i in range(n)]
    K = [_link(chain, i, scale) for i in range(n)]
    if not reverse:
        return [_make_joint(kinds[i], deltas[i], P[i], K[i]) for i in range(n)], None
    one = np.zeros(8)
    one[0] = 1.0
    joints = [
        _make_joint(kinds[i], deltas[i], conjugate(P[i]), conjugate(K[i - 1]) if i else one) for i in reversed(range(n))
    ]
    return joints, K[n - 1]


_EYE8 = np.eye(8)
_LEFT = np.stack([multiply(e, _EYE8).T for e in _EYE8])  # _LEFT[a] @ v = e_a·v
_RIGHT = np.stack([multiply(_EYE8, e).T for e in _EYE8])  # _RIGHT[a] @ v = v·e_a


_LEFT_ROWS = _LEFT.reshape(8, 64)


def left_matrix(p: np.ndarray) -> np.ndarray:
    """The 8×8 matrix of v ↦ p·v (Study product)."""
    p = np.asarray(p)
    return (p @ _LEFT_ROWS).reshape(p.shape[:-1] + (8, 8))


def right_matrix(p: np.ndarray) -> np.ndarray:
    """The 8×8 matrix of v ↦ v·p."""
    return np.tensordot(p, _RIGHT, 1)


_PAIRS = np.triu_indices(8, 1)


def on_curve(j: Joint, Z: np.ndarray, rng) -> np.ndarray:
    """Parameters u with P_j(u) ∝ Z: common roots of the 2×2 minors P_a Z_b − P_b Z_a."""
    return common_roots(curve_minors(j.P, Z).T, rng)


def curve_minors(P: np.ndarray, Z: np.ndarray) -> np.ndarray:
    """The 2×2 minors P_a(u) Z_b − P_b(u) Z_a (..., D+1, 28) of a curve P (D+1, 8) and points Z (..., 8)."""
    a, b = _PAIRS
    return P[:, a] * Z[..., None, b] - P[:, b] * Z[..., None, a]


def evaluate(coeffs: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(R, ...): the polynomial curve of coefficients (D+1, ...) at the parameters u (R,)."""
    return np.einsum("m...,rm->r...", coeffs, np.asarray(u)[:, None] ** np.arange(len(coeffs)))
