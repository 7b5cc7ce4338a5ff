"""Hand-written URDFs for the tests, and the comparison of a converted chain with Pinocchio loading
the same file (the independent oracle)."""

from __future__ import annotations

import glob
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

pin = pytest.importorskip("pinocchio")

from apair.urdf import convert, frameless_chain, load_urdf  # noqa: E402


def robots_dir() -> Path:
    cmeel = pytest.importorskip("cmeel")
    found = glob.glob(os.path.join(cmeel.__path__[0], "..", "cmeel.prefix", "share", "example-robot-data", "robots"))
    if not found:
        pytest.skip("example-robot-data is not installed")
    return Path(found[0])


@dataclass
class J:
    """A joint of a hand-written URDF: its child link gets an <inertial> unless inertial is None."""

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] | None = (0.0, 0.0, 1.0)
    limits: tuple[float, float] | None = (-2.5, 2.5)
    extra: str = ""


@dataclass
class Inertial:
    mass: float
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    I: np.ndarray = field(default_factory=lambda: np.diag([0.01, 0.02, 0.025]))


def random_inertial(rng: np.random.Generator) -> Inertial:
    p = rng.uniform(0.005, 0.05, 3)
    p[2] = rng.uniform(abs(p[0] - p[1]) + 1e-3, p[0] + p[1])  # the triangle inequality
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    I = Q @ np.diag(p) @ Q.T
    return Inertial(float(rng.uniform(0.2, 3.0)), tuple(rng.uniform(-0.1, 0.1, 3)), tuple(rng.uniform(-3, 3, 3)), I)


def _f(v: object) -> str:
    return repr(float(v))  # type: ignore[arg-type]


def _v(v: object) -> str:
    return " ".join(_f(x) for x in v)  # type: ignore[attr-defined]


def urdf(name: str, root: str, joints: list[J], inertials: dict[str, Inertial | None]) -> str:
    links = [root] + [j.child for j in joints]
    out = ['<?xml version="1.0"?>', f'<robot name="{name}">']
    for link in links:
        ine = inertials.get(link)
        if ine is None:
            out.append(f'  <link name="{link}"/>')
            continue
        I = ine.I
        out.append(
            f'  <link name="{link}"><visual><geometry><mesh filename="package://nowhere/{link}.stl"/></geometry></visual>'
            f'<inertial><origin xyz="{_v(ine.xyz)}" rpy="{_v(ine.rpy)}"/>'
            f'<mass value="{_f(ine.mass)}"/><inertia ixx="{_f(I[0, 0])}" ixy="{_f(I[0, 1])}" ixz="{_f(I[0, 2])}" '
            f'iyy="{_f(I[1, 1])}" iyz="{_f(I[1, 2])}" izz="{_f(I[2, 2])}"/></inertial></link>'
        )
    for j in joints:
        axis = "" if j.axis is None else f'<axis xyz="{_v(j.axis)}"/>'
        limit = (
            ""
            if j.limits is None
            else f'<limit lower="{_f(j.limits[0])}" upper="{_f(j.limits[1])}" effort="1" velocity="1"/>'
        )
        out.append(
            f'  <joint name="{j.name}" type="{j.type}"><parent link="{j.parent}"/><child link="{j.child}"/>'
            f'<origin xyz="{_v(j.xyz)}" rpy="{_v(j.rpy)}"/>{axis}{limit}{j.extra}</joint>'
        )
    out.append("</robot>")
    return "\n".join(out) + "\n"


def write(tmp: Path, text: str, name: str = "robot.urdf") -> Path:
    p = tmp / name
    p.write_text(text)
    return p


@dataclass
class Agreement:
    pose: float = 0.0
    jacobian: float = 0.0
    mass_matrix: float = 0.0
    rnea: float = 0.0

    def worst(self, other: Agreement) -> Agreement:
        return Agreement(*(max(a, b) for a, b in zip(vars(self).values(), vars(other).values())))


