"""A chain as a MuJoCo model (MJCF) of the real mechanism: every A-pair as its Griffis-Duffy platform.

Body tree, in the frames of docs/conventions.md §3:

- `link{i}` is the body of link i. Its frame is pair i's *platform frame* (frame i−1 · Rz(θ_i) ·
  Tz(d_i)); its joints are the hinge `pair{i}_theta` (θ_i about the pair's axis) and, for an A-pair,
  the slide `pair{i}_d` (d_i along it, `ref` = d_i(0), so qpos holds d_i itself). Nothing couples
  the two but the legs: the law d_i(θ_i) comes out of the loops, as in the real pair. The hinge's
  range is the joint's hard limits (`chain.hard_limits()`, where the legs or plates collide or an
  explicit limit stops it; none for a free joint), as stiff as the loops; `limits=False` leaves the
  ranges out.
- Pair i's six legs are bodies `pair{i}_leg{k}` in the body that carries frame i−1, each with a
  ball joint at its base point and an equality `connect` (`pair{i}_loop{k}`) at its platform point.
  A leg is a uniform slender rod (the model of §4): transverse inertia m L²/12 about its midpoint;
  its spin about its own axis, which the rod model ignores, gets ½ m ρ² (ρ = leg_radius; a small
  fraction of the transverse inertia if ρ = 0). The spin never couples: nothing acts about the
  axis.
- Sites `pair{i}_base` (frame i−1 at the pair's base, z along its axis) and `pair{i}_platform`
  (the platform frame) give θ_i and d_i to any MuJoCo user; `end_effector` is frame n, `tool` the
  tool frame (frame n · chain.tool: its world pose is chain.fk(q)), on link n; `base` (a site of the
  world) is frame 0.
- The world is apair's world (gravity as chain.gravity): frame 0 is placed at chain.base, so the
  first pair's base plate, legs, site and link body sit at the base's pose.
- A prismatic pair has only its slide `pair{i}_d` (range: its limits in metres), a helical pair its
  hinge and its slide coupled by a joint equality `pair{i}_helix` (d = pitch·θ).
- One motor per pair (`pair{i}_motor`) on the hinge (the slide of a P-pair): ctrl = τ_i, the torque
  about axis i (the force along it).
- Plates (triangles of the pair's radii) and legs are visible geoms that do not collide unless
  `collisions=True`.

The reference configuration (qpos0) is θ = 0 for every pair, where the loops close; keyframe 0 is
the configuration q, legs included (`state`), refused outside the hard limits unless
`outside_limits`. The model's name is escaped (quoteattr); control characters are refused. MuJoCo needs mass and inertia in every moving body:
massless legs and links get MASSLESS × the model's mass scale, and a singular link inertia a floor
of 1e-2 times that (kg m²); both change the dynamics by about MASSLESS.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from . import _validate as V
from .files import Refusal
from .kernels import call

if TYPE_CHECKING:
    from ._typing import ChainLike, PairLike

MASSLESS = 1e-9  # mass given to a massless moving body, relative to the model's mass scale
FLAT = 1e-9  # d below this × the pair's size: the legs are flat (d = 0), refused by `state`
SPIN = 1e-3  # a slender leg's spin inertia, relative to its transverse inertia, where leg_radius = 0
VISUAL_RADIUS = 0.03  # radius of a massless leg's or link's drawn rod, relative to the pair's size
# Solver settings: the loops are equality constraints, made as stiff as MuJoCo allows at this
# timestep (solref time constant = 2 timesteps, the stable minimum; impedance 0.9999, the maximum).
TIMESTEP = 2e-4
SOLREF = (2 * TIMESTEP, 1.0)
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)


def _f(x: ArrayLike) -> str:
    return " ".join(repr(float(v)) if v != 0 else "0" for v in np.atleast_1d(x))


def _quat(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """MuJoCo's quaternion (w, x, y, z) of a rotation matrix."""
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    q = np.array([w, x, y, z])
    return q if q[0] >= 0 else -q


