"""The chain kernels' forms for chains of R-pairs (<family>_revolute<n>, apair.kernels.REVOLUTE): they
are the generic kernels with the slide, pitch and leg terms put to zero (chain_kinematics.revolute),
so at an R-chain's inputs (d = d' = d'' = 0, w = 1, no leg mass) they must give the generic
kernels' values, on both backends and on the designs people build; and AChain takes them exactly
where every pair is an R-pair."""

from __future__ import annotations

import numpy as np
import pytest

import apair
from apair.kernels import REVOLUTE, call, manifest

PI = np.pi
# per family: the per-pose inputs after the law, and how many of the design inputs
# (dh, turning, links, legs, gravity) it takes
FAMILIES = {
    "fk": ((), 1),
    "jacobian": ((), 2),
    "mass_matrix": ((), 4),
    "inverse_dynamics": (("qd", "qdd"), 5),
    "forward_dynamics": (("qd", "tau"), 5),
    "inverse_dynamics_derivatives": (("dddd", "qd", "qdd"), 5),
    "forward_dynamics_derivatives": (("dddd", "qd", "tau"), 5),
}


def r_chain_inputs(n: int, rng: np.random.Generator, special: bool, count: int = 40):
    """law (count, n, 5) at angles with 0 and ±π among them, a design (generic, or of twists 0 and
    ±90° with zero lengths and offsets), and physical links."""
    q = rng.uniform(-PI, PI, (count, n))
    q[: count // 4] = rng.choice([0.0, PI, -PI, PI / 2], (count // 4, n))
    law = np.zeros((count, n, 5))
    law[..., 0], law[..., 1] = np.cos(q / 2), np.sin(q / 2)
    if special:
        a = rng.choice([0.0, 0.0, 0.4], n)
        alpha = rng.choice([0.0, PI / 2, -PI / 2, PI], n)
        c = rng.choice([0.0, 0.3], n)
        phi = rng.choice([0.0, PI / 2], n)
    else:
        a, alpha, c, phi = (rng.uniform(-1, 1, n) for _ in range(4))
    dh = np.stack([a, alpha, c, phi], axis=1)
    links = np.zeros((n, 10))
    links[:, 0] = rng.uniform(0.5, 3.0, n)
    links[:, 1:4] = rng.uniform(-0.3, 0.3, (n, 3))
    links[:, 4:7] = rng.uniform(0.5, 2.0, (n, 3))  # diagonally dominant: positive definite
    links[:, 7:10] = rng.uniform(-0.05, 0.05, (n, 3))
    design = (dh, np.ones(n), links, np.zeros((n, 3)), np.array([0.0, 0.0, -9.81]))
    state = {name: rng.uniform(-2, 2, (count, n)) for name in ("qd", "qdd", "tau")}
    state["dddd"] = np.zeros((count, n))  # an R-pair's third derivative of d
    return law, design, state


def test_the_families_are_the_runtimes():
    """AChain's REVOLUTE names exactly the families that have generated R-chain forms, for every n."""
    assert set(FAMILIES) == REVOLUTE
    names = set(manifest()["kernels"])
    made = {k for k in names if "_revolute" in k and not k.startswith(("law_", "ik_law_"))}
    assert made == {f"{f}_revolute{n}" for f in REVOLUTE for n in range(1, 8)}


@pytest.mark.parametrize("special", [False, True], ids=["generic-design", "special-design"])
@pytest.mark.parametrize("n", range(1, 8))
def test_revolute_kernels_equal_the_generic_ones_on_r_chains(n, special, backend):
    rng = np.random.default_rng(100 * n + special)
    law, design, state = r_chain_inputs(n, rng, special)
    for family, (extra, k) in FAMILIES.items():
        args = (law, *(state[x] for x in extra), *design[:k])
        for want, got in zip(call(f"{family}{n}", *args), call(f"{family}_revolute{n}", *args), strict=True):
            scale = max(float(np.abs(want).max()), 1.0)
            assert np.isfinite(want).all()
            assert np.abs(got - want).max() <= 1e-13 * scale, (family, n, backend)


def test_they_ignore_what_they_fix():
    """The slide, pitch, turning and leg inputs are not read: changing them changes nothing (the
    generic kernel does change), so an R-chain's caller may pass either kernel the same arrays."""
    rng = np.random.default_rng(7)
    law, design, state = r_chain_inputs(6, rng, False)
    other = law.copy()
    other[..., 2:] = rng.uniform(-1, 1, other[..., 2:].shape)
    dh, _, links, _, g = design
    changed = (dh, rng.uniform(0, 1, 6), links, rng.uniform(0.1, 1, (6, 3)), g)
    dddd = {"dddd": rng.uniform(-1, 1, state["dddd"].shape)}
    for family, (extra, k) in FAMILIES.items():
        args = [state[x] for x in extra]
        args_changed = [dddd.get(x, state[x]) for x in extra]
        same = call(f"{family}_revolute6", law, *args, *design[:k])[0]
        assert np.array_equal(call(f"{family}_revolute6", other, *args_changed, *changed[:k])[0], same)
        assert not np.allclose(call(f"{family}6", other, *args_changed, *changed[:k])[0], same)


def _chain(pairs, n=6):
    rng = np.random.default_rng(3)
    links = [apair.Link(1.0 + i, com=(0.05, -0.02, 0.1), inertia=np.diag([0.02, 0.025, 0.03])) for i in range(n)]
    limits = [(-0.5, 0.5) if p.kind == "prismatic" else None for p in pairs]
    return apair.AChain(
        pairs,
        a=rng.uniform(0, 0.5, n),
        alpha=[PI / 2, 0, 0, -PI / 2, PI / 2, 0, -PI / 2][:n],
        links=links,
        limits=limits,
    )


@pytest.mark.parametrize("n", [6, 7])
def test_an_r_chain_takes_them_and_others_do_not(n):
    R = apair.APair.revolute()
    r_chain = _chain([R] * n, n)
    assert r_chain._kernel("mass_matrix") == f"mass_matrix_revolute{n}"
    assert r_chain._kernel("coriolis") == f"coriolis{n}"  # no R-chain form
    for other in (apair.APair(0.06, 0.05), apair.APair.prismatic(), apair.APair.helical(0.01)):
        chain = _chain([R] * (n - 1) + [other], n)
        assert all(chain._kernel(f) == f"{f}{n}" for f in REVOLUTE)
    # the methods (native fast path and validating path) give the generic kernels' values
    q = np.random.default_rng(5).uniform(-PI, PI, (4, n))
    qd, tau = np.ones((4, n)), np.full((4, n), 0.5)
    law, body = r_chain._law(q), r_chain._body
    assert np.allclose(r_chain.mass_matrix(q[0]), call(f"mass_matrix{n}", law[0], *body[:4])[0], rtol=0, atol=1e-12)
    assert np.allclose(r_chain.mass_matrix(q), call(f"mass_matrix{n}", law, *body[:4])[0], rtol=0, atol=1e-12)
    fd = call(f"forward_dynamics{n}", law, qd, tau, *body)[0]
    assert np.allclose(r_chain.forward_dynamics(q, qd, tau), fd, rtol=0, atol=1e-10)
    assert np.allclose(r_chain.forward_dynamics(q[1], qd[1], tau[1]), fd[1], rtol=0, atol=1e-10)
    dfd = call(f"forward_dynamics_derivatives{n}", law, np.zeros((4, n)), qd, tau, *body)
    for got, want in zip(r_chain.forward_dynamics_derivatives(q, qd, tau), dfd, strict=True):
        assert np.allclose(got, want, rtol=1e-12, atol=1e-9)
    did = call(f"inverse_dynamics_derivatives{n}", law[2], np.zeros(n), qd[2], tau[2], *body)
    for got, want in zip(r_chain.inverse_dynamics_derivatives(q[2], qd[2], tau[2])[:2], did, strict=True):
        assert np.allclose(got, want, rtol=1e-12, atol=1e-9)
