"""The single-pose fast path of `ik` for the chains solved in closed form (apair._native.ClosedIK,
set up with the chain's solver): the same numbers as the validating path on spherical-wrist, UR
and 1∥2∥3 arms, UR designs with A-pairs at joint 3 or at joints 1 and 5 and spherical-wrist arms
with an A-pair at joint 3 or 1, and six R-pairs of no such family (the 6R elimination in one C
call, apair_ik6r; None where it does not certify), reachable and unreachable poses; whatever
it declines (other dtypes, NaN, a pose that is not rigid, a bad tol, full=True, frames) goes to the
validating path, which answers or raises as before; the NumPy backend keeps its twin; a chain
pickles after ik."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
import test_ik6r as general_arms
import test_ik_parallel as parallel_arms
import test_ik_parallel_apair as apair_arms
import test_ik_parallel_slides as slides_arms
import test_ik_three_parallel as three_parallel_arms
import test_ik_wrist as wrist_arms
import test_ik_wrist_apair as wrist_apair_arms
import test_ik_wrist_slide1 as wrist_slide1_arms

import apair
from apair.frames import frame
from apair.ik.poses import reach_of

PI = np.pi
pytestmark = pytest.mark.skipif(not apair.c_available(), reason="the compiled C kernels are not installed")


def arms():
    for mod in (wrist_arms, parallel_arms, three_parallel_arms):
        for name in mod.ARMS:
            yield name, mod.arm(name)
    for name in apair_arms.DESIGNS:  # an A-pair at joint 3 (apair_ik_closed_init_apair)
        yield f"{name} + A-pair at joint 3", apair_arms.chain_of(name)
    for name in slides_arms.DESIGNS:  # A-pairs at joints 1 and 5 (the same C entry)
        yield name, slides_arms.chain_of(name)
    for name in wrist_apair_arms.DESIGNS:  # a spherical wrist's A-pair at joint 3
        yield f"{name} + A-pair at joint 3", wrist_apair_arms.chain_of(name)
    for name in wrist_slide1_arms.DESIGNS:  # or at joint 1
        yield f"{name} + A-pair at joint 1", wrist_slide1_arms.chain_of(name)
    yield from general_arms.general_arms().items()  # the 6R elimination (ClosedIK's code 128)


@pytest.fixture(autouse=True)
def c_backend():
    apair.set_backend("c")
    yield
    apair.set_backend(None)


def test_same_numbers_as_the_validating_path():
    for name, chain in arms():
        rng = np.random.default_rng(4)
        chain.ik(chain.fk(np.zeros(6)))
        assert chain._ik_fast is not None, name
        for _ in range(100):
            T = chain.fk(rng.uniform(-PI, PI, 6))
            fast, full = chain.ik(T), chain._ik.solve(T)
            assert fast.shape == full.q.shape and np.array_equal(fast, full.q), name
        far = np.eye(4)
        far[:3, 3] = [2 * reach_of(chain) + 1.0, 0.0, 0.0]  # beyond the reach bound: the validating path answers
        assert chain.ik(far).shape == (0, 6) and chain._ik_fast.call(far, 1e-9) is None


@pytest.mark.parametrize("which", ["UR5", "random 6R #1"])
def test_declined_inputs_take_the_validating_path(which):
    chain = parallel_arms.arm("UR5") if which == "UR5" else general_arms.general_arms()[which]
    T = chain.fk(np.full(6, 0.3))
    expected = chain.ik(T)
    fast = chain._ik_fast
    assert fast.call(T, 1e-9) is not None
    assert fast.call(T.astype(np.float32), 1e-9) is None
    assert fast.call(np.asfortranarray(T), 1e-9) is None
    assert fast.call(T, 0) is None and fast.call(T, 1) is None  # an int tol: the validating path converts it
    # the same answers through the validating path
    assert np.allclose(chain.ik(T.tolist()), expected)
    assert len(chain.ik(T.astype(np.float32))) == len(expected)
    assert np.array_equal(chain.ik(T, full=True).q, expected)
    bad = T.copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="T"):
        chain.ik(bad)
    skew = T.copy()
    skew[:3, :3] *= 1.01
    assert fast.call(skew, 1e-9) is None
    with pytest.raises(ValueError, match="T: the rotation part"):
        chain.ik(skew)
    with pytest.raises(ValueError, match="tol"):
        chain.ik(T, tol=-1.0)
    with pytest.raises(ValueError, match="T"):
        chain.ik(np.eye(3))


def test_framed_chains_and_limits_take_the_validating_path():
    a, alpha, d = parallel_arms.ARMS["UR5"]
    framed = apair.AChain(
        [apair.APair.revolute()] * 6, a=a, alpha=alpha, offset=d, base=frame([0.1, 0.2, 0.3], [0.1, 0.2, 0.3])
    )
    q = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    sols = framed.ik(framed.fk(q))
    assert framed._ik_fast is None and parallel_arms.among(q, sols)
    chain = parallel_arms.arm("UR5")
    T = chain.fk(q)
    inside = chain.ik(T, within_limits=True)
    assert parallel_arms.among(q, inside)


def test_numpy_backend_keeps_its_twin_and_pickling():
    chain = wrist_arms.arm("PUMA560")
    T = chain.fk(np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8]))
    with_c = chain.ik(T)
    apair.set_backend("numpy")
    assert chain._ik_fast.call(T, 1e-9) is None  # disabled with the C backend
    twin = chain.ik(T)
    assert len(twin) == len(with_c) and np.allclose(twin, with_c, atol=1e-9)
    apair.set_backend("c")
    again = pickle.loads(pickle.dumps(chain))
    assert again._ik_fast is None and np.array_equal(again.ik(T), with_c)
