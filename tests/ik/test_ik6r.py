"""The 6R elimination (apair.ik.elimination6r, derivations/chain_ik6r.py): the derived equations at random 6R
poses, the same 16 complex solutions as the homotopy on random and special designs, the chain read
from its end, the fallback where it cannot certify, 5R chains through the virtual joint."""

from __future__ import annotations

import numpy as np
import pytest
from apair_test_helpers import arm_toml

import apair
from apair.ik import elimination6r as ik6r
from apair.ik import homotopy

PI = np.pi


def arm(a, alpha, offset, phi=None) -> apair.AChain:
    return apair.AChain([apair.APair.revolute() for _ in a], a, alpha, offset, phi)


def random_arm(rng, n: int = 6) -> apair.AChain:
    return arm(
        rng.uniform(0.1, 0.5, n), rng.uniform(-1.5, 1.5, n), rng.uniform(-0.2, 0.2, n), rng.uniform(-1.0, 1.0, n)
    )


def same_sets(A: np.ndarray, B: np.ndarray, tol: float = 1e-6) -> bool:
    """Whether the complex solution sets agree (R-pair angles modulo 2π)."""
    if len(A) != len(B):
        return False
    for b in B:
        d = A - b
        re = np.abs(d.real) % (2 * PI)
        if not np.any(np.max(np.maximum(np.minimum(re, 2 * PI - re), np.abs(d.imag)), axis=1) < tol):
            return False
    return True


def contains(sols, q, tol=1e-7) -> bool:
    d = np.abs((sols - q + PI) % (2 * PI) - PI)
    return bool(len(sols)) and bool(np.any(np.all(d < tol, axis=1)))


def test_derived_equations_hold_at_random_poses():
    """P(ψ3) X45 = Q X12 at random real 6R poses, in 40-digit arithmetic, through the DH product."""
    from apair.derivations import chain_ik6r

    assert chain_ik6r.check_equations(chain_ik6r.spec(), samples=2) < 1e-30


def test_the_same_16_solutions_as_the_homotopy():
    rng = np.random.default_rng(21)
    for _ in range(2):
        chain = random_arm(rng)
        problem = homotopy.Problem.of(chain)
        start = homotopy.start_system(problem)
        for q in rng.uniform(-PI, PI, (3, 6)):
            T = chain.fk(q)
            theta = ik6r.solve(problem, T)
            assert theta is not None and theta.shape == (16, 6)
            ends = homotopy.solve(problem, start, T)
            assert ends.complete and same_sets(homotopy.canonical(problem, theta), ends.theta)
            sol = chain.ik(T, full=True)
            assert sol.method == "elimination" and sol.certified and sol.complex_count == 16
            assert contains(sol.q, q) and np.abs(chain.fk(sol.q) - T).max() <= 1e-9


@pytest.fixture
def c_backend():
    """The C steps in use whatever APAIR_BACKEND says (the tests that hold them against their twins)."""
    if not apair.c_available():
        pytest.skip("the compiled C kernels are not installed")
    apair.set_backend("c")
    yield
    apair.set_backend(None)


def test_c_steps_agree_with_numpy(c_backend):
    """apair_ik6r_angles and apair_ik_newton against their NumPy versions: the same angles from the
    same eigenpairs, the same roots and step sizes after Newton (also from perturbed starts, and
    a start far out that must be reported as lost)."""
    rng = np.random.default_rng(8)
    chain = random_arm(rng)
    problem = homotopy.Problem.of(chain)
    pose = problem.pose(chain.fk(rng.uniform(-PI, PI, 6)))
    seen = {}
    real_angles = ik6r.angles

    def spy(*args, engine=None):
        seen["args"] = args
        return real_angles(*args, engine=engine)

    ik6r.angles = spy
    try:
        theta = ik6r.eliminate(problem.dh, pose)
    finally:
        ik6r.angles = real_angles
    assert theta is not None and theta.shape == (16, 6)
    assert np.abs(ik6r.angles(*seen["args"], engine="c") - ik6r.angles(*seen["args"], engine="numpy")).max() < 1e-9
    p = homotopy.target_of(pose)
    start = theta + 1e-3 * (rng.standard_normal(theta.shape) + 1j * rng.standard_normal(theta.shape))
    start[0] = 40j  # |Im θ| beyond imag_max after a step: lost
    args = (problem, start, p, 8, 1e-8, 1e-6, 0.25, ik6r.IMAG_MAX)
    tc, sc = homotopy.newton(*args, engine="c")
    tn, sn = homotopy.newton(*args, engine="numpy")
    assert np.isinf(sc[0]) and np.isinf(sn[0])
    assert np.all(sc[1:] <= 1e-8) and np.all(sn[1:] <= 1e-8)
    assert np.abs(tc[1:] - tn[1:]).max() < 1e-9 and np.abs(tc[1:] - theta[1:]).max() < 1e-8


