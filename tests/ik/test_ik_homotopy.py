"""Inverse kinematics of 5- and 6-joint chains by parameter homotopy (apair.ik.homotopy), the local
solver (AChain.ik_local) and the solution counts (apair.ik.homotopy.counts): round trips on random and
special designs, no false solutions, agreement with a dense multi-start search and with the
eliminations of apair.ik, clear refusals."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from apair_test_helpers import arm_toml

import apair
from apair.cli import main as cli
from apair.ik import elimination1a5r as ik1a5r
from apair.ik import homotopy
from apair.ik.homotopy import counts as ikcounts


def chain_of(pattern: str, rng, special: bool = False) -> apair.AChain:
    """A chain of the pattern; special: twists of 0 and ±90°, zero lengths and offsets (a
    PUMA-like arm: the last three axes meet in a spherical wrist)."""
    n = len(pattern)
    pairs = [apair.APair.revolute() if c == "R" else apair.APair(*rng.uniform(0.05, 0.12, 2)) for c in pattern]
    if special:
        alpha = np.array([np.pi / 2, 0.0, np.pi / 2, -np.pi / 2, np.pi / 2, 0.0])[:n]
        a = np.array([0.0, 0.43, 0.02, 0.0, 0.0, 0.0])[:n]
        c = np.array([0.0, 0.0, 0.15, 0.43, 0.0, 0.1])[:n]
        return apair.AChain(pairs, a, alpha, c)
    return apair.AChain(
        pairs, rng.uniform(0.1, 0.5, n), rng.uniform(-1.5, 1.5, n), rng.uniform(-0.2, 0.2, n), rng.uniform(-1.0, 1.0, n)
    )


@pytest.fixture
def tracked(monkeypatch):
    """chain.ik by the homotopy also where a chain has one A-pair (apair.ik.elimination1a5r would answer)."""
    monkeypatch.setattr(ik1a5r, "applies", lambda problem: False)


def periods(chain):
    return np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])


def contains(sols, q, per, tol=1e-7) -> bool:
    d = np.abs((sols - q + per / 2) % per - per / 2)
    return bool(len(sols)) and bool(np.any(np.all(d < tol, axis=1)))


def test_derived_system_matches_the_dh_route():
    """The homotopy system, its joint derivatives and its pose derivative against the 4×4 DH
    product and complex central differences (mpmath) at a random complex point."""
    from apair.derivations import chain_ik

    assert chain_ik.check_system(2) < 1e-15


def test_6r_has_16_solutions_and_round_trips():
    rng = np.random.default_rng(1)
    for _ in range(2):
        chain = chain_of("RRRRRR", rng)
        start = chain.prepare_ik()
        assert start.count == 16 and start.certified
        for q in rng.uniform(-np.pi, np.pi, (5, 6)):
            T = chain.fk(q)
            sol = chain.ik(T, full=True)
            assert sol.certified and sol.complex_count == 16
            assert contains(sol.q, q, periods(chain))
            assert np.abs(chain.fk(sol.q) - T).max() <= 1e-9  # no false solution
            assert len(sol.q) % 2 == 0  # real solutions of a real pose come in an even number (16 is even)


@pytest.mark.slow
@pytest.mark.parametrize("pattern", ["ARRRRR", "RRARRR", "RARRR", "RRRRA"])
def test_mixed_chains_round_trip(pattern, tracked):
    rng = np.random.default_rng(len(pattern) * 7 + pattern.index("A"))
    chain = chain_of(pattern, rng)
    start = chain.prepare_ik()
    if len(pattern) == 6:
        assert start.count == 48  # one A-pair and five R-pairs (the monodromy count)
    per = periods(chain)
    for q in rng.uniform(-1, 1, (6, chain.n)) * per / 2:
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert contains(sol.q, q, per), (q, sol.q)
        assert np.abs(chain.fk(sol.q) - T).max() <= 1e-9


def test_special_design_at_0_and_pi():
    """A PUMA-like 6R (spherical wrist, twists of 0 and ±90°, zero lengths): its own start set,
    and poses with joints at 0 and π."""
    rng = np.random.default_rng(5)
    chain = chain_of("RRRRRR", rng, special=True)
    start = chain.prepare_ik()
    assert start.count == 8  # a PUMA-type arm: 8 solutions (Pieper's decoupling)
    qs = [
        np.array([0.3, -0.5, 0.4, 0.7, -0.6, 0.2]),
        np.array([0.0, 0.4, np.pi, 0.5, 0.6, 0.0]),
        np.array([np.pi, 0.2, -0.3, 0.0, 1.2, np.pi]),
    ]
    for q in qs:
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert contains(sol.q, q, periods(chain), 1e-6), (q, sol.q)
        assert np.abs(chain.fk(sol.q) - T).max() <= 1e-9


def test_agrees_with_dense_multistart_search():
    """Every solution a dense multi-start least-squares search finds (ik_local from 400 seeds over
    the whole joint range) is among ik's, and ik finds no solution that does not reproduce T."""
    rng = np.random.default_rng(11)
    chain = chain_of("RRRRRR", rng)
    for _ in range(2):
        T = chain.fk(rng.uniform(-np.pi, np.pi, 6))
        sols = chain.ik(T)
        seeds = rng.uniform(-np.pi, np.pi, (400, 6))
        loc = chain.ik_local(T, seeds, tol=1e-10, max_iter=200)
        for q in loc.q[loc.converged]:
            assert contains(sols, q, periods(chain), 1e-6), (q, sols)
        assert loc.converged.sum() > 20


