"""P- and H-pairs in the MuJoCo export (a slide; a hinge and a slide coupled by a joint equality)
against apair's own kinematics and dynamics, and in the specialised code of `apair codegen`."""

from __future__ import annotations

import numpy as np
import pytest
from apair_test_helpers import closed_loop_qacc, loop_rows

import apair
from apair import APair, mjcf

mujoco = pytest.importorskip("mujoco")


def links(n, rng):
    return [
        apair.Link(rng.uniform(0.5, 2), rng.uniform(-0.1, 0.1, 3), np.diag(rng.uniform(0.01, 0.03, 3)))
        for _ in range(n)
    ]


def scara(rng) -> apair.AChain:
    """A SCARA (RRPR: parallel vertical axes, the third a slide) with a helical wrist in place of
    the last R-pair and a sinusoidal A-pair with heavy legs in front: every kind in one chain."""
    pairs = [APair(0.06, 0.05, leg_mass=0.1), APair.revolute(), APair.prismatic(), APair.helical(0.01)]
    return apair.AChain(
        pairs,
        a=[0.35, 0.3, 0.0, 0.0],
        alpha=[0.0, np.pi, 0.0, 0.0],
        offset=[0.4, 0.0, 0.0, 0.05],
        theta_offset=[0.0, 0.0, 0.3, 0.0],
        links=links(4, rng),
        limits=[None, None, (0.0, 0.3), (-3.0, 3.0)],
    )


def driven_dofs(m, chain):
    names = [f"pair{i + 1}_{'d' if p.kind == 'prismatic' else 'theta'}" for i, p in enumerate(chain.pairs)]
    return [m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, nm)] for nm in names]


def test_scara_model_geometry_and_dynamics():
    rng = np.random.default_rng(5)
    chain = scara(rng)
    q = np.array([0.4, -0.7, 0.12, 1.1])
    m = mujoco.MjModel.from_xml_string(chain.to_mjcf(q))
    assert [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)] == mjcf.joint_order(chain)
    slide = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "pair3_d")
    assert m.jnt_type[slide] == mujoco.mjtJoint.mjJNT_SLIDE and np.allclose(m.jnt_range[slide], [0.0, 0.3])
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    assert np.abs(d.efc_pos[loop_rows(d)]).max() < 1e-12  # the legs' loops and the helix
    e = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "end_effector")
    T = chain.fk(q)
    assert np.abs(d.site_xpos[e] - T[:3, 3]).max() < 1e-12
    assert np.abs(d.site_xmat[e].reshape(3, 3) - T[:3, :3]).max() < 1e-12
    dofs = driven_dofs(m, chain)
    for _ in range(3):
        q = rng.uniform([-1, -2, 0.05, -2], [1, 2, 0.25, 2])
        qd = rng.uniform(-1, 1, 4)
        qpos, qvel = mjcf.state(chain, q, qd)
        for tau in (np.zeros(4), rng.uniform(-3, 3, 4)):
            qacc, _ = closed_loop_qacc(m, qpos, qvel, tau)
            ref = chain.forward_dynamics(q, qd, tau)
            assert np.abs(qacc[dofs] - ref).max() <= 1e-6 * np.abs(ref).max(), (qacc[dofs], ref)


def test_stanford_arm_needs_no_loops():
    """The Stanford arm (RRPRRR): a slide and hinges only, so MuJoCo's own qacc is exact."""
    rng = np.random.default_rng(6)
    chain = apair.AChain(
        [APair.revolute(), APair.revolute(), APair.prismatic(), APair.revolute(), APair.revolute(), APair.revolute()],
        a=[0.0] * 6,
        alpha=[-np.pi / 2, np.pi / 2, 0.0, -np.pi / 2, np.pi / 2, 0.0],
        offset=[0.412, 0.154, 0.0, 0.0, 0.0, 0.263],
        theta_offset=[0.0, 0.0, -np.pi / 2, 0.0, 0.0, 0.0],
        links=links(6, rng),
        limits=[None, None, (0.2, 0.9), None, None, None],
    )
    m = mujoco.MjModel.from_xml_string(chain.to_mjcf(np.array([0, 0, 0.5, 0, 0, 0])))
    d = mujoco.MjData(m)
    assert m.neq == 0 and m.nq == 6
    for _ in range(3):
        q = rng.uniform([-3, -3, 0.2, -3, -3, -3], [3, 3, 0.9, 3, 3, 3])
        qd, tau = rng.uniform(-1, 1, 6), rng.uniform(-2, 2, 6)
        d.qpos[:], d.qvel[:] = mjcf.state(chain, q, qd)
        d.ctrl[:] = tau
        mujoco.mj_forward(m, d)
        ref = chain.forward_dynamics(q, qd, tau)
        assert np.abs(d.qacc - ref).max() <= 1e-10 * np.abs(ref).max()
    with pytest.raises(ValueError, match=r"q: joint 3 at 1\.5 m is outside its limits"):
        chain.to_mjcf(np.array([0, 0, 1.5, 0, 0, 0]))


def test_specialised_code_equals_generic():
    """`AChain.specialise` (the code of `apair codegen`) of a chain with P- and H-pairs: every method
    equals the generic kernels'."""
    rng = np.random.default_rng(8)
    chain = scara(rng)
    fast = chain.specialise()
    assert fast.specialised
    q, qd, qdd = np.array([0.3, 0.5, 0.2, -0.4]), rng.normal(size=4), rng.normal(size=4)
    for method, args in [
        ("fk", (q,)),
        ("jacobian", (q,)),
        ("mass_matrix", (q,)),
        ("inverse_dynamics", (q, qd, qdd)),
        ("forward_dynamics", (q, qd, qdd)),
        ("energy", (q, qd)),
    ]:
        np.testing.assert_allclose(getattr(fast, method)(*args), getattr(chain, method)(*args), rtol=1e-12, atol=1e-12)
