"""Constraint varieties of 2-joint chains: vanishing, non-vanishing, the Hilbert function and the
degree, each checked by something independent of the computation."""

from __future__ import annotations

import json
import random
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import apair
from apair import variety as V
from apair.cli import main

X = V.VARS


def chain_2a():
    return apair.AChain([apair.APair(0.1, 0.05), apair.APair(0.1, 0.05)], [0.3, 0.25], [np.pi / 2, 0.0], [0.1, 0.0])


def chain_2r():
    return apair.AChain([apair.APair.revolute(), apair.APair.revolute()], [0.3, 0.25], [np.pi / 2, 0.0], [0.1, 0.0])


@pytest.fixture(scope="module")
def var2a():
    return chain_2a().constraint_variety()


def values(V_, S):
    fns = [sp.lambdify(X, P.as_expr(), "numpy") for P in V_]
    return np.array([f(*S.T) for f in fns])


def random_poses(chain, count, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (count, 2))
    for i, p in enumerate(chain.pairs):
        if p.theta_limit is not None:
            q[:, i] = rng.uniform(-0.98, 0.98, count) * p.theta_limit
    return chain.fk_study(q)


@pytest.mark.slow
def test_2r_is_a_quadric_in_a_3_space():
    W = chain_2r().constraint_variety()
    assert W.exact and W.degree == 2
    assert [P.total_degree() for P in W] == [1, 1, 1, 1, 2]
    assert all(W.hilbert[k] == (k + 1) ** 2 for k in range(7))  # a quadric surface in P^3


@pytest.mark.slow
def test_equations_vanish_on_poses_and_not_elsewhere(var2a):
    chain = chain_2a()
    assert var2a.exact and var2a.degree == 24
    assert [P.total_degree() for P in var2a][:4] == [2, 2, 2, 2]
    assert any(P.as_expr() == X[0] * X[4] + X[1] * X[5] + X[2] * X[6] + X[3] * X[7] for P in var2a)
    S = random_poses(chain, 1000, 1)
    vals = values(var2a, S)
    scale = np.array([max(abs(float(c)) for c in P.coeffs()) for P in var2a])[:, None]
    assert np.max(np.abs(vals) / scale) < 1e-9
    # random points of the Study quadric (y chosen orthogonal to x) are not on the surface
    rng = np.random.default_rng(2)
    x = rng.normal(size=(50, 4))
    y = rng.normal(size=(50, 4))
    y -= (np.sum(x * y, axis=1) / np.sum(x * x, axis=1))[:, None] * x
    off = np.concatenate([x, y], axis=1)
    off /= np.linalg.norm(off, axis=1, keepdims=True)
    assert np.all(np.max(np.abs(values(var2a, off)) / scale, axis=0) > 1e-4)


def test_hilbert_function_from_independent_samples(var2a):
    """Ranks of the monomial matrices at other sample points (other seed) give the same values."""
    js, exact = V.designs(chain_2a())
    pts = V._sample_exact(js, 400, random.Random(99))
    for k in (1, 2, 3, 4):
        mons = V.monomials(k)
        assert V._rank_mod_p(V._monomial_rows_mod_p(pts[: len(mons) + 30], mons).tolist()) == var2a.hilbert[k]


def test_degree_by_counting_points_on_two_hyperplanes():
    """Two random hyperplanes meet the surface in deg points: solve for (u1, u2) by a resultant."""
    js, _ = V.designs(chain_2a())
    u1, u2 = sp.symbols("u1 u2")
    conv = lambda f: sp.Rational(f.numerator, f.denominator)

    def joint(j, u):
        jj = V.JointDesign(j.kind, conv(j.h), conv(j.a), conv(j.c), tuple(map(conv, j.alpha)), tuple(map(conv, j.phi)))
        return V._constant_factors(jj, V._rational_quartic(jj.h, u), sp.Integer(1), sp.Integer(0))

    P = [sp.expand(c) for c in V._smul(joint(js[0], u1), joint(js[1], u2))]
    rng = random.Random(3)
    L = [sum(rng.randint(-9, 9) * c for c in P) for _ in range(2)]
    sq = sp.Poly(sp.sqf_part(sp.resultant(L[0], L[1], u2)), u1)
    f = sp.lambdify((u1, u2), P, "numpy")
    found = []
    for a in np.roots([complex(c) for c in sq.all_coeffs()]):
        for b in np.roots([complex(c) for c in sp.Poly(L[0].subs(u1, a), u2).all_coeffs()]):
            if abs(complex(L[1].subs({u1: a, u2: b}))) < 1e-6 * max(1, abs(b)) ** 8:
                p = np.array(f(a, b), dtype=complex)
                if np.linalg.norm(p) < 1e-9:
                    continue
                p = p / p[np.argmax(np.abs(p))]
                if not any(np.linalg.norm(p - q) < 1e-6 for q in found):
                    found.append(p)
    assert len(found) == 24