def test_unreachable_poses_give_no_solution():
    rng = np.random.default_rng(3)
    for pattern in ("RRRRRR", "RARRR"):
        chain = chain_of(pattern, rng)
        T = np.eye(4)
        T[:3, 3] = [10.0, 0.0, 0.0]  # beyond the reach
        sol = chain.ik(T, full=True)
        assert sol.q.shape == (0, chain.n)
    chain = chain_of("RARRR", rng)  # a 5-joint chain off its 5-dimensional image
    T = chain.fk(rng.uniform(-1, 1, 5))
    T[:3, 3] += [0.01, -0.02, 0.015]
    assert chain.ik(T).shape == (0, 5)


def test_start_system_is_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("APAIR_CACHE", str(tmp_path))
    chain = chain_of("RRRRRR", np.random.default_rng(2))
    first = chain.prepare_ik()
    files = list((tmp_path / "ik").glob("*.npz"))
    assert len(files) == 1
    again = chain.prepare_ik()
    assert again.seconds == first.seconds and np.array_equal(again.solutions, first.solutions)
    other = chain_of("RRRRRR", np.random.default_rng(3)).prepare_ik()
    assert len(list((tmp_path / "ik").glob("*.npz"))) == 2 and other.count == 16


def test_counts_agree_with_the_eliminations():
    """For n ≤ 4 the stored counts (homotopy, virtual joints) equal the complex counts of the
    independent eliminations of apair.ik at a random pose of a random design."""
    rows = {r["pattern"]: r for r in homotopy.stored_counts()}
    rng = np.random.default_rng(0)
    for pattern in ("R", "A", "RR", "AR", "RRR", "ARR", "RRRR", "ARRA"):
        key = min(pattern, pattern[::-1])
        chain = ikcounts.design(pattern)
        sol = chain.ik(chain.fk(rng.uniform(-1, 1, len(pattern))), full=True)
        assert rows[key]["count"] == sol.complex_count, pattern
    assert rows["RRRRRR"]["count"] == 16 and rows["ARRRRR"]["count"] == 48


def test_start_set_at_the_generic_count_is_certified_by_it():
    """A start set that reaches its pattern's generic count ends there (one run, no check loops)
    and is certified by it; below it (a special design, or a count not known) two runs must agree;
    above it the set is not certified."""
    assert homotopy.generic_count(homotopy.Problem.of(ikcounts.design("ARRRRR"))) == 48
    assert homotopy.generic_count(homotopy.Problem.of(ikcounts.design("RRRRRA"))) == 48  # the reverse
    assert homotopy.generic_count(homotopy.Problem.of(ikcounts.design("ARRRR"))) == 48
    assert homotopy.generic_count(homotopy.Problem.of(ikcounts.design("RRRRA"))) == 0  # virtual joints: not stored
    problem = homotopy.Problem.of(chain_of("RRRRRR", np.random.default_rng(2)))
    start = homotopy.prepare(problem, generic=homotopy.generic_count(problem))
    assert start.count == 16 and start.runs == [16] and start.certified
    assert "generic count 16" in start.how
    plain = homotopy.prepare(problem, generic=17)  # as if the pattern had 17: the runs decide
    assert plain.count == 16 and plain.runs == [16, 16] and plain.certified
    assert plain.how.startswith("two monodromy runs found it")
    special = homotopy.Problem.of(chain_of("RRRRRR", np.random.default_rng(2), special=True))
    wrist = homotopy.prepare(special, generic=homotopy.generic_count(special))
    assert wrist.count == 8 and len(wrist.runs) >= 2 and wrist.certified
    doubled = dataclasses.replace(start, generic=15)
    assert "more solutions than the pattern's generic count 15" in doubled.how


