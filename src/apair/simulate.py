"""Time integration of a chain's equations of motion over the generated kernels."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _validate as V


@dataclass
class Trajectory:
    """States at the requested times: t (K,), q and qd (K, n), kinetic and potential energy (K,)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray

    @property
    def energy(self) -> np.ndarray:
        return self.kinetic + self.potential


def simulate(chain, q0, qd0, t, tau=None, *, rtol=1e-10, atol=1e-12, method="DOP853") -> Trajectory:
    from scipy.integrate import solve_ivp

    n = chain.n
    q0 = V.vector("q0", q0, n)
    qd0 = V.vector("qd0", qd0, n)
    t = V.real_array("t", t)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"t: expected at least two output times, got shape {t.shape}")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t: output times must increase strictly")
    V.scalar("rtol", rtol, positive=True)
    V.scalar("atol", atol, positive=True)
    if tau is None:
        torque = lambda _t, _q, _qd: np.zeros(n)
    elif callable(tau):
        def torque(tt, q, qd):
            out = V.real_array("tau", tau(tt, q, qd))
            if out.shape != (n,):
                raise ValueError(f"tau: the callable must return shape ({n},), got {out.shape}")
            return out
    else:
        const = V.vector("tau", tau, n)
        torque = lambda _t, _q, _qd: const

    def rhs(tt, y):
        q, qd = y[:n], y[n:]
        return np.concatenate([qd, chain.forward_dynamics(q, qd, torque(tt, q, qd))])

    sol = solve_ivp(rhs, (t[0], t[-1]), np.concatenate([q0, qd0]), method=method, t_eval=t, rtol=rtol, atol=atol)
    if not sol.success:
        raise ValueError(f"t: the integration failed: {sol.message}")
    q, qd = sol.y[:n].T, sol.y[n:].T
    E = chain.energy(q, qd)
    return Trajectory(t=sol.t, q=q, qd=qd, kinetic=E[:, 0], potential=E[:, 1])
