"""Inverse kinematics by kinematic mapping (apair.ik): completeness, exactness, clear failures."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

import apair
from apair.ik import elimination4, joints, pencil, poses
from apair.study import conjugate, from_matrix, multiply


def random_chain(rng, n, kinds="s") -> apair.AChain:
    pairs = [
        apair.APair.revolute() if kinds[i % len(kinds)] == "r" else apair.APair(*rng.uniform(0.03, 0.1, 2))
        for i in range(n)
    ]
    return apair.AChain(
        pairs, rng.uniform(0.1, 0.4, n), rng.uniform(-1.5, 1.5, n), rng.uniform(-0.1, 0.1, n), rng.uniform(-1.0, 1.0, n)
    )


def periods(chain):
    return np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])


def contains(sols, q, per, tol=1e-8) -> bool:
    d = np.abs((sols - q + per / 2) % per - per / 2)
    return bool(len(sols)) and bool(np.any(np.all(d < tol, axis=1)))


def assert_reproduce(chain, sols, T, tol=1e-9):
    if len(sols):
        assert np.abs(chain.fk(sols) - T).max() <= tol


def test_round_trip_random_4a_designs():
    """≥ 200 random joint vectors on 40 random 4A designs: ik(fk(q)) contains q, every solution is exact."""
    rng = np.random.default_rng(2026)
    found = 0
    for _ in range(40):
        chain = random_chain(rng, 4)
        for q in rng.uniform(-2 * np.pi, 2 * np.pi, (5, 4)):
            T = chain.fk(q)
            sols = chain.ik(T)
            assert sols.shape[1] == 4
            assert_reproduce(chain, sols, T)
            found += contains(sols, q, periods(chain))
    assert found == 200


@pytest.mark.parametrize(
    "n, kinds",
    [(1, "s"), (1, "r"), (2, "s"), (2, "r"), (2, "sr"), (3, "s"), (3, "rs"), (4, "r"), (4, "sr"), (4, "ssrs")],
)
def test_round_trip_mixed_chains(n, kinds):
    rng = np.random.default_rng(n * 100 + len(kinds))
    for _ in range(8):
        chain = random_chain(rng, n, kinds)
        q = rng.uniform(-np.pi, np.pi, n)
        T = chain.fk(q)
        sols = chain.ik(T)
        assert contains(sols, q, periods(chain))
        assert_reproduce(chain, sols, T)


def test_study_point_input_and_example_chain():
    chain = apair.load("examples/4a_chain.toml")  # parallel axes 2, 3, 4: the degenerate-rotation path
    q = np.array([0.3, -0.5, 0.8, 1.1])
    T = chain.fk(q)
    for pose in (T, chain.fk_study(q), -3.0 * chain.fk_study(q)):
        sols = chain.ik(pose)
        assert contains(sols, q, periods(chain))
        assert_reproduce(chain, sols, T)


def test_generic_counts_are_one_complex_one_real():
    """For generic designs and poses the map from joint space onto its image is birational: the
    elimination finds exactly one complex solution, and it is the real one we started from."""
    rng = np.random.default_rng(11)
    for n, kinds in ((2, "s"), (3, "s"), (4, "s"), (4, "sr")):
        chain = random_chain(rng, n, kinds)
        sol = chain.ik(chain.fk(rng.uniform(-3, 3, n)), full=True)
        assert (len(sol.q), sol.complex_count) == (1, 1)


def test_a_pair_at_half_turn_gives_both_branches():
    """θ = π and θ = −π give the same joint transform for an A-pair (d = 0, equal rotations):
    both are solutions and both are returned."""
    rng = np.random.default_rng(5)
    chain = random_chain(rng, 4)
    q = np.array([np.pi, 0.4, -0.9, 1.3])
    sols = chain.ik(chain.fk(q))
    assert contains(sols, q, periods(chain))
    assert contains(sols, q - [2 * np.pi, 0, 0, 0], periods(chain))
    assert_reproduce(chain, sols, chain.fk(q))


def multistart(chain, T, starts, rng):
    """Dense multi-start least squares: the distinct joint vectors that reach T to 1e-10."""
    per = periods(chain)

    def residual(q):
        F = chain.fk(q)
        return np.concatenate([(F[:3, 3] - T[:3, 3]) / 0.3, (F[:3, :3] - T[:3, :3]).ravel()])

    out = []
    for q0 in rng.uniform(-per / 2, per / 2, (starts, chain.n)):
        r = least_squares(residual, q0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        if np.abs(r.fun).max() < 1e-10 and not contains(np.array(out).reshape(-1, chain.n), r.x, per, 1e-6):
            out.append((r.x + per / 2) % per - per / 2)
    return np.array(out).reshape(-1, chain.n)


def test_no_solution_missed_against_multistart():
    rng = np.random.default_rng(99)
    for n, kinds in ((4, "s"), (4, "sr"), (2, "s"), (3, "s")):
        for _ in range(2):
            chain = random_chain(rng, n, kinds)
            T = chain.fk(rng.uniform(-3, 3, n))
            sols = chain.ik(T)
            for q in multistart(chain, T, 40, rng):
                assert contains(sols, q, periods(chain), 1e-6), (q, sols)


def test_unreachable_poses_give_no_solution():
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 4):
        chain = random_chain(rng, n)
        T = chain.fk(rng.uniform(-3, 3, n))
        T[:3, 3] += [0.01, -0.02, 0.015]
        assert chain.ik(T).shape == (0, n)
    chain = random_chain(rng, 4)
    T = np.eye(4)
    T[:3, 3] = [5.0, 0.0, 0.0]  # far beyond the reach
    assert chain.ik(T).shape == (0, 4)


def test_near_singular_pose_is_solved_or_refused_never_wrong():
    """Poses next to a singularity (σ_min(J) small): each returned q reproduces the pose."""
    rng = np.random.default_rng(8)
    chain = random_chain(rng, 2)
    # a 2-joint chain is singular where its two screws are linearly dependent: sample the smallest σ
    Q = rng.uniform(-np.pi, np.pi, (4000, 2))
    sig = np.linalg.svd(chain.jacobian(Q), compute_uv=False)[:, -1]
    for q in Q[np.argsort(sig)[:5]]:
        T = chain.fk(q)
        sols = chain.ik(T)
        assert_reproduce(chain, sols, T)
        assert contains(sols, q, periods(chain))


@pytest.mark.parametrize(
    "T, message",
    [
        (np.eye(3), r"T: expected a 4x4 transform or an 8-vector Study point"),
        (np.full((4, 4), np.nan), r"T: contains NaN"),
        (np.diag([1.0, 1.0, 2.0, 1.0]), r"T: the rotation part is not a proper rotation"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), r"T: the rotation part is not a proper rotation"),
        (np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]), r"T: last row"),
        (np.array([1.0, 0, 0, 0, 1.0, 0, 0, 0]), r"T: not on the Study quadric"),
        (np.zeros(8), r"T: a Study point with x = 0"),
    ],
)
def test_bad_pose(T, message):
    chain = random_chain(np.random.default_rng(0), 2)
    with pytest.raises(ValueError, match=message):
        chain.ik(T)


def test_unsupported_chains():
    rng = np.random.default_rng(1)
    general = apair.APair(0.05, 0.04, leg_length=0.068)
    chain = apair.AChain([general, apair.APair(0.05, 0.05)], [0.2, 0.2], [1.0, 0.5])
    with pytest.raises(ValueError, match=r"pairs\[0\]: a general A-pair"):
        chain.ik(np.eye(4))
    with pytest.raises(ValueError, match=r"tol: must be > 0"):
        random_chain(rng, 2).ik(np.eye(4), tol=0.0)


def test_matrix_and_study_conversions_agree():
    rng = np.random.default_rng(4)
    chain = random_chain(rng, 4)
    q = rng.uniform(-3, 3, 4)
    a = chain.ik(chain.fk(q))
    b = chain.ik(from_matrix(chain.fk(q)))
    np.testing.assert_allclose(a, b, atol=1e-9)


# ----------------------------------------------------------------------------- special designs
TWISTS = np.radians([0.0, 90.0, -90.0, 60.0])
LENGTHS = [0.0, 0.1, 0.3]


def special_chain(rng, n) -> apair.AChain:
    """The constants real robots are built from: twists 0, ±90°, 60°; lengths and offsets 0, 0.1, 0.3;
    R-pairs and sinusoidal A-pairs mixed."""
    pairs = [apair.APair.revolute() if rng.random() < 0.5 else apair.APair(0.05, 0.04) for _ in range(n)]
    return apair.AChain(pairs, rng.choice(LENGTHS, n), rng.choice(TWISTS, n), rng.choice(LENGTHS, n))


def special_angles(rng, n):
    q = rng.uniform(-np.pi, np.pi, n)
    m = rng.random(n)
    q[m < 0.2] = 0.0
    q[(m >= 0.2) & (m < 0.3)] = np.pi
    return q


def test_issue_reproducer_special_4r():
    R = apair.APair.revolute()
    chain = apair.AChain([R] * 4, a=[0.3, 0.3, 0.3, 0], alpha=[-np.pi / 2, -np.pi / 2, np.pi / 2, 0])
    q = np.array([0.1, 0.2, 0.0, 0.4])
    sol = chain.ik(chain.fk(q), full=True)
    assert contains(sol.q, q, periods(chain)) and sol.certified


@pytest.mark.slow
@pytest.mark.parametrize("n, count", [(2, 60), (3, 120), (4, 240)])
def test_special_designs_never_miss_a_full_rank_pose(n, count):
    """Random special designs at joint values with 0 and π: a pose that fk produced, where the
    Jacobian has full rank, is always solved; the elimination (forward or reversed) certifies
    nearly all of them, the local fallback the rest."""
    rng = np.random.default_rng(1400 + n)
    done = certified = 0
    while done < count:
        chain = special_chain(rng, n)
        for _ in range(3):
            q = special_angles(rng, n)
            if np.linalg.matrix_rank(chain.jacobian(q), tol=1e-7) < n:
                continue
            T = chain.fk(q)
            sol = chain.ik(T, full=True)
            assert contains(sol.q, q, periods(chain)), (chain, q)
            assert_reproduce(chain, sol.q, T)
            done += 1
            certified += sol.certified
    assert certified >= 0.97 * done


def test_forward_and_reversed_eliminations_agree():
    """The two orientations of the elimination are independent routes to the same solution set."""
    from apair import ik

    rng = np.random.default_rng(77)
    compared = 0
    for _ in range(40):
        chain = special_chain(rng, 4)
        q = special_angles(rng, 4)
        if np.linalg.matrix_rank(chain.jacobian(q), tol=1e-7) < 4:
            continue
        T = chain.fk(q)
        solver = ik.Solver(chain)
        target = poses.study_point(T)
        target[4:] /= solver.scale
        counts = []
        for reverse in (False, True):
            try:
                cands = solver._elimination(reverse).candidates(target, False)
            except pencil.Degenerate:
                break
            real = [c for c in cands if np.all(np.abs(np.imag(c)) <= elimination4.CAND_TOL * (1 + np.abs(c)))]
            q_all = poses.with_twins(chain, solver._elimination(reverse).angles(real))
            counts.append(len(poses.refine(chain, q_all, T, 1e-9)[0]))
        if len(counts) == 2 and min(counts) > 0:
            assert counts[0] == counts[1], (chain, q)
            compared += 1
    assert compared >= 20


def test_both_preimages_of_an_a_pair_at_pi():
    """A sinusoidal pair's pose curve crosses itself at θ = ±π (one pose, two joint values): with
    the pair in the right half, whose pose the elimination solves for, both must come back."""
    rng = np.random.default_rng(77)
    for _ in range(14):  # the 14th draw of test_forward_and_reversed_eliminations_agree
        chain, q = special_chain(rng, 4), special_angles(rng, 4)
    assert chain.pairs[2].kind != "revolute" and abs(q[2]) == np.pi
    sols = chain.ik(chain.fk(q))
    twin = q.copy()
    twin[2] = -q[2]
    for target in (q, twin):
        assert np.any(np.all(np.abs(sols - target) < 1e-7, axis=1)), (target, sols)


@pytest.mark.parametrize("n", [2, 4])
def test_coaxial_revolute_pairs_are_refused_as_a_curve(n):
    """Two R-pairs on one axis (a_1 = 0, α_1 = 0) turn the pose into a curve of solutions."""
    R = apair.APair.revolute()
    chain = apair.AChain([R] * n, a=[0.0, 0.3, 0.2, 0.1][:n], alpha=[0.0, np.pi / 2, -np.pi / 2, 0.3][:n])
    with pytest.raises(ValueError, match="not isolated"):
        chain.ik(chain.fk(np.full(n, 0.3)))


def forward_solutions(solver, chain, T):
    """The forward elimination's verified solutions alone (no reversed chain, no local search)."""
    target = poses.study_point(T)
    target[4:] /= solver.scale
    elim = solver._elimination(False)
    cands = np.array(elim.candidates(target, False), complex).reshape(-1, chain.n)
    real = cands[np.all(np.abs(cands.imag) <= elimination4.CAND_TOL * (1 + np.abs(cands)), axis=1)]
    return poses.refine(chain, poses.with_twins(chain, elim.angles(real)), T, 1e-9)[0]