def test_reversed_chain_reaches_the_inverse_pose():
    rng = np.random.default_rng(4)
    chain = random_arm(rng)
    problem = homotopy.Problem.of(chain)
    q = rng.uniform(-PI, PI, 6)
    psi = q + problem.dh[:, 3]
    dh_rev, T_rev = ik6r.reversed_chain(problem.dh, problem.pose(chain.fk(q)))
    F = np.eye(4)
    for j in range(6):
        a, alpha, c, _ = dh_rev[j]
        F = F @ homotopy.problem._dh(-psi[5 - j], a, alpha, c, 0.0)
    assert np.abs(F - T_rev).max() < 1e-12


# designs users build: (a, α, c), and whether the elimination must certify generic poses of it
SPECIAL = {
    "axes 1 and 2 parallel (read from the end)": (
        [0.3, 0.4, 0.2, 0.25, 0.15, 0.1],
        [0.0, 0.5, -1.1, 0.9, 1.3, -0.4],
        [0.1, -0.1, 0.05, 0.2, -0.15, 0.07],
        True,
    ),
    "axes 5 and 6 parallel": (
        [0.3, 0.4, 0.2, 0.25, 0.15, 0.1],
        [0.7, 0.5, -1.1, 0.9, 0.0, -0.4],
        [0.1, -0.1, 0.05, 0.2, -0.15, 0.07],
        True,
    ),
    "right angles": (
        [0.3, 0.4, 0.2, 0.25, 0.15, 0.1],
        [PI / 2, -PI / 2, PI / 2, PI / 2, -PI / 2, PI / 2],
        [0.1, -0.1, 0.05, 0.2, -0.15, 0.07],
        True,
    ),
    "intersecting axes 3, 4 (a3 = 0), no offsets": (
        [0.3, 0.4, 0.0, 0.25, 0.15, 0.1],
        [0.7, 0.5, -1.1, 0.9, 1.3, -0.4],
        [0.0] * 6,
        True,
    ),
    "millimetre scale": (
        [3e-4, 4e-4, 2e-4, 2.5e-4, 1.5e-4, 1e-4],
        [0.7, 0.5, -1.1, 0.9, 1.3, -0.4],
        [1e-4, -1e-4, 5e-5, 2e-4, -1.5e-4, 7e-5],
        True,
    ),
    "kilometre scale": (
        [300.0, 400.0, 200.0, 250.0, 150.0, 100.0],
        [0.7, 0.5, -1.1, 0.9, 1.3, -0.4],
        [100.0, -100.0, 50.0, 200.0, -150.0, 70.0],
        True,
    ),
    "PUMA-like (spherical wrist: 8 solutions)": (
        [0.0, 0.43, 0.02, 0.0, 0.0, 0.0],
        [PI / 2, 0.0, PI / 2, -PI / 2, PI / 2, 0.0],
        [0.0, 0.0, 0.15, 0.43, 0.0, 0.1],
        False,
    ),
    "UR-like (axes 2, 3, 4 parallel: 8 solutions)": (
        [0.0, -0.425, -0.392, 0.0, 0.0, 0.0],
        [PI / 2, 0.0, 0.0, PI / 2, -PI / 2, 0.0],
        [0.089, 0.0, 0.0, 0.109, 0.094, 0.082],
        False,
    ),
}


