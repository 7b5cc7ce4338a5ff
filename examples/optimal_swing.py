"""Worked example: a minimum-effort swing of the 4A-chain (examples/4a_chain.toml), optimised with
CasADi through the chain's own equations (AChain.to_casadi).

From rest at q0 to rest at q1 in T = 1 s, inside the joint limits, |q'_i| ≤ QD_MAX and
|τ_i| ≤ TAU_MAX, minimising ∫ τᵀτ dt: CasADi Opti with IPOPT, multiple shooting over N intervals of
piecewise-constant torque, STEPS RK4 steps of `forward_dynamics` per interval (the light last link
needs them: with one step, IPOPT finds motions that only the coarse integrator believes). The torques are then replayed through
`chain.simulate` (adaptive Runge-Kutta over the generated C kernels), whose end state must match
the optimiser's, and q(t) and τ(t) are plotted.

    python examples/optimal_swing.py [OUT.png] [--force]      (needs pip install 'apair[casadi]')
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import apair

CHAIN = Path(__file__).resolve().parent / "4a_chain.toml"
T_END, N, STEPS = 1.0, 40, 4  # the motion's duration [s], the shooting intervals, RK4 steps in each
TAU_MAX = np.array([40.0, 40.0, 20.0, 5.0])  # the joints' torque limits [N m]
QD_MAX = 4.0  # the joints' speed limit [rad/s]
Q0 = np.array([0.0, 0.3, -0.6, 0.0])  # rest to rest [rad]
Q1 = np.array([1.2, 1.0, 0.4, -0.8])


def rk4(f, q, qd, tau, h):
    """One RK4 step of q'' = f(q, q', τ) with τ held."""
    k1q, k1v = qd, f(q, qd, tau)
    k2q, k2v = qd + h / 2 * k1v, f(q + h / 2 * k1q, qd + h / 2 * k1v, tau)
    k3q, k3v = qd + h / 2 * k2v, f(q + h / 2 * k2q, qd + h / 2 * k2v, tau)
    k4q, k4v = qd + h * k3v, f(q + h * k3q, qd + h * k3v, tau)
    return q + h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q), qd + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)


def optimise(chain: apair.AChain):
    """(t (N+1,), q (N+1, n), qd (N+1, n), tau (N, n), IPOPT's statistics) of the optimal swing."""
    import casadi as ca

    fd = chain.to_casadi()["forward_dynamics"]
    n, h = chain.n, T_END / N
    opti = ca.Opti()
    Q, V, U = opti.variable(n, N + 1), opti.variable(n, N + 1), opti.variable(n, N)
    opti.minimize(h * ca.sumsqr(U))
    for k in range(N):
        q_next, v_next = Q[:, k], V[:, k]
        for _ in range(STEPS):
            q_next, v_next = rk4(fd, q_next, v_next, U[:, k], h / STEPS)
        opti.subject_to(Q[:, k + 1] == q_next)
        opti.subject_to(V[:, k + 1] == v_next)
    lim = chain.limits
    for i in range(n):
        opti.subject_to(opti.bounded(lim[i, 0], Q[i, :], lim[i, 1]))
        opti.subject_to(opti.bounded(-TAU_MAX[i], U[i, :], TAU_MAX[i]))
    opti.subject_to(opti.bounded(-QD_MAX, V, QD_MAX))
    opti.subject_to(Q[:, 0] == Q0)
    opti.subject_to(V[:, 0] == 0)
    opti.subject_to(Q[:, N] == Q1)
    opti.subject_to(V[:, N] == 0)
    s = np.linspace(0, 1, N + 1)
    opti.set_initial(Q, (Q0[:, None] * (1 - s) + Q1[:, None] * s))
    opti.set_initial(U, np.tile(chain.gravity_torques(Q0)[:, None], (1, N)))
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes", "tol": 1e-10})
    sol = opti.solve()
    t = np.linspace(0, T_END, N + 1)
    return t, sol.value(Q).T, sol.value(V).T, np.atleast_2d(sol.value(U)).T, sol.stats()


def replay(chain: apair.AChain, t, tau):
    """The torques (zero-order hold) through chain.simulate: its state at the grid's times."""
    h = t[1] - t[0]
    held = lambda s, q, qd: tau[min(int(s / h + 1e-9), len(tau) - 1)]
    return chain.simulate(Q0, np.zeros(chain.n), t, tau=held, rtol=1e-11, atol=1e-13, limits="ignore")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default="optimal_swing.png", help="the plot to write (PNG)")
    ap.add_argument("--force", action="store_true", help="overwrite OUT if it exists")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if out.exists() and not args.force:
        print(f"{out} exists; give --force to overwrite it", file=sys.stderr)
        return 2
    chain = apair.load(CHAIN)
    start = time.perf_counter()
    t, q, qd, tau, stats = optimise(chain)
    seconds = time.perf_counter() - start
    effort = float(np.sum(tau**2) * (t[1] - t[0]))
    print(f"IPOPT: {stats['return_status']} after {stats['iter_count']} iterations, {seconds:.1f} s")
    print(f"effort ∫τᵀτ dt = {effort:.4g} N² m² s; largest torques {np.abs(tau).max(axis=0).round(2)} N m")
    run = replay(chain, t, tau)
    gap = float(np.abs(run.q[-1] - q[-1]).max())
    print(f"replayed through chain.simulate: end state within {gap:.2e} rad of the optimiser's")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for i in range(chain.n):
        line = ax1.plot(t, q[:, i], label=f"q{i + 1}")[0]
        ax1.plot(run.t, run.q[:, i], ":", color=line.get_color())
        ax2.step(t, np.append(tau[:, i], tau[-1, i]), where="post", label=f"τ{i + 1}")
    ax1.set(xlabel="t [s]", ylabel="q [rad]", title="joint angles (dotted: chain.simulate)")
    ax2.set(xlabel="t [s]", ylabel="τ [N m]", title="optimal torques")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Minimum-effort swing of the 4A-chain in 1 s (CasADi Opti + IPOPT on AChain.to_casadi)")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0 if stats["success"] and gap < 1e-4 else 1


if __name__ == "__main__":
    sys.exit(main())