def test_forward_elimination_alone_finds_every_generic_4a_pose():
    """The 48-root route (f against the quadric without a yy block) finds each round trip without
    the reversed chain, and its eigenvalue u_3 is accurate: with a quadric close to the rotation
    quadric, the eigenvalues of one random design lost up to 7 digits and 5 of its 100 poses fell
    through to the fallbacks."""
    from apair import ik

    rng = np.random.default_rng(1)
    for _ in range(4):
        chain = random_chain(rng, 4)
        solver = ik.Solver(chain)
        elim = solver._elimination(False)
        assert len(elim.combinations) == 5  # f, three random, the xy one
        for q in rng.uniform(-np.pi, np.pi, (25, 4)):
            T = chain.fk(q)
            assert contains(forward_solutions(solver, chain, T), q, periods(chain)), (chain, q)
            target = poses.study_point(T)
            target[4:] /= solver.scale
            roots, _ = elim._resultant_roots(elim.image @ joints.left_matrix(target).T)
            u3 = np.tan((q[2] - elim.joints[2].delta) / 4)
            assert np.min(np.abs(roots - u3)) <= 1e-9 * (1 + abs(u3))


def test_quadric_without_yy_block():
    """The fifth combination has no yy block and is orthogonal to the rotation and Study quadrics
    (which vanish on it otherwise); its images have bidegree (6, 6) and f's (4, 4): 48 roots, 8 of
    them spurious at u_3 = ±i, where g(±i, ·) is a multiple of f(±i, ·), and 8 where u_4 = ±i;
    deflated, 32."""
    from apair import ik

    chain = random_chain(np.random.default_rng(3), 4)
    elim = ik.Solver(chain)._elimination(False)
    xy, Qx8 = elim.combinations[-1], elim.combinations[0]
    study = np.zeros((8, 8))
    study[:4, 4:] = study[4:, :4] = np.eye(4)
    assert np.abs(xy[4:, 4:]).max() < 1e-10
    assert abs(np.sum(xy * Qx8)) < 1e-10 and abs(np.sum(xy * study)) < 1e-10
    assert elim.factors[0] == (2, 2) and elim.factors[-1] == (1, 1)
    T = chain.fk(np.array([0.3, -1.0, 2.0, 0.5]))
    target = poses.study_point(T)
    target[4:] /= ik.Solver(chain).scale
    C = elim.image @ joints.left_matrix(target).T
    roots, pair = elim._resultant_roots(C)
    # deflated: the 48 roots of f against the yy-free image less its 8 spurious ones at u_3 = ±i
    # and the 8 where u_4 = ±i (the roots of f(·, ±i), there common to both)
    assert [p.shape for p in pair] == [(5, 5), (5, 5)] and len(roots) == 32
    f, *_, xy = elim._quadric_images(C, elim.factors)
    assert f.shape == (5, 5) and xy.shape == (7, 7)
    full = pencil.hidden_variable(f, xy, np.random.default_rng(0))
    at_i = np.abs(np.abs(full) - 1) + np.abs(full.real) < 1e-4
    fi = (1j ** np.arange(5)) @ f.T  # f(u, i) in u
    where_v_i = np.concatenate([np.roots(fi[::-1]), np.roots(fi[::-1]).conj()])
    at_v_i = np.abs(full[:, None] - where_v_i[None]).min(axis=1) < 1e-6 * (1 + np.abs(full))
    assert len(full) == 48 and np.count_nonzero(at_i) == 8 and np.count_nonzero(at_v_i) == 8
    rest = full[~(at_i | at_v_i)]
    assert np.all(np.abs(rest[:, None] - roots[None]).min(axis=1) <= 1e-6 * (1 + np.abs(rest)))
    assert pencil.deflate(xy, f) is None  # g's degree in v below f's
    assert pencil.deflate(f, xy + 1e-3 * np.random.default_rng(1).standard_normal(xy.shape)) is None  # no multiple


