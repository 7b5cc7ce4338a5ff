"""Base and tool frames (issue 38): ik and ik_local solve for the tool's pose in the world, the
workspace is of the tool's origin in the world, and the generated code refuses frames."""

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


def test_generated_code_refuses_frames(tmp_path):
    framed, plain, *_ = pair_of_chains(np.random.default_rng(9), 2, ("revolute",))
    with pytest.raises(ValueError, match="^base/tool frames are not yet in the generated code; ") as exc:
        framed.specialise()
    assert "\n" not in str(exc.value)
    from apair import specialise

    with pytest.raises(ValueError, match="^base/tool frames are not yet in the generated code; "):
        specialise.write_code(framed, tmp_path / "out", "framed", "framed.toml")
    assert not (tmp_path / "out").exists()
    with pytest.raises(ValueError, match="^base/tool frames are not yet"):
        specialise.content_hash(framed, ("fk",))
    identity = apair.AChain(plain.pairs, plain.a, plain.alpha, base=np.eye(4), tool=None)
    specialise.content_hash(identity, ("fk",))  # identity frames are no frames


def test_cli_codegen_refuses_a_chain_file_with_frames(tmp_path, capsys):
    from test_frames_files import FILE

    from apair.cli import main

    path = tmp_path / "framed.toml"
    path.write_text(FILE)
    capsys.readouterr()
    assert main(["codegen", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "base/tool frames are not yet in the generated code" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()
    plain = tmp_path / "plain.toml"
    plain.write_text(
        FILE.replace("[base]", "[ignored]").split("[ignored]")[0] + FILE.split("rpy_deg = [0, 90, 45]\n")[1]
    )
    assert main(["codegen", str(plain), "--out", str(tmp_path / "ok"), "--kernels", "fk"]) == 0
