"""The inverse-kinematics entry points of the C binding (apair._native.ik_*), all marshalled by one
table: each returns its outputs with the shapes and types its callers unpack, converts what it is
given as PyArg_ParseTuple would, and names the argument that has the wrong shape."""

from __future__ import annotations

import numpy as np
import pytest

from apair import kernels

native = kernels._native()[0]
pytestmark = pytest.mark.skipif(native is None, reason="the C kernels are not installed")

I32, F64, C128 = np.dtype(np.int32), np.dtype(float), np.dtype(complex)


def crandn(rng, *shape):
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


def problem(rng):
    """kind, pair, dh of a 6-joint problem: R-pairs and sinusoidal A-pairs."""
    kind = np.array([0, 1, 0, 1, 0, 0], np.int32)
    pair = np.where(kind[:, None] == 1, rng.uniform(0.05, 0.1, (6, 2)), np.zeros((6, 2)))
    return kind, pair, rng.uniform(-1, 1, (6, 4))


def calls(rng, k=3):
    """Valid arguments of every entry point, and the (dtype, shape) of each output."""
    kind, pair, dh = problem(rng)
    C, Q8 = rng.standard_normal((3, 3, 8)), rng.standard_normal((8, 8))
    f, g = rng.standard_normal((5, 5)), rng.standard_normal((5, 5))
    n = 3
    return {
        "ik_track": (
            (kind, pair, dh, crandn(rng, 7), crandn(rng, 7), 0.8 + 0.6j, crandn(rng, k, 6)),
            [(C128, (k, 6)), (I32, (k,)), (I32, (k,)), (F64, (k,))],
        ),
        "ik_track_slice": (
            (
                kind,
                pair,
                dh,
                crandn(rng, 7),
                crandn(rng, 7),
                crandn(rng, 2, 6),
                crandn(rng, 2, 6),
                0.2j,
                0.5,
                True,
                0.8 + 0.6j,
                crandn(rng, k, 7),
            ),
            [(C128, (k, 7)), (I32, (k,)), (I32, (k,)), (F64, (k,))],
        ),
        "ik6r_angles": (
            (
                crandn(rng, k),
                crandn(rng, k, 24),
                rng.standard_normal((14, 27)),
                rng.standard_normal((14, 8)),
                np.ones(3),
                dh,
                np.eye(4),
            ),
            (C128, (k, 6)),
        ),
        "ik_newton": (
            (kind, pair, dh, crandn(rng, 7), crandn(rng, k, 6), 5, 1e-12, 1e-9, 0.5, 50.0),
            [(C128, (k, 6)), (F64, (k,))],
        ),
        "ik_local": (
            (
                np.zeros(n, np.int32),
                np.zeros((n, 2)),
                rng.uniform(-1, 1, (n, 4)),
                np.full(n, -np.pi),
                np.full(n, np.pi),
                1.0,
                np.eye(4)[None],
                rng.uniform(-1, 1, (k, n)),
                1e-10,
                20,
            ),
            [(F64, (k, n)), (F64, (k,)), (I32, (k,))],
        ),
        "ik4_pencil": (
            (C, Q8, np.zeros(2, np.int32), Q8.T, np.zeros(2, np.int32), 1e300, 0, 1e-8),
            [(F64, (5, 5)), (F64, (5, 5)), (F64, (32, 32))],
        ),
        "ik4_screen": (
            (np.linspace(-1, 1, k), C, f, g, rng.standard_normal((2, 8, 8)), np.ones(8), np.array([1e-6, 1e-8, 1e-6])),
            [
                (I32, (k,)),
                (F64, (k,)),
                (F64, (k, 8)),
                (F64, (k,)),
                (F64, (k, 2, 2)),
                (I32, (k, 2)),
                (F64, (k, 2, 8)),
                (F64, (k, 2)),
            ],
        ),
        "ik4_left": (
            (
                rng.standard_normal((k, 8)),
                rng.standard_normal((3, 8, 8)),
                rng.standard_normal((3, 8)),
                np.array([1.0, 0.1, 0.0, 1.0]),
                np.array([1e-8, 1e-8, 1e-3, 1e-8]),
            ),
            [(I32, (k,)), (F64, (k,)), (F64, (k, 2)), (I32, (k, 2))],
        ),
    }


@pytest.mark.parametrize("k", [0, 1, 3])
def test_outputs_have_the_shapes_and_types_the_callers_unpack(k):
    for name, (args, want) in calls(np.random.default_rng(k), k).items():
        out = getattr(native, name)(*args)
        if isinstance(want, tuple):  # one output: the array itself
            assert isinstance(out, np.ndarray) and (out.dtype, out.shape) == want, name
            continue
        assert isinstance(out, tuple) and len(out) == len(want), name
        for x, (dtype, shape) in zip(out, want):
            assert x.dtype == dtype and x.shape == shape and x.flags.c_contiguous and x.flags.writeable, name


