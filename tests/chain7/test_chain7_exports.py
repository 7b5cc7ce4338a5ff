"""A 7-joint chain everywhere else: MJCF loaded by MuJoCo (its tip site where fk puts it), the
workspace, the viewer page, chain files and URDF import up to 7 joints and a one-line refusal of 8."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from chain7_robots import panda, panda_path

import apair


def test_mjcf_of_the_panda_loads_in_mujoco() -> None:
    mujoco = pytest.importorskip("mujoco")
    chain = panda().chain
    lim = chain.limits
    q = np.random.default_rng(0).uniform(lim[:, 0] + 0.1, lim[:, 1] - 0.1)
    model = mujoco.MjModel.from_xml_string(chain.to_mjcf(q=q))
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    assert len(hinges) == 7 and model.nkey >= 1
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    assert np.allclose(data.qpos[model.jnt_qposadr[hinges]], q)
    ranges = model.jnt_range[hinges]
    assert np.allclose(ranges, lim, atol=1e-9)
    sites = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, s) for s in range(model.nsite)]
    tool = [s for s in range(model.nsite) if "tool" in (sites[s] or "")]
    if tool:  # the tool site (base and tool frames) at fk's pose
        assert np.abs(data.site_xpos[tool[0]] - chain.fk(q)[:3, 3]).max() < 1e-9


def test_workspace_of_a_seven_joint_chain_runs() -> None:
    chain = panda().chain
    w = chain.workspace(samples=20_000, resolution=12, rounds=1)
    assert w.points.shape[1] == 3 and len(w.points) > 0
    assert 0.5 < w.volume < 5.0  # the Panda reaches about 0.85 m: a ball of that radius is 2.6 m^3
    assert np.all(np.linalg.norm(w.points, axis=1) < 1.3)


def test_viewer_page_of_a_seven_joint_chain() -> None:
    html = panda().chain.to_html(workspace=100)
    assert html.lstrip().lower().startswith("<!doctype html")


def _seven_joint_toml(n: int) -> str:
    joint = '[[joint]]\npair = "revolute"\na = 0.1\nalpha_deg = 90\n'
    return 'name = "seven"\n' + joint * n


def test_chain_files_hold_seven_joints_and_refuse_eight(tmp_path: Path) -> None:
    (tmp_path / "seven.toml").write_text(_seven_joint_toml(7))
    assert apair.load(tmp_path / "seven.toml").n == 7
    (tmp_path / "eight.toml").write_text(_seven_joint_toml(8))
    with pytest.raises(ValueError, match=r"pairs: a chain has 1 to 7 pairs, got 8 \[\[joint\]\] tables") as exc:
        apair.load(tmp_path / "eight.toml")
    assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match=r"^pairs: a chain has 1 to 7 pairs, got 8$"):
        apair.AChain([apair.APair.revolute()] * 8, a=np.zeros(8), alpha=np.zeros(8))


def test_urdf_import_to_panda_link8_and_refusal_of_eight(tmp_path: Path) -> None:
    from apair.urdf import convert

    assert convert(panda_path(), "panda_link8").n == 7
    links = "".join(f'<link name="l{i}"/>' for i in range(9))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        f'<origin xyz="0 0 0.1" rpy="{0.3 * i} 0 0"/><axis xyz="0 0 1"/>'
        '<limit lower="-2" upper="2" effort="1" velocity="1"/></joint>'
        for i in range(1, 9)
    )
    path = tmp_path / "eight.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="eight">{links}{joints}</robot>')
    assert apair.load_urdf(path, "l7").n == 7
    with pytest.raises(ValueError, match=r"^tip: the path from 'l0' to 'l8' has 8 joints .*at most 7.*'l7'") as exc:
        convert(path, "l8")
    assert "\n" not in str(exc.value)