def test_isotropic_factors_are_found_and_divided_exactly():
    rng = np.random.default_rng(5)
    P = np.polynomial.polynomial
    q = rng.standard_normal((4, 6))
    p = q
    for _ in range(2):
        p = np.array([P.polymul(col, [1, 0, 1]) for col in p.T]).T  # (1 + u²)² ...
    p = np.array([P.polymul(row, [1, 0, 1]) for row in p])  # ... (1 + v²)
    assert pencil.isotropic_factors(p) == (2, 1)
    assert np.allclose(pencil.isotropic_quotient(p, (2, 1)), q, atol=1e-12)
    p[0, 0] += 1e-6  # no longer divisible
    assert pencil.isotropic_factors(p) == (0, 0)


def test_parallel_axes_give_a_regular_32_root_pencil():
    """examples/4a_chain.toml (joints 2-4 parallel): every quadric image carries (1 + u_3²)²(1 + u_4²)²
    and f vanishes on the whole image. Undivided, every pair of images made a singular 128 × 128
    pencil (its regular part by a random rank completion); divided, two (4, 4) images give a
    regular 32 × 32 one, and every round trip is found by it."""
    from apair import ik

    chain = apair.load("examples/4a_chain.toml")
    solver = ik.Solver(chain)
    elim = solver._elimination(False)
    rng = np.random.default_rng(9)
    for q in rng.uniform(-np.pi, np.pi, (20, 4)):
        T = chain.fk(q)
        target = poses.study_point(T)
        target[4:] /= solver.scale
        roots, pair = elim._resultant_roots(elim.image @ joints.left_matrix(target).T)
        assert pair is not None and len(roots) == 32
        assert contains(forward_solutions(solver, chain, T), q, periods(chain))