def test_inputs_are_converted_and_left_alone():
    """Lists, other dtypes, Fortran order and read-only arrays are accepted; theta (updated in place
    by apair_ik_newton) is copied first; the same numbers as from canonical arrays."""
    rng = np.random.default_rng(1)
    args, _ = calls(rng)["ik_newton"]
    dh32 = args[2].astype(np.float32)
    args = args[:2] + (dh32.astype(float),) + args[3:]
    theta = args[4].copy()
    ref = native.ik_newton(*args)
    assert np.array_equal(args[4], theta)
    ro = theta.copy()
    ro.flags.writeable = False
    other = (args[0].tolist(), np.asfortranarray(args[1]), dh32, args[3].tolist(), ro) + args[5:]
    again = native.ik_newton(*other)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(ref, again))
    local, _ = calls(rng)["ik_local"]
    one = native.ik_local(*local)
    shared = native.ik_local(*local[:6], np.repeat(local[6], 3, 0), *local[7:])  # one pose per seed
    assert all(np.array_equal(a, b) for a, b in zip(one, shared))


def test_optional_arguments_of_the_tracker():
    args, _ = calls(np.random.default_rng(2))["ik_track"]
    for extra in ((), (np.inf,), (np.inf, np.inf), (np.inf, np.inf, 0)):
        assert len(native.ik_track(*args, *extra)) == 4
    with pytest.raises(TypeError, match=r"function takes at most 10 arguments \(11 given\)"):
        native.ik_track(*args, 1.0, 1.0, 1, 1)
    with pytest.raises(TypeError, match=r"function takes at least 7 arguments \(6 given\)"):
        native.ik_track(*args[:6])


@pytest.mark.parametrize(
    "name, j, bad, error, message",
    [
        ("ik_newton", 4, np.zeros((2, 5), complex), ValueError, r"^theta: dimension 1 is 5, expected 6$"),
        ("ik_newton", 3, np.zeros((7, 1), complex), ValueError, r"^p: expected 1 dimensions$"),
        ("ik_newton", 0, np.zeros(6), TypeError, r"Cannot cast"),
        ("ik_newton", 5, 1.5, TypeError, r"cannot be interpreted as an integer"),
        ("ik_newton", 5, 2**40, OverflowError, r"^signed integer is greater than maximum$"),
        ("ik_newton", 6, "x", TypeError, r"^must be real number, not str$"),
        ("ik_track", 5, "x", TypeError, r"must be real number, not str"),
        ("ik_track", 0, np.zeros(5, np.int32), ValueError, r"^kind: dimension 0 is 5, expected 6$"),
        ("ik_local", 1, np.zeros((4, 2)), ValueError, r"^pair: dimension 0 is 4, expected 3$"),
        ("ik_local", 6, np.tile(np.eye(4), (2, 1, 1)), ValueError, r"^target: one pose, or one per seed$"),
        ("ik_local", 0, np.full(3, 7, np.int32), ValueError, r"^ik_local: the chain is not valid"),
        ("ik6r_angles", 1, np.zeros((2, 24), complex), ValueError, r"^vec: dimension 0 is 2, expected 3$"),
        ("ik4_pencil", 2, np.array([2, 0], np.int32), ValueError, r"^ik4_pencil: the factors leave an image constant"),
        ("ik4_screen", 5, np.ones(7), ValueError, r"^probe: dimension 0 is 7, expected 8$"),
        ("ik4_left", 1, np.zeros((1, 8, 8)), ValueError, r"^ik4_left: degrees out of range$"),
        ("ik4_left", 3, np.zeros(5), ValueError, r"^joint: dimension 0 is 5, expected 4$"),
    ],
)
def test_bad_arguments_are_named(name, j, bad, error, message):
    args, _ = calls(np.random.default_rng(3))[name]
    with pytest.raises(error, match=message):
        getattr(native, name)(*args[:j], bad, *args[j + 1 :])


def test_argument_counts_and_keywords_are_refused():
    for name, (args, _) in calls(np.random.default_rng(4)).items():
        with pytest.raises(
            TypeError,
            match=rf"function takes exactly {len(args)} arguments \(0 given\)"
            if name != "ik_track"
            else r"at least 7 arguments \(0 given\)",
        ):
            getattr(native, name)()
        with pytest.raises(TypeError, match="takes no keyword arguments"):
            getattr(native, name)(*args, x=1)


def test_ill_conditioned_pencil_is_none():
    args, _ = calls(np.random.default_rng(5))["ik4_pencil"]
    assert native.ik4_pencil(*args[:5], 0.0, *args[6:]) is None
