"""Base and tool frames (issue 38): ik and ik_local solve for the tool's pose in the world, the
workspace is of the tool's origin in the world, and the generated code takes the frames."""

from __future__ import annotations

import numpy as np
import pytest
from test_frames_kinematics import pair_of_chains, random_q

import apair
from apair.study import from_matrix


@pytest.mark.parametrize(
    "n, kinds", [(2, ("sinusoidal", "revolute")), (3, ("sinusoidal", "revolute")), (6, ("revolute",))]
)
def test_ik_round_trip(n, kinds):
    """fk(ik(T)) = T for a reachable world pose T, the joint values those of the frameless chain's
    ik of base⁻¹·T·tool⁻¹; a Study point of T gives the same."""
    rng = np.random.default_rng(40 + n)
    framed, plain, B, Tt = pair_of_chains(rng, n, kinds)
    q = random_q(rng, framed)
    T = framed.fk(q)
    sols = framed.ik(T)
    assert len(sols) >= 1
    for s in sols:
        np.testing.assert_allclose(framed.fk(s), T, atol=1e-8)
    assert np.abs(sols - q).max(axis=1).min() < 1e-6  # the pose's own q is among them
    dh = np.linalg.inv(B) @ T @ np.linalg.inv(Tt)
    np.testing.assert_allclose(np.sort(sols, axis=0), np.sort(plain.ik(dh), axis=0), atol=1e-8)
    via_study = framed.ik(from_matrix(T))
    np.testing.assert_allclose(np.sort(via_study, axis=0), np.sort(sols, axis=0), atol=1e-8)
    if n < 6:  # a float32 pose: checked at float32's precision, as without frames
        rounded = framed.ik(T.astype(np.float32))
        assert len(rounded) >= 1 and np.abs(framed.fk(rounded) - T).max() < 1e-5
    full = framed.ik(T, full=True, within_limits=True)
    assert len(full.q) == full.inside.sum()


def test_ik_refuses_bad_poses_with_frames():
    framed, *_ = pair_of_chains(np.random.default_rng(3), 2, ("revolute",))
    with pytest.raises(ValueError, match="^T: "):
        framed.ik(np.eye(3))
    with pytest.raises(ValueError, match="^T: "):
        framed.ik(np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(ValueError, match="^T: "):
        framed.ik_local(np.diag([1.0, 1.0, -1.0, 1.0]), np.zeros(2))
    with pytest.raises(ValueError, match="^T: "):
        framed.ik_local(np.zeros((3, 3)), np.zeros(2))


@pytest.mark.parametrize("n", [3, 6])
def test_ik_local_round_trip(n):
    """From a seed near q the local solver reaches the world pose fk(q): single poses (the native
    fast path after the first call) and batches (the validating path)."""
    rng = np.random.default_rng(50 + n)
    framed, plain, B, Tt = pair_of_chains(rng, n)
    for _ in range(3):
        q = random_q(rng, framed)
        T = framed.fk(q)
        seed = np.clip(q + rng.normal(scale=0.02, size=n), framed.limits[:, 0], framed.limits[:, 1])
        sol = framed.ik_local(T, seed)
        assert sol.converged
        np.testing.assert_allclose(framed.fk(sol.q), T, atol=1e-9)
        lists = framed.ik_local(T.tolist(), seed.tolist())  # the validating path, the same numbers
        np.testing.assert_allclose(lists.q, sol.q, atol=1e-12)
    assert framed._local_ik is not None
    qs = random_q(rng, framed, (4,))
    seeds = np.clip(qs + rng.normal(scale=0.02, size=qs.shape), framed.limits[:, 0], framed.limits[:, 1])
    batch = framed.ik_local(framed.fk(qs), seeds)
    assert batch.converged.all()
    np.testing.assert_allclose(framed.fk(batch.q), framed.fk(qs), atol=1e-9)


def test_workspace_points_are_tool_origins_in_the_world():
    rng = np.random.default_rng(8)
    framed, plain, B, Tt = pair_of_chains(rng, 2, ("revolute",))
    ws = framed.workspace(samples=2000, resolution=8, rounds=1)
    ws0 = plain.workspace(samples=2000, resolution=8, rounds=1)
    assert ws.points.shape == ws0.points.shape
    lim = framed.limits
    q = rng.uniform(lim[:, 0], lim[:, 1], (200, 2))
    want = (B @ plain.fk(q) @ Tt)[:, :3, 3]
    np.testing.assert_allclose(framed.fk(q)[:, :3, 3], want, atol=1e-14)
    # every sampled point is near some world tool point of a dense sampling
    dense = framed.fk(rng.uniform(lim[:, 0], lim[:, 1], (40000, 2)))[:, :3, 3]
    pts = ws.points[:50]
    dist = np.min(np.linalg.norm(pts[:, None, :] - dense[None, :, :], axis=-1), axis=1)
    assert dist.max() < 0.05 * np.ptp(dense, axis=0).max()


def test_generated_code_takes_frames(tmp_path):
    """Code generation no longer refuses frames: the specialised chain keeps them (fk of the tool
    in the world, dynamics with the world's gravity), write_code writes the frames into the code,
    the content hash depends on them; identity frames are no frames."""
    from test_frames_kinematics import random_frame

    from apair import specialise

    rng = np.random.default_rng(9)
    framed, plain, B, Tt = pair_of_chains(rng, 2, ("revolute",))
    q = random_q(rng, framed, (5,))
    fast = framed.specialise(["fk", "gravity_torques"])
    np.testing.assert_allclose(fast.fk(q), B @ plain.fk(q) @ Tt, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast.gravity_torques(q), framed.gravity_torques(q), rtol=0, atol=1e-12)
    assert not np.allclose(fast.gravity_torques(q), plain.gravity_torques(q))  # the base turns gravity
    changed = specialise.write_code(framed, tmp_path / "out", "framed", "framed.toml", kernels=["fk"])
    assert "framed.h" in changed
    header = (tmp_path / "out" / "framed.h").read_text()
    assert "#define framed_BASE {" in header and "framed_fk_dh(" in header
    assert specialise.content_hash(framed, ("fk",)) != specialise.content_hash(plain, ("fk",))
    other = apair.AChain(
        plain.pairs,
        plain.a,
        plain.alpha,
        plain.offset,
        plain.theta_offset,
        links=plain.links,
        gravity=plain.gravity,
        base=B,
        tool=random_frame(rng, 0.2),
    )
    assert specialise.content_hash(other, ("fk",)) != specialise.content_hash(framed, ("fk",))
    identity = apair.AChain(plain.pairs, plain.a, plain.alpha, base=np.eye(4), tool=None)
    bare = apair.AChain(plain.pairs, plain.a, plain.alpha)
    assert specialise.content_hash(identity, ("fk",)) == specialise.content_hash(bare, ("fk",))


def test_cli_codegen_writes_a_chain_file_with_frames(tmp_path, capsys):
    import importlib.util

    from test_frames_files import FILE

    from apair.cli import main

    path = tmp_path / "framed.toml"
    path.write_text(FILE)
    assert main(["codegen", str(path), "--out", str(tmp_path / "out"), "--kernels", "fk,jacobian"]) == 0
    chain = apair.load(path)
    spec = importlib.util.spec_from_file_location("framed_module", tmp_path / "out" / "framed.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    q = random_q(np.random.default_rng(1), chain, (4,))
    np.testing.assert_allclose(module.fk(q), chain.fk(q), rtol=0, atol=1e-12)
    np.testing.assert_allclose(module.jacobian(q), chain.jacobian(q), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(module.BASE, chain.base)
