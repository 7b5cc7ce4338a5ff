"""AChain.to_casadi: the chain's equations as CasADi SX functions (generated/casadi, the same lowered
kernels as C and NumPy), against the runtime on every pair kind, legs, frames and seven joints;
CasADi's own derivatives against central differences of the runtime."""

from __future__ import annotations

import math

import numpy as np
import pytest

import apair
from apair import APair, Link

ca = pytest.importorskip("casadi")


def links(n, rng):
    out = []
    for _ in range(n):
        m = rng.uniform(0.5, 2.0)
        x, y, z = rng.uniform(0.05, 0.3, 3)
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        I = Q @ np.diag(m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])) @ Q.T
        out.append(Link(m, rng.uniform(-0.1, 0.1, 3), I))
    return out


def chains():
    rng = np.random.default_rng(3)
    r_b, r_p = 0.05, 0.04
    general = APair(r_b, r_p, leg_length=math.sqrt(r_b**2 + r_p**2 / 4 + 0.5 * r_b * r_p), leg_mass=0.05)
    mixed = apair.AChain(
        [APair.revolute(), APair(0.06, 0.05, leg_mass=0.1), general, APair.prismatic(), APair.helical(0.01)],
        a=[0.0, 0.3, 0.0, 0.1, 0.0],
        alpha=[np.pi / 2, 0.0, -np.pi / 2, 0.0, np.pi / 2],
        offset=[0.25, 0.0, 0.0, 0.0, 0.05],
        theta_offset=[0.0, 0.3, 0.0, 0.2, 0.0],
        links=links(5, rng),
        limits=[None, None, None, (-0.1, 0.2), None],
        gravity=(0.3, -0.2, -9.81),
        base=apair.frame([0.1, 0.2, 0.3], [0.1, -0.2, 0.3]),
        tool=apair.frame([0.0, 0.05, 0.12], [0.0, np.pi / 2, 0.0]),
    )
    seven = apair.AChain(
        [APair.revolute() if i % 2 else APair(0.05, 0.05, leg_mass=0.05) for i in range(7)],
        a=rng.uniform(-0.3, 0.3, 7),
        alpha=rng.choice([0.0, np.pi / 2, -np.pi / 2], 7),
        offset=rng.uniform(-0.2, 0.2, 7),
        links=links(7, rng),
    )
    return {"example": apair.io.load("examples/4a_chain.toml"), "mixed": mixed, "seven": seven}


CHAINS = chains()


