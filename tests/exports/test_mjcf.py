"""The MuJoCo export (apair.mjcf, chain.to_mjcf, apair export mjcf) against apair's own dynamics.

MuJoCo's constraints are soft, so its own qacc is off by the impedance (about 1e-3 here). The closed
loop's accelerations that MuJoCo's model implies are those of its mass matrix, bias forces and loop
constraint Jacobian with the loops held exactly (the KKT system, J̇q̇ by central differences of J):
they must equal chain.forward_dynamics. The motion that MuJoCo's integrator produces with its soft
loops must follow chain.simulate.
"""

import math

import numpy as np
import pytest
from apair_test_helpers import closed_loop_qacc, loop_rows

import apair
from apair import io, mjcf
from apair.cli import main

mujoco = pytest.importorskip("mujoco")

EXAMPLE = "examples/4a_chain.toml"


def mixed_chain():
    """Special design: an R-pair, a sinusoidal pair with heavy legs of finite radius, a general pair
    with a < b (limited range) and massless legs; twists 0, ±90°, zero lengths and offsets."""
    r_b, r_p = 0.05, 0.04
    general = apair.APair(r_b, r_p, leg_length=math.sqrt(r_b**2 + r_p**2 / 4 + 0.5 * r_b * r_p))
    assert general.kind == "general" and general.theta_limit is not None
    pairs = [apair.APair.revolute(), apair.APair(0.06, 0.05, leg_mass=0.08, leg_radius=0.004), general]
    links = [
        apair.Link(1.5, [0.0, 0.02, 0.1], np.diag([0.02, 0.03, 0.01])),
        apair.Link(2.0, [-0.1, 0.0, 0.0], [[0.01, 0.001, 0], [0.001, 0.02, 0], [0, 0, 0.02]]),
        apair.Link(0.7, [0.0, 0.0, 0.05], np.diag([0.004, 0.004, 0.002])),
    ]
    return apair.AChain(
        pairs,
        a=[0.0, 0.3, 0.0],
        alpha=[np.pi / 2, 0.0, -np.pi / 2],
        offset=[0.25, 0.0, 0.0],
        theta_offset=[0.0, 0.3, 0.0],
        links=links,
    )


CHAINS = {"example": lambda: io.load(EXAMPLE), "mixed": mixed_chain}


def model(chain, q=None):
    m = mujoco.MjModel.from_xml_string(chain.to_mjcf(q))
    return m, mujoco.MjData(m)


def hinge_dofs(m, chain):
    return [m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"pair{i + 1}_theta")] for i in range(chain.n)]


def random_state(chain, rng):
    lo, hi = np.maximum(chain.limits[:, 0], -2.0), np.minimum(chain.limits[:, 1], 2.0)
    return rng.uniform(lo + 0.2, hi - 0.2), rng.uniform(-1.5, 1.5, chain.n)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_model_geometry(name):
    """The model loads; at keyframe 0 the loops are closed, every pair's platform site is
    Rz(θ)·Tz(d) from its base site, and the end-effector site is chain.fk(q)."""
    chain = CHAINS[name]()
    rng = np.random.default_rng(1)
    q, _ = random_state(chain, rng)
    m, d = model(chain, q)
    assert [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)] == mjcf.joint_order(chain)
    assert m.nu == chain.n and m.nkey == 1
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    if loop_rows(d).any():
        assert np.abs(d.efc_pos[loop_rows(d)]).max() < 1e-12
    for i, p in enumerate(chain.pairs):
        b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"pair{i + 1}_base")
        t = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"pair{i + 1}_platform")
        Rb, Rt = d.site_xmat[b].reshape(3, 3), d.site_xmat[t].reshape(3, 3)
        rel_R, rel_p = Rb.T @ Rt, Rb.T @ (d.site_xpos[t] - d.site_xpos[b])
        c, s = math.cos(q[i]), math.sin(q[i])
        assert np.allclose(rel_R, [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-12)
        assert np.allclose(rel_p, [0, 0, p.translation(q[i]) if p.kind != "revolute" else 0.0], atol=1e-12)
    e = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "end_effector")
    T = chain.fk(q)
    assert np.abs(d.site_xpos[e] - T[:3, 3]).max() < 1e-12
    assert np.abs(d.site_xmat[e].reshape(3, 3) - T[:3, :3]).max() < 1e-12


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_closed_loop_accelerations_match_forward_dynamics(name):
    """At random states, free and with random motor torques: the accelerations MuJoCo's model
    implies for the closed loops equal chain.forward_dynamics to 1e-6 relative, and the model's
    state of `mjcf.state` satisfies the loops in position and velocity."""
    chain = CHAINS[name]()
    rng = np.random.default_rng(2)
    m, _ = model(chain)
    dofs = hinge_dofs(m, chain)
    for _ in range(3):
        q, qd = random_state(chain, rng)
        qpos, qvel = mjcf.state(chain, q, qd)
        d = mujoco.MjData(m)
        d.qpos[:], d.qvel[:] = qpos, qvel
        mujoco.mj_forward(m, d)
        if loop_rows(d).any():
            J = d.efc_J.reshape(d.nefc, m.nv)[loop_rows(d)]
            assert np.abs(d.efc_pos[loop_rows(d)]).max() < 1e-12
            assert np.abs(J @ qvel).max() < 1e-12 * (1 + np.abs(qvel).max())
        for tau in (np.zeros(chain.n), rng.uniform(-5, 5, chain.n)):
            qacc, _ = closed_loop_qacc(m, qpos, qvel, tau)
            ref = chain.forward_dynamics(q, qd, tau)
            assert np.abs(qacc[dofs] - ref).max() <= 1e-6 * np.abs(ref).max(), (qacc[dofs], ref)


