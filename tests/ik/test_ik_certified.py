"""The answer of 1 to 4 joints (issue 36 items 8 and 9), on examples/4a_chain.toml and a UR-like
4-joint arm: `method` and `certified` agree with docs/conventions.md §7 at reachable, unreachable
and degenerate poses (an elimination's "none" is certified and named "elimination"; a local
search's answer never is), and `full=True` adds the count of the complex solutions without
solving the left half for every root of the resultant (work counted, not timed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import apair
from apair.ik import Solver, elimination4
from apair.ik.joints import left_matrix
from apair.ik.pencil import Degenerate
from apair.ik.poses import study_point

PI = np.pi
ROOT = Path(__file__).resolve().parents[2]
R, S = apair.APair.revolute(), apair.APair(0.05, 0.04)


def example() -> apair.AChain:
    return apair.load(ROOT / "examples" / "4a_chain.toml")


def ur4() -> apair.AChain:
    """The first four joints of a UR5 (axes 2, 3 and 4 parallel: elbow up and down)."""
    return apair.AChain(
        [R] * 4, a=[0, -0.425, -0.39225, 0], alpha=[PI / 2, 0, 0, PI / 2], offset=[0.089159, 0, 0, 0.10915]
    )


CHAINS = {"4A example": example, "UR-like 4R": ur4}


def holds(sols: np.ndarray, q: np.ndarray, tol: float = 1e-7) -> bool:
    return bool(len(sols)) and bool(np.any(np.all(np.abs((sols - q + PI) % (2 * PI) - PI) < tol, axis=1)))


def valid(chain: apair.AChain, q: np.ndarray, T: np.ndarray) -> bool:
    """Some solutions, each reproducing T (a local search need not find them all)."""
    return bool(len(q)) and bool(np.abs(chain.fk(q) - T).max() <= 1e-9)


def same(a: np.ndarray, b: np.ndarray) -> bool:
    """The same solutions, to rounding (in any order: rows equal to rounding sort either way)."""
    return a.shape == b.shape and all(holds(b, q, 1e-9) for q in a)


def reachable(chain: apair.AChain) -> list[np.ndarray]:
    """Random joint vectors, and singular ones: joints at 0 and π (the UR's arm stretched)."""
    rng = np.random.default_rng(9)
    qs = list(rng.uniform(-PI, PI, (8, 4)))
    return qs + [np.array([0.3, -0.7, 0.0, 1.1]), np.array([PI, 0.0, 0.0, PI]), np.zeros(4)]


def unreachable(chain: apair.AChain) -> list[np.ndarray]:
    """Poses within the reach bound but off the 4-joint chain's image (a 4-dimensional family)."""
    rng = np.random.default_rng(10)
    out = []
    for t in ([0.1, 0.2, 0.1], [0.3, 0.0, 0.3], [0.0, 0.0, 0.2]):
        T = np.eye(4)
        T[:3, 3] = t
        out.append(T)
        T = T.copy()
        T[:3, :3] = _rotation(rng)
        out.append(T)
    return out


def _rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.standard_normal(4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


@pytest.mark.parametrize("name", list(CHAINS))
def test_reachable_poses_are_certified_by_the_elimination(name):
    """Random and singular reachable poses: the elimination's set, certified, holding the round
    trip; the plain answer is the full one's q."""
    chain = CHAINS[name]()
    for q in reachable(chain):
        T = chain.fk(q)
        sol = chain.ik(T, full=True)
        assert sol.method == "elimination" and sol.certified and sol.note == "", (q, sol)
        assert holds(sol.q, q), (q, sol.q)
        assert same(chain.ik(T), sol.q)
        assert sol.complex_count is not None and sol.complex_count >= len(sol.q)


@pytest.mark.parametrize("name", list(CHAINS))
def test_unreachable_poses_are_an_elimination_certified_none(name):
    """Within the reach bound but out of reach: the elimination proves there is no real solution
    (within its tolerances), the local search that checks it finds none either: method
    "elimination", certified. Beyond the reach bound: method "reach bound", certified."""
    chain = CHAINS[name]()
    for T in unreachable(chain):
        sol = chain.ik(T, full=True)
        assert len(sol.q) == 0 and sol.method == "elimination" and sol.certified and sol.note == "", sol
    far = np.eye(4)
    far[:3, 3] = [5.0, 0.0, 0.0]
    assert chain.ik(far).shape == (0, 4)
    sol = chain.ik(far, full=True)
    assert len(sol.q) == 0 and sol.certified and sol.method in ("reach bound", "elimination")


@pytest.mark.parametrize("name", list(CHAINS))
def test_where_the_elimination_degenerates_the_local_search_is_not_certified(monkeypatch, name):
    """Every orientation of the elimination degenerate (forced): the local search supplies the
    reachable pose's solution, and neither that set nor an unreachable pose's empty one is
    certified; the note says why."""
    chain = CHAINS[name]()

    def degenerate(self, target, count_complex):
        raise Degenerate("forced by the test")

    monkeypatch.setattr(elimination4.Elimination, "candidates", degenerate)
    T = chain.fk(reachable(chain)[0])
    sol = chain.ik(T, full=True)
    assert sol.method == "local search" and not sol.certified and valid(chain, sol.q, T)
    assert "degenerated" in sol.note and "forced by the test" in sol.note
    sol = chain.ik(unreachable(chain)[0], full=True)
    assert len(sol.q) == 0 and sol.method == "local search" and not sol.certified and "found no solution" in sol.note


def test_a_none_the_local_search_contradicts_is_not_certified(monkeypatch):
    """An elimination that finds nothing at a reachable pose (forced: no candidate) is checked by
    the local search, which finds the solution: "local search", not certified."""
    chain = ur4()
    monkeypatch.setattr(elimination4.Elimination, "candidates", lambda self, target, count_complex: [])
    T = chain.fk(reachable(chain)[1])
    sol = chain.ik(T, full=True)
    assert sol.method == "local search" and not sol.certified and valid(chain, sol.q, T)
    assert "may be incomplete" in sol.note


# Designs with non-real solutions (special constants of tests/ik/test_ik.py): pattern, a, α [°], c, q
WITH_COMPLEX = [
    (
        "SSSR",
        [0.0, 0.3, 0.1, 0.3],
        [0, 0, 0, 60],
        [0.1, 0.3, 0.0, 0.3],
        [PI, 0.0, 2.584899451285138, 2.4950885520270454],
    ),
    (
        "SRRR",
        [0.1, 0.3, 0.1, 0.3],
        [0, 0, 0, 0],
        [0.3, 0.1, 0.0, 0.3],
        [0.10419862298241078, PI, 0.0, -1.5860003520763777],
    ),
]


def reference_count(chain: apair.AChain, T: np.ndarray) -> int:
    """The complex solutions the complete route counts: for every root u_3 of the resultant (and
    the mean of two close ones), the common roots u_4 of all the left half's quadrics, the left
    half solved for each image, the isotropic ones dropped, distinct to 1e-6."""
    solver = Solver(chain)
    el = solver._elimination(False)
    target = study_point(T)
    target[4:] /= solver.scale
    C = el.image @ left_matrix(target).T
    u3s, _ = el._resultant_roots(C)
    rights, images = el._right_pairs(elimination4._with_means(u3s), C, real=False)
    rights, images = elimination4._with_cluster_means(rights, images, C)
    cands = [np.concatenate([left, r]) for r, lefts in zip(rights, el._solve_left_many(images)) for left in lefts]
    cands = [c for c in cands if np.all(np.abs(1 + c * c) > 1e-3 * (1 + np.abs(c) ** 2))]
    distinct: list[np.ndarray] = []
    for c in cands:
        if not any(np.max(np.abs(c - d) / (1 + np.abs(d))) < 1e-6 for d in distinct):
            distinct.append(c)
    return len(distinct)


def chain_of(pattern: str, a, alpha, c) -> apair.AChain:
    return apair.AChain([R if p == "R" else S for p in pattern], a, np.radians(alpha), c)


@pytest.mark.parametrize("design", WITH_COMPLEX, ids=[d[0] for d in WITH_COMPLEX])
def test_the_complex_count_is_the_complete_routes(design):
    """Designs with non-real solutions: full=True counts what the complete route counts, its q are
    the plain answer's."""
    pattern, a, alpha, c, q = design
    chain = chain_of(pattern, a, alpha, c)
    T = chain.fk(np.array(q))
    sol = chain.ik(T, full=True)
    assert sol.certified and holds(sol.q, np.array(q))
    assert sol.complex_count == reference_count(chain, T) > len(sol.q)
    assert same(chain.ik(T), sol.q)


@pytest.mark.parametrize("name", list(CHAINS))
def test_counting_solves_the_left_half_for_few_images(monkeypatch, name):
    """The count of the complex solutions screens the roots u_3 before the left half is solved:
    with full=True the left half takes no more images than the resultant has roots (it took every
    common root of every root, 174 images at the 4A example's poses, 8–80 times the plain time)."""
    chain = CHAINS[name]()
    images: list[int] = []
    roots: list[int] = []
    solve_left, resultant = elimination4.Elimination._solve_left_many, elimination4.Elimination._resultant_roots

    def left(self, Ws):
        images.append(len(Ws))
        return solve_left(self, Ws)

    def counted(self, C):
        out = resultant(self, C)
        roots.append(len(out[0]))
        return out

    monkeypatch.setattr(elimination4.Elimination, "_solve_left_many", left)
    monkeypatch.setattr(elimination4.Elimination, "_resultant_roots", counted)
    for q in reachable(chain)[:6]:
        images.clear()
        roots.clear()
        chain.ik(chain.fk(q), full=True)
        assert len(roots) == 1 and sum(images) <= roots[0], (q, images, roots)
