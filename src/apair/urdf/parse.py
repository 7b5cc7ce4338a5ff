"""URDF text to a tree of links and joints, and the serial path from a base link to a tip link.

Read with the standard library's ElementTree: only the `<link>` and `<joint>` elements directly
under `<robot>` are read (`<transmission>`, `<gazebo>` and the rest are skipped; meshes are never
opened). Every refusal is one line naming the file, the element and the attribute.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .. import _validate as V

MAX_URDF_BYTES = 64 * 2**20  # a URDF is kilobytes; anything this large is not one
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
Matrix = NDArray[np.float64]


def rpy_matrix(rpy: NDArray[np.float64] | tuple[float, float, float]) -> Matrix:
    """URDF's fixed-axis roll, pitch, yaw: R = Rz(y) · Ry(p) · Rx(r)."""
    r, p, y = (float(v) for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def transform(xyz: NDArray[np.float64], rpy: NDArray[np.float64]) -> Matrix:
    """The 4×4 transform of a URDF `<origin xyz rpy>`."""
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(rpy)
    T[:3, 3] = xyz
    return T


@dataclass(frozen=True)
class Inertial:
    """A link's `<inertial>`: mass [kg], the inertial frame in the link frame (4×4), and the
    inertia tensor about the centre of mass in that frame [kg m²]."""

    mass: float
    origin: Matrix
    inertia: Matrix


@dataclass(frozen=True)
class Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: Matrix  # the child link's frame in the parent link's frame at q = 0
    axis: NDArray[np.float64]  # unit vector in the child (joint) frame
    limits: tuple[float, float] | None  # <limit lower upper> of a revolute [rad] or prismatic [m] joint
    mimic: str | None  # the joint it mimics, if any


@dataclass
class Robot:
    name: str
    where: str  # the file, as messages name it
    links: dict[str, Inertial | None] = field(default_factory=dict)
    joints: dict[str, Joint] = field(default_factory=dict)  # by name, in file order
    parent_joint: dict[str, Joint] = field(default_factory=dict)  # by child link
    children: dict[str, list[Joint]] = field(default_factory=dict)  # by parent link, file order

    @property
    def root(self) -> str:
        return next(name for name in self.links if name not in self.parent_joint)

    def chain_to(self, base: str, tip: str) -> list[Joint]:
        """The joints from `base` down to `tip`, base first (fixed ones included)."""
        for role, link in (("base", base), ("tip", tip)):
            if link not in self.links:
                raise ValueError(f"{role}: {self.where} has no link {link!r}{_nearest(link, self.links)}")
        path: list[Joint] = []
        link = tip
        while link != base:
            joint = self.parent_joint.get(link)
            if joint is None:
                raise ValueError(
                    f"base: no path from link {base!r} down to link {tip!r} in {self.where} "
                    f"({tip!r} is not below {base!r}; the root is {self.root!r})"
                )
            path.append(joint)
            link = joint.parent
        return path[::-1]

    def subtree(self, link: str, stop: Joint | None = None) -> list[str]:
        """The links rigidly carried by `link` once every joint but `stop` is locked: `link` and
        everything below it, except what lies beyond `stop`."""
        out, todo = [], [link]
        while todo:
            name = todo.pop()
            out.append(name)
            todo.extend(j.child for j in self.children.get(name, []) if j is not stop)
        return out


def _nearest(name: str, names: Iterable[str]) -> str:
    import difflib

    near = difflib.get_close_matches(name, list(names), n=1)
    return f"; did you mean {near[0]!r}?" if near else ""


def _floats(where: str, text: str | None, n: int, default: tuple[float, ...]) -> NDArray[np.float64]:
    if text is None:
        return np.array(default, dtype=float)
    parts = text.split()
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{where}: expected {n} finite number{'s' * (n > 1)}, got {V.shorten(repr(text), 60)}")
    return np.array(values)


def _origin(where: str, element: ET.Element | None) -> Matrix:
    if element is None:
        return np.eye(4)
    xyz = _floats(f"{where} <origin xyz>", element.get("xyz"), 3, (0.0, 0.0, 0.0))
    rpy = _floats(f"{where} <origin rpy>", element.get("rpy"), 3, (0.0, 0.0, 0.0))
    return transform(xyz, rpy)


def _inertial(where: str, element: ET.Element | None) -> Inertial | None:
    if element is None:
        return None
    mass_el = element.find("mass")
    if mass_el is None:
        raise ValueError(f"{where} <inertial>: has no <mass>")
    mass = float(_floats(f"{where} <mass value>", mass_el.get("value"), 1, ())[0])
    if mass < 0:
        raise ValueError(f"{where} <mass value>: a mass is not negative, got {mass:g} kg")
    I_el = element.find("inertia")
    keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    if I_el is None:
        raise ValueError(f"{where} <inertial>: has no <inertia>")
    v = {k: float(_floats(f"{where} <inertia {k}>", I_el.get(k), 1, ())[0]) for k in keys}
    I = np.array([[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]], [v["ixz"], v["iyz"], v["izz"]]])
    p = np.linalg.eigvalsh(I)
    tol = 1e-12 * max(float(np.max(np.abs(I))), 1e-300)
    if p[0] < -tol or p[0] + p[1] < p[2] - tol:
        raise ValueError(
            f"{where} <inertia>: not a physical inertia tensor (principal moments "
            f"{', '.join(f'{x:.6g}' for x in p)} kg m^2: it must be positive semi-definite and obey "
            "the triangle inequality)"
        )
    return Inertial(mass, _origin(f"{where} <inertial>", element.find("origin")), I)


