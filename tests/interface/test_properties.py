"""Property-based test of the public API's input validation (hypothesis, bounded in time).

For arbitrary input (floats of any size, NaN and infinity, integers, booleans, complex numbers,
strings, None, ragged and deep nestings, arrays of other dtypes, byte orders and shapes) every
public entry point either returns finite results of the promised shape or raises a ValueError whose
message starts with the name of an argument it was given. Nothing else escapes: no TypeError,
OverflowError, RuntimeError or IndexError, and no silently wrong answer.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import apair

SETTINGS = settings(
    max_examples=60,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(-1.0, 1.0),
    st.floats(1e-200, 1e200),
    st.integers(-(10**30), 10**30),
    st.booleans(),
    st.complex_numbers(max_magnitude=10),
    st.none(),
    st.text(max_size=3),
    st.just(np.float32(0.5)),
    st.just(np.int8(3)),
)


@st.composite
def arrays(draw, shape=None):
    """Arrays of many dtypes, byte orders and shapes (or the given shape), values included."""
    if shape is None:
        shape = tuple(draw(st.lists(st.integers(0, 4), max_size=3)))
    dtype = draw(st.sampled_from(["<f8", ">f8", "<f4", "<i8", ">i4", "|b1", "<c16", "|u1"]))
    values = draw(
        st.lists(
            st.floats(-1e3, 1e3) | st.sampled_from([np.nan, np.inf, 0.0]),
            min_size=int(np.prod(shape)),
            max_size=int(np.prod(shape)),
        )
    )
    with np.errstate(all="ignore"):
        arr = np.array(values, dtype=float).reshape(shape).astype(dtype)
    if draw(st.booleans()) and arr.ndim >= 1 and arr.shape[-1] > 1:
        arr = arr[..., ::2]  # a strided view
    return arr


def values(shape=None):
    nested = st.recursive(scalars, lambda inner: st.lists(inner, max_size=4), max_leaves=12)
    return st.one_of(scalars, nested, arrays(shape), arrays())


def _names_an_argument(exc: ValueError, names) -> bool:
    head = str(exc).split(":", 1)[0]
    return any(re.fullmatch(rf"{re.escape(n)}(\[[^\]]*\])*", head) for n in names)


def bad(value) -> bool:
    """Whether a value can have no valid reading: complex, boolean, text, None or ragged, or a
    number that is NaN or infinite (np.asarray's reading; a mixed list such as [True, 1.0] is the
    numbers NumPy makes of it)."""
    try:
        with np.errstate(all="ignore"):
            arr = np.asarray(value)
    except (ValueError, TypeError, OverflowError, RecursionError):
        return True
    if arr.dtype.kind not in "iuf":
        return True
    with np.errstate(all="ignore"):
        return not np.isfinite(arr.astype(float)).all()


def check(call, names, result_check=None, must_fail=False):
    """call() returns a result that passes result_check, or raises a ValueError naming one of
    `names`; with must_fail (some input has no valid reading) it must raise."""
    try:
        out = call()
    except ValueError as exc:
        assert _names_an_argument(exc, names), f"{exc!r} names none of {names}"
        return
    assert not must_fail, "an input with no valid reading was accepted"
    if result_check is not None:
        result_check(out)


def finite(out):
    arr = np.asarray(out, dtype=float)
    assert np.isfinite(arr).all()


CHAIN = apair.AChain(
    [apair.APair(0.05, 0.04), apair.APair.revolute(), apair.APair(0.05, 0.04, leg_length=0.06)],
    [0.3, 0.2, 0.1],
    [np.pi / 2, 0.0, 0.0],
    links=[apair.Link(1.0, [0.1, 0, 0], np.eye(3) * 0.01) for _ in range(3)],
)


@SETTINGS
@given(
    r_b=values(()),
    r_p=values(()),
    leg_length=st.one_of(st.none(), values(())),
    leg_radius=values(()),
    thickness=values(()),
)
@pytest.mark.slow
def test_apair_constructor(r_b, r_p, leg_length, leg_radius, thickness):
    def make():
        p = apair.APair(r_b, r_p, leg_length=leg_length, leg_radius=leg_radius, thickness=thickness)
        assert np.isfinite([p.amplitude, *p.leg_lengths, p.a, p.b]).all()
        assert np.isfinite(p.translation(0.0))
        return p

    check(
        make,
        ["base_radius", "platform_radius", "leg_length", "leg_radius", "thickness"],
        must_fail=any(bad(v) for v in (r_b, r_p, leg_radius, thickness))
        or (leg_length is not None and bad(leg_length)),
    )


@SETTINGS
@given(a=values((3,)), alpha=values((3,)), offset=values((3,)), gravity=values((3,)))
def test_achain_constructor(a, alpha, offset, gravity):
    pairs = [apair.APair.revolute()] * 3
    check(
        lambda: apair.AChain(pairs, a, alpha, offset=offset, gravity=gravity).fk(np.zeros(3)),
        ["a", "alpha", "offset", "gravity"],
        finite,
        must_fail=any(bad(v) for v in (a, alpha, offset, gravity)),
    )


@SETTINGS
@given(mass=values(()), com=values((3,)), inertia=values((3, 3)))
def test_link_constructor(mass, com, inertia):
    check(
        lambda: apair.Link(mass, com, inertia).as_row(),
        ["mass", "com", "inertia"],
        finite,
        must_fail=any(bad(v) for v in (mass, com, inertia)),
    )


@SETTINGS
@given(q=values())
@pytest.mark.parametrize(
    "method, shape",
    [("fk", (4, 4)), ("fk_study", (8,)), ("jacobian", (6, 3)), ("mass_matrix", (3, 3)), ("gravity_torques", (3,))],
)
def test_chain_methods_of_q(method, shape, q):
    def result(out):
        finite(out)
        assert out.shape[out.ndim - len(shape) :] == shape

    check(lambda: getattr(CHAIN, method)(q), ["q", "q[..., 2]"], result, must_fail=bad(q))


@SETTINGS
@given(q=values((3,)), qd=values(), tau=values())
def test_forward_dynamics(q, qd, tau):
    check(
        lambda: CHAIN.forward_dynamics(q, qd, tau),
        ["q", "qd", "tau", "q[..., 2]", "links"],
        finite,
        must_fail=any(bad(v) for v in (q, qd, tau)),
    )


@SETTINGS
@given(T=values())
def test_ik_pose(T):
    chain = apair.AChain([apair.APair(0.05, 0.04), apair.APair.revolute()], [0.3, 0.2], [np.pi / 2, 0.0])
    check(lambda: chain.ik(T), ["T"], lambda q: finite(q) if len(q) else None, must_fail=bad(T))


@SETTINGS
@given(samples=scalars, resolution=scalars, rounds=scalars)
def test_workspace_arguments(samples, resolution, rounds):
    chain = apair.AChain([apair.APair.revolute()], [0.3], [0.0])

    def run():
        if isinstance(samples, (int, float)) and not isinstance(samples, bool) and abs(samples) > 50_000:
            return None  # valid but slow: not this test's business
        return chain.workspace(samples=samples, resolution=resolution, rounds=rounds)

    check(run, ["samples", "resolution", "rounds"])


@SETTINGS
@given(path=st.one_of(st.none(), st.integers(), st.text(max_size=8), st.just("/"), st.just("/dev/null")))
def test_load_path(path):
    check(lambda: apair.load(path), ["path"])


@SETTINGS
@given(
    data=st.dictionaries(
        st.sampled_from(
            [
                "pair",
                "a",
                "alpha",
                "alpha_deg",
                "base_radius",
                "platform_radius",
                "leg_length",
                "limits",
                "limits_deg",
                "mass",
                "com",
                "inertia",
                "x",
            ]
        ),
        values(),
        max_size=8,
    )
)
def test_chain_file_tables(data):
    from apair.io import chain_from_dict

    table = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in data.items()}
    check(lambda: chain_from_dict({"joint": [table]}, where="f"), ["f"])