def _arc(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """The smallest rotation taking the unit vector u to the unit vector v."""
    w = np.cross(u, v)
    c = float(u @ v)
    s = np.linalg.norm(w)
    if s < 1e-15:
        if c > 0:
            return np.eye(3)
        axis = np.cross(u, [1.0, 0, 0] if abs(u[0]) < 0.9 else [0, 1.0, 0])
        return Rotation.from_rotvec(math.pi * axis / np.linalg.norm(axis)).as_matrix()
    return Rotation.from_rotvec(w / s * math.atan2(s, c)).as_matrix()


def _link_offset(chain: ChainLike, i: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(R, p) of frame i in pair i's platform frame, Rz(φ_i) Tz(c_i) Tx(a_i) Rx(α_i): the joint
    transform kernel fk1 at θ = 0, d = 0."""
    law = call("law_revolute", [0.0])[0]
    T = call("fk1", law[None, :], chain._dh[i][None, :])[0]
    return T[:3, :3], T[:3, 3]


def _frames(chain: ChainLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(base, tool): the chain's base and tool transforms (4, 4), the identity where it has none."""
    base, tool = getattr(chain, "base", None), getattr(chain, "tool", None)
    return (
        np.eye(4) if base is None else np.asarray(base, float),
        np.eye(4) if tool is None else np.asarray(tool, float),
    )


def _reference_legs(pair: PairLike) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The legs at θ = 0 (the model's reference), in the pair's base frame: base points (6, 3),
    lengths (6,), and each leg body's reference frame (6, 3, 3), z along the leg."""
    pts = pair.leg_endpoints(0.0)
    axis = pts[:, 1] - pts[:, 0]
    length = np.linalg.norm(axis, axis=1)
    frames = np.stack([_arc(np.array([0, 0, 1.0]), u) for u in axis / length[:, None]])
    return pts[:, 0], length, frames


def _check_q(chain: ChainLike, q: ArrayLike | None) -> NDArray[np.float64]:
    if q is None:
        return np.zeros(chain.n)
    q = V.real_array("q", q)
    if q.shape != (chain.n,):
        raise ValueError(f"q: expected {chain.n} joint values, got shape {q.shape}")
    chain.fk(q)  # validates the ranges of limited pairs
    return q


def _check_within_limits(chain: ChainLike, q: NDArray[np.float64]) -> None:
    """Refuse a keyframe q beyond a joint's hard limits (`chain.hard_limits`, §6), where the real
    mechanism's legs or plates collide or an explicit limit stops it; a free joint takes any angle."""
    for i, (lo, hi) in enumerate(chain.hard_limits()):
        if not lo <= q[i] <= hi:
            unit = "m" if chain.pairs[i].kind == "prismatic" else "rad"
            raise Refusal(
                f"q: joint {i + 1} at {q[i]:.10g} {unit} is outside its limits ({lo:.10g}, {hi:.10g}) {unit}",
                "outside_limits",
                "to export it anyway",
            )


def _check_name(name: object) -> str:
    """The model's name, refused if it holds a character that XML cannot (or should not) carry."""
    return V.text("name", name)


def state(
    chain: ChainLike, q: ArrayLike | None, qd: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(qpos, qvel) of the model of `to_mjcf` at joint angles q (n,) and rates qd (n,), legs and
    slides included, loops closed, in the model's joint order (`joint_order`)."""
    q = _check_q(chain, q)
    qd = np.zeros(chain.n) if qd is None else V.real_array("qd", qd)
    if qd.shape != (chain.n,):
        raise ValueError(f"qd: expected {chain.n} joint rates, got shape {qd.shape}")
    qpos, qvel = [], []
    for i, pair in enumerate(chain.pairs):  # the document order: pair i's legs, then its hinge and slide
        if not pair.is_apair:
            if pair.kind == "helical":
                qpos += [q[i], pair.pitch * q[i]]
                qvel += [qd[i], pair.pitch * qd[i]]
            else:
                qpos.append(q[i])
                qvel.append(qd[i])
            continue
        d, dd = pair.law(q[i])[:2]
        if not (d > FLAT * max(pair.base_radius, pair.platform_radius) and np.isfinite(dd)):
            raise ValueError(
                f"q: pair {i + 1} is at d = 0 (legs flat, q = {float(q[i]):.12g} rad), where the loops leave "
                "the legs' positions and rates undetermined"
            )
        base, length, frames = _reference_legs(pair)
        top = pair.leg_endpoints(q[i])[:, 1]
        for k in range(6):
            L = np.linalg.norm(top[k] - base[k])
            u = (top[k] - base[k]) / L
            R0 = frames[k]  # the leg body's reference frame in the base frame
            R = _arc(R0[:, 2], u) @ R0
            qpos.extend(_quat(R0.T @ R))
            # the platform point's velocity relative to the base, and the leg's rate (⊥ to its axis)
            v = qd[i] * np.cross([0, 0, 1.0], top[k]) + np.array([0, 0, dd * qd[i]])
            w = np.cross(u, v) / L
            qvel.extend(R.T @ w)  # a ball joint's rate is in the leg's own frame
        qpos += [q[i], d]
        qvel += [qd[i], dd * qd[i]]
    return np.array(qpos), np.array(qvel)


def _mass_scale(chain: ChainLike) -> float:
    masses = [lk.mass for lk in chain.links] + [p.leg_mass for p in chain.pairs if p.is_apair]
    return max([m for m in masses if m > 0], default=1.0)


def _size(chain: ChainLike, i: int) -> float:
    p = chain.pairs[i]
    if p.is_apair:
        return max(p.base_radius, p.platform_radius)
    return max(0.02, 0.1 * max(np.abs(chain.a).max(), np.abs(chain.offset).max(), 0.1))


def _hinge(chain: ChainLike, i: int, limits: bool) -> str:
    """Pair i's hinge (a P-pair's slide); with `limits`, its range is the joint's hard limits (repr
    digits: the same floats), as stiff as the loops (a collision stops the real joint dead); none
    for a joint that turns freely."""
    if chain.pairs[i].kind == "prismatic":
        head = f'<joint name="pair{i + 1}_d" type="slide" axis="0 0 1"'
    else:
        head = f'<joint name="pair{i + 1}_theta" type="hinge" axis="0 0 1"'
    lo, hi = chain.hard_limits()[i]
    if not (limits and math.isfinite(lo) and math.isfinite(hi)):
        return head + "/>"
    return f'{head} limited="true" range="{_f([lo, hi])}" solreflimit="{_f(SOLREF)}" solimplimit="{_f(SOLIMP)}"/>'


def to_mjcf(
    chain: ChainLike,
    q: ArrayLike | None = None,
    name: str = "apair chain",
    collisions: bool = False,
    limits: bool = True,
    outside_limits: bool = False,
) -> str:
    """The MJCF text of the chain's mechanism (see the module's docstring); keyframe 0 is q
    (default: all zero), legs and loops consistent. `limits`: the hinges' ranges are the chain's
    hard limits (False: no hinge range). q outside the hard limits, where the legs would collide,
    is refused unless `outside_limits`. `name` (the model's) may not hold control characters."""
    name = _check_name(name)
    limits, outside_limits = V.flag("limits", limits), V.flag("outside_limits", outside_limits)
    q = _check_q(chain, q)
    if not outside_limits:
        _check_within_limits(chain, q)
    scale = _mass_scale(chain)
    tiny = MASSLESS * scale
    col = 'contype="1" conaffinity="1"' if collisions else 'contype="0" conaffinity="0"'
    assets, out = [], []
    qpos, _ = state(chain, q)

    def inertial(
        indent: str, mass: float, pos: NDArray[np.float64], R: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> None:
        """A link's inertial in its body's frame; a massless link, or a singular inertia (a point
        or a rod), gets the MASSLESS floor (MuJoCo needs positive mass and inertia)."""
        floor = tiny * 1e-2  # [kg m²]: the massless mass on a 0.1 m radius
        if mass <= 0:
            mass, inertia = tiny, np.eye(3) * floor
        I = R @ inertia @ R.T
        if np.linalg.eigvalsh(I)[0] < floor:
            I = I + np.eye(3) * floor
        full = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
        out.append(f'{indent}<inertial pos="{_f(pos)}" mass="{_f(mass)}" fullinertia="{_f(full)}"/>')

    def plate(
        indent: str, label: str, radius: float, angle0: float, z: float = 0.0, thick: float | None = None
    ) -> None:
        """A triangle (circumradius `radius`, vertex 0 at polar angle angle0) as a thin prism mesh."""
        t = thick if thick else 0.02 * radius
        ang = angle0 + 2 * np.pi * np.arange(3) / 3
        top = np.stack([radius * np.cos(ang), radius * np.sin(ang), np.full(3, z + t / 2)], 1)
        bot = top - [0, 0, t]
        assets.append(f'    <mesh name="{label}" vertex="{_f(np.concatenate([top, bot]).ravel())}"/>')
        out.append(f'{indent}<geom name="{label}" type="mesh" mesh="{label}" {col} rgba="0.55 0.6 0.7 0.6"/>')

    def rod(
        indent: str,
        label: str,
        a: NDArray[np.float64],
        b: NDArray[np.float64],
        radius: float,
        rgba: str = "0.75 0.55 0.3 1",
    ) -> None:
        if np.linalg.norm(np.asarray(b) - a) < 1e-12:
            return
        out.append(
            f'{indent}<geom name="{label}" type="capsule" fromto="{_f(np.concatenate([a, b]))}" '
            f'size="{_f(radius)}" {col} rgba="{rgba}"/>'
        )

    # frame i−1 in the current body: (R, p); the world carries frame 0 at the chain's base
    base, tool = _frames(chain)
    R_prev, p_prev = base[:3, :3], base[:3, 3]
    indent = "    "
    out.append(f'{indent}<site name="base" pos="{_f(p_prev)}" quat="{_f(_quat(R_prev))}" size="0.01"/>')
    for i, pair in enumerate(chain.pairs):
        n1 = i + 1
        size = _size(chain, i)
        quat_prev = _quat(R_prev)
        out.append(
            f'{indent}<site name="pair{n1}_base" pos="{_f(p_prev)}" quat="{_f(quat_prev)}" size="{_f(0.1 * size)}"/>'
        )
        h0 = 0.0
        if pair.is_apair:
            h0 = pair.translation(0.0)
            base, length, frames = _reference_legs(pair)
            # the base plate (in frame i−1) and the legs
            out.append(f'{indent}<body name="pair{n1}_base_plate" pos="{_f(p_prev)}" quat="{_f(quat_prev)}">')
            plate(indent + "  ", f"pair{n1}_base_plate", pair.base_radius, 0.0, 0.0, pair.thickness or None)
            out.append(f"{indent}</body>")
            for k in range(6):
                L = float(length[k])
                R0 = R_prev @ frames[k]
                m = pair.leg_mass
                It = m * L * L / 12
                Is = 0.5 * m * pair.leg_radius**2 if pair.leg_radius > 0 else SPIN * It
                out.append(
                    f'{indent}<body name="pair{n1}_leg{k + 1}" pos="{_f(p_prev + R_prev @ base[k])}" '
                    f'quat="{_f(_quat(R0))}">'
                )
                out.append(f'{indent}  <joint name="pair{n1}_leg{k + 1}_ball" type="ball"/>')
                if m > 0:
                    out.append(
                        f'{indent}  <inertial pos="0 0 {_f(L / 2)}" mass="{_f(m)}" diaginertia="{_f([It, It, Is])}"/>'
                    )
                else:
                    out.append(
                        f'{indent}  <inertial pos="0 0 {_f(L / 2)}" mass="{_f(tiny)}" '
                        f'diaginertia="{_f([tiny * L * L / 12] * 3)}"/>'
                    )
                radius = pair.leg_radius if pair.leg_radius > 0 else VISUAL_RADIUS * size
                rod(indent + "  ", f"pair{n1}_leg{k + 1}_rod", np.zeros(3), np.array([0, 0, L]), radius)
                out.append(f"{indent}</body>")
        # the link body: pair i's platform frame at θ = 0
        p_body = p_prev + R_prev @ np.array([0, 0, h0])
        out.append(f'{indent}<body name="link{n1}" pos="{_f(p_body)}" quat="{_f(quat_prev)}">')
        ind = indent + "  "
        out.append(ind + _hinge(chain, i, limits))
        if pair.kind == "helical":
            out.append(f'{ind}<joint name="pair{n1}_d" type="slide" axis="0 0 1"/>')
        if pair.is_apair:
            top = float(max(np.max(pair.translation(np.linspace(*pair.motion_range(), 721))), h0))
            out.append(
                f'{ind}<joint name="pair{n1}_d" type="slide" axis="0 0 1" ref="{_f(h0)}" range="0 {_f(2 * top)}"/>'
            )
        R_off, p_off = _link_offset(chain, i)
        link = chain.links[i]
        inertial(ind, link.mass, p_off + R_off @ link.com, R_off, link.inertia)
        out.append(f'{ind}<site name="pair{n1}_platform" size="{_f(0.1 * size)}"/>')
        if pair.is_apair:
            plate(ind, f"pair{n1}_platform_plate", pair.platform_radius, np.pi / 3, 0.0, pair.thickness or None)
        # the link's drawn body: platform origin → along z by c_i → frame i
        knee = np.array([0, 0, chain.offset[i]])
        rod(ind, f"link{n1}_rod_offset", np.zeros(3), knee, VISUAL_RADIUS * size, "0.4 0.45 0.5 1")
        rod(ind, f"link{n1}_rod_length", knee, p_off, VISUAL_RADIUS * size, "0.4 0.45 0.5 1")
        R_prev, p_prev = R_off, p_off
        indent = ind
    out.append(f'{indent}<site name="end_effector" pos="{_f(p_prev)}" quat="{_f(_quat(R_prev))}" size="0.01"/>')
    p_tool, R_tool = p_prev + R_prev @ tool[:3, 3], R_prev @ tool[:3, :3]
    out.append(f'{indent}<site name="tool" pos="{_f(p_tool)}" quat="{_f(_quat(R_tool))}" size="0.01"/>')
    for _ in range(chain.n):
        indent = indent[:-2]
        out.append(f"{indent}</body>")

    key_qpos = qpos

    eq, motors = [], []
    for i, pair in enumerate(chain.pairs):
        n1 = i + 1
        driven = "d" if pair.kind == "prismatic" else "theta"
        motors.append(f'    <motor name="pair{n1}_motor" joint="pair{n1}_{driven}" gear="1"/>')
        if pair.kind == "helical":
            eq.append(
                f'    <joint name="pair{n1}_helix" joint1="pair{n1}_d" joint2="pair{n1}_theta" '
                f'polycoef="0 {_f(pair.pitch)} 0 0 0"/>'
            )
        if not pair.is_apair:
            continue
        for k, L in enumerate(_reference_legs(pair)[1]):
            eq.append(
                f'    <connect name="pair{n1}_loop{k + 1}" body1="pair{n1}_leg{k + 1}" body2="link{n1}" '
                f'anchor="0 0 {_f(L)}"/>'
            )
    g = chain.gravity
    lines = [
        f"<mujoco model={quoteattr(name)}>",
        "  <!-- written by apair (chain.to_mjcf / apair export mjcf): see docs/conventions.md, section MuJoCo -->",
        '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
        f'  <option gravity="{_f(g)}" timestep="{_f(TIMESTEP)}" integrator="RK4" cone="elliptic" '
        'jacobian="dense" solver="Newton" iterations="200" tolerance="1e-12"/>',
        '  <visual><global offwidth="1920" offheight="1080"/>'
        '<headlight ambient="0.45 0.45 0.45" diffuse="0.6 0.6 0.6"/></visual>',
        "  <default>",
        f'    <equality solref="{_f(SOLREF)}" solimp="{_f(SOLIMP)}"/>',
        "  </default>",
    ]
    assets.insert(
        0,
        '    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.85 0.88 0.92" '
        'rgb2="0.55 0.6 0.68" width="64" height="64"/>',
    )
    lines += ["  <asset>"] + assets + ["  </asset>"]
    lines += ["  <worldbody>"] + out + ["  </worldbody>"]
    if eq:
        lines += ["  <equality>"] + eq + ["  </equality>"]
    lines += ["  <actuator>"] + motors + ["  </actuator>"]
    lines += ["  <keyframe>", f'    <key name="q" qpos="{_f(key_qpos)}"/>', "  </keyframe>", "</mujoco>", ""]
    return "\n".join(lines)


def joint_order(chain: ChainLike) -> list[str]:
    """The names of the model's joints in qpos order (legs before their link's hinge and slide)."""
    names = []
    for i, pair in enumerate(chain.pairs):
        n1 = i + 1
        if pair.is_apair:
            names += [f"pair{n1}_leg{k}_ball" for k in range(1, 7)]
        if pair.kind != "prismatic":
            names.append(f"pair{n1}_theta")
        if pair.kind != "revolute":
            names.append(f"pair{n1}_d")
    return names
