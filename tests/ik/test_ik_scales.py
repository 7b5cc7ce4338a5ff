"""Inverse kinematics at every scale (issue 41, items 5, 6, 22): a chain scaled by s has the same
joint solutions at the pose with its translation scaled by s; Study points are projective; poses
far out of reach or overflowing get an honest answer or a one-line ValueError, never NaN or
RuntimeWarnings; float32 poses are accepted."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import apair
from apair.cli import main
from apair.ik import distance, poses
from apair.study import from_matrix

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SCALES = [1e-12, 1e-9, 1e-6, 1.0, 1e3, 1e6, 1e9]
TOL = 1e-9


def scaled(chain: apair.AChain, s: float) -> apair.AChain:
    """The chain with every length (pair radii, link lengths, offsets) times s."""
    pairs = [p if p.kind == "revolute" else apair.APair(p.base_radius * s, p.platform_radius * s) for p in chain.pairs]
    return apair.AChain(pairs, chain.a * s, chain.alpha, chain.offset * s, chain.theta_offset)


def chain_of(name: str) -> apair.AChain:
    if name == "1A":  # the first joint of the 4A example (a = 0, offset 0.2, twist 90°)
        c = apair.load(EXAMPLES / "4a_chain.toml")
        return apair.AChain(c.pairs[:1], c.a[:1] + 0.3, c.alpha[:1], c.offset[:1], c.theta_offset[:1])
    if name == "1A2R":  # mixed: an A-pair and two R-pairs
        c = apair.load(EXAMPLES / "2a_chain.toml")
        pairs = [c.pairs[0], apair.APair.revolute(), apair.APair.revolute()]
        return apair.AChain(pairs, [0.3, 0.25, 0.1], [np.pi / 2, 0.0, 0.7], [0.1, 0.0, 0.05], [0.0, 0.3, 0.0])
    return apair.load(EXAMPLES / f"{name}_chain.toml")


CHAINS = ["1A", "2a", "1A2R", "4a"]
POSES = {n: np.random.default_rng(41 + n).uniform(-np.pi, np.pi, (2, n)) for n in (1, 2, 3, 4)}


def same_angles(A: np.ndarray, B: np.ndarray, chain: apair.AChain, tol: float = 1e-7) -> bool:
    if A.shape != B.shape:
        return False
    per = np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])
    d = np.abs((A[:, None] - B[None] + per / 2) % per - per / 2)  # (a, b, n)
    return bool(np.all(np.any(np.all(d < tol, axis=-1), axis=1)))


def check_exact(chain: apair.AChain, q: np.ndarray, T: np.ndarray, size: float, tol: float = TOL) -> None:
    """fk(q) reproduces T: rotation entries to tol, translations to tol times the chain's size."""
    F = chain.fk(q)
    assert np.abs(F[:, :3, :3] - T[:3, :3]).max() <= tol
    assert np.abs(F[:, :3, 3] - T[:3, 3]).max() <= tol * size


@pytest.fixture(autouse=True)
def no_runtime_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        yield


@pytest.mark.parametrize("name", CHAINS)
def test_scaled_chain_has_the_same_solutions(name):
    """ik(fk(q)) at every scale: the solutions of the unit chain (which contain q), each exact to
    a tolerance that scales with the chain, the same certificate."""
    base = chain_of(name)
    size = poses.length_scale(base)
    for q in POSES[base.n]:
        ref = base.ik(base.fk(q), full=True)
        per = np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in base.pairs])
        assert np.any(np.all(np.abs((ref.q - q + per / 2) % per - per / 2) < 1e-7, axis=1))
        for s in SCALES:
            chain = scaled(base, s)
            T = chain.fk(q)
            sol = chain.ik(T, full=True)
            assert same_angles(sol.q, ref.q, base), (name, s, sol.q, ref.q)
            assert sol.certified == ref.certified and sol.method == ref.method, (name, s)
            check_exact(chain, sol.q, T, s * size)
            assert np.all(sol.error <= TOL)