@pytest.mark.parametrize("name", list(SPECIAL))
def test_special_designs_stay_complete(name):
    """Where the elimination certifies, its set is the homotopy's; where it cannot (fewer than 16
    solutions, a singular pose), ik falls back to the homotopy; either way the round trip holds at
    random poses and at joints of 0 and π."""
    a, alpha, c, generic = SPECIAL[name]
    chain = arm(a, alpha, c)
    problem = homotopy.Problem.of(chain)
    start = homotopy.start_system(problem)
    rng = np.random.default_rng(len(name))
    # joints at 0 and π (θ5 off 0 and π: the wrists of the last two designs would be singular)
    qs = list(rng.uniform(-PI, PI, (4, 6))) + [
        np.array([0.0, PI, 0.3, PI, 0.5, -0.7]),
        np.array([PI, 0.4, 0.0, -1.0, 1.2, 0.0]),
    ]
    certified = 0
    for q in qs:
        T = chain.fk(q)
        theta = ik6r.solve(problem, T)
        if theta is not None:
            certified += 1
            assert same_sets(homotopy.canonical(problem, theta), homotopy.solve(problem, start, T).theta), name
        sol = chain.ik(T, full=True)
        family = chain.kinematic_family().key
        closed = family.startswith("spherical-") or family == "three-inner-parallel"  # apair.ik.wrist, .parallel
        assert sol.method == ("closed form" if closed else "elimination" if theta is not None else "homotopy")
        assert contains(sol.q, q, 1e-6), (name, q, sol.q)
        assert np.abs(chain.fk(sol.q) - T).max() <= 1e-9
    if generic:
        assert certified >= 4, name
    else:
        assert certified == 0 and start.count == 8, name


def general_arms() -> dict[str, apair.AChain]:
    """Six R-pairs of no closed-form family, at random and as users build them (SPECIAL's designs the
    elimination certifies): the 6R elimination's chains (tests/ik/test_ik_closed_fast.py takes them too)."""
    rng = np.random.default_rng(30)
    arms = {f"random 6R #{k}": random_arm(rng) for k in range(2)}
    arms.update({name: arm(a, alpha, c) for name, (a, alpha, c, generic) in SPECIAL.items() if generic})
    return arms


def test_one_c_call_is_the_numpy_steps(c_backend):
    """apair_ik6r_solve (the elimination, else the reversed chain's, Newton and the checks, with
    SciPy's LAPACK, in one C call) against the NumPy steps: the same 16 solutions, and None at the
    same poses (a singular one among them), on random designs and those users build (axes 1 and 2
    parallel: from the end; right angles; no offsets; mm and km), joints at 0 and π too."""
    for name, chain in general_arms().items():
        problem = homotopy.Problem.of(chain)
        rng = np.random.default_rng(len(name))
        qs = list(rng.uniform(-PI, PI, (5, 6))) + [np.array([0.0, PI, 0.3, PI, 0.5, -0.7]), np.zeros(6)]
        for q in qs:
            T = chain.fk(q)
            c, py = ik6r.solve(problem, T, engine="c"), ik6r.solve(problem, T, engine="numpy")
            assert (c is None) == (py is None), (name, q)
            if c is not None:
                assert same_sets(homotopy.canonical(problem, c), homotopy.canonical(problem, py)), (name, q)
    singular = arm([0.3, 0.4, 0.2, 0.25, 0.15, 0.1], [0.7, 0.5, -1.1, 0.9, 1.3, -0.4], [0.0] * 6)
    T = singular.fk(np.zeros(6))
    problem = homotopy.Problem.of(singular)
    assert ik6r.solve(problem, T, engine="c") is None and ik6r.solve(problem, T, engine="numpy") is None