def test_a_path_diverging_on_the_way_to_a_generic_pose_is_tracked_again(monkeypatch):
    """Every solution at a generic pose is finite: a path of a monodromy check loop that diverged
    lost its way and gets a new γ (a special six-A-pair design lost one so and went uncertified)."""
    problem = homotopy.Problem.of(chain_of("RRRRRR", np.random.default_rng(2)))
    start = homotopy.prepare(problem, generic=16)
    real_track, calls = homotopy.track, []

    def track(problem, p0, p1, gamma, rows, **kw):
        e, s, steps, cond = real_track(problem, p0, p1, gamma, rows, **kw)
        calls.append(len(rows))
        if len(calls) == 1:
            s = s.copy()
            s[:3] = homotopy.DIVERGED
        return e, s, steps, cond

    monkeypatch.setattr(homotopy.tracker, "track", track)
    pa = homotopy.random_pose(np.random.default_rng(4))
    _, status = homotopy.segment(problem, start.p0, pa, start.solutions, np.random.default_rng(5), finite=True)
    assert calls == [16, 3] and np.all(status == homotopy.OK)
    calls.clear()
    _, status = homotopy.segment(problem, start.p0, pa, start.solutions, np.random.default_rng(5))
    assert calls == [16] and np.sum(status == homotopy.DIVERGED) == 3  # toward a pose that need not be generic


def test_count_of_a_pattern_is_recomputed():
    """The machinery behind the stored table, run again on small patterns."""
    rows = {r["pattern"]: r for r in homotopy.stored_counts()}
    for pattern in ("RR", "RRRRRR"):
        assert ikcounts.count(pattern)["count"] == rows[pattern]["count"]


def test_ik_local_converges_within_limits_batched():
    rng = np.random.default_rng(4)
    chain = chain_of("ARRRRA", rng)
    q = rng.uniform(-1, 1, (50, 6))
    T = chain.fk(q)
    res = chain.ik_local(T, q + rng.uniform(-0.3, 0.3, q.shape))
    assert res.q.shape == (50, 6) and res.residual.shape == (50,) and res.converged.mean() > 0.95
    ok = res.converged
    assert np.abs(chain.fk(res.q[ok]) - T[ok]).max() <= 1e-10
    # one pose, many seeds (broadcast), and the limits respected
    lim = chain.limits
    seeds = rng.uniform(lim[:, 0], lim[:, 1], (20, 6))
    r2 = chain.ik_local(T[0], seeds)
    assert r2.q.shape == (20, 6)
    assert np.all((r2.q >= lim[:, 0]) & (r2.q <= lim[:, 1]))
    # a general A-pair and n = 2: any chain
    g = apair.AChain([apair.APair(0.05, 0.04, leg_length=0.068), apair.APair.revolute()], [0.2, 0.1], [0.5, 1.0])
    qg = np.array([0.2, 0.3])
    r3 = g.ik_local(g.fk(qg), qg + 0.05)
    assert r3.residual <= 1e-10 and bool(r3.converged)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"T": np.full((4, 4), np.nan)}, r"T: contains NaN"),
        ({"T": np.eye(3)}, r"T: expected a 4x4 transform"),
        ({"q0": np.zeros(5)}, r"q0"),
        ({"q0": np.full(6, 10.0)}, r"q0: joint 1 lies outside chain.limits"),
        ({"max_iter": 0}, r"max_iter: must be >= 1"),
        ({"tol": -1.0}, r"tol"),
        ({"T": np.stack([np.eye(4)] * 3 + [np.diag([1.0, 1.0, -1.0, 1.0])])}, r"not a proper rotation"),
        (
            {"T": np.stack([np.eye(4), np.eye(4) + np.eye(4, k=-3) * 0.5])},
            r"T: last row must be \[0, 0, 0, 1\], got \[0.5",
        ),
    ],
)
def test_ik_local_bad_input(kwargs, message):
    chain = chain_of("RRRRRR", np.random.default_rng(0))
    args = {"T": chain.fk(np.zeros(6)), "q0": np.zeros(6)}
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        chain.ik_local(**args)


