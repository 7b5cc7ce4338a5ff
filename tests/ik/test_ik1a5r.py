"""The elimination of six-joint chains with one A-pair (apair.ik.elimination1a5r, derivations/chain_ik1a5r.py):
the generated equations at random poses against the DH product, the same solutions as the
homotopy with the A-pair at every joint, roots far out, special designs, 5-joint chains through
the virtual joint, unreachable poses, the fallback."""

from __future__ import annotations

import numpy as np
import pytest

import apair
from apair import kernels
from apair.ik import elimination1a5r as ik1a5r
from apair.ik import homotopy

PI = np.pi


def chain_of(pattern: str, rng, a=None, alpha=None, c=None) -> apair.AChain:
    n = len(pattern)
    pairs = [apair.APair.revolute() if ch == "R" else apair.APair(*rng.uniform(0.05, 0.12, 2)) for ch in pattern]
    a = rng.uniform(0.1, 0.5, n) if a is None else a
    alpha = rng.uniform(-1.5, 1.5, n) if alpha is None else alpha
    c = rng.uniform(-0.2, 0.2, n) if c is None else c
    return apair.AChain(pairs, a, alpha, c, rng.uniform(-1.0, 1.0, n))


def pattern_at(k: int, n: int = 6) -> str:
    return "R" * (k - 1) + "A" + "R" * (n - k)


def periods(chain) -> np.ndarray:
    return np.array([2 * PI if p.kind == "revolute" else 4 * PI for p in chain.pairs])


def contains(sols, q, per, tol=1e-7) -> bool:
    d = np.abs((sols - q + per / 2) % per - per / 2)
    return bool(len(sols)) and bool(np.any(np.all(d < tol, axis=1)))


def among(A: np.ndarray, B: np.ndarray, kind: np.ndarray, tol: float = 1e-6) -> int:
    """How many rows of B are rows of A (R-pair angles modulo 2π, A-pair angles modulo 4π)."""
    w = np.where(kind == 1, 0.5, 1.0)
    return sum(bool(np.any(np.abs(np.exp(1j * w * (A - b)) - 1).max(axis=1) < tol)) for b in B)


def _dh(theta, a, alpha, c, phi, d=0.0):
    ct, st, ca, sa = np.cos(theta + phi), np.sin(theta + phi), np.cos(alpha), np.sin(alpha)
    return np.array(
        [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, c + d], [0, 0, 0, 1]]
    )


@pytest.mark.parametrize("k", [1, 2, 3])
def test_generated_equations_hold_at_random_poses(k):
    """P(C, S) X_{k+1,k+2} = Q X_right from the generated kernel, at poses of the plain DH product
    (docs/conventions.md §3) with A-pair angles over the whole (−2π, 2π]; and nowhere else."""
    rng = np.random.default_rng(k)
    (m1, m2), _, (r1, r2) = ik1a5r._split(k)
    for _ in range(4):
        dh = np.column_stack(
            [rng.uniform(-1, 1, 6), rng.uniform(-3, 3, 6), rng.uniform(-1, 1, 6), rng.uniform(-3, 3, 6)]
        )
        h = rng.uniform(0.05, 0.5)
        theta = rng.uniform(-2 * PI, 2 * PI, 6)
        T = np.eye(4)
        for i in range(6):
            T = T @ _dh(theta[i], *dh[i], d=h * np.cos(theta[i] / 2) if i == k - 1 else 0.0)
        P, Q = kernels.call(f"ik1a5r_equations_{k}", dh, np.array([h]), T)
        cs = lambda i: np.array([1, np.cos(theta[i - 1] + dh[i - 1, 3]), np.sin(theta[i - 1] + dh[i - 1, 3])])
        C, S = np.cos(theta[k - 1] / 2), np.sin(theta[k - 1] / 2)
        basis = np.array([C**i * S**j for i, j in [(i, 0) for i in range(5)] + [(i, 1) for i in range(4)]])
        lhs = P.reshape(14, 81) @ np.kron(basis, np.kron(cs(m1), cs(m2)))
        rhs = Q @ np.kron(cs(r1), cs(r2))
        assert np.abs(lhs - rhs).max() < 1e-12 * (1 + np.abs(lhs).max())
        theta[k - 1] += 0.1  # another A-pair angle: the equations no longer hold
        C, S = np.cos(theta[k - 1] / 2), np.sin(theta[k - 1] / 2)
        basis = np.array([C**i * S**j for i, j in [(i, 0) for i in range(5)] + [(i, 1) for i in range(4)]])
        lhs = P.reshape(14, 81) @ np.kron(basis, np.kron(cs(m1), cs(m2)))
        assert np.abs(lhs - rhs).max() > 1e-6