def compiled_ik():
    from apair import ik

    if elimination4.native_in_use() is None:
        pytest.skip("the compiled C kernels are not installed")
    return ik


def test_compiled_4_joint_steps_agree_with_numpy(monkeypatch):
    """apair_ik4_pencil, apair_ik4_screen and apair_ik4_left against the NumPy path they replace, step
    by step, on random 4A and mixed designs, special ones and examples/4a_chain.toml (a 32-root
    pencil of two random combinations): the same eigenvalues, screened pairs and left halves."""
    ik = compiled_ik()
    native = elimination4.native_in_use
    rng = np.random.default_rng(21)
    generic = [random_chain(rng, 4), random_chain(rng, 4, "sr"), random_chain(rng, 4, "r")]
    chains = generic + [apair.load("examples/4a_chain.toml")] + [special_chain(rng, 4) for _ in range(4)]
    compared = lefts_compared = 0
    for chain in chains:
        solver = ik.Solver(chain)
        elim = solver._elimination(False)
        qs = [rng.uniform(-np.pi, np.pi, 4), special_angles(rng, 4)]
        for q in qs:
            target = poses.study_point(chain.fk(q))
            target[4:] /= solver.scale
            if elim.pre is not None:
                target = multiply(elim.pre, conjugate(target))
            C = elim.image @ joints.left_matrix(target).T
            steps = {}
            for engine in ("c", "numpy"):
                monkeypatch.setattr(elimination4, "native_in_use", native if engine == "c" else (lambda: None))
                roots, pair = elim._resultant_roots(C)
                u3 = np.sort_complex(roots)
                real = u3[np.abs(u3.imag) <= elimination4.CAND_TOL * (1 + np.abs(u3))].real
                screened = elim._screen(real, pair, C) if pair is not None else None
                steps[engine] = u3, pair, screened
            (uc, pc, sc), (un, pn, sn) = steps["c"], steps["numpy"]
            assert len(uc) == len(un)
            # each root matched (double roots, e.g. the spurious ones at ±i, differ by about √ε)
            finite = uc[np.abs(uc) < 1e3]  # those near infinity are ill-conditioned in either engine
            assert np.all(np.abs(finite[:, None] - un[None]).min(axis=1) <= 1e-5 * (1 + np.abs(finite)))
            if pc is None:
                assert pn is None
                continue
            assert all(np.allclose(a, b, rtol=1e-12, atol=1e-14 * np.abs(b).max()) for a, b in zip(pc, pn))
            if sc is None or len(sc[0]) == 0:
                continue
            if any(chain is c for c in generic):
                # the same pairs (u_3, u_4), as sets: one that only one engine accepts, the other
                # left undecided (a residual near a bound). (Special designs have multiple roots,
                # whose copies, about the root's fourth root apart, may be accepted as spurious
                # candidates by one engine and rejected by the other: there the answers decide.)
                for (a, _, _), (b, _, rest) in ((sc, sn), (sn, sc)):
                    for u in a:
                        near = 1e-5 * (1 + np.abs(u).max())
                        accepted = len(b) and np.abs(b - u).max(axis=1).min() <= near
                        assert accepted or np.any(np.abs(rest - u[0]) <= near)
                compared += 1
            lefts = {}  # the left half of the same images, every design
            for engine in ("c", "numpy"):
                monkeypatch.setattr(elimination4, "native_in_use", native if engine == "c" else (lambda: None))
                lefts[engine] = elim._solve_left_many(sc[1])
            for a, b in zip(lefts["c"], lefts["numpy"]):
                assert len(a) == len(b) and all(np.allclose(x, y, rtol=1e-7) for x, y in zip(a, b))
            lefts_compared += 1
        # and the answers: the same verified solutions (u_3 left undecided, a residual between
        # the screen's bounds, may differ with rounding: the common-roots path decides those)
        answers = {}
        for engine in ("c", "numpy"):
            monkeypatch.setattr(elimination4, "native_in_use", native if engine == "c" else (lambda: None))
            chain._ik = None
            answers[engine] = [chain.ik(chain.fk(q)) for q in qs]
        for a, b in zip(answers["c"], answers["numpy"]):  # as sets (twins at ±π may swap places)
            assert a.shape == b.shape and all(contains(b, x, periods(chain)) for x in a)
    assert compared >= 5 and lefts_compared >= 12


