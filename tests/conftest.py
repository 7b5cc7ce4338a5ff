"""Shared fixtures: the symbolic kernel specs (re-derived once per session) and their evaluation."""

from __future__ import annotations

import importlib

import mpmath
import numpy as np
import pytest
import sympy as sp

import apair
from codegen.__main__ import DERIVATIONS


@pytest.fixture(scope="session", autouse=True)
def specialised_cache(tmp_path_factory):
    """Compiled specialised chains (AChain.specialise) go to a fresh folder, not the user's cache."""
    import os

    old = os.environ.get("APAIR_CACHE")
    os.environ["APAIR_CACHE"] = str(tmp_path_factory.mktemp("apair-cache"))
    yield
    if old is None:
        os.environ.pop("APAIR_CACHE", None)
    else:
        os.environ["APAIR_CACHE"] = old


@pytest.fixture(scope="session")
def derivations():
    """{module name: (polynomial sets, kernel specs, facts)}, derived afresh once per session."""
    return {name: importlib.import_module(f"derivations.{name}").derive() for name in DERIVATIONS}


@pytest.fixture(scope="session")
def derived(derivations):
    """{kernel name: KernelSpec} straight from the derivations (independent of generated/)."""
    return {k.name: k for _, ks, _ in derivations.values() for k in ks}


@pytest.fixture(params=["c", "numpy"])
def backend(request):
    """Run a test once per kernel backend."""
    if request.param == "c" and not apair.c_available():
        pytest.fail("the C library is not installed (make install)")
    apair.set_backend(request.param)
    yield request.param
    apair.set_backend(None)


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