@pytest.mark.parametrize("k", [1, 3, 5])
def test_the_same_solutions_as_the_homotopy(k):
    """Joint k the A-pair (k = 5: read from the end): the elimination's 48 candidates, the converged
    ones among the homotopy's endpoints, the same real solutions, and chain.ik by elimination."""
    rng = np.random.default_rng(30 + k)
    chain = chain_of(pattern_at(k), rng)
    problem = homotopy.Problem.of(chain)
    start = homotopy.start_system(problem)
    assert start.count == 48
    per = periods(chain)
    for q in rng.uniform(-1, 1, (2, 6)) * per / 2:
        T = chain.fk(q)
        theta = ik1a5r.solve(problem, T)
        assert theta is not None and theta.shape == (48, 6)
        ends = homotopy.solve(problem, start, T)
        # every endpoint the homotopy refined is an elimination root (not the other way round: a
        # path may fail), to 1e-6 where the elimination must refine (|Im θ_A| <= NEAR_REAL)
        regular = ends.theta if ends.singular is None else ends.theta[~ends.singular]
        near = regular[np.abs(regular[:, k - 1].imag) <= ik1a5r.NEAR_REAL]
        assert among(theta, near, problem.kind) == len(near) and len(regular) >= 40
        real, tracked = homotopy.real_angles(problem, theta), homotopy.real_angles(problem, ends.theta)
        assert among(real, tracked, problem.kind) == len(tracked)
        assert len(real) == len(tracked) or not ends.complete
        sol = chain.ik(T, full=True)
        assert sol.method == "elimination" and sol.certified and sol.complex_count == 48
        assert len(sol.q) == len(real) and contains(sol.q, q, per)
        assert np.abs(chain.fk(sol.q) - T).max() <= 1e-9


@pytest.mark.parametrize("k", [1, 2, 3, 4, 5, 6])
def test_round_trips_with_the_a_pair_at_every_joint(k):
    rng = np.random.default_rng(40 + k)
    for _ in range(2):
        chain = chain_of(pattern_at(k), rng)
        per = periods(chain)
        for q in rng.uniform(-1, 1, (2, 6)) * per / 2:
            T = chain.fk(q)
            sol = chain.ik(T, full=True)
            assert sol.method == "elimination" and sol.certified, (k, q)
            assert contains(sol.q, q, per) and np.abs(chain.fk(sol.q) - T).max() <= 1e-9


