"""The measurements of one chain over its joint space: joint ranges and axial travel, dexterity
(manipulability and condition number), gravity torques, mass and inertia, inverse-kinematics
solution counts.

Dexterity is scale-free: the Jacobian's translation rows are divided by a length (the chain's
length scale, `apair.ik.poses.length_scale`, the same for the chain and its twin), so a chain
scaled by s has the same numbers. Its singular values σ₁ ≥ … ≥ σ_k (k = min(6, n)) give the
manipulability σ₁⋯σ_k (√det(J Jᵀ) for n = 6, √det(Jᵀ J) for n < 6) and the condition number
σ₁/σ_k; a sample is near a singularity where σ_k/σ₁ < SINGULAR.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from .twin import Chain

SINGULAR = 0.01  # σ_min/σ_max below this: near a singularity
TRAVEL_GRID = 4001  # angles per joint range at which the axial travel d(θ) is evaluated
MAX_IK_JOINTS = 4  # ik counts for n ≤ 4 (elimination, milliseconds); 5 and 6 need start systems


def uniform(chain: Chain, count: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """(count, n) joint vectors drawn uniformly inside the chain's limits."""
    lim = chain.limits
    return rng.uniform(lim[:, 0], lim[:, 1], (count, chain.n))


def full_turns(chain: Chain) -> list[bool]:
    """Per joint: whether nothing stops it (no explicit limit, no collision, no range end)."""
    return [not bool(np.isfinite(row).any()) for row in chain.hard_limits()]


def axial_travel(chain: Chain) -> NDArray[np.float64]:
    """(n,): max d − min d of each joint over its range [m] (0 for an R-pair): the translation
    along its axis that an A-pair adds. d(θ) on a grid of the range with its ends and 0."""
    out = np.zeros(chain.n)
    for i, (pair, (lo, hi)) in enumerate(zip(chain.pairs, chain.limits)):
        if not pair.is_apair:  # an R-pair, or a P- or H-pair whose slide is its own
            continue
        theta = np.linspace(lo, hi, TRAVEL_GRID)
        if lo < 0 < hi:
            theta = np.append(theta, 0.0)
        d = pair.law(theta)[:, 0]
        out[i] = float(d.max() - d.min())
    return out


def scaled_singular_values(chain: Chain, q: NDArray[np.float64], scale: float) -> NDArray[np.float64]:
    """(m, min(6, n)): singular values of the Jacobian with its translation rows over `scale`."""
    J = chain.jacobian(q).copy()
    J[:, :3, :] /= scale
    return np.asarray(np.linalg.svd(J, compute_uv=False), dtype=np.float64)


def dexterity(
    chain: Chain, q: NDArray[np.float64], scale: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """(manipulability (m,), condition number (m,), share near a singularity) at the samples q."""
    s = scaled_singular_values(chain, q, scale)
    w = np.prod(s, axis=1)
    smallest = s[:, -1]
    kappa = np.full(len(s), math.inf)
    kappa[smallest > 0] = s[smallest > 0, 0] / smallest[smallest > 0]
    near = float(np.mean(s[:, -1] < SINGULAR * s[:, 0]))
    return w, kappa, near


def gravity(chain: Chain, q: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(max |g_i|, RMS g_i) per joint over the samples q [N m]."""
    g = chain.gravity_torques(q)
    return np.abs(g).max(axis=0), np.sqrt(np.mean(g**2, axis=0))


def masses(chain: Chain) -> tuple[float, float]:
    """(total mass, the legs' mass) [kg]: the links plus six legs of leg_mass per A-pair. The plates
    have no mass of their own: the link that carries a pair's platform is its body."""
    legs = 6.0 * sum(p.leg_mass for p in chain.pairs if p.is_apair)
    return float(sum(link.mass for link in chain.links) + legs), float(legs)


def inertia(chain: Chain, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """(n,): the mean over the samples of the mass matrix's diagonal (legs included) [kg m²]."""
    M = chain.mass_matrix(q)
    return np.diagonal(M, axis1=-2, axis2=-1).mean(axis=0)


def ik_counted(chain: Chain) -> bool:
    """Whether all-solutions inverse kinematics covers the chain's pairs (R- and sinusoidal A-pairs)."""
    return all(p.kind in ("revolute", "sinusoidal") for p in chain.pairs)


def ik_counts(chain: Chain, q: NDArray[np.float64]) -> tuple[int | None, list[int], list[int]]:
    """(complex count at the first sample's pose, real counts and real counts inside the limits
    at every sample's pose); None and empty lists for n > MAX_IK_JOINTS and for chains with P- or
    H-pairs or general A-pairs, whose all-solutions inverse kinematics apair does not have."""
    if chain.n > MAX_IK_JOINTS or len(q) == 0 or not ik_counted(chain):
        return None, [], []
    complex_count: int | None = None
    real, inside = [], []
    for k, pose in enumerate(chain.fk(q)):
        sol = chain.ik(pose, full=True)
        if k == 0:
            complex_count = sol.complex_count
        real.append(len(sol.q))
        inside.append(int(np.count_nonzero(sol.inside)))
    return complex_count, real, inside
