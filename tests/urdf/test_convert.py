"""Hand-written URDFs covering every case of the DH conversion agree with Pinocchio."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from robots import J, check, compare, random_inertial, urdf, write

from apair import io
from apair.urdf import convert, frameless_chain, load_urdf, to_toml
from apair.urdf.parse import rpy_matrix


def _unit(v: np.ndarray) -> tuple[float, float, float]:
    u = v / np.linalg.norm(v)
    return (float(u[0]), float(u[1]), float(u[2]))


@pytest.mark.parametrize("seed", range(8))
def test_odd_axes_and_origins(tmp_path, seed: int) -> None:
    """Axes in random directions (negative components included) from random origins, full inertia
    tensors in rotated inertial frames: the general (skew) case."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 7))
    joints = [
        J(
            f"j{i}",
            "revolute",
            f"l{i}",
            f"l{i + 1}",
            tuple(rng.uniform(-0.3, 0.3, 3)),
            tuple(rng.uniform(-3, 3, 3)),
            _unit(rng.normal(size=3)),
        )
        for i in range(n)
    ]
    inertials = {f"l{i}": random_inertial(rng) for i in range(n + 1)}
    p = write(tmp_path, urdf("odd", "l0", joints, inertials))
    conv = convert(p, f"l{n}")
    assert conv.n == n and all(j.normal in ("skew", "last") for j in conv.joints)
    check(compare(p, f"l{n}", seed=seed))


def test_parallel_intersecting_coincident_negative(tmp_path) -> None:
    """Parallel axes (same and opposite sense), intersecting axes, two joints on one line, axes
    along -z and -y: each case's choice of frame, and the agreement."""
    s = math.sqrt(0.5)
    joints = [
        J("j1", "revolute", "b", "l1", (0.1, 0.2, 0.3), (0.3, 0.2, 0.1), (0.0, 0.0, -1.0)),
        J("j2", "revolute", "l1", "l2", (0.0, 0.0, 0.4), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),  # coincident with j1
        J("j3", "revolute", "l2", "l3", (0.3, 0.0, 0.1), (0.0, 0.0, 0.0), (0.0, 0.0, -1.0)),  # parallel, opposite
        J("j4", "revolute", "l3", "l4", (0.2, 0.1, 0.0), (0.0, 0.0, 0.0), (s, s, 0.0)),  # intersects? no: skew
        J(
            "j5", "continuous", "l4", "l5", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, -1.0, 0.0), limits=None
        ),  # intersects j4
        J("j6", "revolute", "l5", "l6", (0.0, 0.0, 0.15), (1.0, 0.0, 0.0), (0.0, -1.0, 0.0)),
    ]
    rng = np.random.default_rng(3)
    inertials = {f"l{i}": random_inertial(rng) for i in range(1, 7)}
    p = write(tmp_path, urdf("cases", "b", joints, inertials))
    conv = convert(p, "l6")
    normals = [j.normal for j in conv.joints]
    assert normals[0] == "coincident" and normals[1] == "parallel" and normals[3] == "intersecting"
    assert conv.joints[1].offset == 0.0 and conv.joints[1].alpha == pytest.approx(math.pi)
    assert conv.joints[3].a == 0.0
    assert conv.joints[4].limits is None and conv.joints[0].limits == (-2.5, 2.5)
    check(compare(p, "l6"))