def test_roots_far_out_stay_unrefined_and_the_real_set_complete():
    """Axes 5 and 6 nearly parallel (α5 ≈ −1°): eight of the 48 solutions lie far out (|Im θ6| ≈ 13)
    where Newton cannot verify them in double precision (the homotopy's start set has only 40);
    they cannot be real, so the real set is still certified, and it is the homotopy's."""
    pairs = [apair.APair.revolute()] * 5 + [apair.APair(0.0745031826908456, 0.06983469217548101)]
    chain = apair.AChain(
        pairs,
        [
            0.21810032223000847,
            0.422430246890233,
            0.45288691088577204,
            0.46043579233104837,
            0.3478431338842776,
            0.4088326243453847,
        ],
        [
            -1.122227522422231,
            -0.4602242503166587,
            0.8607077028463559,
            -0.13568826154326774,
            -0.01660264756828611,
            0.8547098489551814,
        ],
        [
            -0.11058163814423963,
            0.14652618627324432,
            0.09607758334738836,
            -0.16926469181968762,
            -0.03022128978810409,
            0.16657087130195475,
        ],
        [
            -0.45893781484543994,
            -0.9747275141021376,
            -0.6583074597100336,
            0.08601125116470865,
            -0.7962189780280278,
            -0.8919669504739778,
        ],
    )
    problem = homotopy.Problem.of(chain)
    start = homotopy.start_system(problem)
    rng = np.random.default_rng(3)
    for q in rng.uniform(-1, 1, (2, 6)) * periods(chain) / 2:
        T = chain.fk(q)
        theta = ik1a5r.solve(problem, T)
        assert theta is not None
        _, size = homotopy.newton(problem, theta, problem.target(T), 8, 1e-8, 1e-6, 0.25, 30.0)
        far = ~(size <= 1e-6)
        assert far.sum() >= 8 and np.all(np.abs(theta[far, 5].imag) > ik1a5r.NEAR_REAL)
        real, tracked = (
            homotopy.real_angles(problem, theta),
            homotopy.real_angles(problem, homotopy.solve(problem, start, T).theta),
        )
        assert among(real, tracked, problem.kind) == len(tracked) == len(real)
        sol = chain.ik(T, full=True)
        assert sol.method == "elimination" and sol.certified and contains(sol.q, q, periods(chain))


# designs users build, with the A-pair first: (a, α, c)
SPECIAL = {
    "right angles, no offsets": (
        [0.3, 0.4, 0.2, 0.25, 0.15, 0.1],
        [PI / 2, -PI / 2, PI / 2, PI / 2, -PI / 2, PI / 2],
        [0.0] * 6,
    ),
    "axes 2 and 3 parallel": (
        [0.3, 0.4, 0.2, 0.25, 0.15, 0.1],
        [0.7, 0.0, -1.1, 0.9, 1.3, -0.4],
        [0.1, -0.1, 0.05, 0.2, -0.15, 0.07],
    ),
    "intersecting axes (a = 0 at joints 1, 4)": (
        [0.0, 0.4, 0.2, 0.0, 0.15, 0.1],
        [0.7, 0.5, -1.1, 0.9, 1.3, -0.4],
        [0.1, -0.1, 0.05, 0.2, -0.15, 0.07],
    ),
    "PUMA-like": (
        [0.0, 0.43, 0.02, 0.0, 0.0, 0.0],
        [PI / 2, 0.0, PI / 2, -PI / 2, PI / 2, 0.0],
        [0.0, 0.0, 0.15, 0.43, 0.0, 0.1],
    ),
    "millimetre scale": (
        [3e-4, 4e-4, 2e-4, 2.5e-4, 1.5e-4, 1e-4],
        [0.7, 0.5, -1.1, 0.9, 1.3, -0.4],
        [1e-4, -1e-4, 5e-5, 2e-4, -1.5e-4, 7e-5],
    ),
}


@pytest.mark.parametrize("name", list(SPECIAL))
def test_special_designs_round_trip(name):
    """Whichever route answers (the elimination where it certifies, else the homotopy), the round
    trip holds at random poses and with joints at 0, π and the A-pair at ±π and 2π."""
    a, alpha, c = SPECIAL[name]
    scale = 1e-3 if "millimetre" in name else 1.0
    pairs = [apair.APair(0.08 * scale, 0.07 * scale)] + [apair.APair.revolute()] * 5
    chain = apair.AChain(pairs, a, alpha, c)
    rng = np.random.default_rng(len(name))
    qs = list(rng.uniform(-PI, PI, (2, 6))) + [
        np.array([PI, 0.0, PI, 0.3, 0.5, -0.7]),
        np.array([2 * PI, 0.4, 0.0, -1.0, 1.2, PI]),
        np.array([-PI, 0.4, 0.3, PI, 0.8, 0.0]),
    ]
    routes = set()
    for q in qs:
        T = chain.fk(q)
        try:
            sol = chain.ik(T, full=True)
        except ValueError as exc:  # a curve of solutions (PUMA-like wrist at θ5 = 0 or π) is refused
            assert "not isolated" in str(exc) and name == "PUMA-like"
            continue
        routes.add(sol.method)
        assert contains(sol.q, q, periods(chain), 1e-6), (name, q, sol.q)
        assert np.abs(chain.fk(sol.q) - T).max() <= 1e-9
    assert routes