def test_4a_example_at_the_smallest_scale():
    """At 1e-140 the 4A example was refused as 'not isolated'; at the smallest scale its lengths
    may take (1e-140, or 1e-38 where lengths must be 1e-40 m or more) it has the unit chain's
    solutions."""
    base = chain_of("4a")
    q = POSES[4][0]
    ref = base.ik(base.fk(q))
    for s in (1e-140, 1e-38):
        try:
            chain = scaled(base, s)
        except ValueError as exc:
            assert "outside the range" in str(exc)
            continue
        break
    T = chain.fk(q)
    sols = chain.ik(T)
    assert same_angles(sols, ref, base)
    check_exact(chain, sols, T, s * poses.length_scale(base))


def test_length_scale_is_the_chains_size():
    base = chain_of("4a")
    for s in (1e-30, 1e-9, 1.0, 1e9):
        assert poses.length_scale(scaled(base, s)) == pytest.approx(s * poses.length_scale(base), rel=1e-12)
    assert poses.length_scale(apair.AChain([apair.APair.revolute()] * 2, [0.0, 0.0], [0.5, 0.0])) == 1.0


@pytest.mark.parametrize("factor", [1e160, 1e-160, -1e160, 1e300, 1e-300])
def test_study_point_is_projective(factor):
    """A Study point times any non-zero factor is the same pose: the same solutions, certified."""
    chain = chain_of("4a")
    q = POSES[4][1]
    ref = chain.ik(chain.fk_study(q), full=True)
    assert len(ref.q) >= 1
    sol = chain.ik(chain.fk_study(q) * factor, full=True)
    assert same_angles(sol.q, ref.q, chain) and sol.certified and sol.complex_count == ref.complex_count


def test_huge_study_point_in_the_cli(capsys):
    """`apair ik 4a_chain.toml 1e300 0 0 0 0 0 0 0` is the identity pose (out of this chain's
    reach): answered as unreachable, with no warning and no NaN; and a reachable Study point
    given as 1e300 times itself is solved."""
    chain = chain_of("4a")
    assert chain.ik([1e300, 0, 0, 0, 0, 0, 0, 0], full=True).q.shape == chain.ik(np.eye(4), full=True).q.shape
    code = main(["ik", str(EXAMPLES / "4a_chain.toml"), "1e300", "0", "0", "0", "0", "0", "0", "0"])
    out, err = capsys.readouterr()
    assert code == 1 and err == "" and "unreachable" in out and "nan" not in out.lower()
    study = chain.fk_study(POSES[4][0])
    huge = study * (1e300 / np.abs(study).max())
    code = main(["ik", str(EXAMPLES / "4a_chain.toml"), *[repr(float(x)) for x in huge]])
    out, err = capsys.readouterr()
    assert code == 0 and err == "" and "real solution(s)" in out


@pytest.mark.parametrize("name", CHAINS)
@pytest.mark.parametrize("far", [1e3, 1e300])
def test_far_translation_is_unreachable(name, far):
    """A translation far beyond the chain's reach: no solution, certified, no warning; the same
    for a Study point; the CLI says it is unreachable."""
    chain = chain_of(name)
    T = np.eye(4)
    T[:3, 3] = [far, -far / 2, far / 3]
    sol = chain.ik(T, full=True)
    assert sol.q.shape == (0, chain.n) and sol.certified
    assert sol.method == ("reach bound" if far > 1e6 else "elimination")  # full: complex solutions counted
    assert chain.ik(from_matrix(T)).shape == (0, chain.n)
    assert chain.ik(T, full=True, within_limits=True).q.shape == (0, chain.n)
    dp, dr, q = distance(chain, T)
    assert np.isfinite(dp) and dp > 0.5 * far and np.isfinite(q).all() and np.isfinite(dr)


def test_far_translation_cli(capsys, tmp_path):
    T = np.eye(4)
    T[0, 3] = 1e300
    code = main(["ik", str(EXAMPLES / "4a_chain.toml"), *[repr(float(x)) for x in T.ravel()]])
    out, err = capsys.readouterr()
    assert code == 1 and err == "" and "unreachable" in out and "nan" not in out.lower()


