"""Shared fixtures: the symbolic kernel specs (re-derived once per session) and their evaluation."""

from __future__ import annotations

import importlib

import pytest

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


# The files whose tests share the session's derivations (the fixture above, about two minutes):
# under pytest-xdist they go to one worker, so it is derived once.
SHARED_DERIVATIONS = {"tests/derivation/test_derivations.py", "tests/derivation/test_kernels_symbolic.py"}


def pytest_xdist_make_scheduler(config, log):
    """Under pytest-xdist (`make test` runs a worker per core) each file's tests stay on one worker, as with
    `--dist loadfile`: its module fixtures (some are C builds of a minute) are made once; and the two
    files of SHARED_DERIVATIONS share one worker. (xdist's `loadgroup` marks do not group under
    pytest 9.)"""
    from xdist.scheduler import LoadFileScheduling

    class Scheduling(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = super()._split_scope(nodeid)
            return "derivations" if path in SHARED_DERIVATIONS else path

    return Scheduling(config, log)
