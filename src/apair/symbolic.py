"""A chain's equations as CasADi functions (`AChain.to_casadi`): SX expression graphs built from the
generated CasADi kernels (generated/casadi: the same lowered kernels as the C and NumPy ones, the
pair laws and legs included), so CasADi's derivatives, code generation and optimisers work through
them. CasADi is an optional dependency (pip install 'apair[casadi]').

The graphs are those of the generated kernels with the chain's design folded in as constants: what
the kernels compute inside a pair's range. A general pair near its range end (d' unbounded) or a
mass matrix that is not positive definite gives NaN, as the kernels do; the runtime's checks of q
(ranges, limits) are not part of a graph.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ._typing import ChainLike

FUNCTIONS = ("fk", "jacobian", "mass_matrix", "inverse_dynamics", "forward_dynamics")


def _casadi() -> tuple[Any, Any]:
    """(casadi, the generated kernels by name), or an ImportError that says how to get CasADi."""
    try:
        import casadi

        from .generated.casadi import KERNELS
    except ImportError as exc:  # pragma: no cover - the test extra has casadi
        raise ImportError(f"to_casadi needs CasADi: pip install 'apair[casadi]' ({exc})") from None
    return casadi, KERNELS


def to_casadi(chain: ChainLike) -> dict[str, Any]:
    """{name: casadi.Function} for fk(q) -> T (4×4, the tool in the world), jacobian(q) -> J (6×n,
    world frame, rows [v; ω] of the tool's origin), mass_matrix(q) -> M (n×n),
    inverse_dynamics(q, qd, qdd) -> tau and forward_dynamics(q, qd, tau) -> qdd (n each): the
    chain's methods of the same names, as SX graphs."""
    ca, K = _casadi()
    n = chain.n
    q, qd, qdd, tau = (ca.SX.sym(name, n) for name in ("q", "qd", "qdd", "tau"))
    law = []
    for i, p in enumerate(chain.pairs):
        kernel, params = p.law_kernel
        law += K[kernel](q[i], *([x] for x in params))[0]
    dh, turning, links, legs, gravity = (np.ascontiguousarray(x, float).ravel().tolist() for x in chain._body)

    def matrix(entries: list[Any], rows: int, cols: int) -> Any:
        return ca.reshape(ca.vertcat(*entries), cols, rows).T  # the kernels' row-major order

    of = lambda family: K[chain._kernel(family)]  # an R-chain's own where it has one
    T = matrix(of("fk")(law, dh)[0], 4, 4)
    J = matrix(of("jacobian")(law, dh, turning)[0], 6, n)
    T, J = _framed(ca, chain, T, J)
    M = matrix(of("mass_matrix")(law, dh, turning, links, legs)[0], n, n)
    tau_id = ca.vertcat(*of("inverse_dynamics")(law, qd, qdd, dh, turning, links, legs, gravity)[0])
    qdd_fd = ca.vertcat(*of("forward_dynamics")(law, qd, tau, dh, turning, links, legs, gravity)[0])
    return {
        "fk": ca.Function("fk", [q], [T], ["q"], ["T"]),
        "jacobian": ca.Function("jacobian", [q], [J], ["q"], ["J"]),
        "mass_matrix": ca.Function("mass_matrix", [q], [M], ["q"], ["M"]),
        "inverse_dynamics": ca.Function("inverse_dynamics", [q, qd, qdd], [tau_id], ["q", "qd", "qdd"], ["tau"]),
        "forward_dynamics": ca.Function("forward_dynamics", [q, qd, tau], [qdd_fd], ["q", "qd", "tau"], ["qdd"]),
    }


def _framed(ca: Any, chain: ChainLike, T: Any, J: Any) -> tuple[Any, Any]:
    """fk and the Jacobian of frame n in frame 0 (T, J) made the tool's in the world, as AChain
    composes them: base · T · tool, and [Rb (v + ω × r); Rb ω] with r = R_n · (the tool's offset)."""
    base, tool = np.asarray(chain.base, float), np.asarray(chain.tool, float)
    Jv, Jw = J[:3, :], J[3:, :]
    offset = tool[:3, 3]
    if offset.any():
        r = ca.mtimes(T[:3, :3], ca.DM(offset))
        Jv = Jv + ca.vertcat(
            Jw[1, :] * r[2] - Jw[2, :] * r[1], Jw[2, :] * r[0] - Jw[0, :] * r[2], Jw[0, :] * r[1] - Jw[1, :] * r[0]
        )
    Rb = ca.DM(base[:3, :3])
    return ca.mtimes(ca.mtimes(ca.DM(base), T), ca.DM(tool)), ca.vertcat(ca.mtimes(Rb, Jv), ca.mtimes(Rb, Jw))
