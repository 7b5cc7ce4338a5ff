"""URDF prismatic joints become P-pairs: the SCARA (RRPR) and the Stanford arm (RRPRRR), and a slide
along a skew axis, against Pinocchio loading the same file; their ranges in metres; refusals."""

from __future__ import annotations

import numpy as np
import pytest
from robots import J, check, compare, random_inertial, urdf, write

from apair.urdf import load_urdf, to_toml

HALF = np.pi / 2


def _inertials(rng, joints):
    return {j.child: random_inertial(rng) for j in joints}


def scara(tmp_path, rng):
    joints = [
        J("shoulder", "revolute", "base", "arm1", (0.0, 0.0, 0.4)),
        J("elbow", "revolute", "arm1", "arm2", (0.35, 0.0, 0.0)),
        J("quill", "prismatic", "arm2", "quill", (0.3, 0.0, 0.0), axis=(0.0, 0.0, -1.0), limits=(0.0, 0.2)),
        J("wrist", "continuous", "quill", "flange", (0.0, 0.0, -0.05), axis=(0.0, 0.0, -1.0), limits=None),
        J("tcp_mount", "fixed", "flange", "tcp", (0.0, 0.0, -0.1), axis=None, limits=None),
    ]
    return write(tmp_path, urdf("scara", "base", joints, _inertials(rng, joints[:4])), "scara.urdf")


def stanford(tmp_path, rng):
    joints = [
        J("j1", "revolute", "base", "l1", (0.0, 0.0, 0.412), limits=(-3.0, 3.0)),
        J("j2", "revolute", "l1", "l2", (0.0, 0.154, 0.0), (-HALF, 0.0, 0.0)),
        J("j3", "prismatic", "l2", "l3", (0.0, 0.0, 0.0), (HALF, 0.0, 0.0), limits=(0.2, 0.9)),
        J("j4", "revolute", "l3", "l4", (0.0, 0.0, 0.1)),
        J("j5", "revolute", "l4", "l5", (0.0, 0.0, 0.0), (-HALF, 0.0, 0.0)),
        J("j6", "revolute", "l5", "l6", (0.0, 0.0, 0.0), (HALF, 0.0, 0.0)),
        J("flange", "fixed", "l6", "tool", (0.0, 0.0, 0.263), axis=None, limits=None),
    ]
    return write(tmp_path, urdf("stanford", "base", joints, _inertials(rng, joints[:6])), "stanford.urdf")


def test_scara_agrees_with_pinocchio(tmp_path) -> None:
    path = scara(tmp_path, np.random.default_rng(1))
    chain = load_urdf(path, "tcp")
    assert [p.kind for p in chain.pairs] == ["revolute", "revolute", "prismatic", "revolute"]
    assert np.array_equal(chain.limits[2], [0.0, 0.2])
    check(compare(path, "tcp"))


def test_stanford_arm_agrees_with_pinocchio(tmp_path) -> None:
    path = stanford(tmp_path, np.random.default_rng(2))
    assert [p.kind for p in load_urdf(path, "tool").pairs] == ["revolute"] * 2 + ["prismatic"] + ["revolute"] * 3
    check(compare(path, "tool"))


def test_slides_along_skew_axes_agree_with_pinocchio(tmp_path) -> None:
    """Slides and hinges along axes in general directions, origins with rotations: the DH constants
    of a slide's line through its child's origin."""
    rng = np.random.default_rng(3)
    joints = []
    parent = "b"
    for k, kind in enumerate(["prismatic", "revolute", "prismatic", "prismatic", "revolute"]):
        axis = tuple(rng.normal(size=3))
        lim = (-0.3, 0.4) if kind == "prismatic" else (-2.5, 2.5)
        joints.append(
            J(f"j{k}", kind, parent, f"l{k}", tuple(rng.uniform(-0.3, 0.3, 3)), tuple(rng.uniform(-3, 3, 3)), axis, lim)
        )
        parent = f"l{k}"
    path = write(tmp_path, urdf("skew", "b", joints, _inertials(rng, joints)))
    check(compare(path, parent))


def test_chain_file_of_a_prismatic_joint(tmp_path) -> None:
    text = to_toml(scara(tmp_path, np.random.default_rng(4)), "tcp")
    block = text.split("URDF joint quill (prismatic)")[1].split("[[joint]]")[0]
    assert 'pair = "prismatic"\n' in block and "limits = [0.0, 0.2]  # URDF <limit lower upper>" in block
    assert "at URDF displacement 0" in block


def test_replacing_a_slide_or_by_a_slide(tmp_path) -> None:
    """An A-pair in place of the slide takes its own range (the URDF's is in metres); a slide in
    place of a hinge needs its range given."""
    path = scara(tmp_path, np.random.default_rng(5))
    chain = load_urdf(path, "tcp", pairs={3: {"pair": "sinusoidal", "base_radius": 0.05, "platform_radius": 0.04}})
    assert chain.pairs[2].kind == "sinusoidal" and chain.limits[2][1] < np.pi
    with pytest.raises(ValueError, match=r"^pairs\[2\]: missing limits \(a prismatic joint's range"):
        load_urdf(path, "tcp", pairs={2: {"pair": "prismatic"}})
    chain = load_urdf(path, "tcp", pairs={2: {"pair": "prismatic", "limits": [-0.1, 0.1]}})
    assert chain.pairs[1].kind == "prismatic"


def test_prismatic_joint_needs_its_limit(tmp_path) -> None:
    joints = [J("j1", "prismatic", "b", "l1", limits=None)]
    path = write(tmp_path, urdf("arm", "b", joints, {}))
    with pytest.raises(ValueError, match=r"joint 'j1': a prismatic joint needs <limit lower=\.\.\. upper=\.\.\.>$"):
        load_urdf(path, "l1")