def test_compiled_left_half_refuses_only_points_off_its_surface():
    """apair_ik4_left's "no root" (status 2) is a proof: on random Study points off the left half's
    surface it says so, and the general path finds nothing there either; on points of the surface
    it returns their parameters."""
    ik = compiled_ik()
    rng = np.random.default_rng(4)
    chain = random_chain(rng, 4)
    elim = ik.Solver(chain)._elimination(False)
    j2 = elim.joints[1]
    joint = np.array([j2.kind == "revolute", j2.delta, j2.offset, j2.sign], float)
    x, y = rng.standard_normal((2, 20, 4))
    y -= np.sum(x * y, axis=1, keepdims=True) / np.sum(x * x, axis=1, keepdims=True) * x
    off = np.concatenate([x, y], 1)  # on the Study quadric, off the surface
    status, *_ = elimination4.native_in_use().ik4_left(off, elim.Zmap, j2.P, joint, elimination4.LEFT_TOL)
    assert np.all(status == 2)
    assert all(len(s) == 0 for s in elim._solve_left_general(off))
    u = np.tan(rng.uniform(-1.4, 1.4, (20, 2)))
    on = multiply(joints.evaluate(elim.joints[0].A, u[:, 0]), joints.evaluate(elim.joints[1].A, u[:, 1]))
    status, u1, u2, ok = elimination4.native_in_use().ik4_left(on, elim.Zmap, j2.P, joint, elimination4.LEFT_TOL)
    assert np.all(status == 0)
    assert np.allclose(u1, u[:, 0], rtol=1e-8)
    assert np.all(np.any(ok.astype(bool) & np.isclose(u2, u[:, 1:], rtol=1e-8), axis=1))