def states(chain, rng, count=4):
    lim = chain.limits
    for _ in range(count):
        lo, hi = np.maximum(lim[:, 0], -3), np.minimum(lim[:, 1], 3)
        span = hi - lo
        yield rng.uniform(lo + 0.05 * span, hi - 0.05 * span), rng.normal(size=chain.n), rng.normal(size=chain.n)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_functions_equal_the_runtime(name):
    chain = CHAINS[name]
    F = chain.to_casadi()
    assert sorted(F) == sorted(["fk", "jacobian", "mass_matrix", "inverse_dynamics", "forward_dynamics"])
    rng = np.random.default_rng(4)
    for q, qd, qdd in states(chain, rng):
        np.testing.assert_allclose(np.array(F["fk"](q)), chain.fk(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(np.array(F["jacobian"](q)), chain.jacobian(q), rtol=0, atol=1e-12)
        M = chain.mass_matrix(q)
        np.testing.assert_allclose(np.array(F["mass_matrix"](q)), M, rtol=0, atol=1e-12 * np.abs(M).max())
        tau = chain.inverse_dynamics(q, qd, qdd)
        got = np.array(F["inverse_dynamics"](q, qd, qdd)).ravel()
        np.testing.assert_allclose(got, tau, rtol=0, atol=1e-12 * np.abs(tau).max())
        got = np.array(F["forward_dynamics"](q, qd, tau)).ravel()
        np.testing.assert_allclose(got, chain.forward_dynamics(q, qd, tau), rtol=0, atol=1e-12 * np.abs(qdd).max() * 10)


@pytest.mark.parametrize("name", ["example", "mixed"])
def test_casadi_derivatives_equal_central_differences(name):
    """CasADi's jacobian of its forward dynamics, and of fk, against central differences of the
    runtime's (an independent route: the graph is differentiated, the runtime only evaluated)."""
    chain = CHAINS[name]
    F = chain.to_casadi()
    n = chain.n
    q_, qd_, tau_ = (ca.SX.sym(s, n) for s in ("q", "qd", "tau"))
    fd = F["forward_dynamics"](q_, qd_, tau_)
    D = ca.Function("D", [q_, qd_, tau_], [ca.jacobian(fd, q_), ca.jacobian(fd, qd_), ca.jacobian(fd, tau_)])
    rng = np.random.default_rng(5)
    for q, qd, _ in states(chain, rng, 2):
        tau = rng.normal(size=n)
        dq, dqd, dtau = (np.array(x) for x in D(q, qd, tau))
        h = 1e-6
        for k in range(n):
            e = np.zeros(n)
            e[k] = h
            col_q = (chain.forward_dynamics(q + e, qd, tau) - chain.forward_dynamics(q - e, qd, tau)) / (2 * h)
            col_qd = (chain.forward_dynamics(q, qd + e, tau) - chain.forward_dynamics(q, qd - e, tau)) / (2 * h)
            np.testing.assert_allclose(dq[:, k], col_q, rtol=1e-5, atol=1e-6 * np.abs(col_q).max())
            np.testing.assert_allclose(dqd[:, k], col_qd, rtol=1e-5, atol=1e-6 * np.abs(col_qd).max())
        np.testing.assert_allclose(dtau, np.linalg.inv(chain.mass_matrix(q)), rtol=1e-10, atol=1e-12)


def test_casadi_generates_c_of_the_chain(tmp_path):
    """CasADi's own code generation through the functions: the generated C evaluates like the graph."""
    chain = CHAINS["example"]
    F = chain.to_casadi()["inverse_dynamics"]
    import subprocess

    cg = ca.CodeGenerator("id_chain.c", {"with_header": True})
    cg.add(F)
    cg.generate(str(tmp_path) + "/")
    lib = tmp_path / "id_chain.so"
    subprocess.run(["gcc", "-O1", "-fPIC", "-shared", str(tmp_path / "id_chain.c"), "-o", str(lib)], check=True)
    G = ca.external("inverse_dynamics", str(lib))
    q, qd, qdd = np.array([0.3, -0.2, 0.4, 0.1]), np.array([0.5, 0.1, -0.3, 0.2]), np.array([1.0, -0.5, 0.2, 0.3])
    np.testing.assert_allclose(
        np.array(G(q, qd, qdd)).ravel(), chain.inverse_dynamics(q, qd, qdd), rtol=1e-13, atol=1e-13
    )


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_casadi_jacobian_of_forward_dynamics_equals_the_derivative_kernels(name):
    """CasADi differentiating its graph of forward_dynamics equals forward_dynamics_derivatives (the
    generated derivative kernels) to 1e-9: two independent routes to the same derivatives."""
    chain = CHAINS[name]
    n = chain.n
    q_, qd_, tau_ = (ca.SX.sym(s, n) for s in ("q", "qd", "tau"))
    fd = chain.to_casadi()["forward_dynamics"](q_, qd_, tau_)
    D = ca.Function("D", [q_, qd_, tau_], [ca.jacobian(fd, q_), ca.jacobian(fd, qd_), ca.jacobian(fd, tau_)])
    rng = np.random.default_rng(6)
    for q, qd, _ in states(chain, rng, 3):
        tau = rng.normal(size=n) * 3
        for got, ref in zip(D(q, qd, tau), chain.forward_dynamics_derivatives(q, qd, tau)):
            got = np.array(got)
            assert np.abs(got - ref).max() <= 1e-9 * max(1.0, np.abs(ref).max()), name