@pytest.mark.parametrize(
    "pose, what",
    [
        (np.array([1e-300, 0, 0, 0, 0, 1e10, 0, 0]), "overflow"),  # translation 2|y|/|x| = 2e310
        (np.array([1e-200, 0, 0, 0, 0, 1e200, 0, 0]), "overflow"),
        (np.array([0.6, 0.8, 0, 0, 0, 0, 1e308, 1e308]), "overflow"),  # |y| finite, 2 y x̃ is not
    ],
)
def test_overflowing_study_point_is_refused(pose, what):
    """A Study point whose translation overflows a double: a one-line ValueError naming T."""
    chain = chain_of("4a")
    with pytest.raises(ValueError, match=rf"^T: .*{what}") as exc:
        chain.ik(pose)
    assert "\n" not in str(exc.value) and "[" not in str(exc.value)


def test_huge_but_finite_study_translation_is_unreachable():
    chain = chain_of("4a")
    sol = chain.ik(np.array([1e-150, 0, 0, 0, 0, 1e150, 0, 0]), full=True)  # translation 2e300
    assert sol.q.shape == (0, 4) and sol.certified


@pytest.mark.parametrize("name", CHAINS)
def test_float32_pose_is_accepted(name):
    """A float32 pose (matrix or Study point) is solved to float32 precision; its rotation is
    checked at float32 precision, so a pose that is not a rotation is still refused."""
    chain = chain_of(name)
    q = POSES[chain.n][0]
    ref = chain.ik(chain.fk(q))
    for pose in (chain.fk(q).astype(np.float32), chain.fk_study(q).astype(np.float32)):
        sols = chain.ik(pose)
        assert same_angles(sols, ref, chain, tol=1e-4), (sols, ref)
        F = chain.fk(sols)
        assert np.abs(F - chain.fk(q)).max() <= 1e-5
    bad = chain.fk(q).astype(np.float32)
    bad[0, 0] += 1e-3
    with pytest.raises(ValueError, match="^T: the rotation part is not a proper rotation"):
        chain.ik(bad)
    with pytest.raises(ValueError, match="^T: .*float16"):
        chain.ik(chain.fk(q).astype(np.float16))


def test_float64_rotation_check_is_not_loosened():
    chain = chain_of("4a")
    T = chain.fk(POSES[4][0])
    T[0, 0] += 1e-7  # fine for float32, not for float64
    with pytest.raises(ValueError, match="^T: the rotation part is not a proper rotation"):
        chain.ik(T)


def test_lost_candidates_are_not_certified(monkeypatch):
    """Where the elimination loses a candidate (not finite, as an overflow would make it), its
    empty answer proves nothing: a pose near the reach that the local search does not reach is
    not certified unreachable."""
    from apair.ik import solver

    chain = chain_of("4a")
    T = chain.fk(POSES[4][0])
    T[:3, 3] += [0.01, -0.02, 0.015]  # off the 4-dimensional image, within the reach bound
    assert chain.ik(T, full=True).certified  # the elimination's "none" stands
    monkeypatch.setattr(solver.Elimination, "candidates", lambda self, target, cc: [np.full(4, np.nan)])
    chain = chain_of("4a")
    sol = chain.ik(T, full=True)
    assert sol.q.shape == (0, 4) and not sol.certified


@pytest.mark.parametrize("kinds", ["RRRRRR", "ARRRRR"])
def test_scaled_six_joint_chain_has_the_same_solutions(kinds):
    """Six joints (the 6R and the one-A-pair eliminations): the same solutions at every scale,
    each exact; below 1 mm the design was normalised by 1 mm, not by its size, and refused."""
    rng = np.random.default_rng(6)
    pairs = [apair.APair(0.06, 0.05) if k == "A" else apair.APair.revolute() for k in kinds]
    base = apair.AChain(
        pairs, rng.uniform(0.1, 0.5, 6), rng.uniform(-1.5, 1.5, 6), rng.uniform(-0.2, 0.2, 6), rng.uniform(-1, 1, 6)
    )
    size = poses.length_scale(base)
    q = rng.uniform(-np.pi, np.pi, 6)
    ref = base.ik(base.fk(q), full=True)
    assert len(ref.q) >= 1 and ref.certified
    for s in SCALES:
        chain = scaled(base, s)
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert same_angles(sol.q, ref.q, base), (kinds, s)
        assert (sol.method, sol.certified, sol.complex_count) == (ref.method, ref.certified, ref.complex_count)
        check_exact(chain, sol.q, T, s * size)
