"""Derivatives of a chain's dynamics in its state (AChain.inverse_dynamics_derivatives,
AChain.forward_dynamics_derivatives), from the generated kernels of
derivations/chain_dynamics_derivatives.py: forward-mode derivatives of the recursions' steps,
exact up to rounding (no finite differences); and the Jacobian's time derivative
(AChain.jacobian_dot, the kernels jacobian_dot<n> of derivations/chain_kinematics.py).

The kernels take the joints' law values as every chain kernel does, and d'''(θ) per joint from
each pair's law_<kind>_d3 kernel (the law's third derivative, which only ∂τ/∂θ needs). Inputs are
validated, snapped and broadcast as for AChain.inverse_dynamics; gravity is the chain's (in the
world, as the kernels take it in frame 0).
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .kernels import call

Triple = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


class DynamicsChain(Protocol):
    """What is used of an `apair.AChain`: its validation and law values, as its dynamics use them."""

    @property
    def n(self) -> int: ...
    @property
    def _law_groups(self) -> list[tuple[str, NDArray[np.intp], list[NDArray[np.float64]]]]: ...
    @property
    def _body(self) -> tuple[NDArray[np.float64], ...]: ...
    @property
    def _framed(self) -> bool: ...
    @property
    def base(self) -> NDArray[np.float64]: ...
    @property
    def tool(self) -> NDArray[np.float64]: ...

    def _state(self, q: ArrayLike, strict: bool = ..., **named: ArrayLike) -> list[NDArray[np.float64]]: ...
    def _law(self, q: NDArray[np.float64]) -> NDArray[np.float64]: ...


def third_derivatives(chain: DynamicsChain, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """(..., n): d'''(θ_i) of each joint at a validated, snapped q (one call per law kernel)."""
    out = np.empty(q.shape)
    for kernel, idx, params in chain._law_groups:
        out[..., idx] = call(f"{kernel}_d3", q[..., idx, None], *params)[0][..., 0]
    return out


def _law(chain: DynamicsChain, q: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The law values (..., n, 5) and d''' (..., n) of a validated q, refused at a range end."""
    law, dddd = chain._law(q), third_derivatives(chain, q)
    if not (np.isfinite(law).all() and np.isfinite(dddd).all()):
        raise ValueError("q: a joint is at its pair's limit, where d'(theta) is unbounded")
    return law, dddd


def inverse_dynamics_derivatives(chain: DynamicsChain, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> Triple:
    """(∂τ/∂θ, ∂τ/∂θ', ∂τ/∂θ'' = M), each (..., n, n) with [..., i, k] = ∂τ_i/∂x_k."""
    q_, qd_, qdd_ = chain._state(q, qd=qd, qdd=qdd)
    law, dddd = _law(chain, q_)
    n, body = chain.n, chain._body
    dq, dqd = call(f"inverse_dynamics_derivatives{n}", law, dddd, qd_, qdd_, *body)
    M = call(f"mass_matrix{n}", law, *body[:4])[0]  # dh, turning, links, legs
    return dq, dqd, M


def forward_dynamics_derivatives(chain: DynamicsChain, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> Triple:
    """(∂θ''/∂θ, ∂θ''/∂θ', ∂θ''/∂τ = M⁻¹), each (..., n, n) with [..., i, k] = ∂θ''_i/∂x_k, at
    θ'' = forward_dynamics(q, qd, tau)."""
    q_, qd_, tau_ = chain._state(q, qd=qd, tau=tau)
    law, dddd = _law(chain, q_)
    out: list[Any] = call(f"forward_dynamics_derivatives{chain.n}", law, dddd, qd_, tau_, *chain._body)
    if not all(np.isfinite(x).all() for x in out):
        raise ValueError(
            "links: the mass matrix is not positive definite at this q (give every moving body mass and inertia)"
        )
    return out[0], out[1], out[2]


def jacobian_dot(chain: DynamicsChain, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
    """(..., 6, n): dJ/dt of chain.jacobian(q) moving at qd (world frame, rows [v; ω] of the tool's
    origin). With a tool offset p, J's rows [v + ω × r; ω] (r = R_n p) change by ω̇ × r + ω × ṙ,
    ṙ = ω_n × r, ω_n = J_ω q'; the base rotates both blocks."""
    q_, qd_ = chain._state(q, qd=qd)
    law = chain._law(q_)
    if not np.isfinite(law).all():
        raise ValueError("q: a joint is at its pair's limit, where d'(theta) is unbounded")
    body = chain._body
    out: NDArray[np.float64] = call(f"jacobian_dot{chain.n}", law, qd_, *body[:2])[0]
    if not chain._framed:
        return out
    base, tool = chain.base, chain.tool
    dJv, dJw = out[..., :3, :], out[..., 3:, :]
    if tool[:3, 3].any():  # frame n in frame 0 and its Jacobian's ω rows, from the frame-0 kernels
        r = call(f"fk{chain.n}", law, body[0])[0][..., :3, :3] @ tool[:3, 3]
        Jw0 = call(f"jacobian{chain.n}", law, *body[:2])[0][..., 3:, :]
        r_dot = np.cross(np.einsum("...ik,...k->...i", Jw0, qd_), r)
        dJv = dJv + np.cross(dJw, r[..., :, None], axis=-2) + np.cross(Jw0, r_dot[..., :, None], axis=-2)
    Rb = base[:3, :3]
    return np.concatenate([Rb @ dJv, Rb @ dJw], axis=-2)
