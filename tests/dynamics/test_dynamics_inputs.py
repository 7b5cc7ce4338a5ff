"""Dynamics inputs: Link, links, gravity, states, simulate, the single-pair API, chain files with
inertia, and the worked example."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import apair

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"mass": -1.0}, r"^mass: must be >= 0"),
        ({"mass": np.nan}, r"^mass:"),
        ({"mass": 1.0, "com": [0, 0]}, r"^com: expected shape \(3,\)"),
        ({"mass": 1.0, "com": [0, np.inf, 0]}, r"^com:"),
        ({"mass": 1.0, "inertia": np.eye(2)}, r"^inertia: expected shape \(3, 3\)"),
        ({"mass": 1.0, "inertia": [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]}, r"^inertia: must be symmetric"),
        ({"mass": 1.0, "inertia": np.diag([1.0, 1.0, -0.1])}, r"^inertia: must be positive semi-definite"),
        ({"mass": 1.0, "inertia": np.diag([0.1, 0.1, 1.0])}, r"^inertia: .*triangle inequality"),
        ({"mass": 1.0, "inertia": [[1, 0, 0], [0, 1, 0], [0, 0, np.nan]]}, r"^inertia:"),
    ],
)
def test_link_rejects(kwargs, match):
    with pytest.raises(ValueError, match=match):
        apair.Link(**kwargs)


def test_link_accepts_physical_bodies():
    rod = apair.Link(2.0, [0, 0, 0.5], np.diag([1 / 6, 1 / 6, 0.0]))  # a thin rod: I_zz = 0
    assert rod.as_row().tolist() == [2.0, 0, 0, 0.5, 1 / 6, 1 / 6, 0.0, 0, 0, 0]
    assert apair.Link(0.0).inertia.shape == (3, 3)


def chain2(**kw):
    pairs = [apair.APair(0.1, 0.1, leg_mass=0.1), apair.APair.revolute()]
    links = [
        apair.Link(1.0, [0, 0, 0.05], np.diag([0.01, 0.01, 0.02])),
        apair.Link(0.5, [0.1, 0, 0], np.diag([0.001, 0.002, 0.002])),
    ]
    args = dict(links=links)
    args.update(kw)
    return apair.AChain(pairs, [0.3, 0.2], [np.pi / 2, 0.0], **args)


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"links": [apair.Link(1.0)]}, r"^links: expected 2 links"),
        ({"links": [apair.Link(1.0), "x"]}, r"^links\[1\]: expected a Link"),
        ({"links": 3}, r"^links: expected a sequence"),
        ({"gravity": [0, 0]}, r"^gravity: expected shape \(3,\)"),
        ({"gravity": [0, 0, np.nan]}, r"^gravity:"),
    ],
)
def test_chain_dynamics_arguments(kw, match):
    with pytest.raises(ValueError, match=match):
        chain2(**kw)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda c: c.bias([0.1, 0.2], [0.1]), r"^qd: expected shape"),
        (lambda c: c.inverse_dynamics([0.1, 0.2], [0.1, 0.2], [[0.1, 0.2, 0.3]]), r"^qdd: expected shape"),
        (lambda c: c.inverse_dynamics(np.zeros((3, 2)), np.zeros((4, 2)), np.zeros(2)), r"^qd: batch shape"),
        (lambda c: c.forward_dynamics([0.1, 0.2], [0, 0], [np.inf, 0]), r"^tau:"),
        (lambda c: c.mass_matrix([np.nan, 0.0]), r"^q:"),
        (lambda c: c.simulate([0, 0], [0, 0], [0.0]), r"^t: expected at least two"),
        (lambda c: c.simulate([0, 0], [0, 0], [0.0, 1.0, 0.5]), r"^t: output times must increase"),
        (lambda c: c.simulate([0, 0], [0, 0, 0], [0.0, 1.0]), r"^qd0: expected shape"),
        (lambda c: c.simulate([0, 0], [0, 0], [0.0, 1.0], tau=[1.0]), r"^tau: expected shape"),
        (lambda c: c.simulate([0, 0], [0, 0], [0.0, 1.0], tau=lambda t, q, qd: np.zeros(3)), r"^tau: the callable"),
        (lambda c: c.simulate([0, 0], [0, 0], [0.0, 1.0], rtol=-1), r"^rtol:"),
    ],
)
def test_dynamics_call_rejects(call, match):
    with pytest.raises(ValueError, match=match):
        call(chain2())


def test_massless_chain_cannot_be_accelerated():
    chain = apair.AChain([apair.APair.revolute()], [0.3], [0.0])
    with pytest.raises(ValueError, match=r"^links: the mass matrix is not positive definite"):
        chain.forward_dynamics([0.0], [0.0], [1.0])


def test_pair_dynamics_inputs():
    p = apair.APair(0.1, 0.1, leg_mass=0.1)
    with pytest.raises(ValueError, match=r"^platform: expected a Link"):
        p.dynamics(0.1, platform="plate")
    with pytest.raises(ValueError, match=r"^qd:"):
        p.dynamics(0.1, qd=np.nan)
    with pytest.raises(ValueError, match=r"^g:"):
        p.dynamics(0.1, g=[1, 2])
    with pytest.raises(ValueError, match=r"^qd: shapes"):
        p.dynamics(np.zeros(3), qd=np.zeros(4))
    out = p.dynamics(np.linspace(-1, 1, 7), qd=1.0)
    assert out.shape == (7, 4)


def test_chain_file_with_inertia(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text("""gravity = [0, 0, -3.7]
[[joint]]
pair = "sinusoidal"
base_radius = 0.1
platform_radius = 0.1
leg_mass = 0.1
a = 0.3
alpha_deg = 90
mass = 2.0
com = [0, 0, 0.05]
inertia = [0.01, 0.01, 0.015, 0.0, 0.0, 0.001]
""")
    chain = apair.load(path)
    np.testing.assert_array_equal(chain.gravity, [0, 0, -3.7])
    assert chain.links[0].mass == 2.0 and chain.links[0].inertia[1, 2] == 0.001
    assert chain.pairs[0].leg_mass == 0.1
    path.write_text(path.read_text().replace("inertia = [0.01, 0.01, 0.015, 0.0, 0.0, 0.001]", "inertia = [1, 2]"))
    with pytest.raises(ValueError, match=r"joint 1\.inertia: expected numbers of shape"):
        apair.load(path)
    path.write_text(path.read_text().replace("inertia = [1, 2]", "inertia = [0.1, 0.1, 1.0]"))
    with pytest.raises(ValueError, match=r"joint 1\.inertia: .*triangle inequality"):
        apair.load(path)


def test_worked_example_writes_its_plot_and_keeps_existing_files(tmp_path):
    out = tmp_path / "pd.png"
    script = ROOT / "examples" / "pair_dynamics.py"
    res = subprocess.run([sys.executable, str(script), str(out)], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert "legs/platform = 0.180" in res.stdout and out.stat().st_size > 10_000
    again = subprocess.run([sys.executable, str(script), str(out)], capture_output=True, text=True)
    assert again.returncode == 2 and "--force" in again.stderr
