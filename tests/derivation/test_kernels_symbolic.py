"""Layer 1: every generated kernel (C and NumPy) against its symbolic spec at random points."""

from __future__ import annotations

import zlib

import numpy as np
import pytest
from apair_test_helpers import evaluate_spec

from apair.kernels import call, manifest

# Every test here derives the kernels afresh (about a minute): the full suite only.
pytestmark = pytest.mark.slow

POINTS = 100


def random_inputs(spec, rng: np.random.Generator, count: int) -> list[np.ndarray]:
    """Inputs inside each kernel's domain (positive radii and lengths, a + b cos θ > 0)."""
    out = []
    for arg in spec.inputs:
        shape = (count,) + arg.shape
        if arg.name in ("radii", "leg_length", "h", "b", "legs"):
            x = rng.uniform(0.2, 2.0, shape)
        else:
            x = rng.uniform(-3.0, 3.0, shape)
        out.append(x)
    names = [a.name for a in spec.inputs]
    if "law" in names and spec.inputs[names.index("law")].shape[-1] == 5:
        # chain kernels: the law's half angles are those of an angle (the rotations are rotations)
        law = out[names.index("law")]
        half = rng.uniform(-np.pi, np.pi, law.shape[:-1])
        law[..., 0], law[..., 1] = np.cos(half), np.sin(half)
    if spec.name.startswith("ik_") and not spec.name.startswith(("ik_wrist", "ik_parallel", "ik_three_parallel")):
        # the homotopy's kernels at a complex angle θ, |Im θ| <= 1 (the closed forms take a real pose)
        dims = (count,) + spec.inputs[0].shape[: -2 if spec.name.startswith("ik_system") else -1]
        theta = rng.uniform(-np.pi, np.pi, dims) + 1j * rng.uniform(-1, 1, dims)
        if spec.name.startswith(("ik_law", "ik_residual")):  # they take v = exp(iθ/2)
            v = np.exp(0.5j * theta)
            out[0] = np.stack([v.real, v.imag], -1)
        else:
            h = rng.uniform(0.0, 0.3, theta.shape)
            vals = np.stack(
                [np.cos(theta / 2), np.sin(theta / 2), h * np.cos(theta / 2), -h / 2 * np.sin(theta / 2)], -1
            )
            out[0] = np.stack([vals.real, vals.imag], -1)
    if spec.name.startswith("forward_dynamics"):  # physical links: M is positive definite
        links = out[[a.name for a in spec.inputs].index("links")]
        links[..., 0] = rng.uniform(0.5, 3.0, links.shape[:-1])
        links[..., 1:4] = rng.uniform(-0.3, 0.3, links.shape[:-1] + (3,))
        links[..., 4:7] = rng.uniform(0.5, 2.0, links.shape[:-1] + (3,))
        links[..., 7:10] = rng.uniform(-0.05, 0.05, links.shape[:-1] + (3,))
    if spec.name.startswith("law_general"):  # a > -b cos θ, on both sides of a = b (its d''' kernel too)
        theta, a, b = out
        out[1] = np.abs(b) * rng.uniform(-0.9, 3.0, a.shape)
        lim = np.arccos(np.clip(-out[1] / b, -1, 1))
        out[0] = rng.uniform(-0.95, 0.95, theta.shape) * lim
    return out


def rel_error(got: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(got - ref)) / max(np.max(np.abs(ref)), 1e-300))


def test_manifest_lists_every_derived_kernel(derived):
    assert set(manifest()["kernels"]) == set(derived)
    for name, k in manifest()["kernels"].items():
        assert [a["name"] for a in k["inputs"]] == [a.name for a in derived[name].inputs]
        assert [tuple(a["shape"]) for a in k["outputs"]] == [a.shape for a in derived[name].outputs]


_REFERENCE: dict = {}


def reference(spec):
    """Random inputs of a kernel and its 40-digit reference values, shared by both backends."""
    if spec.name not in _REFERENCE:
        rng = np.random.default_rng(zlib.crc32(spec.name.encode()))
        inputs = random_inputs(spec, rng, POINTS)
        _REFERENCE[spec.name] = inputs, evaluate_spec(spec, inputs)
    return _REFERENCE[spec.name]


@pytest.mark.parametrize("name", sorted(manifest()["kernels"]))
def test_kernel_matches_symbolic(name, derived, backend):
    spec = derived[name]
    inputs, ref = reference(spec)
    batched = call(name, *inputs)  # one batched call
    worst = 0.0
    for k in range(POINTS):
        for got, want in zip(batched, ref):
            worst = max(worst, rel_error(got[k], want[k]))
        if k < 5:  # the single-call path too
            single = call(name, *[x[k] for x in inputs])
            for got, want in zip(single, ref):
                worst = max(worst, rel_error(got, want[k]))
    assert worst <= 1e-12, f"{name} ({backend}): relative error {worst:.3e}"


def test_batched_broadcasts_shared_inputs(backend):
    """A design shared by the whole batch (stride 0) gives the same as repeating it."""
    rng = np.random.default_rng(7)
    dh = rng.uniform(-1, 1, (3, 4))
    law = rng.uniform(-1, 1, (11, 3, 5))
    shared = call("fk3", law, dh)[0]
    repeated = call("fk3", law, np.broadcast_to(dh, (11, 3, 4)).copy())[0]
    np.testing.assert_array_equal(shared, repeated)
    grid = call("fk3", law.reshape(11, 1, 3, 5), dh)[0]
    assert grid.shape == (11, 1, 4, 4)
    np.testing.assert_array_equal(grid[:, 0], shared)
    # a composite kernel (forward dynamics calls the mass matrix and inverse dynamics kernels)
    chain_args = [rng.uniform(-1, 1, (11, 3)), rng.uniform(-1, 1, (11, 3))]
    links = np.tile([1.0, 0.1, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], (3, 1))
    legs, g = np.zeros((3, 3)), np.array([0.0, 0.0, -9.81])
    law[..., :2] = np.stack([np.cos(law[..., 0]), np.sin(law[..., 0])], axis=-1)
    turning = np.ones(3)
    shared = call("forward_dynamics3", law, *chain_args, dh, turning, links, legs, g)[0]
    repeated = call(
        "forward_dynamics3",
        law,
        *chain_args,
        *(np.broadcast_to(x, (11,) + x.shape).copy() for x in (dh, turning, links, legs, g)),
    )[0]
    np.testing.assert_array_equal(shared, repeated)


def test_non_contiguous_inputs(backend):
    """Strided views and Fortran-ordered arrays give the same results as contiguous copies."""
    rng = np.random.default_rng(11)
    big = rng.uniform(-3, 3, (20, 3, 10))
    law = big[:, :, ::2]  # a strided view, (20, 3, 5)
    dh = np.asfortranarray(rng.uniform(-1, 1, (3, 4)))
    turning = np.array([1.0, 9.0, 0.0, 9.0, 1.0])[::2]  # strided too: a slide in the middle
    got = call("jacobian3", law, dh, turning)[0]
    want = call("jacobian3", np.ascontiguousarray(law), np.ascontiguousarray(dh), np.ascontiguousarray(turning))[0]
    np.testing.assert_array_equal(got, want)
    assert got.shape == (20, 6, 3)