def test_motor_torques_are_the_tau_argument():
    """A torque on motor i changes the accelerations exactly as τ_i does in forward_dynamics."""
    chain = mixed_chain()
    rng = np.random.default_rng(3)
    m, _ = model(chain)
    dofs = hinge_dofs(m, chain)
    q, qd = random_state(chain, rng)
    qpos, qvel = mjcf.state(chain, q, qd)
    base, _ = closed_loop_qacc(m, qpos, qvel, np.zeros(chain.n))
    for i in range(chain.n):
        tau = np.zeros(chain.n)
        tau[i] = 2.0
        diff = closed_loop_qacc(m, qpos, qvel, tau)[0][dofs] - base[dofs]
        ref = chain.forward_dynamics(q, qd, tau) - chain.forward_dynamics(q, qd, np.zeros(chain.n))
        assert np.abs(diff - ref).max() <= 1e-6 * np.abs(ref).max()


def test_free_motion_follows_simulate():
    """0.3 s of free motion in MuJoCo (its integrator, its soft loops, the exported solver
    settings) from a state away from d = 0: the angles follow chain.simulate to 1e-5 rad and the
    loops stay closed to 1e-6 m."""
    chain = io.load(EXAMPLE)
    rng = np.random.default_rng(4)
    q0, qd0 = rng.uniform(-1, 1, chain.n), rng.uniform(-1, 1, chain.n)
    m, d = model(chain, q0)
    d.qpos[:], d.qvel[:] = mjcf.state(chain, q0, qd0)
    adr = [m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"pair{i + 1}_theta")] for i in range(chain.n)]
    steps = int(round(0.3 / m.opt.timestep))
    every = steps // 30
    ts = np.arange(0, steps + 1, every) * m.opt.timestep
    ref = chain.simulate(q0, qd0, ts, limits="ignore").q
    got, loop = [], 0.0
    for k in range(steps + 1):
        if k % every == 0:
            got.append(d.qpos[adr].copy())
        mujoco.mj_step(m, d)
        loop = max(loop, np.abs(d.efc_pos[loop_rows(d)]).max())
    assert np.ptp(ref, axis=0).max() > 0.3  # it moves
    assert np.abs(np.array(got) - ref).max() < 1e-5
    assert loop < 1e-6


