"""Base and tool frames (issue 38) in chain files ([base], [tool]), the MuJoCo export and the
viewer's data."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from test_frames_kinematics import pair_of_chains, random_q

import apair
from apair import io, view

FILE = """
name = "framed"
gravity = [0.5, -1.0, -9.81]
[base]
xyz = [0.1, -0.2, 0.75]
rpy = [0.3, -0.2, 1.2]
[tool]
xyz = [0.0, 0.02, 0.12]
rpy_deg = [0, 90, 45]
[[joint]]
pair = "sinusoidal"
base_radius = 0.06
platform_radius = 0.05
a = 0.0
alpha_deg = 90
offset = 0.2
mass = 2.0
com = [0.0, -0.05, 0.0]
inertia = [0.01, 0.008, 0.01]
[[joint]]
pair = "revolute"
a = 0.35
alpha = 0
mass = 1.0
inertia = [0.004, 0.03, 0.03]
"""


def expected(xyz, rpy):
    """The transform of xyz and URDF rpy, by scipy (extrinsic x, y, z)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    T[:3, 3] = xyz
    return T


def test_file_equals_api_chain():
    chain = io.loads(FILE)
    B = expected([0.1, -0.2, 0.75], [0.3, -0.2, 1.2])
    T = expected([0.0, 0.02, 0.12], np.radians([0, 90, 45]))
    np.testing.assert_allclose(chain.base, B, atol=1e-15)
    np.testing.assert_allclose(chain.tool, T, atol=1e-15)
    api = apair.AChain(
        [apair.APair(0.06, 0.05), apair.APair.revolute()],
        [0.0, 0.35],
        [math.pi / 2, 0.0],
        [0.2, 0.0],
        links=[
            apair.Link(2.0, [0, -0.05, 0], np.diag([0.01, 0.008, 0.01])),
            apair.Link(1.0, [0, 0, 0], np.diag([0.004, 0.03, 0.03])),
        ],
        gravity=[0.5, -1.0, -9.81],
        base=B,
        tool=T,
    )
    q = np.array([0.4, -1.1])
    np.testing.assert_allclose(chain.fk(q), api.fk(q), atol=1e-14)
    np.testing.assert_allclose(chain.jacobian(q), api.jacobian(q), atol=1e-14)
    np.testing.assert_allclose(chain.gravity_torques(q), api.gravity_torques(q), atol=1e-12)
    # without the tables: no frames (and an empty table is the identity)
    plain = io.loads(FILE.split("[base]")[0] + FILE.split("rpy_deg = [0, 90, 45]\n")[1])
    assert not plain._framed
    empty = io.loads(FILE.replace("xyz = [0.1, -0.2, 0.75]\nrpy = [0.3, -0.2, 1.2]\n", ""))
    np.testing.assert_array_equal(empty.base, np.eye(4))


@pytest.mark.parametrize(
    "old, new, words",
    [
        (
            "rpy = [0.3, -0.2, 1.2]",
            "rpy = [0.3, -0.2, 1.2]\nrpy_deg = [0, 0, 0]",
            "chain: base: give rpy or rpy_deg, not both",
        ),
        ("rpy = [0.3, -0.2, 1.2]", "rpx = [0.3, -0.2, 1.2]", "chain: base: unknown key rpx; did you mean rpy?"),
        ("rpy = [0.3, -0.2, 1.2]", "rpy = [0.3, -0.2, 90]", "chain: base.rpy: [0.3, -0.2, 90] is more than a turn"),
        ("xyz = [0.1, -0.2, 0.75]", "xyz = [0.1, -0.2]", "chain: base.xyz: expected numbers of shape (3,)"),
        ("xyz = [0.1, -0.2, 0.75]", "xyz = [0.1, -0.2, nan]", "chain: base.xyz: expected a finite number"),
        ("xyz = [0.1, -0.2, 0.75]", "xyz = [0.1, -0.2, 1e41]", "chain: base.xyz[2]: 1e+41 m is outside the range"),
        ("rpy_deg = [0, 90, 45]", 'rpy_deg = [0, "90", 45]', "chain: tool.rpy_deg: expected numbers of shape (3,)"),
        ("[tool]\n", "tool = 3\n[tol]\n", "chain: unknown key tol; did you mean tool?"),
    ],
)
def test_bad_tables_are_refused(old, new, words):
    assert old in FILE
    with pytest.raises(ValueError) as exc:
        io.loads(FILE.replace(old, new, 1))
    assert str(exc.value).startswith(words), str(exc.value)
    assert "\n" not in str(exc.value)


