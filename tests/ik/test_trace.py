"""The trace test (apair.ik.homotopy.trace): its extended-precision system against the generated kernel, the
augmented system's derivatives, and verdicts that can fail: a complete start set passes, a set
short of one solution fails, a witness set short of its farthest point fails; special designs
(a UR-like arm with 8 solutions) are certified; the verdict is cached and shown by the CLI."""

from __future__ import annotations

import dataclasses

import flint
import numpy as np
import pytest
from apair_test_helpers import arm_toml

import apair
from apair.cli import main as cli
from apair.ik import homotopy
from apair.ik.homotopy import counts as ikcounts
from apair.ik.homotopy import trace

PI = np.pi


def crandn(rng, *shape):
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


@pytest.mark.parametrize("pattern", ["RRRRRR", "ARRARA", "AAAAAA"])
def test_exact_system_matches_the_kernel(pattern):
    """FLINT's DH route and ik_system6 agree at complex points, far out ones included."""
    problem = homotopy.Problem.of(ikcounts.design(pattern))
    rng = np.random.default_rng(len(pattern) + pattern.count("A"))
    for spread in (0.3, 3.0):
        theta = rng.uniform(-PI, PI, 6) + spread * rng.standard_normal(6) * 1j
        P = crandn(rng, 7)
        F = homotopy.system(problem, theta, P, np.zeros(7, complex))[0]
        with flint.ctx.workdps(40):
            G = trace.exact_system(problem, [trace._acb(v) for v in theta], [trace._acb(v) for v in P])
        G = np.array([complex(g.mid()) for g in G])
        assert np.abs(F - G).max() <= 1e-12 * (1 + np.abs(G).max()), (pattern, spread)


@pytest.mark.parametrize("times_lambda", [True, False])
def test_slice_derivatives(times_lambda):
    """∂H/∂(θ, λ) and ∂H/∂s of the augmented system against complex central differences."""
    rng = np.random.default_rng(5)
    problem = homotopy.Problem.of(ikcounts.design("ARRARR"))
    sl = trace.Slice(
        problem,
        crandn(rng, 7),
        crandn(rng, 7),
        crandn(rng, 2, 6),
        crandn(rng, 2, 6),
        complex(crandn(rng, 1)[0]),
        complex(crandn(rng, 1)[0]),
        times_lambda,
    )
    x, s, h = crandn(rng, 1, 7) * 0.5, np.array([0.3 + 0.2j]), 1e-6
    _, J, Hs = sl(x, s)
    for k in range(7):
        e = np.zeros((1, 7), complex)
        e[0, k] = h
        fd = (sl(x + e, s)[0] - sl(x - e, s)[0]) / (2 * h)
        assert np.abs(fd[0] - J[0, :, k]).max() <= 1e-7 * (1 + np.abs(J).max()), k
    fd = (sl(x, s + h)[0] - sl(x, s - h)[0]) / (2 * h)
    assert np.abs(fd[0] - Hs[0]).max() <= 1e-7 * (1 + np.abs(Hs).max())


@pytest.mark.slow
def test_slice_tracker_c_matches_numpy():
    """apair_ik_track_slice and the NumPy tracker on the same slice paths: the same steps and
    endpoints (both modes: the trace family from the start set, a hyperplane move of its images)."""
    if homotopy.tracker.native_in_use() is None:
        pytest.skip("the compiled C kernels are not installed")
    problem = homotopy.Problem.of(ikcounts.design("ARRARR"))
    start = homotopy.prepare(problem)
    rng = np.random.default_rng(3)
    w, ell = homotopy.random_pose(rng), 0.3 * crandn(rng, 2, 6)
    X0 = np.concatenate([start.solutions, np.zeros((start.count, 1))], axis=1)
    family = trace.Slice(problem, start.p0, w, ell, np.zeros_like(ell), 0, 0.7 + 0.2j, True)
    X1, status, _, _ = family.track_once(0.8 + 0.6j, X0, engine="c")
    z, w1, _, _ = trace.coordinates(problem, X1[:, :6])
    ell1 = ell / np.sum(ell[0] * z[0] + ell[1] * w1[0])  # ℓ1 = 1 at the first point, ℓ − 1 = −0.7/λ at the others
    move = trace.Slice(problem, start.p0, w, ell1, ell - ell1, 0, 0, False)
    for sl, X in ((family, X0), (move, X1[:1])):
        c = sl.track_once(0.8 + 0.6j, X, engine="c")
        n = sl.track_once(0.8 + 0.6j, X, engine="numpy")
        assert np.all(c[1] == homotopy.OK) and np.array_equal(c[1], n[1]) and np.array_equal(c[2], n[2])
        assert np.abs(c[0] - n[0]).max() <= 1e-8