def _joint(where: str, el: ET.Element, links: dict[str, Inertial | None]) -> Joint:
    name = el.get("name")
    if not name:
        raise ValueError(f"{where}: a <joint> has no name")
    w = f"{where}: joint {name!r}"
    kind = el.get("type")
    if kind not in JOINT_TYPES:
        raise ValueError(f"{w}: unknown type {kind!r} (URDF's are {', '.join(JOINT_TYPES)})")
    ends = []
    for tag in ("parent", "child"):
        e = el.find(tag)
        link = None if e is None else e.get("link")
        if link is None:
            raise ValueError(f"{w}: has no <{tag} link=...>")
        if link not in links:
            raise ValueError(f"{w}: <{tag}> names link {link!r}, which {where} does not define")
        ends.append(link)
    axis_el = el.find("axis")
    axis = _floats(f"{w} <axis xyz>", None if axis_el is None else axis_el.get("xyz"), 3, (1.0, 0.0, 0.0))
    norm = float(np.linalg.norm(axis))
    if kind in ("revolute", "continuous", "prismatic") and not norm > 0:
        raise ValueError(f"{w} <axis xyz>: the axis is the zero vector")
    limits = None
    if kind in ("revolute", "prismatic"):
        lim = el.find("limit")
        if lim is None:
            raise ValueError(
                f"{w}: a {kind} joint needs <limit lower=... upper=...>"
                + (" (use continuous for none)" if kind == "revolute" else "")
            )
        lo = float(_floats(f"{w} <limit lower>", lim.get("lower"), 1, (0.0,))[0])
        hi = float(_floats(f"{w} <limit upper>", lim.get("upper"), 1, (0.0,))[0])
        if not lo < hi:
            unit = "rad" if kind == "revolute" else "m"
            raise ValueError(f"{w} <limit>: expected lower < upper, got lower={lo:g}, upper={hi:g} {unit}")
        limits = (lo, hi)
    mimic_el = el.find("mimic")
    mimic = None if mimic_el is None else (mimic_el.get("joint") or "?")
    return Joint(name, kind, ends[0], ends[1], _origin(w, el.find("origin")), axis / (norm or 1.0), limits, mimic)


def parse(path: str | os.PathLike[str]) -> Robot:
    """The robot of a URDF file: its links, joints and tree, checked (one root, no link with two
    parents, no loop)."""
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"path: expected a URDF file name, got {V.shorten(repr(path))}")
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"path: no such file {str(p)!r}" if not p.exists() else f"path: {str(p)!r} is not a file")
    if p.stat().st_size > MAX_URDF_BYTES:
        raise ValueError(f"path: {str(p)!r} is larger than {MAX_URDF_BYTES // 2**20} MiB, not a URDF file")
    where = str(p)
    try:
        root = ET.parse(p).getroot()
    except ET.ParseError as exc:
        line, col = exc.position
        reason = str(exc).split(":")[0]
        raise ValueError(f"{where}: not well-formed XML: {reason} (line {line}, column {col + 1})") from None
    if root.tag != "robot":
        raise ValueError(f"{where}: not a URDF file (the root element is <{V.shorten(root.tag, 40)}>, not <robot>)")
    robot = Robot(V.replace_refused(root.get("name") or p.stem), where)
    for el in root.findall("link"):
        name = el.get("name")
        if not name:
            raise ValueError(f"{where}: a <link> has no name")
        if name in robot.links:
            raise ValueError(f"{where}: link {name!r} is defined twice")
        robot.links[name] = _inertial(f"{where}: link {name!r}", el.find("inertial"))
    if not robot.links:
        raise ValueError(f"{where}: the robot has no <link>")
    for el in root.findall("joint"):
        joint = _joint(where, el, robot.links)
        if joint.name in robot.joints:
            raise ValueError(f"{where}: joint {joint.name!r} is defined twice")
        if joint.child in robot.parent_joint:
            other = robot.parent_joint[joint.child].name
            raise ValueError(f"{where}: link {joint.child!r} is the child of two joints ({other!r} and {joint.name!r})")
        robot.joints[joint.name] = joint
        robot.parent_joint[joint.child] = joint
        robot.children.setdefault(joint.parent, []).append(joint)
    roots = [name for name in robot.links if name not in robot.parent_joint]
    if len(roots) != 1:
        said = "no root (the joints form a loop)" if not roots else f"{len(roots)} roots ({', '.join(roots[:4])})"
        raise ValueError(f"{where}: the links form no single tree: {said}")
    if len(robot.subtree(roots[0])) != len(robot.links):
        raise ValueError(f"{where}: the links form no single tree: some joints form a loop")
    for joint in robot.joints.values():
        if joint.mimic is not None and joint.mimic not in robot.joints:
            raise ValueError(f"{where}: joint {joint.name!r} mimics joint {joint.mimic!r}, which is not defined")
    return robot


def matrix_rpy(R: Matrix) -> tuple[float, float, float]:
    """URDF's (roll, pitch, yaw) of a rotation matrix, the inverse of `rpy_matrix`. Roll comes from
    the row of Rz(−yaw)·R that Ry(p)·Rx(r) gives as (0, cos r, −sin r): entries of size 1, so the
    angles rebuild R to rounding even at or near pitch ±π/2 (yaw 0 where R leaves it open, cos(pitch) below 2.5e-16)."""
    across = math.hypot(R[0, 0], R[1, 0])  # cos(pitch)
    yaw = math.atan2(R[1, 0], R[0, 0]) if across > 2.5e-16 else 0.0  # at ±π/2 rounding: roll takes all
    pitch = math.atan2(-R[2, 0], across)
    cy, sy = math.cos(yaw), math.sin(yaw)
    roll = math.atan2(sy * R[0, 2] - cy * R[1, 2], cy * R[1, 1] - sy * R[0, 1])
    return roll, pitch, yaw
