"""The workspace volume: never negative, converging to figures found without it (an exact shell, a
hit-or-miss count of reachable points), scaling as length³, and its counts bounded."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

import apair
from apair import workspace as W
from apair.cli import main

R = apair.APair.revolute
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FOUR_A = apair.load(EXAMPLES / "4a_chain.toml")


def arm(L1: float, L2: float) -> apair.AChain:
    """A 3R arm (vertical axis, then two parallel axes, every joint a full turn): its origin
    reaches the spherical shell |L1 − L2| ≤ r ≤ L1 + L2."""
    return apair.AChain([R(), R(), R()], [0.0, L1, L2], [math.pi / 2, 0.0, 0.0])


def shell(L1: float, L2: float) -> float:
    return 4 / 3 * math.pi * ((L1 + L2) ** 3 - abs(L1 - L2) ** 3)


class Scaled:
    """A chain with every length times s, made from its positions (fk's translation and the
    Jacobian's position rows times s): the scale range of workspace() itself, beyond the lengths
    an AChain accepts (1e-40 to 1e40 m)."""

    def __init__(self, chain: apair.AChain, s: float) -> None:
        self.chain, self.s = chain, s
        self.pairs, self.limits, self.n = chain.pairs, chain.limits, chain.n

    def fk(self, q):
        T = self.chain.fk(q).copy()
        T[..., :3, 3] *= self.s
        return T

    def jacobian(self, q):
        J = self.chain.jacobian(q).copy()
        J[..., :3, :] *= self.s
        return J


# ----------------------------------------------------------------------------- never negative
@pytest.mark.parametrize("samples", [4000, 8000, 12_000, 40_000])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_volume_of_the_4a_chain_is_never_negative(samples, seed):
    """Too few samples for the voxels left holes in the voxel body, each costing four voxels, and
    gave -1.006 m³ at 4000 samples (CLI defaults)."""
    ws = FOUR_A.workspace(samples=samples, resolution=24, seed=seed)
    assert ws.volume > 0 and 0 < ws.volume_error < math.inf
    assert ws.volume_voxel >= ws.voxel * (1 - 1e-12)
    assert "-" not in ws.summary.split("±")[0]


@pytest.mark.parametrize("seed", [0, 1])
def test_volume_of_a_shell_thinner_than_its_voxels_is_never_negative(seed):
    """A shell 0.02 m thick measured with 0.026 m voxels: the truth within the stated error."""
    ws = arm(0.3, 0.01).workspace(samples=8000, resolution=24, seed=seed)
    assert ws.volume > 0 and ws.volume_error > 0
    assert abs(ws.volume - shell(0.3, 0.01)) <= 3 * ws.volume_error


# ----------------------------------------------------------------------------- convergence
@pytest.mark.parametrize("L1, L2", [(0.3, 0.2), (0.3, 0.3)])
def test_volume_converges_to_the_exact_shell(L1, L2):
    exact = shell(L1, L2)
    errors = []
    for samples in (4000, 32_000, 256_000):
        ws = arm(L1, L2).workspace(samples=samples, resolution=24, seed=4)
        assert 0 < ws.volume and abs(ws.volume - exact) <= 3 * ws.volume_error, samples
        errors.append(ws.volume_error)
    assert errors[0] > errors[1] > errors[2] and errors[2] < 0.15 * exact


def reachable_volume(chain, points: int, seed: int) -> tuple[float, float]:
    """A hit-or-miss volume and its standard error, without voxels: uniform points in a box around
    the reach, each reachable when a damped Gauss-Newton solve for the position alone, from its
    four nearest sampled positions and inside the limits (q = centre + half-width·sin z), meets it
    to 1e-9 m. A miss only undercounts, and only near the boundary."""
    rng = np.random.default_rng(seed)
    lo, hi = chain.limits[:, 0], chain.limits[:, 1]
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    dense = rng.uniform(lo, hi, (400_000, chain.n))
    where = chain.fk(dense)[:, :3, 3]
    pad = 0.05 * (where.max(0) - where.min(0))
    box_lo, box_hi = where.min(0) - pad, where.max(0) + pad
    x = rng.uniform(box_lo, box_hi, (points, 3))
    _, near = cKDTree(where).query(x, k=4)
    target = np.repeat(x, 4, axis=0)
    z = np.arcsin(np.clip((dense[near.ravel()] - mid) / half, -1 + 1e-12, 1 - 1e-12))
    for _ in range(40):
        q = mid + half * np.sin(z)
        e = target - chain.fk(q)[:, :3, 3]
        J = chain.jacobian(q)[:, :3, :] * (half * np.cos(z))[:, None, :]
        JJt = J @ np.swapaxes(J, 1, 2) + 1e-6 * np.eye(3)
        z = z + np.einsum("kij,ki->kj", J, np.linalg.solve(JJt, e[..., None])[..., 0])
    miss = np.linalg.norm(target - chain.fk(mid + half * np.sin(z))[:, :3, 3], axis=1)
    p = float(np.mean(miss.reshape(-1, 4).min(axis=1) < 1e-9))
    box = float(np.prod(box_hi - box_lo))
    return p * box, box * math.sqrt(p * (1 - p) / points)


def test_4a_volume_converges_to_a_hit_or_miss_count():
    reference, ref_err = reachable_volume(FOUR_A, 20_000, seed=11)
    assert ref_err < 0.02 * reference
    errors = []
    for samples in (8000, 40_000, 300_000):
        ws = FOUR_A.workspace(samples=samples, resolution=24, seed=1)
        assert abs(ws.volume - reference) <= 3 * math.hypot(ws.volume_error, ref_err), samples
        errors.append(ws.volume_error)
    assert errors[0] > errors[1] > errors[2] and errors[2] < 0.15 * reference


# ----------------------------------------------------------------------------- scale
@pytest.mark.parametrize("s", [1e-100, 1e-80, 1e-30, 1e-6, 1e6, 1e15, 1e60, 1e100])
def test_volume_scales_as_length_cubed(s):
    """Chains whose lengths an AChain accepts are built scaled; the others go through Scaled."""
    kw = dict(samples=8000, resolution=10, seed=1)
    if 1e-40 <= 0.2 * s and 0.3 * s <= 1e40:
        unit, scaled = arm(0.3, 0.2).workspace(**kw), arm(0.3 * s, 0.2 * s).workspace(**kw)
    else:
        unit, scaled = W.workspace(Scaled(arm(0.3, 0.2), 1.0), **kw), W.workspace(Scaled(arm(0.3, 0.2), s), **kw)
    volume, error = scaled.volume / s**3, scaled.volume_error / s**3
    assert scaled.volume_error > 0 and error > 0
    assert abs(volume - unit.volume) <= error
    assert volume == pytest.approx(unit.volume, rel=1e-9) and error == pytest.approx(unit.volume_error, rel=1e-9)
    assert scaled.voxel / s == pytest.approx(unit.voxel, rel=1e-12)


@pytest.mark.parametrize("s", [1e-110, 1e150])
def test_workspace_whose_volume_is_no_normal_double_is_refused_in_a_line(s):
    with pytest.raises(ValueError, match=r"^chain: the workspace is .* m across") as info:
        W.workspace(Scaled(arm(0.3, 0.2), s), samples=4000, resolution=10)
    assert "\n" not in str(info.value)


def test_cli_workspace_with_a_huge_link_gives_a_message(tmp_path, capsys):
    f = tmp_path / "huge.toml"
    f.write_text(
        '[[joint]]\npair = "revolute"\na = 0\nalpha_deg = 90\n[[joint]]\npair = "revolute"\na = 1e150\nalpha = 0\n'
    )
    assert main(["workspace", str(f), "--samples", "4000", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "Overflow" not in err
    assert err.startswith("apair workspace: error:") and "1e+150" in err


# ----------------------------------------------------------------------------- counts
@pytest.mark.parametrize(
    "kw, message",
    [
        (dict(samples=10**9), r"samples: must be <= 100000000"),
        (dict(samples=10**8, poses=True), r"samples: .* GiB to keep; at most \d+ fit"),
        (dict(resolution=10**6), r"resolution: must be <= \d+"),
        (dict(resolution=3), r"resolution: must be >= 4"),
        (dict(rounds=10**6), r"rounds: must be <= 100"),
        (dict(rounds=0), r"rounds: must be >= 1"),
        (dict(samples=8000, rounds=9), r"samples: at least 9000"),
        (dict(seed=-1), r"seed: must be >= 0"),
        (dict(seed=2**64), r"seed: must be <= \d+"),
    ],
)
def test_counts_are_bounded_with_a_one_line_message(kw, message):
    args = dict(samples=8000, resolution=10) | kw
    with pytest.raises(ValueError, match=message) as info:
        W.workspace(arm(0.3, 0.2), **args)
    assert "\n" not in str(info.value)


def test_cli_refuses_too_many_samples(tmp_path, capsys):
    f = tmp_path / "arm.toml"
    f.write_text('[[joint]]\npair = "revolute"\na = 0.3\nalpha = 0\n[[joint]]\npair = "revolute"\na = 0.2\nalpha = 0\n')
    assert main(["workspace", str(f), "--samples", "1000000000", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "samples" in err and "100000000" in err


def test_a_negative_extrapolation_gives_the_bracket_not_a_negative_volume(monkeypatch):
    """Where the extrapolation to voxel size 0 falls below 0 (a body thinner than its voxels), the
    volume is what is known for certain: between 0 and the occupied voxels' volume."""
    rng = np.random.default_rng(2)
    unit = rng.uniform(0, 1, (20_000, 3)) * [1.0, 1.0, 0.001]  # a thin slab
    monkeypatch.setattr(W, "_estimate", lambda *args: (-0.01, 0.001))
    volume, error, h, _ = W._unit_volume(unit, [10_000, 20_000], resolution=8, seed=0)
    top = W._occupied(unit, h) * h**3
    assert volume == pytest.approx(top / 2) and error == pytest.approx(top / math.sqrt(12))
    assert abs(volume - 0.001) <= 2 * error
