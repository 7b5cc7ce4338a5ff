"""The derivations against the known results of docs/conventions.md §2, and generated/ against them."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import sympy as sp

import apair

# Every test here derives the kernels afresh (about a minute): the full suite only.
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
r_b, r_p, L1, L2 = sp.symbols("r_b r_p L1 L2", positive=True)
a, b, h, theta = sp.symbols("a b h theta", real=True)
x0, x3, y0, y3 = sp.symbols("x0 x3 y0 y3", real=True)


def test_pair_facts_match_the_known_results(derivations):
    _, _, facts = derivations["apair_pair"]
    assert sp.simplify(facts["d_squared"] - (a + b * sp.cos(theta))) == 0
    assert sp.simplify(facts["amplitude"] - sp.sqrt(2 * r_b * r_p)) == 0
    assert sp.expand(facts["sinusoidal_L1"] ** 2 - (r_b**2 + r_p**2 / 4 + r_b * r_p)) == 0
    cons = facts["consistency"]
    assert sp.expand(cons.lhs - cons.rhs - (L1**2 - L2**2 - sp.Rational(3, 4) * (r_b**2 - r_p**2))) == 0


def test_mobility_is_one_along_the_motion(derivations):
    _, _, facts = derivations["apair_pair"]
    assert len(facts["mobility"]) >= 8
    for sigma5, sigma6 in facts["mobility"]:
        assert sigma6 < 1e-30 and sigma5 > 1e-6  # rank exactly 5


def test_pair_quadric_is_the_stated_one():
    eqs = apair.polynomials.load("apair_motion")
    stated = 4 * (y0**2 + y3**2) - (a + b) * x0**2 - (a - b) * x3**2
    assert sp.expand(eqs["pair_quadric"] - stated) == 0
    assert eqs["law"].rhs == a + b * sp.cos(theta)
    assert eqs["law_sinusoidal"].rhs == h * sp.cos(theta / 2)


def test_rational_parametrisation_lies_on_the_pair(derivations):
    eqs = apair.polynomials.load("apair_motion")
    u = sp.Symbol("u", real=True)
    P = {n: eqs[f"rational_{n}"] for n in ("x0", "x3", "y0", "y3")}
    on = eqs["pair_quadric"].xreplace({x0: P["x0"], x3: P["x3"], y0: P["y0"], y3: P["y3"]})
    on = on.xreplace({a: b, h: sp.sqrt(2 * b)})
    assert sp.expand(on) == 0
    assert sp.expand(P["x0"] * P["y0"] + P["x3"] * P["y3"]) == 0
    assert max(sp.Poly(c, u).degree() for c in P.values()) == 4  # a rational quartic


def test_polynomials_load_back_equal_to_the_derivation(derivations):
    for sets, _, _ in derivations.values():
        for ps in sets:
            loaded = apair.polynomials.load(ps.name)
            assert list(loaded) == [e.label for e in ps.entries]
            for e in ps.entries:
                got = loaded[e.label]
                if e.rhs is None:
                    assert sp.expand(got - e.expr) == 0, (ps.name, e.label)
                else:
                    assert sp.expand(got.lhs - e.expr) == 0 and sp.simplify(got.rhs - e.rhs) == 0, (ps.name, e.label)


def test_chain_jacobian_route_checked(derivations):
    _, _, facts = derivations["chain_kinematics"]
    assert set(facts["jacobian_check"]) == {1, 2, 3}
    assert all(v < 1e-40 for v in facts["jacobian_check"].values())


@pytest.mark.parametrize("seed", ["1", "4242"])
def test_generation_is_deterministic(seed, tmp_path):
    """Regenerating under another hash seed gives the same files byte for byte (two of the
    derivations, to keep the suite quick; `make check` compares everything with generated/)."""
    env = dict(os.environ, PYTHONHASHSEED=seed, PYTHONPATH=str(ROOT))
    res = subprocess.run(
        [sys.executable, "-m", "codegen", "--out", str(tmp_path), "--only", "apair_pair", "chain_kinematics"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr
    fresh = {p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file()}
    own = {
        rel
        for rel in fresh
        if rel.parts[0] in ("c", "numpy", "polynomials")
        and rel.name
        not in (
            "apair.h",
            "apair_internal.h",
            "apair_registry.c",
            "CMakeLists.txt",
            "apair.pc.in",
            "__init__.py",
        )
    }  # indexes of all, and the solvers (sized by the whole set)
    assert len(own) >= 10
    for rel in sorted(own):
        assert (tmp_path / rel).read_bytes() == (ROOT / "generated" / rel).read_bytes(), rel


def test_every_generated_file_names_its_source_and_hash():
    for p in (ROOT / "generated").rglob("*"):
        if p.is_file() and p.suffix in (".c", ".h", ".py", ".txt", ".tex") and "__pycache__" not in p.parts:
            head = p.read_text()[:1000]  # the banner (the registry's lists every derivation)
            assert "Do not edit" in head and ("Content hash" in head), p
            # derived sets name their derivation; the example varieties name their exporter; the
            # copies of the hand-written C their source in src/csrc
            assert (
                "derivations/" in head
                or "codegen/varieties.py" in head
                or "(hand-written)" in head
                or p.name == "__init__.py"
            ), p


def test_chain2_study_polynomials_are_the_kernel(backend):
    """The printed Study point of a 2-joint chain evaluates to fk_study of a random 2A-chain."""
    import numpy as np

    eqs = apair.polynomials.load("chain2_study")
    rng = np.random.default_rng(8)
    chain = apair.AChain(
        [apair.APair(0.3, 0.5), apair.APair(0.4, 0.2, leg_length=0.45)],
        rng.uniform(-1, 1, 2),
        rng.uniform(-3, 3, 2),
        rng.uniform(-1, 1, 2),
        rng.uniform(-3, 3, 2),
    )
    q = rng.uniform(-1, 1, 2)
    d = [p.translation(x) for p, x in zip(chain.pairs, q)]
    values = {}
    for i in range(2):
        ht, ha = (q[i] + chain.theta_offset[i]) / 2, chain.alpha[i] / 2
        for name, v in [
            ("C", np.cos(ht)),
            ("S", np.sin(ht)),
            ("K", np.cos(ha)),
            ("L", np.sin(ha)),
            ("a", chain.a[i]),
            ("D", chain.offset[i] + d[i]),
        ]:
            values[sp.Symbol(f"{name}_{i + 1}", real=True)] = v
    got = np.array([float(eqs[n].xreplace(values)) for n in ("x0", "x1", "x2", "x3", "y0", "y1", "y2", "y3")])
    want = chain.fk_study(q)
    assert np.allclose(got, want, atol=1e-13) or np.allclose(got, -want, atol=1e-13)


def test_dynamics_routes_checked(derivations):
    _, _, facts = derivations["chain_dynamics"]
    assert set(facts["bias_check"]) == {1, 2, 3}
    assert all(v < 1e-20 for v in facts["bias_check"].values())


def test_single_pair_equation_matches_the_hand_result(derivations):
    """J = I_zz + m(c_x²+c_y²) + (m + 2 m_l) d'² + (5/4) m_l r_p², G = (m + 3 m_l) g d'."""
    _, _, f = derivations["apair_dynamics"]
    m, cx, cy, Izz, ml, g = sp.symbols("m c_x c_y I_zz m_l g", real=True)
    rp = sp.Symbol("r_p", positive=True)
    d1, d2 = sp.symbols("dd ddd", real=True)
    assert sp.expand(f["J"] - (Izz + m * (cx**2 + cy**2) + (m + 2 * ml) * d1**2 + sp.Rational(5, 4) * ml * rp**2)) == 0
    assert sp.expand(f["G"] - (m + 3 * ml) * g * d1) == 0
    assert sp.expand(f["half_dJ"] - (m + 2 * ml) * d1 * d2) == 0