def compare(path: Path, tip: str, base: str | None = None, samples: int = 20, seed: int = 0) -> Agreement:
    """apair's converted chain against Pinocchio on the same file at random q within the limits:
    the tip's pose (base · fk · tool), its Jacobian (LOCAL_WORLD_ALIGNED at the tip frame), the mass
    matrix (crba) and inverse dynamics (rnea). Returns the largest errors (pose and Jacobian
    absolute, dynamics relative to the largest entry)."""
    conv = convert(path, tip, base)
    chain = frameless_chain(conv)
    framed = load_urdf(path, tip, base)  # with its base and tool frames: compared as it is
    model = pin.buildModelFromUrdf(str(path))
    names = [j.name for j in conv.joints]
    lock = [model.getJointId(n) for n in model.names[1:] if n not in names]
    full_data = model.createData()
    pin.forwardKinematics(model, full_data, pin.neutral(model))
    pin.updateFramePlacements(model, full_data)
    base_link = conv.base_link
    T_wb = full_data.oMf[model.getFrameId(base_link)].homogeneous
    reduced = pin.buildReducedModel(model, lock, pin.neutral(model)) if lock else model
    reduced.gravity.linear = T_wb[:3, :3] @ np.array([0.0, 0.0, -9.81])  # -z of the base link
    data = reduced.createData()
    fid = reduced.getFrameId(tip)
    jids = [reduced.getJointId(n) for n in names]
    assert reduced.nv == len(names)
    rng = np.random.default_rng(seed)
    lims = chain.limits
    worst = Agreement()
    for _ in range(samples):
        q = rng.uniform(lims[:, 0], lims[:, 1])
        qd, qdd = rng.normal(size=(2, len(q)))
        qp = np.zeros(reduced.nq)
        v_order = [reduced.joints[j].idx_v for j in jids]
        for j, x in zip(jids, q):
            jm = reduced.joints[j]
            if jm.nq == 2:
                qp[jm.idx_q : jm.idx_q + 2] = np.cos(x), np.sin(x)
            else:
                qp[jm.idx_q] = x
        vp, ap = np.zeros(reduced.nv), np.zeros(reduced.nv)
        vp[v_order], ap[v_order] = qd, qdd
        pin.forwardKinematics(reduced, data, qp)
        pin.updateFramePlacements(reduced, data)
        T_ref = np.linalg.inv(T_wb) @ data.oMf[fid].homogeneous
        J_ref = pin.computeFrameJacobian(reduced, data, qp, fid, pin.LOCAL_WORLD_ALIGNED)[:, v_order]
        J_ref = np.vstack([T_wb[:3, :3].T @ J_ref[:3], T_wb[:3, :3].T @ J_ref[3:]])
        M_ref = pin.crba(reduced, data, qp)
        M_ref = (np.triu(M_ref) + np.triu(M_ref, 1).T)[np.ix_(v_order, v_order)]
        tau_ref = pin.rnea(reduced, data, qp, vp, ap)[v_order]

        F = chain.fk(q)
        T = conv.base @ F @ conv.tool
        J = chain.jacobian(q)
        arm = F[:3, :3] @ conv.tool[:3, 3]
        v = J[:3] + np.cross(J[3:].T, arm).T
        R0 = conv.base[:3, :3]
        J_world = np.vstack([R0 @ v, R0 @ J[3:]])
        M = chain.mass_matrix(q)
        tau = chain.inverse_dynamics(q, qd, qdd)
        scale_M = max(1.0, float(np.abs(M_ref).max()))
        scale_tau = max(1.0, float(np.abs(tau_ref).max()))
        for T_, J_, M_, tau_ in (
            (T, J_world, M, tau),
            (framed.fk(q), framed.jacobian(q), framed.mass_matrix(q), framed.inverse_dynamics(q, qd, qdd)),
        ):
            worst = worst.worst(
                Agreement(
                    float(np.abs(T_ - T_ref).max()),
                    float(np.abs(J_ - J_ref).max()),
                    float(np.abs(M_ - M_ref).max()) / scale_M,
                    float(np.abs(tau_ - tau_ref).max()) / scale_tau,
                )
            )
    return worst


def check(agreement: Agreement) -> None:
    assert agreement.pose < 1e-12, agreement
    assert agreement.jacobian < 1e-12, agreement
    assert agreement.mass_matrix < 1e-10, agreement
    assert agreement.rnea < 1e-10, agreement
