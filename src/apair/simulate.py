"""Time integration of a chain's equations of motion over the generated kernels.

Joint limits are events: with limits="stop" (the default) the integration ends where a joint
first reaches one of its hard limits (`AChain.hard_limits`: explicit, collision or range end),
located to the integrator's tolerance; the trajectory up to there is returned, the state at the
event as its last sample, and `Trajectory.stop` says which joint hit which limit when. With
limits="ignore" the joints pass through explicit and collision limits (the legs are taken to pass
through each other), and only the end of a general pair's range of motion (d = 0, where the motion
itself ends) stops the run.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _validate as V

if TYPE_CHECKING:
    from ._typing import ChainLike

# tau(t, q, qd) -> (n,): the torques as a function of the time and the state
Torque = Callable[[float, NDArray[np.float64], NDArray[np.float64]], ArrayLike]


@dataclass(frozen=True)
class LimitStop:
    """Where a run ended: joint (1-based) reached its `side` ("lower" or "upper") limit `value`
    [rad] at time t [s]."""

    joint: int
    side: str
    value: float
    t: float

    def __str__(self) -> str:
        return f"joint {self.joint} reached its {self.side} limit {self.value:.6g} rad at t = {self.t:.6g} s"


@dataclass
class Trajectory:
    """States at the requested times: t (K,), q and qd (K, n), kinetic and potential energy (K,)."""

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    kinetic: NDArray[np.float64]
    potential: NDArray[np.float64]
    stop: LimitStop | None = None  # the joint limit that ended the run, None if it ran to t[-1]

    @property
    def energy(self) -> NDArray[np.float64]:
        return self.kinetic + self.potential


def simulate(
    chain: ChainLike,
    q0: ArrayLike,
    qd0: ArrayLike,
    t: ArrayLike,
    tau: ArrayLike | Torque | None = None,
    *,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    method: str = "DOP853",
    limits: str = "stop",
) -> Trajectory:
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
    if not isinstance(limits, str) or limits not in ("stop", "ignore"):
        raise ValueError(f"limits: expected 'stop' or 'ignore', got {V.shorten(repr(limits))}")
    bounds = _bounds(chain, limits)
    for i, (lo, hi) in enumerate(bounds):
        if not lo <= q0[i] <= hi:
            raise ValueError(
                f"q0: joint {i + 1} at {q0[i]:.6g} rad is outside its limits ({lo:.6g}, {hi:.6g}) rad"
                + (" (limits='ignore' passes explicit and collision limits)" if limits == "stop" else "")
            )
    torque: Torque
    if tau is None:
        torque = lambda _t, _q, _qd: np.zeros(n)
    elif callable(tau):
        given = tau

        def checked(tt: float, q: NDArray[np.float64], qd: NDArray[np.float64]) -> NDArray[np.float64]:
            out = V.real_array("tau", given(tt, q, qd))
            if out.shape != (n,):
                raise ValueError(f"tau: the callable must return shape ({n},), got {out.shape}")
            return out

        torque = checked
    else:
        const = V.vector("tau", tau, n)
        torque = lambda _t, _q, _qd: const
    # a trial stage of the integrator may look past a range end before the event is located:
    # the law is evaluated just inside it there (the stage is then rejected or the event found)
    inside = bounds.copy()
    ends = [i for i, p in enumerate(chain.pairs) if p.theta_limit is not None]
    for i in ends:
        lim = cast(float, chain.pairs[i].theta_limit) * (1 - 1e-9)  # ends: the pairs with a limit
        inside[i] = max(inside[i, 0], -lim), min(inside[i, 1], lim)

    def rhs(tt: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        q, qd = y[:n], y[n:]
        if ends:
            q = q.copy()
            q[ends] = np.clip(q[ends], inside[ends, 0], inside[ends, 1])
        return np.concatenate([qd, chain.forward_dynamics(q, qd, torque(tt, y[:n], qd))])

    events: list[_LimitEvent] = []
    which: list[tuple[int, str, float]] = []
    for i, (lo, hi) in enumerate(inside):
        for side, value, sign in (("lower", lo, 1.0), ("upper", hi, -1.0)):
            if np.isfinite(value):
                events.append(_LimitEvent(i, value, sign))
                which.append((i, side, bounds[i, 0 if side == "lower" else 1]))
    sol = solve_ivp(
        rhs,
        (t[0], t[-1]),
        np.concatenate([q0, qd0]),
        method=method,
        t_eval=t,
        rtol=rtol,
        atol=atol,
        events=events or None,
    )
    if sol.status == -1:
        raise ValueError(f"t: the integration failed: {sol.message}")
    times, Y, stop = sol.t, sol.y, None
    if sol.status == 1:  # a limit event ended the run: its state is the last sample
        k = next(k for k, te in enumerate(sol.t_events) if len(te))
        i, side, value = which[k]
        te, ye = sol.t_events[k][0], sol.y_events[k][0]
        stop = LimitStop(i + 1, side, float(value), float(te))
        keep = times < te
        times, Y = np.append(times[keep], te), np.concatenate([Y[:, keep], ye[:, None]], axis=1)
    q, qd = Y[:n].T, Y[n:].T
    E = chain.energy(np.clip(q, inside[:, 0], inside[:, 1]) if ends else q, qd)
    return Trajectory(t=times, q=q, qd=qd, kinetic=E[:, 0], potential=E[:, 1], stop=stop)


class _LimitEvent:
    """solve_ivp's event of joint i reaching `value` from inside (sign: +1 the lower limit, −1 the
    upper one): terminal, in the falling direction."""

    terminal = True
    direction = -1

    def __init__(self, i: int, value: float, sign: float) -> None:
        self.i, self.value, self.sign = i, value, sign

    def __call__(self, _t: float, y: NDArray[np.float64]) -> float:
        return self.sign * (y[self.i] - self.value)


def _bounds(chain: ChainLike, limits: str) -> NDArray[np.float64]:
    """(n, 2) the limits that stop a run: all hard limits, or only the range ends of general pairs."""
    if limits == "stop":
        return chain.hard_limits()
    out = np.tile([-np.inf, np.inf], (chain.n, 1))
    for i, p in enumerate(chain.pairs):
        if p.theta_limit is not None:
            out[i] = -p.theta_limit, p.theta_limit
    return out