def test_five_joint_chains_through_the_virtual_joint():
    rng = np.random.default_rng(12)
    chain = chain_of("RARRR", rng)
    per = periods(chain)
    for q in rng.uniform(-1, 1, (3, 5)) * per / 2:
        sol = chain.ik(chain.fk(q), full=True)
        assert sol.method == "elimination" and sol.certified and sol.complex_count == 1
        assert contains(sol.q, q, per)
    T = chain.fk(rng.uniform(-PI, PI, 5))
    T[:3, 3] += [0.01, -0.02, 0.015]  # off the 5-dimensional image
    assert chain.ik(T).shape == (0, 5)


def test_unreachable_pose_has_48_complex_and_no_real_solutions():
    chain = chain_of("ARRRRR", np.random.default_rng(2))
    T = np.eye(4)
    T[:3, 3] = [10.0, 0.0, 0.0]
    sol = chain.ik(T, full=True)
    assert sol.q.shape == (0, 6) and sol.method == "elimination" and sol.complex_count == 48 and sol.certified


def test_falls_back_to_the_homotopy_where_it_cannot_certify(monkeypatch):
    """A candidate that cannot be verified (here: not finite, as from a singular step) makes the
    elimination decline; chain.ik then tracks the homotopy and still finds the pose's solution."""
    rng = np.random.default_rng(7)
    chain = chain_of("ARRRRR", rng)
    q = rng.uniform(-PI, PI, 6)
    T = chain.fk(q)
    real = ik1a5r.angles
    monkeypatch.setattr(ik1a5r, "angles", lambda *args: real(*args) * np.nan)
    assert ik1a5r.solve(homotopy.Problem.of(chain), T) is None
    sol = chain.ik(T, full=True)
    assert sol.method == "homotopy" and contains(sol.q, q, periods(chain))


def test_column_divisions_remove_exactly_the_isotropic_factors():
    """apair.ik.pencil.Linearisation on M(τ) = C(τ)·diag(1 + τ², 1 + τ², 1, 1)·S (C random, its first two
    columns of degree 2, the others of degree 4; S a random constant mix): two factors found and
    divided out, the same other eigenvalues as the plain companion, and a polynomial without the
    factor left alone."""
    from apair.ik import pencil

    rng = np.random.default_rng(5)
    C = rng.standard_normal((5, 4, 4))
    C[3:, :, :2] = 0
    S = rng.standard_normal((4, 4))
    D = np.zeros((5, 4, 4))  # C·diag(1 + τ², 1 + τ², 1, 1)
    D += C
    D[2:, :, :2] += C[:3, :, :2]
    M = D @ S
    lin = pencil.Linearisation.of(M, 10)
    assert lin.removed == 2 and lin.size == 4 * 4 - 4
    plain = np.linalg.eigvals(pencil.Linearisation.plain(4, 4).companion(M))
    deflated = np.linalg.eigvals(lin.companion(M))
    rest = plain[np.minimum(np.abs(plain - 1j), np.abs(plain + 1j)) > 1e-6]
    assert len(rest) == len(deflated) == 12
    assert max(np.min(np.abs(deflated - t)) for t in rest) < 1e-8
    assert pencil.Linearisation.of(C @ S, 10).removed == 0
