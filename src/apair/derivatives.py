"""Derivatives of a chain's dynamics in its state (AChain.inverse_dynamics_derivatives,
AChain.forward_dynamics_derivatives), from the generated kernels of
derivations/chain_dynamics_derivatives.py: reverse-mode derivatives of the recursions' steps,
exact up to rounding (no finite differences); and the Jacobian's time derivative
(AChain.jacobian_dot, the kernels jacobian_dot<n> of derivations/chain_kinematics.py).

The kernels take the joints' law values as every chain kernel does, and d'''(θ) per joint from
each pair's law_<kind>_d3 kernel (the law's third derivative, which only ∂τ/∂θ needs). Inputs are
validated, snapped and broadcast as for AChain.inverse_dynamics; gravity is the chain's (in the
world, as the kernels take it in frame 0).

Single calls with canonical inputs (float64 arrays of one shape, inside the ranges) take the chain's
native fast path (apair.kernels.native_chain), which forms the law values and d3 of the laws
and runs the kernels in one C call: the ∂ID kernel with the mass_matrix kernel (`KERNELS_OF`), the
∂FD kernel alone (None where M is not positive definite: then the validating path says so).
"""

from __future__ import annotations

from typing import Any, Protocol, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .kernels import FastPath, call

Triple = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
# AChain's methods (apair.chain.METHODS) that the fast path computes with several kernels on the
# same inputs, their outputs in this order: (∂τ/∂θ, ∂τ/∂θ') and M
KERNELS_OF = {"inverse_dynamics_derivatives": ("inverse_dynamics_derivatives", "mass_matrix")}


def kernels_of(family: str) -> tuple[str, ...]:
    """The kernel families of a method of AChain's fast path (`KERNELS_OF`, else the family)."""
    return KERNELS_OF.get(family, (family,))


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
    @property
    def _fast(self) -> FastPath: ...

    def _state(self, q: ArrayLike, strict: bool = ..., **named: ArrayLike) -> list[NDArray[np.float64]]: ...
    def _law(self, q: NDArray[np.float64]) -> NDArray[np.float64]: ...
    def _kernel(self, family: str) -> str: ...


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


def _fast(chain: DynamicsChain, method: int, *args: Any) -> Any:
    """The fast path's outputs (a tuple of arrays for several), or None (validate first)."""
    return chain._fast.call(method, *args)


def inverse_dynamics_derivatives(
    chain: DynamicsChain, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, method: int = -1
) -> Triple:
    """(∂τ/∂θ, ∂τ/∂θ', ∂τ/∂θ'' = M), each (..., n, n) with [..., i, k] = ∂τ_i/∂x_k; `method`: its
    index in the chain's fast path (-1: none)."""
    out: Any = chain._fast.call(method, q, qd, qdd) if method >= 0 else None
    if out is not None:
        return out
    q_, qd_, qdd_ = chain._state(q, qd=qd, qdd=qdd)
    out = _fast(chain, method, q_, qd_, qdd_) if method >= 0 else None
    if out is not None:
        return out
    law, dddd = _law(chain, q_)
    body = chain._body
    dq, dqd = call(chain._kernel("inverse_dynamics_derivatives"), law, dddd, qd_, qdd_, *body)
    M = call(chain._kernel("mass_matrix"), law, *body[:4])[0]  # dh, turning, links, legs
    return dq, dqd, M


def forward_dynamics_derivatives(
    chain: DynamicsChain, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, method: int = -1
) -> Triple:
    """(∂θ''/∂θ, ∂θ''/∂θ', ∂θ''/∂τ = M⁻¹), each (..., n, n) with [..., i, k] = ∂θ''_i/∂x_k, at
    θ'' = forward_dynamics(q, qd, tau); `method`: its index in the chain's fast path (-1: none)."""
    out: Any = chain._fast.call(method, q, qd, tau) if method >= 0 else None
    if out is not None:
        return out
    q_, qd_, tau_ = chain._state(q, qd=qd, tau=tau)
    out = _fast(chain, method, q_, qd_, tau_) if method >= 0 else None
    if out is None:  # the generic kernels (NaN where M is not positive definite)
        law, dddd = _law(chain, q_)
        out = call(chain._kernel("forward_dynamics_derivatives"), law, dddd, qd_, tau_, *chain._body)
    if not all(np.isfinite(x).all() for x in out):
        raise ValueError(
            "links: the mass matrix is not positive definite at this q (give every moving body mass and inertia)"
        )
    return out[0], out[1], out[2]


def jacobian_dot(chain: DynamicsChain, q: ArrayLike, qd: ArrayLike, method: int = -1) -> NDArray[np.float64]:
    """(..., 6, n): dJ/dt of chain.jacobian(q) moving at qd (world frame, rows [v; ω] of the tool's
    origin); `method`: its index in the chain's fast path (-1: none), whose fk (0) and jacobian (2)
    give frame n and its Jacobian in frame 0. With a tool offset p, J's rows [v + ω × r; ω]
    (r = R_n p) change by ω̇ × r + ω × ṙ, ṙ = ω_n × r, ω_n = J_ω q'; the base rotates both blocks."""
    out: Any = chain._fast.call(method, q, qd) if method >= 0 else None
    if out is None:
        q, qd = chain._state(q, qd=qd)
        out = _fast(chain, method, q, qd) if method >= 0 else None
    if out is None:
        law = chain._law(cast("NDArray[np.float64]", q))
        if not np.isfinite(law).all():
            raise ValueError("q: a joint is at its pair's limit, where d'(theta) is unbounded")
        out = call(f"jacobian_dot{chain.n}", law, qd, *chain._body[:2])[0]
    if not chain._framed:
        return cast("NDArray[np.float64]", out)
    return _framed_jacobian_dot(chain, out, np.asarray(q, dtype=np.float64), np.asarray(qd, dtype=np.float64))


def _framed_jacobian_dot(
    chain: DynamicsChain, out: NDArray[np.float64], q: NDArray[np.float64], qd: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The frame-0 dJ/dt `out` at a valid q (the fast path took it, or the validating path made it
    so) made the tool's in the world (see jacobian_dot)."""
    base, tool = chain.base, chain.tool
    dJv, dJw = out[..., :3, :], out[..., 3:, :]
    if tool[:3, 3].any():  # frame n in frame 0 and its Jacobian's ω rows, from the frame-0 kernels
        F, J0 = chain._fast.call(0, q), chain._fast.call(2, q)
        if F is None or J0 is None:
            law, body = chain._law(q), chain._body
            F, J0 = call(chain._kernel("fk"), law, body[0])[0], call(chain._kernel("jacobian"), law, *body[:2])[0]
        Sr = _skew(F[..., :3, :3] @ tool[:3, 3])
        Jw0 = J0[..., 3:, :]
        r_dot = -Sr @ (Jw0 @ qd[..., None])  # ω_n × r
        # ω × r per column is −[r]× ω: the columns of dJv gain −[r]× ω̇ − [ṙ]× ω
        dJv = dJv - Sr @ dJw - _skew(r_dot[..., 0]) @ Jw0
    Rb = base[:3, :3]
    return np.concatenate([Rb @ dJv, Rb @ dJw], axis=-2)


def _skew(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """(..., 3, 3): the cross-product matrices [v]× (so [v]× w = v × w) of v (..., 3)."""
    out = np.zeros(v.shape + (3,))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    return out
