"""The serial path of a URDF as DH constants (docs/conventions.md §3) plus a base and a tool frame.

Everything is computed from the joint axes at q = 0 in the base link's frame, and is exact (up to
rounding): with A_i(θ_i) = Rz(θ_i + φ_i) · Tz(c_i) · Tx(a_i) · Rx(α_i),

    pose of the tip link in the base link = base · A_1(q_1) ⋯ A_n(q_n) · tool,

with q_i the URDF joint angle itself (sign and zero included): DH axis z_{i−1} points along the
URDF `<axis>` of joint i (so the angles agree in sign) and φ_i absorbs the angle's zero. A
prismatic joint is a P-pair: its q_i is the URDF displacement along the same axis (c_i + q_i along
z_{i−1}, c_i the offset at displacement 0), its angle the constant φ_i; its axis is the line along
`<axis>` through the child link's origin (a slide has no line of its own: any parallel line moves
the links alike, and this one is the URDF's).

Frames (all at q = 0):

- Frame 0: z along joint 1's axis, origin the foot of the perpendicular from the base link's
  origin to that axis, x the base link's x projected onto the plane normal to z (its y if its x is
  within 25.8° of the axis; |x·z| ≥ 0.9).
- Frame i (1 ≤ i < n): z along joint i+1's axis, x along the common normal of axes i and i+1,
  pointing from axis i to axis i+1, origin where that normal meets axis i+1 (a_i ≥ 0):
  - intersecting axes: a_i = 0, x_i = z_{i−1} × z_i normalised (this sign, always);
  - parallel axes (the angle between the lines below 1e-14 rad): the common normal is not unique;
    apair takes the one through frame i−1's origin (c_i = 0), α_i = 0 or π;
  - coincident axes: a_i = 0, c_i = 0, x_i = x_{i−1}.
- Frame n: z along joint n's axis (a_n = 0, α_n = 0), origin the foot of the perpendicular from
  the tip link's origin to that axis, x the tip link's x projected as for frame 0 (or its y).
- base = frame 0 in the base link's frame; tool = the tip link's frame in frame n.

Lengths below 1e-15 of the robot's size and angles below 1e-15 rad are rounding and written as 0.
A conversion is checked by rebuilding every frame from its constants. Two axes close to parallel
(without being so within 1e-14 rad) whose common normal lies more than 1e4 times the robot's size
out (the largest distance of a joint or the tip from the base link's origin) are refused: their
constants would be that large, and the chain's poses would lose as many digits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..chain import MAX_JOINTS
from .inertia import Body, link_poses, merge
from .parse import Joint, Matrix, Robot

PARALLEL = 1e-14  # rad: axes closer to parallel than this are parallel
ROUNDING = 1e-15  # relative: lengths (and angles in rad) below this are rounding, written as 0
FAR = 1e4  # the common normal of two axes this many times the robot's size out is refused
CHECK = 1e-10  # relative: the frames rebuilt from the constants agree with the URDF's to this


@dataclass(frozen=True)
class ConvertedJoint:
    """One R-pair of the chain and where its values came from."""

    name: str  # the URDF joint
    type: str  # revolute, continuous or prismatic
    a: float
    alpha: float
    offset: float
    theta_offset: float
    limits: tuple[float, float] | None  # URDF <limit lower upper> [rad; m if prismatic]; None for continuous
    normal: str  # how x_i was chosen: skew, intersecting, parallel, coincident, last
    fixed: tuple[str, ...]  # fixed joints folded in before this joint (after the previous one)
    body: Body  # link i: the URDF links merged into it, mass, com and inertia in frame i


@dataclass(frozen=True)
class Converted:
    """A URDF's serial path from `base_link` to `tip_link` as DH constants and frames."""

    robot: str
    source: str
    base_link: str
    tip_link: str
    joints: tuple[ConvertedJoint, ...]
    base: Matrix  # 4×4: DH frame 0 in the base link's frame
    tool: Matrix  # 4×4: the tip link's frame in DH frame n
    tip_fixed: tuple[str, ...]  # fixed joints between joint n and the tip link

    @property
    def n(self) -> int:
        return len(self.joints)

    def gravity_dh(self, gravity: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Gravity given in the base link's frame (default (0, 0, −9.81)) in DH frame 0."""
        g = np.array([0.0, 0.0, -9.81]) if gravity is None else np.asarray(gravity, float)
        return np.asarray(self.base[:3, :3].T @ g)


def _unit(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.asarray(v / np.linalg.norm(v))


def _x_across(z: NDArray[np.float64], R: Matrix) -> NDArray[np.float64]:
    """A unit x normal to z: R's x projected onto the plane normal to z, or R's y if R's x is
    within 25.8° of z (|x·z| ≥ 0.9)."""
    ref = R[:, 0] if abs(float(R[:, 0] @ z)) < 0.9 else R[:, 1]
    return _unit(ref - (ref @ z) * z)


def _frame(x: NDArray[np.float64], z: NDArray[np.float64], o: NDArray[np.float64]) -> Matrix:
    F = np.eye(4)
    F[:3, 0], F[:3, 1], F[:3, 2], F[:3, 3] = x, np.cross(z, x), z, o
    return F


def _angle(u: NDArray[np.float64], v: NDArray[np.float64], about: NDArray[np.float64]) -> float:
    """The angle from u to v about `about` (all unit, u and v normal to `about`), in (−π, π]."""
    t = math.atan2(float(np.cross(u, v) @ about), float(u @ v))
    if abs(t) < ROUNDING:
        return 0.0
    return math.pi if t == -math.pi else t


def dh_matrix(a: float, alpha: float, offset: float, theta: float) -> Matrix:
    """A_i = Rz(θ) · Tz(c) · Tx(a) · Rx(α) (θ the joint angle plus φ)."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array(
        [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, offset], [0, 0, 0, 1.0]]
    )


def _path(robot: Robot, base: str, tip: str) -> tuple[list[Joint], list[list[Joint]]]:
    """The moving joints from base to tip, and the fixed joints before each of them (and after the
    last, as the final entry); refuses a joint apair cannot take, one line per kind."""
    moving: list[Joint] = []
    fixed: list[list[Joint]] = [[]]
    for joint in robot.chain_to(base, tip):
        w = f"{robot.where}: joint {joint.name!r}"
        if joint.mimic is not None:
            raise ValueError(
                f"{w} mimics joint {joint.mimic!r}: mimic joints on the path from {base!r} to {tip!r} "
                "are not supported (an apair joint is driven on its own)"
            )
        if joint.type in ("floating", "planar"):
            raise ValueError(
                f"{w} is {joint.type}: a {joint.type} joint has more than one degree of freedom, which "
                "an apair chain cannot hold; give a base below it"
            )
        if joint.type == "fixed":
            fixed[-1].append(joint)
        else:
            moving.append(joint)
            fixed.append([])
    if not moving:
        raise ValueError(f"tip: no revolute, continuous or prismatic joint between links {base!r} and {tip!r}")
    if len(moving) > MAX_JOINTS:
        nearest = moving[MAX_JOINTS - 1].child
        raise ValueError(
            f"tip: the path from {base!r} to {tip!r} has {len(moving)} joints "
            f"({moving[0].name} ... {moving[-1].name}); an apair chain has at most {MAX_JOINTS}: give tip at a "
            f"nearer link (e.g. {nearest!r}, {MAX_JOINTS} joints from {base!r}) or a base further out"
        )
    return moving, fixed


def convert(robot: Robot, tip: str, base: str | None = None) -> Converted:
    """The serial path from `base` (default: the root link) to `tip` as DH constants and frames."""
    base = robot.root if base is None else base
    moving, fixed = _path(robot, base, tip)
    poses = link_poses(robot, base)
    n = len(moving)
    T_tip = poses[tip]
    size = max(
        [1e-300]
        + [float(np.linalg.norm(poses[j.child][:3, 3])) for j in moving]
        + [float(np.linalg.norm(T_tip[:3, 3]))]
    )
    tiny = ROUNDING * size
    points = [poses[j.child][:3, 3] for j in moving]
    axes = [_unit(poses[j.child][:3, :3] @ j.axis) for j in moving]

    # frame 0
    z, p = axes[0], points[0]
    o = p - (p @ z) * z
    x = _x_across(z, np.eye(3))
    frames = [_frame(x, z, o)]
    rows: list[tuple[float, float, float, float, str]] = []
    for i in range(n):
        z_prev, x_prev, o_prev = z, x, o
        if i + 1 < n:
            z, p = axes[i + 1], points[i + 1]
            cross = np.cross(z_prev, z)
            s = float(np.linalg.norm(cross))
            if s < PARALLEL:
                w = o_prev - p
                foot = p + (w @ z) * z
                r = foot - o_prev
                r = r - (r @ z_prev) * z_prev
                dist = float(np.linalg.norm(r))
                if dist < tiny:
                    normal, x, a, c = "coincident", x_prev, 0.0, 0.0
                else:
                    normal, x, a, c = "parallel", r / dist, dist, 0.0
            else:
                nrm = cross / s
                a_signed = float((p - o_prev) @ nrm)
                # the foot of the common normal on axis i: o_prev + c z_prev
                w = o_prev - p
                b, d_, e_ = float(z_prev @ z), float(z_prev @ w), float(z @ w)
                c = (b * e_ - d_) / (s * s)
                if abs(a_signed) < tiny:
                    normal, x, a = "intersecting", nrm, 0.0
                else:
                    normal, x, a = "skew", math.copysign(1.0, a_signed) * nrm, abs(a_signed)
            o = o_prev + c * z_prev + a * x
            alpha = _angle(z_prev, z, x)
        else:  # the last frame: on joint n's axis, x after the tip link's
            normal = "last"
            c = float((T_tip[:3, 3] - o_prev) @ z_prev)
            x, a, alpha = _x_across(z_prev, T_tip[:3, :3]), 0.0, 0.0
            o = o_prev + c * z_prev
        c = 0.0 if abs(c) < tiny else c
        rows.append((a, alpha, c, _angle(x_prev, x, z_prev), normal))
        frames.append(_frame(x, z, o))

    for i, (a, _, c, _, _) in enumerate(rows[:-1]):
        if max(abs(c), a) > FAR * size:  # the common normal far out: fk would lose digits
            angle = math.asin(min(1.0, float(np.linalg.norm(np.cross(axes[i], axes[i + 1])))))
            raise ValueError(
                f"{robot.where}: joints {moving[i].name!r} and {moving[i + 1].name!r} have axes {angle:.3g} rad "
                f"from parallel whose common normal lies {max(abs(c), a):.3g} m out ({FAR:g} times the robot's "
                "size): their DH constants are too ill-conditioned to convert exactly"
            )
    # check: the frames rebuilt from the constants are the URDF's
    F = frames[0].copy()
    rebuilt = [F]
    for i, (a, alpha, c, phi, _) in enumerate(rows):
        F = F @ dh_matrix(a, alpha, c, phi)
        rebuilt.append(F)
        line = np.cross(points[i + 1] - F[:3, 3], axes[i + 1]) if i + 1 < n else np.zeros(3)
        error = max(
            float(np.linalg.norm(line)) / size,
            float(np.max(np.abs(F[:3, 2] - (axes[i + 1] if i + 1 < n else axes[i])))),
        )
        if error > CHECK:
            angle = math.asin(min(1.0, float(np.linalg.norm(np.cross(axes[i], axes[min(i + 1, n - 1)])))))
            raise ValueError(
                f"{robot.where}: joints {moving[i].name!r} and {moving[min(i + 1, n - 1)].name!r} have axes "
                f"{angle:.3g} rad from parallel: their DH constants are too ill-conditioned to convert exactly"
            )
    tool = np.linalg.inv(F) @ T_tip
    joints = []
    for i, (joint, (a, alpha, c, phi, normal)) in enumerate(zip(moving, rows)):
        stop = moving[i + 1] if i + 1 < n else None
        body = merge(robot, robot.subtree(joint.child, stop), poses, rebuilt[i + 1], size)
        joints.append(
            ConvertedJoint(
                joint.name,
                joint.type,
                a,
                alpha,
                c,
                phi,
                joint.limits,
                normal,
                tuple(j.name for j in fixed[i]),
                body,
            )
        )
    return Converted(
        robot.name, robot.where, base, tip, tuple(joints), frames[0], tool, tuple(j.name for j in fixed[n])
    )
