"""Each apair link's mass, centre of mass and inertia tensor, from the URDF links it is made of.

apair's link i (docs/conventions.md §4) is the rigid body that joint i moves: the URDF child link
of joint i and every link below it, fixed or not, up to the next joint on the path (joints off the
path are locked at 0, as Pinocchio's buildReducedModel locks them at its neutral configuration).
Its centre of mass and inertia are expressed in DH frame i; a link without `<inertial>` adds
nothing (massless).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .parse import Matrix, Robot


@dataclass(frozen=True)
class Body:
    mass: float
    com: NDArray[np.float64]  # in DH frame i [m]
    inertia: Matrix  # about the centre of mass, in DH frame i [kg m^2]
    links: tuple[str, ...]  # the URDF links merged, the joint's child first
    massless: tuple[str, ...]  # those without <inertial> (or with zero mass and inertia)


def link_poses(robot: Robot, base: str) -> dict[str, Matrix]:
    """Every link below `base` (and base), its frame in base's frame with all joints at 0."""
    poses = {base: np.eye(4)}
    todo = [base]
    while todo:
        name = todo.pop()
        for joint in robot.children.get(name, []):
            poses[joint.child] = poses[name] @ joint.origin
            todo.append(joint.child)
    return poses


def merge(robot: Robot, links: list[str], poses: dict[str, Matrix], frame: Matrix, size: float) -> Body:
    """The rigid body made of `links` (poses in the base link's frame at q = 0), with its centre of
    mass and inertia about it in `frame` (a 4×4 pose in the same frame)."""
    inv = np.linalg.inv(frame)
    masses, coms, tensors, massless = [], [], [], []
    for name in links:
        inertial = robot.links[name]
        if inertial is None or (inertial.mass == 0 and not np.any(inertial.inertia)):
            massless.append(name)
            continue
        T = inv @ poses[name] @ inertial.origin  # the inertial frame in DH frame i
        R = T[:3, :3]
        masses.append(inertial.mass)
        coms.append(T[:3, 3])
        tensors.append(R @ inertial.inertia @ R.T)
    mass = float(sum(masses))
    com = sum((m * c for m, c in zip(masses, coms)), np.zeros(3)) / mass if mass > 0 else np.zeros(3)
    inertia = np.zeros((3, 3))
    for m, c, I in zip(masses, coms, tensors):
        r = c - com
        inertia += I + m * (float(r @ r) * np.eye(3) - np.outer(r, r))
    inertia = (inertia + inertia.T) / 2
    com[np.abs(com) < 1e-15 * size] = 0.0
    inertia[np.abs(inertia) < 1e-15 * np.max(np.abs(inertia), initial=0.0)] = 0.0
    return Body(mass, com, inertia, tuple(links), tuple(massless))
