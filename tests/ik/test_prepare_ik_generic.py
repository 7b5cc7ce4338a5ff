"""prepare_ik's verdict "no isolated solutions at a generic pose" (apair.ik.homotopy.monodromy,
issue 36 item 7): it rests on the Jacobian at random seed points, so a singular point of a generic
design is drawn again, and only a design singular at every point drawn is refused."""

from __future__ import annotations

import numpy as np
import pytest

import apair
from apair.ik import homotopy
from apair.ik.homotopy import monodromy

R = apair.APair.revolute()


def prepare_rng(problem: homotopy.Problem) -> np.random.Generator:
    """The generator homotopy.prepare hands its first monodromy run (seed 0)."""
    return np.random.default_rng([0, problem.n, problem.joints, 17])


def first_seed_point(monkeypatch) -> np.ndarray:
    """The first joint vector the seed search of a 6-joint chain draws (the same for every design:
    it comes from prepare's generator), read where it asks for the poses through it."""
    seen: list[np.ndarray] = []

    def record(problem, theta):
        seen.append(np.array(theta))
        raise StopIteration

    with monkeypatch.context() as m:
        m.setattr(monodromy, "linear_pose", record)
        problem = homotopy.Problem.of(apair.AChain([R] * 6, [0.3] * 6, [1.0] * 6))
        with pytest.raises(StopIteration):
            monodromy._seed_solution(problem, prepare_rng(problem))
    return seen[0]


def jacobian_at(chain: apair.AChain, theta: np.ndarray) -> np.ndarray:
    """The homotopy's Jacobian dF/dθ at θ and a pose through it (one with a rotation part)."""
    problem = homotopy.Problem.of(chain)
    A, b = homotopy.linear_pose(problem, theta)
    p, *_ = np.linalg.lstsq(A, -b, rcond=None)
    p = p + np.linalg.svd(A)[2][-1].conj()
    return homotopy.system(problem, theta, p, np.zeros(7, complex))[1]


def relative_det(chain: apair.AChain, theta: np.ndarray) -> complex:
    """det of jacobian_at over the product of all but its smallest singular value (≈ the smallest
    singular value, with a phase)."""
    J = jacobian_at(chain, theta)
    return complex(np.linalg.det(J) / np.prod(np.linalg.svd(J, compute_uv=False)[:-1]))


def singular_at(theta: np.ndarray) -> apair.AChain:
    """A random 6R design whose Jacobian is singular at θ: a_3 and c_4 solved for by Newton's
    method (one complex equation, two real unknowns); every other constant random."""
    rng = np.random.default_rng(3)
    a, alpha, c = rng.uniform(0.1, 0.5, 6), rng.uniform(-1.5, 1.5, 6), rng.uniform(-0.2, 0.2, 6)

    def chain(x):
        aa, cc = a.copy(), c.copy()
        aa[2], cc[3] = x
        return apair.AChain([R] * 6, aa, alpha, cc)

    x = np.array([a[2], c[3]])
    for _ in range(30):
        f = relative_det(chain(x), theta)
        if abs(f) < 1e-14:
            break
        d = [(relative_det(chain(x + 1e-7 * e), theta) - f) / 1e-7 for e in np.eye(2)]
        x = x - np.linalg.solve([[d[0].real, d[1].real], [d[0].imag, d[1].imag]], [f.real, f.imag])
    return chain(x)


def test_a_singular_first_seed_point_is_drawn_again(monkeypatch):
    """A generic 6R design built so that the first seed point prepare_ik draws is singular there:
    the point is drawn again, and the start set has the generic 6R count, certified."""
    theta = first_seed_point(monkeypatch)
    chain = singular_at(theta)
    sv = np.linalg.svd(jacobian_at(chain, theta), compute_uv=False)
    assert sv[-1] < 1e-12 * sv[0]  # singular where the seed search first looks
    start = chain.prepare_ik()
    assert start.count == 16 and start.certified


def test_a_design_without_isolated_solutions_is_still_refused(monkeypatch):
    """Two R-pairs on one axis: singular at every point, refused after SEED_DRAWS of them."""
    coaxial = apair.AChain([R] * 6, [0.0, 0.3, 0.2, 0.1, 0.2, 0.1], [0.0, 1.0, 0.5, 1.2, 0.7, 0.4])
    problem = homotopy.Problem.of(coaxial)
    calls: list[int] = []
    real = monodromy.linear_pose
    monkeypatch.setattr(monodromy, "linear_pose", lambda *args: (calls.append(1), real(*args))[1])
    with pytest.raises(ValueError, match=r"no isolated solutions.*singular at \d+ random points"):
        monodromy._seed_solution(problem, prepare_rng(problem))
    assert len(calls) == monodromy.SEED_DRAWS


def random_design(rng: np.random.Generator) -> apair.AChain:
    pattern = rng.choice(["R", "A"], 6)
    pairs = [R if c == "R" else apair.APair(*rng.uniform(0.03, 0.12, 2)) for c in pattern]
    return apair.AChain(
        pairs,
        rng.uniform(0.05, 0.5, 6),
        rng.uniform(-np.pi, np.pi, 6),
        rng.uniform(-0.3, 0.3, 6),
        rng.uniform(-1, 1, 6),
    )


def test_generic_six_joint_chains_are_never_refused():
    """The seed search of 600 random 6-joint designs (R/A patterns, twists over the whole circle),
    each with prepare's generator and four runs' worth of draws: never a refusal, and every seed
    point is a regular solution of its pose."""
    rng = np.random.default_rng(36)
    for _ in range(600):  # 2000 (none refused) took 2 of the suite's 20 minutes
        problem = homotopy.Problem.of(random_design(rng))
        draws = prepare_rng(problem)
        for _ in range(4):
            theta, p = monodromy._seed_solution(problem, draws)
            F, J, _ = homotopy.system(problem, theta, p, np.zeros(7, complex))
            sv = np.linalg.svd(J, compute_uv=False)
            assert np.abs(F).max() <= 1e-9 and sv[-1] >= 1e-8 * sv[0]