@pytest.mark.slow
def test_trace_test_decides():
    """One witness set, three start sets: the complete one passes by many orders of magnitude,
    the one short of a solution fails, and so does the complete one against the witness set short
    of its farthest point (far out in the complex, where double precision alone would hide it)."""
    problem = homotopy.Problem.of(ikcounts.design("RRRRRR", seed=3))
    start = homotopy.prepare(problem)
    assert start.count == 16
    w, ell, W, S = trace.witness_points(problem, start, np.random.default_rng([0, 23]))
    assert len(S) == 16 and len(W) > 100
    full = trace.trace_test(problem, start, witnesses=(w, ell, W, S))
    assert full.passed and full.deviation < 1e-11 and full.witnesses == len(W)
    fewer = trace.trace_test(problem, start, witnesses=(w, ell, W, S[1:]))
    assert not fewer.passed and fewer.deviation > 10 * trace.TRACE_TOL
    far = int(np.argmax(np.abs(W[:, :6].imag).sum(1)))
    assert np.abs(W[far, :6].imag).max() > 5  # far out indeed
    lacking = trace.trace_test(problem, start, witnesses=(w, ell, np.delete(W, far, 0), S))
    assert not lacking.passed and lacking.deviation > 10 * trace.TRACE_TOL


@pytest.mark.slow
def test_missing_start_solutions_are_found():
    """A start set short of three solutions: the trace family's loops carry witnesses back to
    them, and the completed set passes."""
    problem = homotopy.Problem.of(ikcounts.design("ARRRRR", seed=1))
    start = homotopy.prepare(problem)
    assert start.count == 48
    short = dataclasses.replace(start, solutions=start.solutions[3:])
    done = trace.certify(problem, short)
    assert done.count == 48 and done.certified and done.traced and done.runs[-1] == 48
    index = homotopy.Index(problem)
    for x in done.solutions:
        index.add(x)
    assert not any(index.add(x) for x in start.solutions[:3])


@pytest.mark.slow
def test_special_design_is_certified():
    """A UR-like arm (axes 2, 3, 4 parallel, twists of 0 and ±90°, zero lengths): 8 solutions,
    which two monodromy runs could only agree on; the trace test certifies them."""
    chain = apair.AChain(
        [apair.APair.revolute()] * 6,
        [0.0, -0.425, -0.392, 0.0, 0.0, 0.0],
        [PI / 2, 0.0, 0.0, PI / 2, -PI / 2, 0.0],
        [0.089, 0.0, 0.0, 0.109, 0.094, 0.082],
    )
    start = chain.prepare_ik(trace=True)
    assert start.count == 8 and start.traced and start.certified and start.trace < 1e-11
    q = np.array([0.0, PI, 0.3, PI, 0.5, -0.7])
    sol = chain.ik(chain.fk(q), full=True)
    assert sol.certified and np.any(np.all(np.abs((sol.q - q + PI) % (2 * PI) - PI) < 1e-7, axis=1))


@pytest.mark.slow
def test_verdict_is_cached_and_shown(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("APAIR_CACHE", str(tmp_path / "cache"))
    path = arm_toml(tmp_path)
    chain = apair.load(path)
    plain = chain.prepare_ik()
    assert not plain.traced and plain.certified
    assert cli(["ik-prepare", str(path), "--trace", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "start system of 16 complex solutions, certified complete: the trace test passed" in out
    huge = dataclasses.replace(plain, solutions=np.zeros((trace.MAX_SOLUTIONS + 1, 6), complex))
    with pytest.raises(ValueError, match=r"^trace: the start set has 201 complex solutions"):
        trace.certify(homotopy.Problem.of(chain), huge)  # refused before any work
    cached = chain.prepare_ik()  # the traced set replaced the plain one in the cache
    assert cached.traced and cached.certified and cached.witnesses > 100
    assert np.array_equal(cached.solutions, plain.solutions)