def test_c_constants_are_the_modules():
    """apair_ik6r_solve's tolerances and chart turns (#define IK6R_<NAME> ... /* NAME */ and
    ik6r_sigma in src/csrc/apair_ik6r.c) are apair.ik.elimination6r's, and apair_ik6r's real-candidate
    tolerance is the homotopy's."""
    import re
    from pathlib import Path

    src = (Path(__file__).resolve().parents[2] / "src" / "csrc" / "apair_ik6r.c").read_text()
    found = re.findall(r"#define IK6R_\w+\s+([-0-9.e]+)\s+/\* ([A-Z_]+) \*/", src)
    assert len(found) >= 10
    for value, name in found:
        assert float(value) == getattr(ik6r, name), name
    real = re.search(r"#define IK6R_REAL ([-0-9.e]+)", src).group(1)
    assert float(real) == homotopy.problem.REAL
    sigma = re.search(r"ik6r_sigma\[3\] = \{([^}]*)\}", src).group(1)
    assert tuple(float(x) for x in sigma.split(",")) == ik6r.SIGMA


def test_singular_pose_falls_back_to_the_homotopy():
    """No offsets: at θ = 0 the arm is singular (a double root); the elimination declines."""
    chain = arm([0.3, 0.4, 0.2, 0.25, 0.15, 0.1], [0.7, 0.5, -1.1, 0.9, 1.3, -0.4], [0.0] * 6)
    T = chain.fk(np.zeros(6))
    assert ik6r.solve(homotopy.Problem.of(chain), T) is None
    sol = chain.ik(T, full=True)
    assert sol.method == "homotopy" and contains(sol.q, np.zeros(6), 1e-6)


def test_a_wrist_singularity_is_refused():
    """PUMA-like at θ5 = 0: axes 4 and 6 in line, a curve of solutions (θ4 + θ6 fixed): the general
    solver refuses it; the closed form gives one member of each continuum and says so
    (tests/ik/test_ik_wrist.py)."""
    from apair.ik.solver import Solver

    a, alpha, c, _ = SPECIAL["PUMA-like (spherical wrist: 8 solutions)"]
    chain = arm(a, alpha, c)
    general = Solver(chain)
    general._closed = None
    T = chain.fk(np.array([0.3, -0.5, 0.4, 0.7, 0.0, 0.2]))
    with pytest.raises(ValueError, match="not isolated"):
        general.solve(T)
    sol = chain.ik(T, full=True)
    assert sol.method == "closed form" and "axes 4 and 6 in line" in sol.note


def test_five_r_chains_through_the_virtual_joint():
    rng = np.random.default_rng(8)
    chain = random_arm(rng, 5)
    for q in rng.uniform(-PI, PI, (4, 5)):
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert sol.method == "elimination" and sol.certified and sol.complex_count == 1
        assert contains(sol.q, q)
    T = chain.fk(rng.uniform(-PI, PI, 5))
    T[:3, 3] += [0.01, -0.02, 0.015]  # off the 5-dimensional image
    assert chain.ik(T).shape == (0, 5)


def test_unreachable_pose_has_16_complex_and_no_real_solutions():
    chain = random_arm(np.random.default_rng(2))
    T = np.eye(4)
    T[:3, 3] = [10.0, 0.0, 0.0]
    sol = chain.ik(T, full=True)
    assert sol.q.shape == (0, 6) and sol.method == "elimination" and sol.complex_count == 16


def test_cli_names_the_route(tmp_path, capsys):
    from apair.cli import main as cli

    path = arm_toml(tmp_path)
    chain = apair.load(path)
    q = np.array([0.3, -0.5, 0.8, 1.1, -0.4, 0.2])
    assert cli(["ik", str(path), *[repr(float(x)) for x in chain.fk(q).ravel()]]) == 0
    out = capsys.readouterr().out
    assert "of 16 complex, by elimination; family general; angles in rad" in out


@pytest.mark.parametrize(
    "T, message",
    [
        (np.eye(3), "expected a 4x4 transform"),
        (np.full((4, 4), np.nan), "NaN"),
        (np.zeros(8), "exceptional"),
        (np.diag([1.0, 1, -1, 1]), "proper rotation"),
    ],
)
def test_bad_poses_are_refused_by_name(T, message):
    chain = random_arm(np.random.default_rng(2))
    with pytest.raises(ValueError, match=message) as info:
        chain.ik(T)
    assert str(info.value).startswith("T:")
