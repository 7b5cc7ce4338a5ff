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