def test_tables_not_dicts_and_misplaced_keys():
    with pytest.raises(ValueError, match=r"^chain: base: expected a \[base\] table"):
        io.loads("base = [1, 2, 3]\n" + FILE.split("[base]\nxyz = [0.1, -0.2, 0.75]\nrpy = [0.3, -0.2, 1.2]\n")[1])
    bad = FILE.replace("a = 0.35\n", "a = 0.35\nbase = 1\n")
    with pytest.raises(ValueError, match="base belongs at the top of the file"):
        io.loads(bad)


mujoco = pytest.importorskip("mujoco")


def _mj(chain, q):
    m = mujoco.MjModel.from_xml_string(chain.to_mjcf(q))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    return m, d


def _site(m, d, name):
    k = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)
    assert k >= 0, name
    return d.site_xmat[k].reshape(3, 3), d.site_xpos[k]


@pytest.mark.parametrize("kinds", [("revolute",), ("sinusoidal", "revolute")])
def test_mjcf_tool_site_is_fk(kinds):
    rng = np.random.default_rng(60 + len(kinds))
    framed, plain, B, T = pair_of_chains(rng, 3, kinds)
    q = random_q(rng, framed)
    m, d = _mj(framed, q)
    R, p = _site(m, d, "tool")
    F = framed.fk(q)
    np.testing.assert_allclose(R, F[:3, :3], atol=1e-12)
    np.testing.assert_allclose(p, F[:3, 3], atol=1e-12)
    R, p = _site(m, d, "end_effector")  # frame n in the world
    Fn = B @ plain.fk(q)
    np.testing.assert_allclose(R, Fn[:3, :3], atol=1e-12)
    np.testing.assert_allclose(p, Fn[:3, 3], atol=1e-12)
    R, p = _site(m, d, "base")
    np.testing.assert_allclose(R, B[:3, :3], atol=1e-12)
    np.testing.assert_allclose(p, B[:3, 3], atol=1e-12)
    np.testing.assert_allclose(m.opt.gravity, framed.gravity)
    # the plain chain's tool site is its end effector
    m0, d0 = _mj(plain, q)
    np.testing.assert_allclose(_site(m0, d0, "tool")[1], plain.fk(q)[:3, 3], atol=1e-12)


def test_mjcf_gravity_torques_with_a_base():
    """MuJoCo's bias force at rest (gravity in the world, frame 0 at the base) is g(θ)."""
    rng = np.random.default_rng(7)
    framed, *_ = pair_of_chains(rng, 4, ("revolute",))
    for _ in range(3):
        q = random_q(rng, framed)
        m, d = _mj(framed, q)
        g = framed.gravity_torques(q)
        np.testing.assert_allclose(d.qfrc_bias, g, rtol=0, atol=1e-7 * max(1.0, np.abs(g).max()))


def test_view_data_carries_the_frames():
    rng = np.random.default_rng(11)
    framed, plain, B, T = pair_of_chains(rng, 2, ("revolute",))
    data = view.chain_data(framed, workspace=50)
    np.testing.assert_array_equal(np.reshape(data["base"], (4, 4)), B)
    np.testing.assert_array_equal(np.reshape(data["tool"], (4, 4)), T)
    pts = np.reshape(data["workspace"], (-1, 3))
    lim = framed.limits
    q = np.random.default_rng(0).uniform(lim[:, 0], lim[:, 1], (50, 2))
    np.testing.assert_allclose(pts, framed.fk(q)[:, :3, 3], rtol=1e-6, atol=1e-6)
    plain_data = view.chain_data(plain)
    np.testing.assert_array_equal(plain_data["base"], np.eye(4).ravel())
    html = framed.to_html()
    assert "kinematics(qs).tool" in html and "chain.base" in html
