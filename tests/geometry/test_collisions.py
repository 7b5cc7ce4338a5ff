"""Collision limits of A-pairs: exact root isolation checked against dense scans of the clearance."""

from __future__ import annotations

import math

import numpy as np
import pytest

import apair
from apair import collisions as C


def test_segment_distance_against_brute_force():
    """The clamped closest-point formula against a fine grid over both segment parameters."""
    rng = np.random.default_rng(3)
    grid = np.linspace(0.0, 1.0, 801)
    for _ in range(30):
        P0, P1, Q0, Q1 = rng.normal(size=(4, 3))
        if rng.random() < 0.3:
            Q1 = Q0 + 2.5 * (P1 - P0)  # parallel segments
        A = P0 + grid[:, None] * (P1 - P0)
        B = Q0 + grid[:, None] * (Q1 - Q0)
        brute = np.linalg.norm(A[:, None] - B[None], axis=-1).min()
        exact = C.segment_distance(P0, P1, Q0, Q1)
        assert exact <= brute + 1e-12 and brute - exact < 1e-5


def _scan(pair, sign, stop):
    """First θ (in direction sign) where the clearance reaches zero: a grid of 4001 points, then
    bisection to 1e-13 — independent of the polynomials."""

    def clearance(th):
        legs, plate = C.clearances(pair, np.asarray(th))
        return np.minimum(legs.min(axis=-1), plate)

    th = sign * np.linspace(0.0, stop, 4001)[1:]
    f = clearance(th)
    k = int(np.argmax(f <= 0))
    assert f[k] <= 0, "no touch within the scanned range"
    lo, hi = (th[k - 1] if k else 0.0), th[k]
    while abs(hi - lo) > 1e-13:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if clearance(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def random_pair(rng, kind):
    rb, rp = rng.uniform(0.03, 0.1, 2)
    if kind == "sinusoidal":
        pair = apair.APair(rb, rp)
    else:
        lo = math.sqrt(max(rb**2 + rp**2 / 4 - rb * rp, 0.0))
        pair = apair.APair(rb, rp, leg_length=lo + rng.uniform(0.01, 1.5) * (rb + rp))
    free = C.clearances(pair, np.array(0.0))[0].min()
    return apair.APair(
        rb,
        rp,
        None if kind == "sinusoidal" else pair.leg_lengths[0],
        leg_radius=rng.uniform(0.0, 0.45) * free,
        thickness=rng.uniform(0.0, 0.95) * pair.translation(0.0),
    )


@pytest.mark.parametrize("kind", ["sinusoidal", "general"])
def test_limits_agree_with_a_dense_scan(kind):
    rng = np.random.default_rng(17 if kind == "sinusoidal" else 18)
    seen = set()
    for _ in range(12):
        pair = random_pair(rng, kind)
        lim = pair.collision_limits()
        seen.add(lim.what.split()[0])
        stop = min(pair.theta_limit or 2 * math.pi, 2 * math.pi) * (1 - 1e-12)
        for sign, value in ((1, lim.theta_max), (-1, lim.theta_min)):
            if math.isinf(value):
                legs, plate = C.clearances(pair, sign * np.linspace(0, stop, 4001))
                assert np.minimum(legs.min(axis=-1), plate).min() > 0
                continue
            assert abs(_scan(pair, sign, stop) - value) < 1e-9, (pair, lim)
        # at the limit the reported bodies touch
        for value in (lim.theta_max, lim.theta_min):
            if math.isinf(value):
                continue
            legs, plate = C.clearances(pair, np.array(value))
            assert min(legs.min(), plate) == pytest.approx(0.0, abs=1e-12)
        if lim.what.startswith("legs"):
            i, j = (int(k) - 1 for k in lim.what.split()[1::2])  # legs are numbered from 1
            th = lim.theta_max if lim.theta_max <= -lim.theta_min else lim.theta_min
            pts = pair.leg_endpoints(th)
            gap = C.segment_distance(pts[i, 0], pts[i, 1], pts[j, 0], pts[j, 1])
            assert gap == pytest.approx(2 * pair.leg_radius, rel=1e-9)
    assert seen == {"legs", "plates"}  # both kinds of first touch were exercised


def test_thin_legs_and_thin_plates():
    """Without radius or thickness the sinusoidal pair stops where the plates meet (d = 0, θ = ±π)
    unless two leg axes cross first."""
    pair = apair.APair(0.05, 0.05)
    lim = pair.collision_limits()
    assert lim.theta_max <= math.pi + 1e-12 and lim.theta_min >= -math.pi - 1e-12
    assert lim.theta_max == pytest.approx(-lim.theta_min, abs=1e-9)  # the pair is mirror symmetric


def test_plates_limit_in_closed_form():
    """Thick plates and thin legs: the plates touch at h cos(θ/2) = τ."""
    pair = apair.APair(0.05, 0.02, thickness=0.04)
    lim = pair.collision_limits()
    assert lim.what == "plates"
    assert lim.theta_max == pytest.approx(2 * math.acos(0.04 / pair.amplitude), abs=1e-12)
    assert lim.theta_min == pytest.approx(-lim.theta_max, abs=1e-12)


def test_revolute_pairs_are_free():
    assert apair.APair.revolute().collision_limits() == (-math.inf, math.inf, "none")


def test_bad_radii_and_thickness():
    with pytest.raises(ValueError, match="leg_radius"):
        apair.APair(0.05, 0.05, leg_radius=-0.001)
    with pytest.raises(ValueError, match="leg_radius.*cannot move"):
        apair.APair(0.05, 0.05, leg_radius=0.05).collision_limits()
    with pytest.raises(ValueError, match="thickness.*cannot move"):
        apair.APair(0.05, 0.05, thickness=0.2).collision_limits()
    with pytest.raises(ValueError, match="thickness"):
        apair.APair(0.05, 0.05, thickness=float("nan"))


def test_chain_limits_from_pairs_and_files(tmp_path):
    pair = apair.APair(0.05, 0.05, leg_radius=0.002)
    chain = apair.AChain([pair, apair.APair.revolute()], [0.2, 0.1], [0.5, 0.0])
    lim = pair.collision_limits()
    assert np.allclose(chain.limits, [[lim.theta_min, lim.theta_max], [-math.pi, math.pi]])
    narrow = apair.AChain([pair, apair.APair.revolute()], [0.2, 0.1], [0.5, 0.0], limits=[(-0.5, 0.5), None])
    assert np.allclose(narrow.limits[0], [-0.5, 0.5])
    with pytest.raises(ValueError, match=r"limits\[0\].*collision-free"):
        apair.AChain([pair], [0.2], [0.5], limits=[(-4.0, 0.5)]).limits  # noqa: B018 (the access raises)
    with pytest.raises(ValueError, match=r"limits\[0\]"):
        apair.AChain([pair], [0.2], [0.5], limits=[(0.5, -0.5)])
    f = tmp_path / "c.toml"
    f.write_text(
        '[[joint]]\npair = "sinusoidal"\nbase_radius = 0.05\nplatform_radius = 0.05\nleg_radius = 0.002\n'
        "thickness = 0.001\nlimits_deg = [-30, 45]\na = 0.2\nalpha = 0.5\n"
    )
    c = apair.load(f)
    assert np.allclose(c.limits, [[-math.pi / 6, math.pi / 4]]) and c.pairs[0].thickness == 0.001
    f.write_text(f.read_text().replace("limits_deg = [-30, 45]", "limits = [-1.0]"))
    with pytest.raises(ValueError, match="limits"):
        apair.load(f)


def test_clearance_plot_and_cli(tmp_path, capsys):
    from apair.cli import main
    from apair.plots import clearance

    pair = apair.APair(0.05, 0.04, leg_radius=0.003)
    out = clearance(pair, tmp_path / "c.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="exists"):
        clearance(pair, out)
    f = tmp_path / "c.toml"
    f.write_text(
        '[[joint]]\npair = "sinusoidal"\nbase_radius = 0.05\nplatform_radius = 0.04\nleg_radius = 0.003\n'
        'a = 0.2\nalpha = 0.5\n[[joint]]\npair = "revolute"\na = 0.1\nalpha = 0\n'
    )
    assert main(["limits", str(f), "--plot", str(tmp_path / "d.png")]) == 0
    text = capsys.readouterr().out
    lim = pair.collision_limits()
    assert f"{math.degrees(lim.theta_max):+10.4f}" in text and lim.what in text and "-180.0000" in text
    assert (tmp_path / "d.png").stat().st_size > 1000
    assert main(["limits", str(f), "--plot", str(tmp_path / "d.png")]) == 2  # no silent overwrite
    assert main(["limits", str(f), "--plot", str(tmp_path / "d.png"), "--force"]) == 0


def test_ik_keeps_or_marks_solutions_by_the_limits():
    pair = apair.APair(0.1, 0.05, leg_radius=0.002)
    chain = apair.AChain([pair, apair.APair(0.05, 0.025, leg_radius=0.001)], [0.3, 0.2], [1.1, 0.0])
    lim = chain.limits
    inside = np.array([0.5 * lim[0, 1], 0.3 * lim[1, 0]])
    outside = np.array([0.5 * (lim[0, 1] + math.pi), 0.2])  # beyond joint 1's collision limit
    assert chain.within_limits(np.stack([inside, outside])).tolist() == [True, False]
    for q, kept in ((inside, 1), (outside, 0)):
        T = chain.fk(q)
        assert np.abs(chain.ik(T) - q).max(axis=1).min() < 1e-8
        assert len(chain.ik(T, within_limits=True)) == kept
