"""A family at the base end of a six-joint R-chain (a spherical wrist at joints 1-3, axes 3, 4, 5
parallel, axes 4, 5, 6 parallel with 1 and 2 meeting) solved in closed form as the reversed chain's
(issue 42).

In standard DH, T⁻¹ = Π_{i=6..1} Rx(−α_i) Tx(−a_i) Tz(−c_i) Rz(−ψ_i) regroups into Tx(−a_6) Rx(−α_6)
times six DH joints run from the tool: reversed joint k (joint 7 − k of the chain) has ψ' = −ψ_{7−k},
c' = −c_{7−k}, a' = −a_{6−k}, α' = −α_{6−k} (a'_6 = α'_6 = 0), so θ' = −θ_{7−k} with φ' = −φ_{7−k}.
The reversed chain's frame-6 pose is T' = Tx(a_6) Rx(α_6) T⁻¹, and its family is a forward one
that apair.ik.wrist, apair.ik.parallel or apair.ik.three_parallel solves (apair.ik.families names
the chain's family after it; apair.ik.forms picks the form). `ReversedView` is the reversed chain
as those solvers read a chain (its DH constants, fk and Jacobian, from the chain's own); `Reversed`
maps a pose to it and its solutions back, and verifies them on the chain itself.
"""

from __future__ import annotations

import math
import re

import numpy as np
from numpy.typing import NDArray

from ..frames import dh_matrix, inverse
from ..kernels import native_in_use, native_module
from .closed import note
from .poses import refine

REVERSED = 4  # or'ed into the family's code (apair.h: APAIR_IK_REVERSED)


class ReversedView:
    """The six-joint chain `chain` run from its tool to its base (the module's docstring)."""

    def __init__(self, chain) -> None:
        a, alpha = np.asarray(chain.a, float), np.asarray(chain.alpha, float)
        self.chain = chain
        self.n = chain.n
        self.pairs = list(chain.pairs)[::-1]
        self.limits = [(-float(hi), -float(lo)) for lo, hi in list(chain.limits)[::-1]]
        self.a = -np.append(a[4::-1], 0.0)
        self.alpha = -np.append(alpha[4::-1], 0.0)
        self.offset = -np.asarray(chain.offset, float)[::-1]
        self.theta_offset = -np.asarray(chain.theta_offset, float)[::-1]
        self.front = dh_matrix(float(a[5]), float(alpha[5]), 0.0, 0.0)  # T' = front · T⁻¹

    @staticmethod
    def original(q: NDArray[np.float64]) -> NDArray[np.float64]:
        """The chain's joint values (..., 6) of the reversed chain's q: θ_{7−k} = −θ'_k."""
        return -np.asarray(q, float)[..., ::-1]

    def pose(self, Tm: NDArray[np.float64]) -> NDArray[np.float64]:
        """The reversed chain's frame-6 pose at the chain's frame-6 pose Tm."""
        return self.front @ inverse(Tm)

    def fk(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(..., 4, 4): front · fk(θ)⁻¹ at θ = original(q)."""
        T = self.chain.fk(self.original(q))
        R, p = T[..., :3, :3], T[..., :3, 3]
        out = np.zeros(T.shape)
        out[..., :3, :3] = self.front[:3, :3] @ np.swapaxes(R, -1, -2)
        out[..., :3, 3] = self.front[:3, 3] - np.einsum("ij,...kj,...k->...i", self.front[:3, :3], R, p)
        out[..., 3, 3] = 1.0
        return out

    def jacobian(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(..., 6, 6): the reversed chain's geometric Jacobian from the chain's J = [v; ω] at θ:
        T⁻¹'s origin moves with Rᵀ (ω × p − v) and turns with −Rᵀ ω (base frame coordinates, p, R
        of fk(θ)), front turns both, and ∂θ_{7−k}/∂θ'_k = −1."""
        theta = self.original(q)
        T, J = self.chain.fk(theta), self.chain.jacobian(theta)
        RT = self.front[:3, :3] @ np.swapaxes(T[..., :3, :3], -1, -2)  # (..., 3, 3)
        v, w = J[..., :3, :], J[..., 3:, :]
        p = np.broadcast_to(T[..., :3, 3, None], v.shape)
        out = np.concatenate([RT @ (v - np.cross(w, p, axis=-2)), RT @ w], axis=-2)
        return out[..., ::-1]


def _renumber(note: str) -> str:
    """A note of the reversed chain's solver in the chain's joint and axis numbers (k → 7 − k), a
    list of them ascending ("joints 2, 3, 4 and 6" → "joints 1, 3, 4 and 5")."""

    def ascending(m: re.Match[str]) -> str:
        ks = sorted(7 - int(k) for k in re.findall(r"[1-6]", m.group(0)))
        return str(ks[0]) if len(ks) == 1 else ", ".join(map(str, ks[:-1])) + f" and {ks[-1]}"

    return re.sub(r"\b[1-6](?:(?:, | and )[1-6])*\b", ascending, note)


class Reversed:
    """The closed form of a chain whose family sits at its base end: `inner`, the closed form of
    the reversed chain `view` (apair.ik.forms picks it), mapped."""

    def __init__(self, chain, scale: float, view: ReversedView, inner) -> None:
        self.chain, self.scale, self.view, self.inner = chain, scale, view, inner
        self.code = inner.code | REVERSED
        self.amplitude = None  # (every joint an R-pair)
        self.flags = inner.flags
        self.dh = np.column_stack([chain.a, chain.alpha, chain.offset, chain.theta_offset]).astype(np.float64)
        native, _ = native_module()
        try:  # the C form (apair_ik_closed with APAIR_IK_REVERSED), as ik's fast path calls it
            self.native = None if native is None else native.ClosedIK(self.code, self.dh, scale, math.inf)
        except ValueError:
            self.native = None

    def solve(self, Tm: NDArray[np.float64], tol: float) -> tuple[NDArray[np.float64], NDArray[np.float64], int, str]:
        """Every real solution (k, 6) at frame 6's pose Tm, verified to tol on the chain itself,
        their errors, the candidates examined and the note (the chain's joint numbers): in C where
        the C backend is in use, else the same steps here. The reversed chain's pose error differs
        from the chain's by the lever |p|/scale of a rotation error, so its solver checks to
        tol (2 + 2|p|/scale); the chain's check decides."""
        if self.native is not None and native_in_use() is not None:
            out = self.native.call(Tm, tol)  # None: a pose its C form declines (the steps below answer)
            if out is not None:
                q, err, candidates, flags = out
                return q, err, candidates, _renumber(note({why for bit, why in self.flags.items() if flags & bit}))
        lever = float(np.linalg.norm(Tm[:3, 3])) / self.scale
        q, _, candidates, text = self.inner.solve(self.view.pose(Tm), tol * (2 + 2 * lever))
        q, err = refine(self.chain, self.view.original(q), Tm, tol, self.scale)
        return q, err, candidates, _renumber(text)
