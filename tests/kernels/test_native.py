"""The C binding (apair._native): the fast path, the converting path and the batch forms all give
the same numbers as single calls and as the NumPy kernels, and bad calls name what is wrong."""

from __future__ import annotations

import numpy as np
import pytest

from apair import kernels
from apair.generated.numpy import KERNELS as NUMPY_KERNELS

pytestmark = pytest.mark.skipif(not kernels.c_available(), reason="the C kernels are not installed")


def random_inputs(name: str, rng, batch=()):
    """Random inputs; the chain kernels get law values of real angles and bodies with mass."""
    spec = kernels.manifest()["kernels"][name]["inputs"]
    out = [rng.uniform(-1, 1, batch + tuple(a["shape"])) for a in spec]
    for x, a in zip(out, spec):
        if a["name"] == "law" and a["shape"][-1] == 5:
            half = rng.uniform(-np.pi, np.pi, x.shape[:-1])
            x[..., 0], x[..., 1] = np.cos(half), np.sin(half)
        if a["name"] == "links":
            x[..., 0] = rng.uniform(0.5, 2.0, x.shape[:-1])
            x[..., 4:7] = rng.uniform(0.5, 1.0, x.shape[:-1] + (3,))
            x[..., 7:10] *= 0.05
        if a["name"] == "legs":
            x[..., 0] = rng.uniform(0.0, 0.1, x.shape[:-1])
            x[..., 1:] = rng.uniform(0.02, 0.1, x.shape[:-1] + (2,))
    return out


def test_registry_holds_every_kernel_of_the_manifest():
    native = kernels._native()[0]
    assert sorted(native.names()) == sorted(kernels.manifest()["kernels"])
    assert native.content_hash == kernels.manifest()["content_hash"]


@pytest.mark.parametrize(
    "name",
    ["fk6", "jacobian4", "mass_matrix3", "inverse_dynamics6", "coriolis2", "pair_legs", "forward_dynamics4", "energy2"],
)
def test_batch_with_shared_or_per_item_design_equals_single_calls(name):
    """Shared design inputs (stride 0) take the hoisted path; per-item ones the plain one."""
    rng = np.random.default_rng(1)
    spec = kernels.manifest()["kernels"][name]["inputs"]
    per_item = random_inputs(name, rng, (7,))
    shared = [x if a["name"] in ("theta", "qd", "qdd", "tau", "law", "d") else x[0] for x, a in zip(per_item, spec)]
    for inputs in (per_item, shared):
        batched = kernels.call(name, *inputs)
        for k in range(7):
            one = kernels.call(name, *[x[k] if x.ndim > len(a["shape"]) else x for x, a in zip(inputs, spec)])
            for b, o in zip(batched, one):
                assert np.array_equal(b[k], o, equal_nan=True)  # the same operations in the same order
        reference = NUMPY_KERNELS[name](*inputs)
        reference = reference if isinstance(reference, tuple) else (reference,)
        for b, ref in zip(batched, reference):
            np.testing.assert_allclose(b, ref, rtol=1e-11, atol=1e-12)


def test_inputs_that_need_converting_or_broadcasting():
    rng = np.random.default_rng(2)
    law, dh = random_inputs("fk3", rng)
    ref = kernels.call("fk3", law, dh)[0]
    # lists, float32 and a strided view go through the converting path
    assert np.array_equal(kernels.call("fk3", law.tolist(), dh.tolist())[0], ref)
    wide = np.zeros((3, 8))
    wide[:, ::2] = dh
    assert np.array_equal(kernels.call("fk3", law, wide[:, ::2])[0], ref)
    assert kernels.call("fk3", law.astype(np.float32), dh)[0].shape == (4, 4)
    # different batch shapes broadcast against each other
    laws = rng.uniform(-1, 1, (5, 1, 3, 5))
    dhs = rng.uniform(-1, 1, (4, 3, 4))
    out = kernels.call("fk3", laws, dhs)[0]
    assert out.shape == (5, 4, 4, 4)
    assert np.array_equal(out[2, 3], kernels.call("fk3", laws[2, 0], dhs[3])[0])
    # an empty batch
    assert kernels.call("fk3", np.zeros((0, 3, 5)), dh)[0].shape == (0, 4, 4)


def test_bad_calls_name_the_problem():
    rng = np.random.default_rng(3)
    law, dh = random_inputs("fk3", rng)
    with pytest.raises(ValueError, match="fk3: input dh must end in shape"):
        kernels.call("fk3", law, dh[:2])
    with pytest.raises(TypeError, match="fk3: expected 2 inputs"):
        kernels.call("fk3", law)
    with pytest.raises(ValueError, match="no generated kernel called 'fk9'"):
        kernels.call("fk9", law, dh)
    with pytest.raises(ValueError, match="do not broadcast|shape mismatch|broadcast"):
        kernels.call("fk3", rng.uniform(size=(5, 3, 5)), rng.uniform(size=(4, 3, 4)))
