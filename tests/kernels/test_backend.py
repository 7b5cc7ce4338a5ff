"""Backend selection: C by default, NumPy on request, and a single notice when C is missing."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import apair
from apair import kernels


def test_c_is_the_default_when_installed(monkeypatch):
    monkeypatch.delenv("APAIR_BACKEND", raising=False)
    apair.set_backend(None)
    assert apair.c_available()
    assert apair.backend() == "c"


def test_environment_selects_numpy(monkeypatch):
    monkeypatch.setenv("APAIR_BACKEND", "numpy")
    apair.set_backend(None)  # the environment is read again
    try:
        assert apair.backend() == "numpy"
    finally:
        monkeypatch.delenv("APAIR_BACKEND")
        apair.set_backend(None)


def test_missing_library_falls_back_once(monkeypatch):
    monkeypatch.delenv("APAIR_BACKEND", raising=False)
    chain = apair.AChain([apair.APair(0.05, 0.04), apair.APair.revolute()], [0.3, 0.2], [np.pi / 2, 0.0])
    q = np.array([0.2, -0.4])
    with_c = chain.fk(q)
    monkeypatch.setattr(kernels, "_native", lambda: (None, "the compiled C kernels are gone (test)"))
    monkeypatch.setitem(kernels._state, "warned", False)
    monkeypatch.setitem(kernels._state, "resolved", None)
    chain = apair.AChain(chain.pairs, chain.a, chain.alpha)  # built without the C kernels: no fast path
    with pytest.warns(RuntimeWarning, match="using the NumPy kernels"):
        first = chain.fk(q)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        second = chain.jacobian(q)  # no second notice
    assert apair.backend() == "numpy"
    np.testing.assert_allclose(first, with_c, atol=1e-15)
    assert second.shape == (6, 2)
    with pytest.raises(ValueError, match="^backend: 'c' requested"):
        apair.set_backend("c")
