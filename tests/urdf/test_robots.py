"""Converted real robots (example-robot-data) agree with Pinocchio on the same URDF."""

from __future__ import annotations

import pytest
from robots import check, compare, robots_dir

from apair.urdf import convert


@pytest.mark.parametrize("tip", ["tool0", "wrist_3_link", "ee_link", "forearm_link"])
def test_ur5_agrees_with_pinocchio(tip: str) -> None:
    path = robots_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
    a = compare(path, tip)
    print("ur5", tip, a)
    check(a)


def test_ur5_from_base_link() -> None:
    path = robots_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
    check(compare(path, "tool0", base="base_link"))


def test_panda_with_seven_joints_agrees_with_pinocchio() -> None:
    path = robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    assert convert(path, "panda_link8").n == 7
    check(compare(path, "panda_link8"))


def test_panda_link6_agrees_with_pinocchio() -> None:
    path = robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    a = compare(path, "panda_link6")
    print("panda", a)
    check(a)
    assert convert(path, "panda_link6").n == 6
