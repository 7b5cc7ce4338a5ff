"""`AChain`: a serial chain of R- and A-pairs in the DH convention of CONVENTIONS.md §3.

Joint i: A_i(θ_i) = Rz(θ_i + φ_i) · Tz(c_i + d_i(θ_i)) · Tx(a_i) · Rx(α_i). Each method computes
the joints' law values with their pairs' kernels and hands everything to one generated chain
kernel for n joints (derivations/chain_kinematics.py); batches stay in the kernel.
"""
from __future__ import annotations

import numpy as np

from . import _validate as V
from .kernels import call
from .pair import APair
from .study import normalise

MAX_JOINTS = 6


class AChain:
    """A chain of `pairs` with DH constants a (link lengths), alpha (twists), offset (c),
    theta_offset (φ). Angles in radians, lengths in metres."""

    def __init__(self, pairs, a, alpha, offset=None, theta_offset=None):
        try:
            pairs = list(pairs)
        except TypeError as exc:
            raise ValueError(f"pairs: expected a sequence of APair, got {pairs!r}") from exc
        n = len(pairs)
        if not 1 <= n <= MAX_JOINTS:
            raise ValueError(f"pairs: a chain has 1 to {MAX_JOINTS} pairs, got {n}")
        for i, p in enumerate(pairs):
            if not isinstance(p, APair):
                raise ValueError(f"pairs[{i}]: expected an APair, got {type(p).__name__}")
        self.pairs = pairs
        self.a = V.vector("a", a, n)
        self.alpha = V.vector("alpha", alpha, n)
        self.offset = np.zeros(n) if offset is None else V.vector("offset", offset, n)
        self.theta_offset = np.zeros(n) if theta_offset is None else V.vector("theta_offset", theta_offset, n)
        self._dh = np.ascontiguousarray(np.stack([self.a, self.alpha, self.offset, self.theta_offset], axis=1))

    @property
    def n(self) -> int:
        return len(self.pairs)

    def __repr__(self) -> str:
        return (f"AChain({self.pairs!r}, a={self.a.tolist()}, alpha={self.alpha.tolist()}, "
                f"offset={self.offset.tolist()}, theta_offset={self.theta_offset.tolist()})")

    def _q(self, q, name: str = "q") -> np.ndarray:
        q = V.real_array(name, q, trailing=(self.n,))
        return q

    def law(self, q) -> np.ndarray:
        """(..., n, 3): each joint's (d, d', d'') at q."""
        q = self._q(q)
        return np.stack([p.law(q[..., i], name=f"q[..., {i}]") for i, p in enumerate(self.pairs)], axis=-2)

    def _kernel(self, stem: str, q, law=None):
        q = self._q(q)
        return call(f"{stem}{self.n}", q, self._dh, self.law(q) if law is None else law)[0]

    def fk(self, q) -> np.ndarray:
        """(..., 4, 4): the pose of frame n in the base frame; q is (n,) or (..., n)."""
        return self._kernel("fk", q)

    def fk_study(self, q) -> np.ndarray:
        """(..., 8): the Study point (x0..x3, y0..y3) of fk(q), with |x| = 1; (x, y) ~ (−x, −y)."""
        return normalise(self._kernel("fk_study", q))

    def jacobian(self, q) -> np.ndarray:
        """(..., 6, n): geometric Jacobian, base frame, rows [v; ω] (v of the origin of frame n)."""
        law = self.law(q)
        if np.any(~np.isfinite(law)):
            raise ValueError("q: a joint is at its pair's limit, where d'(theta) is unbounded")
        return self._kernel("jacobian", q, law)
