"""Workspaces: the volume against exact shells, the 2A surface against its variety, Dask runs
against local ones, pictures and the command line."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import apair
from apair.cli import main

R = apair.APair.revolute
EXAMPLES = Path(__file__).parent.parent / "examples"


def arm(L1, L2):
    """A 3R arm (vertical axis, then two parallel axes): its origin reaches the spherical shell
    |L1 − L2| ≤ r ≤ L1 + L2."""
    return apair.AChain([R(), R(), R()], [0.0, L1, L2], [math.pi / 2, 0.0, 0.0])


@pytest.mark.parametrize("L1, L2", [(0.3, 0.3), (0.3, 0.2)])
def test_volume_of_a_spherical_shell_within_its_uncertainty(L1, L2):
    exact = 4 / 3 * math.pi * ((L1 + L2) ** 3 - abs(L1 - L2) ** 3)
    ws = arm(L1, L2).workspace(seed=3)
    assert abs(ws.volume - exact) <= ws.volume_error
    assert ws.volume_error < 0.08 * exact  # and the uncertainty is useful
    r = np.linalg.norm(ws.points, axis=1)
    assert r.max() <= L1 + L2 + 1e-12 and r.min() >= abs(L1 - L2) - 1e-12
    rb = np.linalg.norm(ws.boundary, axis=1)  # boundary voxels lie on the two spheres
    near = np.minimum(np.abs(rb - (L1 + L2)), np.abs(rb - abs(L1 - L2)))
    assert near.max() < 1.8 * ws.voxel
    assert len(ws.history) == 4 and ws.history[-1][0] == len(ws.points)


def test_points_of_a_2a_chain_lie_on_its_variety():
    """The 2A example's workspace poses satisfy the exact variety written by codegen.varieties."""
    chain = apair.load(EXAMPLES / "2a_chain.toml")
    ws = chain.workspace(samples=20_000, resolution=12, poses=True)
    assert ws.poses.shape == (20_000, 8)
    assert np.all(chain.within_limits(ws.q))
    eqs = apair.polynomials.load("variety_2a_chain")
    xs = sp.symbols("x0 x1 x2 x3 y0 y1 y2 y3", real=True)
    for e in eqs.values():
        f = sp.lambdify(xs, e, "numpy")
        size = sum(abs(float(c)) for c in sp.Poly(e, *xs).coeffs())
        assert np.abs(f(*ws.poses.T)).max() / size < 1e-13
    assert np.allclose(np.linalg.norm(ws.poses[:, :4], axis=1), 1.0)


def test_samples_stay_inside_explicit_limits():
    chain = apair.AChain([R(), R(), R()], [0.0, 0.3, 0.2], [math.pi / 2, 0, 0], limits=[(-1, 1), (0, 2), None])
    ws = chain.workspace(samples=8_000, resolution=10, seed=1)
    assert np.all(chain.within_limits(ws.q))
    assert ws.q[:, 0].min() < -0.95 and ws.q[:, 0].max() > 0.95


def test_dask_runs_agree_with_the_local_run():
    from dask.distributed import Client, LocalCluster

    chain = arm(0.3, 0.2)
    kw = dict(samples=8_000, resolution=10, rounds=2, seed=5)
    local = chain.workspace(**kw)
    threads = chain.workspace(engine="threads", **kw)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            remote = chain.workspace(engine=client, **kw)
            by_address = chain.workspace(engine=cluster.scheduler_address, **kw)
    for other in (threads, remote, by_address):
        assert np.array_equal(other.points, local.points) and np.array_equal(other.q, local.q)
        assert other.volume == local.volume and other.volume_error == local.volume_error


def test_bad_workspace_input():
    chain = arm(0.3, 0.2)
    with pytest.raises(ValueError, match="samples"):
        chain.workspace(samples=100)
    with pytest.raises(ValueError, match="resolution"):
        chain.workspace(samples=8000, resolution=2)
    with pytest.raises(ValueError, match="samples"):
        chain.workspace(samples=float("nan"))
    with pytest.raises(ValueError, match="engine"):
        chain.workspace(samples=8000, engine=42)


def test_pictures(tmp_path):
    from apair.plots import chain_picture, pair_animation, segments

    chain = apair.load(EXAMPLES / "4a_chain.toml")
    q = [0.3, -0.5, 0.8, 1.1]
    segs = segments(chain, q)
    links = [s for s in segs if s[2] == "link"]
    assert np.allclose(links[-1][1], chain.fk(q)[:3, 3])  # the drawn chain ends at fk(q)
    assert sum(s[2] == "leg" for s in segs) == 6 * 4
    ws = arm(0.3, 0.2).workspace(samples=8_000, resolution=10)
    for path, make, magic in ((tmp_path / "w.png", lambda p: ws.plot(p), b"\x89PNG"),
                              (tmp_path / "c.png", lambda p: chain_picture(chain, q, p), b"\x89PNG"),
                              (tmp_path / "a.gif", lambda p: pair_animation(chain.pairs[0], p, frames=6), b"GIF8")):
        make(path)
        assert path.read_bytes()[:4] == magic
        with pytest.raises(ValueError, match="exists"):
            make(path)


def test_leg_lengths_in_the_picture_are_the_pairs():
    from apair.plots import segments

    chain = apair.load(EXAMPLES / "4a_chain.toml")
    legs = [np.linalg.norm(b - a) for a, b, kind in segments(chain, [0.3, -0.5, 0.8, 1.1]) if kind == "leg"]
    expected = np.concatenate([p.leg_lengths for p in chain.pairs])
    assert np.allclose(legs, expected)


def test_cli_workspace(tmp_path, capsys):
    out = tmp_path / "w.png"
    f = tmp_path / "arm.toml"
    f.write_text('[[joint]]\npair = "revolute"\na = 0\nalpha_deg = 90\n[[joint]]\npair = "revolute"\na = 0.3\nalpha = 0\n'
                 '[[joint]]\npair = "revolute"\na = 0.2\nalpha = 0\n')
    assert main(["workspace", str(f), "--samples", "8000", "--resolution", "10", "--plot", str(out)]) == 0
    cap = capsys.readouterr()
    assert "workspace volume" in cap.out and "batches" in cap.err and out.stat().st_size > 1000
    assert main(["workspace", str(f), "--samples", "8000", "--plot", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
