"""Helpers shared by tests in several folders (imported by name: `from apair_test_helpers import
...`; a helper imported from `conftest` would resolve to whichever folder's conftest came first):
reference values of a derived spec in 40-digit arithmetic, and a generic 6R arm's chain file."""

from __future__ import annotations

import mpmath
import numpy as np
import sympy as sp


def evaluate_spec(spec, inputs: list[np.ndarray], digits: int = 40) -> list[np.ndarray]:
    """Reference values of a spec at a batch of points, step by step in `digits`-digit arithmetic.

    `inputs` carry a leading batch axis. Each step and output is lambdified on its own (small
    expressions) and evaluated in order on object arrays of mpmath numbers, so the reference
    follows the derivation and shares nothing with CSE, printers or templates.
    """
    count = len(inputs[0])
    spec = spec.flattened()  # the callees' steps inlined: the reference shares no generated code
    with mpmath.workdps(digits):
        env = {}
        for arg, x in zip(spec.inputs, inputs):
            flat = np.asarray(x, dtype=float).reshape(count, -1)
            for k, s in enumerate(arg.symbols):
                env[s] = np.array([mpmath.mpf(float(v)) for v in flat[:, k]], dtype=object)
        for sym, expr in spec.steps:
            env[sym] = _eval(expr, env, count)
        outs = []
        for a in spec.outputs:
            cols = [_eval(sp.S(e), env, count) for e in a.exprs]
            outs.append(np.array([[float(c[i]) for c in cols] for i in range(count)]).reshape((count,) + a.shape))
        return outs


def _vectorised(fn):
    return np.frompyfunc(fn, 1, 1)


_MODULE = {
    name: _vectorised(getattr(mpmath, name))
    for name in ("cos", "sin", "tan", "sqrt", "acos", "asin", "atan", "exp", "log")
}
_CACHE: dict = {}


def _eval(expr, env, count):
    syms = tuple(sorted(expr.free_symbols, key=str))
    key = (expr, syms)
    fn = _CACHE.get(key)
    if fn is None:
        fn = _CACHE[key] = sp.lambdify(syms, expr, modules=[_MODULE, "mpmath"])
    out = fn(*[env[s] for s in syms])
    if not isinstance(out, np.ndarray):
        out = np.full(count, mpmath.mpf(out), dtype=object)
    return out


def arm_toml(folder):
    """A 6R arm's chain file (generic geometry, twists in degrees) written into folder: its path."""
    path = folder / "arm.toml"
    joints = "\n".join(
        f'[[joint]]\npair = "revolute"\na = {a}\nalpha_deg = {al}\noffset = {c}\n'
        for a, al, c in [
            (0.1, 90, 0.3),
            (0.4, 10, 0.0),
            (0.05, 80, 0.02),
            (0.0, -70, 0.4),
            (0.02, 60, 0.0),
            (0.0, 20, 0.1),
        ]
    )
    path.write_text(f'name = "arm"\n{joints}')
    return path


def loop_rows(d):
    """The equality rows of MuJoCo's constraint data d (the loops, and helical couplings)."""
    import mujoco

    return d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY


def closed_loop_qacc(m, qpos, qvel, ctrl):
    """The accelerations of MuJoCo's model with its loops held exactly: M, qfrc_bias, the actuator
    forces and the equality rows' Jacobian J, with J̇q̇ by central differences; the redundant rows
    (six legs give one relation each) are handled by the null space of J."""
    import mujoco

    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:], d.ctrl[:] = qpos, qvel, ctrl
    mujoco.mj_forward(m, d)
    J = d.efc_J.reshape(d.nefc, m.nv)[loop_rows(d)].copy()
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    f = d.qfrc_actuator + d.qfrc_passive - d.qfrc_bias
    eps, Js = 1e-6, []
    for sign in (1, -1):
        e = mujoco.MjData(m)
        qp = np.array(qpos, float)
        mujoco.mj_integratePos(m, qp, qvel, sign * eps)
        e.qpos[:], e.qvel[:] = qp, qvel
        mujoco.mj_forward(m, e)
        Js.append(e.efc_J.reshape(e.nefc, m.nv)[loop_rows(e)].copy())
    Jdqd = (Js[0] - Js[1]) @ qvel / (2 * eps)
    _, S, Vt = np.linalg.svd(J)
    rank = int((S > 1e-9 * S[0]).sum())
    N = Vt[rank:].T
    particular = -np.linalg.pinv(J, rcond=1e-9) @ Jdqd
    z = np.linalg.solve(N.T @ M @ N, N.T @ (f - M @ particular))
    return particular + N @ z, rank