def test_refusals():
    rng = np.random.default_rng(6)
    coaxial = apair.AChain([apair.APair.revolute()] * 6, [0.0, 0.3, 0.2, 0.1, 0.2, 0.1], [0.0, 1.0, 0.5, 1.2, 0.7, 0.4])
    with pytest.raises(ValueError, match=r"not isolated|curves"):
        coaxial.ik(coaxial.fk(np.full(6, 0.3)))
    with pytest.raises(ValueError, match=r"start systems are for 5 and 6 joints"):
        chain_of("RRRR", rng).prepare_ik()
    general = apair.APair(0.05, 0.04, leg_length=0.068)
    g = apair.AChain([general] + [apair.APair.revolute()] * 5, [0.2] * 6, [1.0] * 6)
    with pytest.raises(ValueError, match=r"pairs\[0\]: a general A-pair"):
        g.ik(np.eye(4))


def test_cli(tmp_path, capsys):
    path = arm_toml(tmp_path)
    assert cli(["ik-prepare", str(path), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "start system of 16 complex solutions, certified" in out
    assert cli(["show", "ik_counts"]) == 0
    out = capsys.readouterr().out
    assert "RRRRRR" in out and " 16 " in out
    assert cli(["ik-prepare", str(tmp_path / "missing.toml")]) == 2


def test_numpy_tracker_agrees_with_the_c_tracker():
    """The same paths by apair_ik_track (C) and track_numpy (the fallback): the same endpoints."""
    chain = chain_of("RRARRR", np.random.default_rng(8))
    problem = homotopy.Problem.of(chain)
    start = chain.prepare_ik()
    T = chain.fk(np.array([0.3, -0.2, 0.5, 1.0, -0.7, 0.4]))
    p1 = problem.target(T)
    ends = {}
    for engine in ("c", "numpy"):
        end, status, _, _ = homotopy.track(problem, start.p0, p1, np.exp(0.4j), start.solutions[:12], engine=engine)
        ends[engine] = (end, status)
    (ec, sc), (en, sn) = ends["c"], ends["numpy"]
    both = (sc == homotopy.OK) & (sn == homotopy.OK)
    assert both.sum() >= 10
    d = np.abs(homotopy.canonical(problem, ec[both]) - homotopy.canonical(problem, en[both])).max(axis=1)
    assert np.all(d < 1e-6) and np.median(d) < 1e-10  # one solution each (the worst conditioned to ~1e-7)


@pytest.mark.slow
def test_far_out_solutions_are_refined_in_extended_precision():
    """Solutions far out in the complex (|Im θ| > 9) at a generic pose: with the residual in
    extended precision (ik_residual6_wide) the tracker's Newton refines each to the solution that
    Newton at 50 digits (apair.ik.homotopy.trace's independent DH route) confirms, and none is left SINGULAR;
    with double residuals alone it stalls orders of magnitude farther away."""
    flint = pytest.importorskip("flint")
    from apair.ik.homotopy import trace

    problem = homotopy.Problem.of(ikcounts.design("AARRRR"))
    p0, sols, _ = homotopy.monodromy.monodromy(problem, np.random.default_rng(2))
    far = sols[np.abs(sols.imag).max(axis=1) > 9]
    assert len(far) >= 5

    def exact(x0):
        with flint.ctx.workdps(50):
            P, x = [trace._acb(v) for v in p0], [trace._acb(v) for v in x0]
            for _ in range(5):
                G = np.array([complex(v.mid()) for v in trace.exact_system(problem, x, P)])
                _, J, _ = homotopy.system(problem, np.array([complex(v.mid()) for v in x]), p0, np.zeros(7, complex))
                x = [(xi + trace._acb(di)).mid() for xi, di in zip(x, np.linalg.solve(J, -G))]
            return np.array([complex(v.mid()) for v in x])

    worst = {}
    for wide in ((4.0, 4.0), (np.inf, np.inf)):
        end, status, _, _ = homotopy.track(problem, p0, p0, 1.0, far, wide=wide)
        worst[wide] = max(np.abs(e - exact(e)).max() for e in end)
        if wide[0] < np.inf:
            assert np.all(status == homotopy.OK), status
    assert worst[(4.0, 4.0)] < 1e-10 and worst[(np.inf, np.inf)] > 100 * worst[(4.0, 4.0)], worst


@pytest.mark.slow
def test_threads_track_the_same_paths(monkeypatch):
    """The paths shared among threads end where one thread takes them (bit for bit: each path is
    tracked on its own), and a bad APAIR_THREADS is refused."""
    chain = chain_of("ARRRRR", np.random.default_rng(9))
    problem = homotopy.Problem.of(chain)
    start = chain.prepare_ik()
    p1 = problem.target(chain.fk(np.array([0.4, -0.3, 0.2, 0.9, -0.5, 0.1])))
    out = {}
    for threads in ("1", "3"):
        monkeypatch.setenv("APAIR_THREADS", threads)
        out[threads] = homotopy.track(problem, start.p0, p1, np.exp(0.3j), start.solutions)
    for a, b in zip(out["1"], out["3"]):
        assert np.array_equal(a, b)
    monkeypatch.setenv("APAIR_THREADS", "two")
    with pytest.raises(ValueError, match="APAIR_THREADS"):
        homotopy.track(problem, start.p0, p1, np.exp(0.3j), start.solutions)


def test_ik_without_the_c_kernels():
    """With the NumPy backend, n = 6 is solved by the NumPy tracker (slower, the same answer)."""
    from apair import kernels

    chain = chain_of("RRRRRR", np.random.default_rng(9))
    q = np.array([0.4, -0.3, 0.9, -1.2, 0.5, 2.0])
    T = chain.fk(q)
    want = chain.ik(T)
    kernels.set_backend("numpy")
    try:
        got = apair.AChain(chain.pairs, chain.a, chain.alpha, chain.offset, chain.theta_offset).ik(T)
    finally:
        kernels.set_backend(None)
    assert got.shape == want.shape and np.abs(got - want).max() < 1e-9


C_PROGRAM = r"""
#include <math.h>
#include <stdio.h>
#include "apair.h"

int main(void)
{
    /* a 6R chain: dh rows (a, alpha, c, phi) */
    const double dh[24] = {0.1, 1.5, 0.3, 0, 0.4, 0.2, 0, 0, 0.05, 1.4, 0.02, 0, 0, -1.2, 0.4, 0, 0.02, 1.0, 0, 0, 0, 0.3, 0.1, 0};
    const int kind[6] = {0, 0, 0, 0, 0, 0};
    const double pair[12] = {0}, lower[6] = {-3.1, -3.1, -3.1, -3.1, -3.1, -3.1}, upper[6] = {3.1, 3.1, 3.1, 3.1, 3.1, 3.1};
    const double q[6] = {0.3, -0.5, 0.8, 1.1, -0.4, 0.2};
    double law[30], T[16], S[8];
    for (int i = 0; i < 6; i++) apair_law_revolute(q + i, law + 5 * i);
    apair_fk6(law, dh, T);
    apair_fk_study6(law, dh, S);
    /* the local solver from a seed 0.2 rad away, two items sharing the target */
    double seed[12], out[12], res[2];
    int conv[2];
    for (int i = 0; i < 6; i++) { seed[i] = q[i] + 0.2; seed[6 + i] = q[i] - 0.2; }
    apair_ik_chain ch = {6, kind, pair, dh, lower, upper, 0.4};
    if (apair_ik_local(&ch, 2, T, 0, seed, 6, 1e-10, 100, out, res, conv) != 0) return 1;
    /* the tracker on the path from the pose to itself (a unit homotopy): q stays put */
    apair_ik_problem pb = {6, kind, pair, dh};
    apair_ik_options opt;
    apair_ik_default_options(&opt);
    double p[14] = {0}, gamma[2] = {1, 0}, start[12], end[12], cond;
    for (int k = 0; k < 3; k++) p[2 * k] = T[4 * k + 3];
    for (int k = 0; k < 4; k++) p[6 + 2 * k] = S[k];
    for (int i = 0; i < 6; i++) { start[2 * i] = q[i]; start[2 * i + 1] = 0; }
    int status, steps;
    if (apair_ik_track(&pb, &opt, p, p, gamma, 1, start, end, &status, &steps, &cond) != 0) return 2;
    double d = 0;
    for (int i = 0; i < 6; i++) d = fmax(d, fabs(end[2 * i] - q[i]) + fabs(end[2 * i + 1]));
    printf("%d %d %.3e %.3e %d %.3e\n", conv[0], conv[1], res[0], res[1], status, d);
    return !(conv[0] && conv[1] && status == APAIR_PATH_OK && d < 1e-12);
}
"""


@pytest.mark.slow
def test_c_api_of_the_solvers_under_sanitizers(tmp_path):
    """apair_ik_local and apair_ik_track called from C, the solvers (the library's hand-written C, and
    the registry) built with ASan and UBSan. The generated kernels are plain -O0 objects here: the
    driver of tests/generation/test_c_hygiene.py runs every one of them under both sanitizers."""
    import shutil
    import subprocess
    from concurrent.futures import ThreadPoolExecutor
    from pathlib import Path

    if shutil.which("gcc") is None:
        pytest.skip("gcc is required")
    root = Path(__file__).resolve().parents[2]
    cdir = root / "generated" / "c"
    prog = tmp_path / "solvers.c"
    prog.write_text(C_PROGRAM)
    exe = tmp_path / "solvers"
    common = ["-std=c99", "-Wall", "-Wextra", "-Werror", f"-I{cdir}"]
    sanitize = ["-O1", "-fsanitize=address,undefined", "-fno-sanitize-recover=all"]
    sanitized = {p.name for p in (root / "src" / "csrc").glob("*.c")} | {"apair_registry.c", prog.name}
    sources = [prog, *sorted(cdir.glob("*.c"))]
    assert sanitized <= {p.name for p in sources}

    def compile_one(src: Path) -> subprocess.CompletedProcess:
        flags = common + (sanitize if src.name in sanitized else ["-O0"])
        return subprocess.run(
            ["gcc", *flags, "-c", str(src), "-o", str(tmp_path / f"{src.stem}.o")], capture_output=True, text=True
        )

    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(compile_one, sources))
    failed = [r for r in results if r.returncode]
    if failed and any("sanitize" in r.stderr for r in failed):
        pytest.skip("the sanitizer runtimes are not installed")
    assert not failed, failed[0].stderr
    objects = [str(tmp_path / f"{src.stem}.o") for src in sources]
    build = subprocess.run(["gcc", *sanitize, *objects, "-o", str(exe), "-lm"], capture_output=True, text=True)
    if build.returncode and "sanitize" in build.stderr:
        pytest.skip("the sanitizer runtimes are not installed")
    assert build.returncode == 0, build.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout + run.stderr


def test_a_path_that_jumped_is_tracked_again(tracked):
    """A 1A5R design and pose where, at the first γ, the path to the real solution jumped onto
    another path's endpoint (so it came out regular, and only the other path was retried, which then
    met that endpoint): both paths of a shared endpoint must be tracked again, and the round trip
    found (this pose was missed by the bench before)."""
    pairs = [apair.APair(0.0894522450069962, 0.08317438085810323)] + [apair.APair.revolute()] * 5
    chain = apair.AChain(
        pairs,
        [
            0.263635203177209,
            0.18895241699896512,
            0.4816851661181739,
            0.10775141501509339,
            0.191913467375736,
            0.14151345832805196,
        ],
        [
            -0.3218506212560599,
            1.05104389114957,
            -0.5148268530667165,
            0.38861836889957235,
            0.46808403937365384,
            1.1772035292198306,
        ],
        [
            -0.0818416888849614,
            -0.021256176303189822,
            -0.024558618496665297,
            -0.08726532048028118,
            0.16744413665010577,
            -0.11806065323127078,
        ],
        [
            0.6871820774332562,
            0.07303753391445089,
            0.9248489585971429,
            -0.2783536752238869,
            -0.36779126683054164,
            0.40316882447018854,
        ],
    )
    q = np.array(
        [
            -0.5749977310747729,
            1.0259281067603379,
            1.790164090382775,
            2.106829768361326,
            -3.0893720644103655,
            0.8085360585797985,
        ]
    )
    sol = chain.ik(chain.fk(q), full=True)
    per = np.array([4 * np.pi] + [2 * np.pi] * 5)
    d = np.abs((sol.q - q + per / 2) % per - per / 2)
    assert np.any(np.all(d < 1e-7, axis=1)), sol
    assert sol.complex_count == 48 and sol.certified


def test_missing_solutions_are_found_by_chains_in_one_round(monkeypatch):
    """Paths that failed and a path that jumped at the first γ: one retry round, chasing from
    each start whose endpoint is missing to the start whose first-γ endpoint its path reached,
    finds every missing solution (a new γ permutes start and end solutions, so tracking the
    failed starts alone finds known ones again)."""
    chain = ikcounts.design("ARRRRR", seed=2)
    problem = homotopy.Problem.of(chain)
    start = homotopy.prepare(problem, seed=0)
    assert start.count == 48
    T = chain.fk(np.random.default_rng(1).uniform(-1, 1, 6))
    truth = homotopy.solve(problem, start, T)
    assert truth.failed == 0 and len(truth.theta) == 48
    real_track, gammas = homotopy.track, []

    def track(problem, p0, p1, gamma, rows, **kw):
        e, s, steps, cond = real_track(problem, p0, p1, gamma, rows, **kw)
        if not gammas:  # the first γ: 6 paths fail, path 7 jumps onto path 8's endpoint
            s = s.copy()
            s[:6] = homotopy.FAILED
            e = e.copy()
            e[7] = e[8]
        if gamma not in gammas:
            gammas.append(gamma)
        return e, s, steps, cond

    monkeypatch.setattr(homotopy.tracker, "track", track)
    ends = homotopy.solve(problem, start, T)
    assert len(gammas) == 2  # one retry round
    assert ends.failed == 0 and ends.complete == start.certified and len(ends.theta) == 48
    index = homotopy.Index(problem)
    assert all(index.add(t) for t in truth.theta) and not any(index.add(t) for t in ends.theta)


def test_unrefined_endpoints_are_one_solution_within_loose():
    """Endpoints not refined to full accuracy (far out) differ by up to 1e-3 for one solution:
    they are merged within LOOSE, refined ones within SAME, and a refined endpoint takes the place
    of an unrefined one."""
    problem = homotopy.Problem.of(ikcounts.design("AARRRR"))
    x = np.array([0.3 + 11j, -1.0, 2.0, 0.5, -0.2, 1.0 + 0.3j])
    index = homotopy.Index(problem)
    assert index.place(x, loose=True) == (True, 0)
    assert index.place(x + 2e-3, loose=True) == (False, 0)
    assert index.place(x + 2e-3j) == (False, 0) and index.loose == [False]
    assert np.allclose(index.rows[0], x + 2e-3j)
    assert index.place(x + 5e-3j) == (True, 1)  # refined ones differ by more than SAME
    assert index.place(x + 0.05, loose=True)[0]  # distinct beyond LOOSE
    assert index.place(x + (4 * np.pi + 1e-3), loose=True) == (False, 0)  # the real part modulo 4π


def test_tracking_in_a_forked_child(monkeypatch, tracked):
    """A child forked after the parent's tracking threads started makes its own (no hang)."""
    import multiprocessing

    monkeypatch.setenv("APAIR_THREADS", "2")  # a pool in the parent on any machine
    chain = chain_of("ARRRRR", np.random.default_rng(9))
    chain.prepare_ik()
    T = chain.fk(np.array([0.4, -0.3, 0.2, 0.9, -0.5, 0.1]))
    here = chain.ik(T)
    with multiprocessing.get_context("fork").Pool(1) as pool:
        there = pool.apply_async(chain.ik, (T,)).get(timeout=120)
    assert np.array_equal(here, there)


def test_canonical_passes_failed_endpoints_quietly():
    """A failed path's endpoint (NaN, inf) goes through canonical without a RuntimeWarning."""
    problem = homotopy.Problem.of(chain_of("ARRRRR", np.random.default_rng(0)))
    theta = np.array([[np.nan] * 6, [np.inf + 1j] * 6, [7.0 + 0.5j] * 6])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = homotopy.canonical(problem, theta)
    assert np.all(np.isnan(out[:2].real)) and np.allclose(out[2], [7 - 4 * np.pi + 0.5j] + [7 - 2 * np.pi + 0.5j] * 5)
