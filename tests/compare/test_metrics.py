"""The joint-space measurements against independent computations: manipulability and condition
number against numpy on the Jacobian, the gravity torques against differences of the potential
energy, the inertia against the kinetic energy, the mass against the potential energy's change when
everything is lifted, the axial travel against the sinusoidal law's closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest
from compare_designs import arm3a, mixed

import apair
from apair.compare import metrics, twin
from apair.ik.poses import length_scale

RNG = np.random.default_rng(11)


def six_joint() -> apair.AChain:
    pairs = [apair.APair(0.05, 0.04), apair.APair.revolute(), apair.APair(0.04, 0.04)] + [apair.APair.revolute()] * 3
    return apair.AChain(
        pairs, [0.05, 0.4, 0.05, 0, 0, 0], np.radians([90, 0, 90, -90, 90, 0]), [0.3, 0, 0, 0.35, 0, 0.08]
    )


@pytest.mark.parametrize("make", [arm3a, mixed, six_joint])
def test_manipulability_and_condition_against_numpy(make):
    chain = make()
    q = metrics.uniform(chain, 300, RNG)
    L = length_scale(chain)
    w, kappa, near = metrics.dexterity(chain, q, L)
    J = chain.jacobian(q) * np.array([1 / L] * 3 + [1.0] * 3)[:, None]
    gram = J @ np.swapaxes(J, 1, 2) if chain.n == 6 else np.swapaxes(J, 1, 2) @ J
    assert np.allclose(w, np.sqrt(np.linalg.det(gram)), rtol=1e-8)
    assert np.allclose(kappa, np.linalg.cond(J), rtol=1e-8)
    assert near == pytest.approx(np.mean(1 / np.linalg.cond(J) < metrics.SINGULAR))


def test_dexterity_is_scale_free():
    """A chain with every length times 7 has the same manipulability and condition numbers."""
    chain = six_joint()
    big = apair.AChain(
        [apair.APair(0.35, 0.28), apair.APair.revolute(), apair.APair(0.28, 0.28)] + [apair.APair.revolute()] * 3,
        7 * chain.a,
        chain.alpha,
        7 * chain.offset,
    )
    q = metrics.uniform(chain, 200, RNG)
    small_w, small_k, _ = metrics.dexterity(chain, q, length_scale(chain))
    big_w, big_k, _ = metrics.dexterity(big, q, length_scale(big))
    assert np.allclose(small_w, big_w, rtol=1e-9) and np.allclose(small_k, big_k, rtol=1e-9)


def test_a_wrist_singularity_is_counted_near_a_singularity():
    """The 6R twin's wrist at θ5 = 0 lines up the axes of joints 4 and 6 through the end effector's
    origin: two equal Jacobian columns, so the condition number is infinite (or huge)."""
    other = twin.build(six_joint())
    q = np.array([[0.3, 0.2, -0.4, 0.5, 0.0, 0.2], [0.3, 0.2, -0.4, 0.5, 1.0, 0.2]])
    _, kappa, near = metrics.dexterity(other, q, 0.4)
    assert kappa[0] > 1e12 and kappa[1] < 1e3 and near == 0.5


def test_gravity_torques_against_the_potential_energy():
    chain = mixed()
    q = metrics.uniform(chain, 400, RNG)
    g_max, g_rms = metrics.gravity(chain, q)
    eps = 1e-6
    zero = np.zeros_like(q)
    g = np.stack(
        [
            (chain.energy(q + eps * e, zero)[:, 1] - chain.energy(q - eps * e, zero)[:, 1]) / (2 * eps)
            for e in np.eye(chain.n)
        ],
        axis=1,
    )
    assert np.allclose(g_max, np.abs(g).max(axis=0), rtol=1e-6, atol=1e-8)
    assert np.allclose(g_rms, np.sqrt(np.mean(g**2, axis=0)), rtol=1e-6, atol=1e-8)


def test_inertia_against_the_kinetic_energy():
    """M_ii = 2 T(q, e_i): the mean diagonal from the kinetic energy at unit joint speeds."""
    chain = mixed()
    q = metrics.uniform(chain, 300, RNG)
    diag = np.stack([2 * chain.energy(q, np.broadcast_to(e, q.shape))[:, 0] for e in np.eye(chain.n)], axis=1)
    assert np.allclose(metrics.inertia(chain, q), diag.mean(axis=0), rtol=1e-10)


def test_mass_against_the_potential_energy_of_a_lift():
    """Raising the first R-pair's offset by δ lifts every body (links and legs above it) by δ: the
    potential energy grows by m g δ."""
    chain = mixed()
    lifted = apair.AChain(
        chain.pairs,
        chain.a,
        chain.alpha,
        chain.offset + [0.1, 0, 0],
        links=chain.links,
        limits=[(-2.5, 2.0), None, None],
    )
    q = metrics.uniform(chain, 5, RNG)
    dV = lifted.energy(q, np.zeros_like(q))[:, 1] - chain.energy(q, np.zeros_like(q))[:, 1]
    mass, legs = metrics.masses(chain)
    assert np.allclose(dV, mass * 9.81 * 0.1, rtol=1e-12)
    assert legs == pytest.approx(6 * (0.07 + 0.03))
    assert metrics.masses(twin.build(chain)) == (pytest.approx(mass - legs), 0.0)


def test_axial_travel_is_the_sinusoidal_rise_over_the_range():
    """d = h cos(θ/2) over |θ| ≤ θ_max: travel h (1 − cos(θ_max/2)); an R-pair none."""
    chain = mixed()
    travel = metrics.axial_travel(chain)
    pair, (lo, hi) = chain.pairs[1], chain.limits[1]
    assert travel[0] == 0
    assert travel[1] == pytest.approx(pair.amplitude * (1 - math.cos(max(-lo, hi) / 2)), rel=1e-9)
    general = chain.pairs[2]
    lo, hi = chain.limits[2]
    grid = np.linspace(lo, hi, 100_001)
    d = general.translation(grid)
    assert travel[2] == pytest.approx(d.max() - d.min(), rel=1e-6)
    assert np.all(metrics.axial_travel(twin.build(chain)) == 0)


def test_full_turns():
    chain = mixed()
    assert metrics.full_turns(chain) == [False, False, False]
    assert metrics.full_turns(twin.build(chain)) == [False, True, True]


def test_ik_counts_at_sampled_poses():
    """Each sampled pose is reached by its own sample: at least one real solution, at most the
    complex count; none counted for more than four joints."""
    chain = arm3a()
    q = metrics.uniform(chain, 4, RNG)
    complex_count, real, inside = metrics.ik_counts(chain, q)
    assert complex_count == chain.ik(chain.fk(q[0]), full=True).complex_count
    assert all(1 <= r <= complex_count for r in real) and all(0 <= i <= r for i, r in zip(inside, real))
    assert all(i >= 1 for i in inside)  # the sample itself lies inside the limits
    assert metrics.ik_counts(six_joint(), q[:, [0, 1, 2, 0, 1, 2]]) == (None, [], [])
