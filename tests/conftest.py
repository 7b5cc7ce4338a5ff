"""Shared fixtures: the symbolic kernel specs (re-derived once per session) and their evaluation."""
from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import apair
from derivations import apair_pair, chain_kinematics


@pytest.fixture(scope="session")
def derivations():
    """{module name: (polynomial sets, kernel specs, facts)}, derived afresh once per session."""
    return {mod.__name__.split(".")[-1]: mod.derive() for mod in (apair_pair, chain_kinematics)}


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
    """Reference values of a spec at one point, step by step in `digits`-digit arithmetic.

    Each step and output is lambdified on its own (small expressions) and evaluated in order, so
    the reference follows the derivation and shares nothing with CSE, printers or templates.
    """
    with mpmath.workdps(digits):
        env = {}
        for arg, x in zip(spec.inputs, inputs):
            for s, v in zip(arg.symbols, np.asarray(x, dtype=float).ravel()):
                env[s] = mpmath.mpf(float(v))
        for sym, expr in spec.steps:
            env[sym] = _eval(expr, env)
        return [np.array([float(_eval(sp.S(e), env)) for e in a.exprs]).reshape(a.shape) for a in spec.outputs]


_CACHE: dict = {}


def _eval(expr, env):
    syms = tuple(sorted(expr.free_symbols, key=str))
    key = (expr, syms)
    fn = _CACHE.get(key)
    if fn is None:
        fn = _CACHE[key] = sp.lambdify(syms, expr, modules="mpmath")
    return fn(*[env[s] for s in syms])