def test_fixed_mid_chain_massless_and_branch(tmp_path) -> None:
    """A fixed joint mid-chain whose child has an inertial (merged into the link before it), a link
    without <inertial>, a branch off the path (a revolute joint, locked at 0 and merged) and a
    continuous joint with a negative axis."""
    rng = np.random.default_rng(7)
    joints = [
        J("j1", "continuous", "b", "l1", (0.0, 0.0, 0.1), (0.0, 0.0, 0.0), (0.0, 0.0, -1.0), limits=None),
        J("f1", "fixed", "l1", "m1", (0.1, 0.05, 0.2), (0.4, -0.2, 0.9), None, limits=None),
        J("j2", "revolute", "m1", "l2", (0.0, 0.1, 0.0), (1.5707963267948966, 0.0, 0.0), (0.0, 1.0, 0.0)),
        J("side", "revolute", "l2", "s1", (0.2, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
        J("j3", "revolute", "l2", "l3", (0.25, 0.0, 0.05), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
        J("f2", "fixed", "l3", "tip", (0.1, 0.0, 0.0), (0.0, 0.3, 0.0), None, limits=None),
    ]
    inertials = {
        "l1": random_inertial(rng),
        "m1": random_inertial(rng),
        "l2": None,
        "s1": random_inertial(rng),
        "l3": random_inertial(rng),
        "tip": random_inertial(rng),
    }
    p = write(tmp_path, urdf("merged", "b", joints, inertials))
    conv = convert(p, "tip")
    assert conv.n == 3
    assert conv.joints[0].body.links == ("l1", "m1") and conv.joints[1].fixed == ("f1",)
    assert set(conv.joints[1].body.links) == {"l2", "s1"} and conv.joints[1].body.massless == ("l2",)
    assert conv.joints[1].body.mass == pytest.approx(inertials["s1"].mass)
    assert set(conv.joints[2].body.links) == {"l3", "tip"} and conv.tip_fixed == ("f2",)
    check(compare(p, "tip"))
    check(compare(p, "l3", base="m1"))  # a base below the root: from link m1 on


def test_massless_chain_and_identity_frames(tmp_path) -> None:
    """A planar 2R arm along z without any <inertial>: the base is the identity, the tool a shift
    along x, the mass matrix zero, the limits the URDF's; the pose by hand."""
    joints = [
        J("j1", "revolute", "b", "l1", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (-1.0, 2.0)),
        J("j2", "revolute", "l1", "l2", (0.5, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (-2.0, 1.0)),
        J("f", "fixed", "l2", "tip", (0.4, 0.0, 0.0), (0.0, 0.0, 0.0), None, None),
    ]
    p = write(tmp_path, urdf("planar", "b", joints, {}))
    conv = convert(p, "tip")
    assert np.array_equal(conv.base, np.eye(4))
    chain = load_urdf(p, "tip")
    assert chain.a.tolist() == [0.5, 0.0] and chain.offset.tolist() == [0.0, 0.0]
    assert chain.limits.tolist() == [[-1.0, 2.0], [-2.0, 1.0]]
    assert np.array_equal(chain.mass_matrix([0.3, 0.2]), np.zeros((2, 2)))
    q = np.array([0.7, -1.1])
    assert np.array_equal(conv.tool, [[1, 0, 0, 0.4], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    T = chain.fk(q)
    assert T[:3, 3] == pytest.approx(
        [0.5 * math.cos(0.7) + 0.4 * math.cos(-0.4), 0.5 * math.sin(0.7) + 0.4 * math.sin(-0.4), 0.0], abs=1e-15
    )
    check(compare(p, "tip"))


def test_chain_file_round_trip(tmp_path) -> None:
    """The chain file's text: TOML whose [[joint]] tables io reads into the same chain, and whose
    [base] and [tool] rebuild the frames; limits beyond a turn in degrees."""
    rng = np.random.default_rng(11)
    joints = [
        J(
            f"j{i}",
            "revolute",
            f"l{i}",
            f"l{i + 1}",
            tuple(rng.uniform(-0.3, 0.3, 3)),
            tuple(rng.uniform(-3, 3, 3)),
            _unit(rng.normal(size=3)),
            (-7.0, 6.5) if i == 0 else (-1.0, 1.0),
        )
        for i in range(4)
    ]
    p = write(tmp_path, urdf("odd", "l0", joints, {f"l{i}": random_inertial(rng) for i in range(5)}))
    conv = convert(p, "l4")
    doc = tomllib.loads(to_toml(p, "l4"))
    assert doc["joint"][0]["limits_deg"] == [math.degrees(-7.0), math.degrees(6.5)] and doc["joint"][1]["limits"] == [
        -1.0,
        1.0,
    ]
    for key, T in (("base", conv.base), ("tool", conv.tool)):
        R = rpy_matrix(doc[key]["rpy"])
        assert np.abs(R - T[:3, :3]).max() < 1e-15 and doc[key]["xyz"] == T[:3, 3].tolist()
    frames = {k: doc.pop(k) for k in ("base", "tool")}
    assert frames
    file_chain = io.chain_from_dict(doc)
    ref = frameless_chain(conv)
    q = rng.uniform(-1, 1, 4)
    assert np.array_equal(file_chain.fk(q), ref.fk(q))  # the values written are the values used
    assert np.abs(file_chain.mass_matrix(q) - ref.mass_matrix(q)).max() < 1e-15
    assert file_chain.hard_limits()[0] == pytest.approx([-7.0, 6.5], abs=1e-15)


def test_apair_replaces_a_joint(tmp_path) -> None:
    joints = [
        J(f"j{i}", "revolute", f"l{i}", f"l{i + 1}", (0.0, 0.0, 0.2), (0.0, 1.0 * i, 0.0), (0.0, 0.0, 1.0), (-1.0, 1.0))
        for i in range(3)
    ]
    p = write(tmp_path, urdf("r3", "l0", joints, {}))
    pairs = {2: {"pair": "sinusoidal", "base_radius": 0.06, "platform_radius": 0.05}}
    doc = tomllib.loads(to_toml(p, "l3", pairs=pairs))
    assert doc["joint"][1]["pair"] == "sinusoidal" and doc["joint"][1]["base_radius"] == 0.06
    assert doc["joint"][1]["limits"] == [-1.0, 1.0] and doc["joint"][0]["pair"] == "revolute"
    chain = frameless_chain(convert(p, "l3"), pairs)
    assert chain.pairs[1].kind == "sinusoidal" and chain.pairs[1].amplitude == pytest.approx(math.sqrt(2 * 0.06 * 0.05))
    with pytest.raises(ValueError, match=r"^pairs: joint 4 is not a joint of the chain \(1 to 3\)$"):
        to_toml(p, "l3", pairs={4: {"pair": "sinusoidal"}})
    with pytest.raises(ValueError, match=r"^pairs\[2\]: 'leg_length' is not a key of a sinusoidal pair"):
        to_toml(p, "l3", pairs={2: {"pair": "sinusoidal", "leg_length": 0.1}})
    with pytest.raises(ValueError, match=r"^pairs\[2\]: missing platform_radius$"):
        to_toml(p, "l3", pairs={2: {"pair": "sinusoidal", "base_radius": 0.06}})


def test_rpy_round_trip() -> None:
    """matrix_rpy inverts rpy_matrix to rounding, at and near pitch ±pi/2 too (the [base] and
    [tool] tables)."""
    from apair.frames import rpy_matrix as chain_rpy
    from apair.urdf.parse import matrix_rpy

    rng = np.random.default_rng(5)
    for k in range(3000):
        r = rng.uniform(-math.pi, math.pi, 3)
        if k % 3 == 0:
            r[1] = math.copysign(math.pi / 2, r[1]) + rng.normal() * 10.0 ** rng.uniform(-17, -3)
        R = rpy_matrix(r)
        assert np.abs(chain_rpy(matrix_rpy(R)) - R).max() < 1e-15
    assert matrix_rpy(rpy_matrix((0.3, math.pi / 2, 0.0)))[2] == 0.0
