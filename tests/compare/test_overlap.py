"""The shared workspace: the shares reached by one alone against known bodies, the sections'
codes, and the default line inside what both reach."""

from __future__ import annotations

import numpy as np
import pytest

from apair.compare import overlap

RNG = np.random.default_rng(5)


def cube(lo, count=200_000):
    return RNG.uniform(lo, np.asarray(lo) + 1.0, (count, 3))


def test_shares_of_two_offset_cubes():
    """Unit cubes offset by half a side: each reaches a third of the union alone, a third both."""
    a, b = cube([0.0, 0.0, 0.0]), cube([0.5, 0.0, 0.0])
    h = 0.05
    origin = np.zeros(3) - 1e-9
    only_a, only_b, both = overlap.shares(overlap.voxels(a, origin, h), overlap.voxels(b, origin, h))
    assert (only_a, only_b, both) == (pytest.approx(1 / 3), pytest.approx(1 / 3), pytest.approx(1 / 3))


def test_shares_of_nested_balls():
    """A ball of radius 0.5 inside one of radius 1: the larger alone reaches 1 − 1/8 of the union."""

    def ball(r, count=300_000):
        p = RNG.normal(size=(count, 3))
        return r * p / np.linalg.norm(p, axis=1)[:, None] * RNG.uniform(0, 1, (count, 1)) ** (1 / 3)

    h = 0.08  # some 37 samples per voxel of the larger ball: none of its voxels left empty
    origin = np.full(3, -1.0 - h / 3)
    small, big = overlap.voxels(ball(0.5), origin, h), overlap.voxels(ball(1.0), origin, h)
    only_small, only_big, both = overlap.shares(small, big)
    assert only_small == 0
    assert only_big == pytest.approx(7 / 8, abs=0.05)  # voxels along the surfaces blur it by about h / r


def test_sections_code_who_reaches_each_voxel():
    a = {(0, 0, 0), (1, 0, 0)}
    b = {(1, 0, 0), (2, 0, 0)}
    (x_layer, _, x_image), (_, _, y_image), (z_layer, corner, z_image) = overlap.sections(a, b, np.zeros(3), 0.5)
    assert z_image[:, 0].tolist() == [1, 3, 2] and z_layer == 0.25 and corner.tolist() == [0.0, 0.0]
    assert x_layer == 0.75 and x_image.tolist() == [[3]]  # the middle layer in x: both reach it


def test_the_default_line_runs_through_the_shared_interior():
    a, b = cube([0.0, 0.0, 0.0]), cube([0.5, 0.0, 0.0])
    h, origin = 0.1, np.full(3, -1e-9)
    shared = overlap.voxels(a, origin, h) & overlap.voxels(b, origin, h)
    ends = overlap.line(shared, origin, h, np.random.default_rng(0))
    assert ends is not None
    s = np.linspace(0, 1, 1000)[:, None]
    on = ends[0] + s * (ends[1] - ends[0])
    assert np.all((on[:, 0] > 0.5 + h) & (on[:, 0] < 1.0 - h))  # one voxel inside both, at least
    assert np.all((on[:, 1:] > h) & (on[:, 1:] < 1.0 - h))
    assert np.linalg.norm(ends[1] - ends[0]) > 0.6  # the longest found, not any


def test_no_line_in_a_thin_shared_part():
    flat = {(i, j, 0) for i in range(10) for j in range(10)}
    assert overlap.line(flat, np.zeros(3), 0.1, np.random.default_rng(0)) is None
