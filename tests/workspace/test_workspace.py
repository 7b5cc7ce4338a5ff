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
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def arm(L1, L2):
    """A 3R arm (vertical axis, then two parallel axes): its origin reaches the spherical shell
    |L1 − L2| ≤ r ≤ L1 + L2."""
    return apair.AChain([R(), R(), R()], [0.0, L1, L2], [math.pi / 2, 0.0, 0.0])


@pytest.mark.slow
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
    for path, make, magic in (
        (tmp_path / "w.png", lambda p: ws.plot(p), b"\x89PNG"),
        (tmp_path / "c.png", lambda p: chain_picture(chain, q, p), b"\x89PNG"),
        (tmp_path / "a.gif", lambda p: pair_animation(chain.pairs[0], p, frames=6), b"GIF8"),
    ):
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
    f.write_text(
        '[[joint]]\npair = "revolute"\na = 0\nalpha_deg = 90\n[[joint]]\npair = "revolute"\na = 0.3\nalpha = 0\n'
        '[[joint]]\npair = "revolute"\na = 0.2\nalpha = 0\n'
    )
    assert main(["workspace", str(f), "--samples", "8000", "--resolution", "10", "--plot", str(out)]) == 0
    cap = capsys.readouterr()
    assert "workspace volume" in cap.out and "batches" in cap.err and out.stat().st_size > 1000
    assert main(["workspace", str(f), "--samples", "8000", "--plot", str(out)]) == 2
    assert "exists" in capsys.readouterr().err


# ----------------------------------------------------------------------------- curves and surfaces
REV = apair.APair.revolute()


@pytest.mark.parametrize(
    "chain, dimension, exact",
    [
        (apair.AChain([REV], [0.3], [0.0]), 1, 2 * np.pi * 0.3),  # a circle
        (apair.AChain([REV, REV], [0.3, 0.1], [0.0, 0.0]), 2, np.pi * (0.4**2 - 0.2**2)),  # a planar annulus
        (apair.AChain([REV, REV], [0.0, 0.3], [np.pi / 2, 0.0]), 2, 4 * np.pi * 0.3**2),  # a sphere
        (apair.AChain([REV, REV], [0.3, 0.0], [np.pi / 2, 0.0]), 1, 2 * np.pi * 0.3),  # joint 2 moves nothing
    ],
)
def test_curves_and_surfaces_report_dimension_and_measure_not_a_volume(chain, dimension, exact):
    ws = chain.workspace(samples=120_000 if dimension == 2 else 12_000, seed=3)
    assert ws.dimension == dimension and ws.volume is None and ws.volume_error is None
    assert abs(ws.measure - exact) <= 0.06 * exact
    assert ("curve" if dimension == 1 else "surface") in ws.summary and "volume" in ws.summary


def test_cli_workspace_of_a_one_joint_chain(tmp_path, capsys):
    f = tmp_path / "one.toml"
    f.write_text('[[joint]]\npair = "revolute"\na = 0.3\nalpha = 0\n')
    assert main(["workspace", str(f), "--samples", "8000", "--quiet", "--plot", str(tmp_path / "w.png")]) == 0
    out = capsys.readouterr().out
    assert "a curve (dimension 1, no volume)" in out and "length" in out


def test_every_cross_section_shows_its_boundary_voxels():
    from apair.plots import section

    for chain in (arm(0.3, 0.2), apair.load(EXAMPLES / "4a_chain.toml")):
        ws = chain.workspace(samples=20_000, resolution=12)
        for axis in range(3):
            layer, slab, edge = section(ws, axis)
            assert edge.sum() > 0 and slab.sum() > 0, axis


def test_chain_picture_is_fit_for_a_paper(tmp_path, monkeypatch):
    """Equal aspect, labelled axes with units, base and end effector marked, filled plates, legs as
    wide as their radius."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from apair import plots

    captured = {}
    monkeypatch.setattr(plt, "close", lambda fig: captured.setdefault("fig", fig))
    thick = apair.APair(0.05, 0.04, leg_radius=0.003)
    chain = apair.AChain([thick, apair.APair(0.05, 0.04)], [0.1, 0.1], [np.pi / 2, 0.0])
    plots.chain_picture(chain, [0.3, 0.2], tmp_path / "c.png")
    ax = captured["fig"].axes[0]
    assert ax.get_box_aspect() is not None and np.allclose(ax.get_box_aspect() / ax.get_box_aspect()[0], 1)
    spans = [np.ptp(lim) for lim in (ax.get_xlim(), ax.get_ylim(), ax.get_zlim())]
    assert np.allclose(spans, spans[0])
    assert [ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel()] == ["x [m]", "y [m]", "z [m]"]
    assert {t.get_text() for t in ax.get_legend().get_texts()} >= {"base", "end effector"}
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    plates = [c for c in ax.collections if isinstance(c, Poly3DCollection)]
    assert len(plates) == 1 and len(plates[0].get_paths()) == 4  # two pairs, two plates each
    widths = sorted({round(line.get_linewidth(), 3) for line in ax.lines if line.get_color() == "C0"})
    assert len(widths) == 2 and widths[-1] > 2 * widths[0]  # the thick legs drawn thicker


def test_repr_in_plot_titles_shows_the_leg_data():
    p = apair.APair(0.05, 0.04, leg_radius=0.002)
    assert "leg_radius=0.002" in repr(p)


@pytest.mark.parametrize("seed", range(4))
def test_surface_measure_from_sparse_samples_is_positive(seed):
    """Few samples for a surface (3000 at resolution 8): the voxel size grows until the samples
    fill the voxels, so the length-0 extrapolation never goes negative (it gave −4.8e-5 m² for this
    RA chain's surface). Its area is checked against the same chain sampled densely."""
    pairs = [REV, apair.APair(0.010957233721340689, 0.007323815019344117)]
    chain = apair.AChain(pairs, [0.039265401535042994, 0.0], np.radians([-57.6, 129.24]), [0.0, 0.0], [0.0, -0.93])
    coarse = chain.workspace(samples=3000, resolution=8, rounds=1, seed=seed)
    sparse = chain.workspace(samples=3000, rounds=1, seed=seed)
    dense = chain.workspace(samples=120_000, seed=seed)
    assert coarse.dimension == sparse.dimension == dense.dimension == 2
    assert 0.5 * dense.measure <= coarse.measure <= 1.5 * dense.measure  # voxels 1/8 of the size
    assert 0.85 * dense.measure <= sparse.measure <= 1.15 * dense.measure