def test_options_and_files(tmp_path):
    chain = mixed_chain()
    xml = chain.to_mjcf()
    assert 'contype="0" conaffinity="0"' in xml and 'contype="1"' not in xml
    assert 'contype="1" conaffinity="1"' in chain.to_mjcf(collisions=True)
    out = tmp_path / "m.xml"
    chain.to_mjcf(path=out)
    assert out.read_text() == xml
    with pytest.raises(ValueError, match="exists"):
        chain.to_mjcf(path=out)
    with pytest.raises(ValueError, match="q: expected 3"):
        chain.to_mjcf([0.0, 0.1])
    with pytest.raises(ValueError, match="q"):
        chain.to_mjcf([0.0, np.nan, 0.0])
    with pytest.raises(ValueError, match="range"):
        chain.to_mjcf([0.0, 0.0, 3.0])  # past the general pair's |θ| ≤ 120°
    with pytest.raises(ValueError, match="qd"):
        mjcf.state(chain, np.zeros(3), np.zeros(4))


def test_cli_export(tmp_path, capsys):
    out = tmp_path / "chain.xml"
    assert main(["export", "mjcf", EXAMPLE, "--out", str(out), "--q", "10,20,-30,40", "--deg"]) == 0
    assert "MuJoCo model written" in capsys.readouterr().out
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    chain = io.load(EXAMPLE)
    assert np.allclose(
        d.qpos[[m.jnt_qposadr[j] for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]],
        np.radians([10, 20, -30, 40]),
    )
    assert main(["export", "mjcf", EXAMPLE, "--out", str(out)]) == 2  # exists
    assert "exists" in capsys.readouterr().err
    assert main(["export", "mjcf", EXAMPLE, "--out", str(tmp_path / "b.xml"), "--q", "1,x,2,3"]) == 2
    assert "not a number" in capsys.readouterr().err
    assert main(["export", "mjcf", EXAMPLE, "--out", str(out), "--force"]) == 0
    assert out.read_text() == chain.to_mjcf()


def test_point_mass_link_and_flat_legs():
    """A point-mass link (singular inertia) on one pair with massless legs: MuJoCo's floors leave
    the dynamics as they are; the state at d = 0 (legs flat) is refused."""
    chain = apair.AChain([apair.APair(0.05, 0.05)], a=[0.2], alpha=[0.5], links=[apair.Link(1.2, [0.1, 0.0, 0.05])])
    m, _ = model(chain)
    rng = np.random.default_rng(6)
    for _ in range(3):
        q, qd = rng.uniform(-2.0, 2.0, 1), rng.uniform(-2, 2, 1)
        tau = rng.uniform(-1, 1, 1)
        qacc, _ = closed_loop_qacc(m, *mjcf.state(chain, q, qd), tau)
        ref = chain.forward_dynamics(q, qd, tau)
        assert abs(qacc[hinge_dofs(m, chain)][0] - ref[0]) <= 1e-6 * abs(ref[0])
    with pytest.raises(ValueError, match="d = 0"):
        mjcf.state(chain, [np.pi])


def test_revolute_arm_needs_no_loops():
    """A 6R arm (PUMA-like: twists ±90°, zero lengths) has no equality constraints, so MuJoCo's
    own qacc is exact: it equals forward_dynamics to rounding, which checks the links' inertials."""
    pairs = [apair.APair.revolute() for _ in range(6)]
    links = [apair.Link(1.0 + 0.1 * i, [0.01 * i, 0.0, 0.05], np.diag([0.01, 0.012, 0.005])) for i in range(6)]
    chain = apair.AChain(
        pairs,
        a=[0, 0.43, 0.02, 0, 0, 0],
        alpha=[np.pi / 2, 0, -np.pi / 2, np.pi / 2, -np.pi / 2, 0],
        offset=[0, 0, 0.15, 0.43, 0, 0.05],
        theta_offset=[0, 0.2, 0, 0, 0, np.pi],
        links=links,
    )
    m, d = model(chain)
    assert m.neq == 0 and m.nq == 6
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd, tau = rng.uniform(-3, 3, 6), rng.uniform(-1, 1, 6), rng.uniform(-2, 2, 6)
        d.qpos[:], d.qvel[:] = mjcf.state(chain, q, qd)
        d.ctrl[:] = tau
        mujoco.mj_forward(m, d)
        ref = chain.forward_dynamics(q, qd, tau)
        assert np.abs(d.qacc - ref).max() <= 1e-10 * np.abs(ref).max()