def test_float_variant_for_a_general_pair():
    chain = apair.AChain(
        [apair.APair(0.1, 0.05, leg_length=0.12), apair.APair.revolute()], [0.3, 0.25], [np.pi / 2, 0.0]
    )
    W = chain.constraint_variety(max_degree=2)
    assert not W.exact and W.residual < 1e-10
    assert W.dims[2] >= 1  # at least the Study quadric
    S = random_poses(chain, 200, 5)
    vals = values(W, S / np.linalg.norm(S, axis=1, keepdims=True))
    assert np.max(np.abs(vals)) < 1e-9


def test_variety_inputs(tmp_path):
    with pytest.raises(ValueError, match=r"^chain: constraint varieties are computed for 2-pair chains"):
        apair.AChain([apair.APair.revolute()] * 3, [0.1] * 3, [0.0] * 3).constraint_variety()
    with pytest.raises(ValueError, match=r"^max_degree:"):
        chain_2r().constraint_variety(max_degree=7)


@pytest.mark.slow
def test_cli_variety(capsys, tmp_path):
    path = tmp_path / "c.toml"
    path.write_text(
        '[[joint]]\npair = "revolute"\na = 0.3\nalpha_deg = 90\noffset = 0.1\n'
        '[[joint]]\npair = "revolute"\na = 0.25\nalpha = 0\n'
    )
    assert main(["variety", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["exact"] and data["degree"] == 2 and len(data["equations"]) == 5
    assert main(["variety", str(path)]) == 0
    assert "surface of degree 2" in capsys.readouterr().out


def test_float_variant_agrees_with_the_exact_one(var2a):
    """For a rational design, the SVD route on poses from the kernels spans the exact forms."""
    W = V._constraint_variety_float(chain_2a(), 3, seed=1)
    assert not W.exact and W.residual < 1e-9
    assert W.dims[2] == var2a.dims[2] and W.dims[3] == var2a.dims[3]
    assert [P.total_degree() for P in W] == [P.total_degree() for P in var2a if P.total_degree() <= 3]
    S = random_poses(chain_2a(), 300, 8)
    S = S / np.linalg.norm(S, axis=1, keepdims=True)
    assert np.max(np.abs(values(W, S))) < 1e-9


def test_example_variety_in_generated_vanishes_on_its_poses():
    """generated/polynomials/variety_2a_chain (written by codegen.varieties) holds on 1000 poses of
    examples/2a_chain.toml and not on random points of the Study quadric."""
    eqs = apair.polynomials.load("variety_2a_chain")
    xs = sp.symbols("x0 x1 x2 x3 y0 y1 y2 y3", real=True)
    fns = [sp.lambdify(xs, e, "numpy") for e in eqs.values()]
    size = np.array([sum(abs(float(c)) for c in sp.Poly(e, *xs).coeffs()) for e in eqs.values()])[:, None]
    chain = apair.load(Path(__file__).resolve().parents[2] / "examples" / "2a_chain.toml")
    rng = np.random.default_rng(5)
    S = chain.fk_study(rng.uniform(-2 * np.pi, 2 * np.pi, (1000, 2)))
    vals = np.array([f(*S.T) for f in fns]) / size  # the points have |x| = 1 and |y| < 1
    assert np.abs(vals).max() < 1e-13
    R = rng.standard_normal((200, 8))
    x, y = R[:, :4], R[:, 4:]
    R[:, 4:] = y - (np.sum(x * y, 1) / np.sum(x * x, 1))[:, None] * x  # onto the Study quadric
    R /= np.linalg.norm(R, axis=1, keepdims=True)
    far = np.abs(np.array([f(*R.T) for f in fns]) / size).max(axis=0)
    assert far.min() > 1e-6


# ----------------------------------------------------------------------------- symbolic design
SYMBOLIC = apair.polynomials.load("chain_variety_symbolic")
NOTES = {e["label"]: e["note"] for e in apair.polynomials.raw("chain_variety_symbolic")["entries"]}
DESIGN = sp.symbols("a c_alpha s_alpha h1 h2", real=True)


def symbolic_forms(kinds, a, cs, h1, h2, generic_only=False):
    """The derived forms of a chain kind with a design put in; cs = (cos, sin) of α/2 up to a factor."""
    vals = dict(zip(DESIGN, (a, *cs, h1, h2)))
    return [
        sp.Poly(sp.expand(e.subs(vals)), *X)
        for label, e in SYMBOLIC.items()
        if label.startswith(kinds + "_") and not (generic_only and "special" in NOTES[label])
    ]


def pair(kind, radius):
    return apair.APair(radius, radius / 2) if kind == "A" else apair.APair.revolute()


def evaluate(forms, S):
    """|F| / (sum of |coefficients|) of each form at each unit point."""
    fns = [sp.lambdify(X, F.as_expr(), "numpy") for F in forms]
    size = np.array([sum(abs(float(c)) for c in F.coeffs()) for F in forms])[:, None]
    return np.abs(np.array([np.broadcast_to(f(*S.T), len(S)) for f in fns])) / size


@pytest.mark.parametrize("kinds", ["AA", "AR", "RA", "RR"])
def test_symbolic_forms_vanish_on_the_poses_of_random_designs(kinds):
    """Put random designs into the derived forms: they vanish on 1000 poses from the fk kernel (which
    knows nothing of them), and the generic ones do not all vanish off the surface."""
    rng = np.random.default_rng(11)
    for _ in range(3):
        a, alpha = rng.uniform(0.05, 0.5), rng.uniform(-3.0, 3.0)
        pairs = [pair(k, r) for k, r in zip(kinds, rng.uniform(0.03, 0.2, 2))]
        h = [0.0 if p.kind == "revolute" else p.amplitude for p in pairs]
        chain = apair.AChain(pairs, [a, 0.0], [alpha, 0.0], [0.0, 0.0])
        cs = (np.cos(alpha / 2), np.sin(alpha / 2))
        forms = symbolic_forms(kinds, a, cs, *h)
        assert len(forms) >= 5
        S = random_poses(chain, 1000, int(rng.integers(1000)))
        assert evaluate(forms, S / np.linalg.norm(S, axis=1, keepdims=True)).max() < 1e-12
        R = rng.standard_normal((100, 8))
        R[:, 4:] -= (np.sum(R[:, :4] * R[:, 4:], 1) / np.sum(R[:, :4] ** 2, 1))[:, None] * R[:, :4]
        R /= np.linalg.norm(R, axis=1, keepdims=True)
        assert evaluate(symbolic_forms(kinds, a, cs, *h, generic_only=True), R).max(axis=0).min() > 1e-6


def _span(polys, k):
    mons = V.monomials(k)
    rows = [[P.coeff_monomial(m) for m in mons] for P in polys if P.total_degree() == k]
    return sp.Matrix(rows) if rows else sp.zeros(0, len(mons))


@pytest.mark.parametrize("kinds", ["AA", "AR", "RR"])
def test_symbolic_forms_span_what_the_exact_engine_finds(kinds):
    """At a rational design the specialised forms span exactly the linear forms and quadrics that the
    engine finds (apair.variety: nullspaces on sampled points), no more and no fewer."""
    a, t = sp.Rational(2, 5), sp.Rational(3, 7)  # t = tan(α/2)
    pairs = [pair(k, r) for k, r in zip(kinds, (0.1, 0.05))]  # amplitude sqrt(2 r r/2) = r
    h = [sp.Rational(1, 10) if kinds[0] == "A" else 0, sp.Rational(1, 20) if kinds[1] == "A" else 0]
    chain = apair.AChain(pairs, [float(a), 0.0], [2 * np.arctan(3 / 7), 0.0], [0.0, 0.0])
    W = V.constraint_variety(chain, max_degree=2, hilbert_degree=2)
    assert W.exact
    engine, mine = list(W), symbolic_forms(kinds, a, (1, t), *h)
    for forms in (engine, mine):  # the degree-2 part of the ideal includes x_j · (linear forms)
        forms += [sp.Poly(g * F.as_expr(), *X) for F in list(forms) if F.total_degree() == 1 for g in X]
    for k in (1, 2):
        M, N = _span(engine, k), _span(mine, k)
        assert M.rank() == W.dims[k] == N.rank() == M.col_join(N).rank()
