"""Inverse kinematics with joints held (`AChain.ik(T, fix={k: value})`): the held joints folded
exactly into the base, the tool or their neighbours' DH constants, leaving a chain of the other
joints that the solvers take (a 7-joint arm with one joint held is a 6-joint problem)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _validate as V
from .frames import dh_matrix, inverse
from .ik.poses import pose_matrix

if TYPE_CHECKING:
    from .ik import Solution

AChain = Any  # an apair.chain.AChain: this module sits below it (the chain passes its class as `make`)

PARALLEL = 1e-14  # |z × u| below this: the two joint axes are parallel (the DH normal taken through the origin)
HOLD_TOL = 1e-11  # a folded chain reproduces the original to this (relative to its size), else it is refused


def _as_dh(G: NDArray[np.float64]) -> tuple[float, float, float, float, float, float]:
    """G (4, 4), from a frame whose z is one joint axis to a frame whose z is the next, as
    Rz(δ) · Tz(e) · Tx(a) · Rx(α) · Rz(δ') · Tz(e'): the DH step along the axes' common normal
    (through the origin where they are parallel) and the screw along the second axis that remains.
    Returns (δ, e, a, α, δ', e')."""
    p, u = G[:3, 3], G[:3, 2]
    s = math.hypot(u[0], u[1])  # |e_z × u|
    if s > PARALLEL:
        x = np.array([-u[1], u[0], 0.0]) / s
        t1 = (u[2] * p[2] - float(p @ u)) / (s * s)  # feet of the common normal: t0 e_z and p + t1 u
        e = p[2] + t1 * u[2]
    else:
        r = np.array([p[0], p[1], 0.0])
        if math.hypot(r[0], r[1]) <= PARALLEL * max(1.0, float(np.abs(p).max())):
            r = np.array([G[0, 0], G[1, 0], 0.0])  # coincident axes: keep the frame's own x
        x, e, t1 = r / math.hypot(r[0], r[1]), 0.0, 0.0
    delta = math.atan2(x[1], x[0])
    cd, sd = math.cos(delta), math.sin(delta)
    uy = -sd * u[0] + cd * u[1]  # u in the frame turned by δ about z
    size = max(1.0, float(np.abs(p).max()))
    a = _snap(float(x @ (p + t1 * u)), size)
    delta, e, alpha = _snap_angle(delta), _snap(e, size), _snap_angle(math.atan2(-uy, u[2]))
    S = inverse(dh_matrix(a, alpha, e, delta)) @ G
    return delta, e, a, alpha, _snap_angle(math.atan2(S[1, 0], S[0, 0])), _snap(float(S[2, 3]), size)


SNAP = 64 * np.finfo(float).eps  # a folded constant this close to 0 or to a multiple of π/2 is that


def _snap(x: float, size: float) -> float:
    """A length of rounding noise (|x| ≤ SNAP · size) made 0: the solvers see the exact geometry
    (intersecting axes) rather than a near-degenerate one."""
    return 0.0 if abs(x) <= SNAP * size else x


def _snap_angle(x: float) -> float:
    """An angle within SNAP of a multiple of π/2 put on it (the same float as the chain files')."""
    k = round(x / (math.pi / 2))
    return k * (math.pi / 2) if abs(x - k * (math.pi / 2)) <= SNAP else x


def hold(chain: AChain, fix: Mapping[int, float], make: Callable[..., AChain]) -> tuple[AChain, list[int], list[float]]:
    """The chain of the joints not in `fix` (k from 1: value [rad]), the held ones' transforms
    folded in: joint 1 into the base, joint n into the tool, an interior joint k, with Tx(a_{k−1}) ·
    Rx(α_{k−1}), into new DH constants of joint k − 1 (`_as_dh`) and the screw left over into φ, c
    of joint k + 1 (the pairs' laws d_i(θ_i) are untouched: exact). Returns (chain, the kept
    joints' indices from 0, the held values in joint order). Refused in one line where a fold is
    ill-conditioned (joints k − 1 and k + 1 nearly but not exactly parallel at that value).
    `make` builds the chain (apair.chain.AChain: this module sits below it and never imports it)."""
    if not isinstance(fix, Mapping):
        raise ValueError(f"fix: expected a mapping {{joint (from 1): value [rad]}}, got {V.shorten(repr(fix))}")
    held: dict[int, float] = {}
    hard = chain.hard_limits()
    for key, value in fix.items():
        k = V.integer("fix", key, minimum=1, maximum=chain.n)
        v = V.scalar(f"fix[{k}]", value)
        lo, hi = hard[k - 1]
        if not lo <= v <= hi:
            raise ValueError(f"fix[{k}]: {v:.12g} rad lies outside joint {k}'s range ({lo:.6g}, {hi:.6g}) rad")
        held[k - 1] = v
    if not held:
        raise ValueError("fix: expected at least one joint, got an empty mapping")
    if len(held) >= chain.n:
        raise ValueError(f"fix: holds all {chain.n} joints, leaving none to solve (use fk)")
    if chain.n - len(held) > 6:
        raise ValueError(f"fix: leaves {chain.n - len(held)} joints; ik solves at most 6: hold more")
    pairs = list(chain.pairs)
    dh = [list(map(float, row)) for row in chain._dh]
    limits = list(chain._explicit_limits)
    index = list(range(chain.n))
    B, Tt = chain.base, chain.tool
    for i in sorted(held, reverse=True):  # from the last: the lower joints keep their positions
        j = index.index(i)
        a, alpha, c, phi = dh[j]
        v = held[i]
        C = dh_matrix(a, alpha, c + float(chain.pairs[i].law(v, name=f"fix[{i + 1}]")[0]), v + phi)
        if j == 0:
            B = B @ C
        elif j == len(index) - 1:
            Tt = C @ Tt
        else:
            delta, e, a2, alpha2, delta2, e2 = _as_dh(dh_matrix(dh[j - 1][0], dh[j - 1][1], 0.0, 0.0) @ C)
            dh[j - 1] = [a2, alpha2, dh[j - 1][2] + e, dh[j - 1][3] + delta]
            dh[j + 1] = [dh[j + 1][0], dh[j + 1][1], dh[j + 1][2] + e2, dh[j + 1][3] + delta2]
        del pairs[j], dh[j], limits[j], index[j]
    rows = np.array(dh)
    sub = make(pairs, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3], limits=limits, base=B, tool=Tt)
    # the fold is exact in exact arithmetic; in floating point it is checked on random joint vectors
    lim = sub.limits
    q = np.random.default_rng(0).uniform(lim[:, 0], lim[:, 1], (8, sub.n))
    full = np.empty((8, chain.n))
    full[:, index] = q
    full[:, sorted(held)] = [held[i] for i in sorted(held)]
    size = 1.0 + float(np.abs(chain._dh[:, [0, 2]]).sum()) + float(np.abs(chain.base[:3, 3]).sum())
    size += float(np.abs(chain.tool[:3, 3]).sum())
    gap = float(np.abs(sub.fk(q) - chain.fk(full)).max()) / size
    if not gap <= HOLD_TOL:
        raise ValueError(
            f"fix: at these values the neighbours of a held interior joint have nearly parallel axes, where "
            f"DH constants are ill-conditioned (folded chain off by {gap:.1e} of its size): hold other values"
        )
    return sub, index, [held[i] for i in sorted(held)]


def held_ik(
    chain: AChain,
    T: ArrayLike,
    tol: float,
    full: bool,
    within_limits: bool,
    fix: Mapping[int, float],
    make: Callable[..., AChain],
) -> NDArray[np.float64] | Solution:
    """AChain.ik with joints held (`fix`): the folded chain's solutions (`hold`) with the held
    values put back, their errors measured on `chain` (base⁻¹·T·tool⁻¹ against frame n's pose)."""
    sub, index, values = hold(chain, fix, make)
    try:
        sol = sub.ik(T, tol=tol, full=True)
    except ValueError as exc:
        if not str(exc).startswith("chain: "):
            raise
        names = ", ".join(f"{k}" for k in sorted(set(range(1, chain.n + 1)) - {i + 1 for i in index}))
        raise ValueError(f"fix: with joint(s) {names} held there, {str(exc)[len('chain: ') :]}") from None
    held = sorted(set(range(chain.n)) - set(index))
    q = np.empty((len(sol.q), chain.n))
    q[:, index] = sol.q
    q[:, held] = values
    Tm = np.asarray(pose_matrix(T), dtype=float)
    target = chain._to_dh(Tm) if chain._framed else Tm
    plain = chain._dh_chain()
    error = np.abs(plain.fk(q) - target).max(axis=(-2, -1)) if len(q) else np.zeros(0)
    inside = chain.within_limits(q)
    if within_limits:
        q, error, inside = q[inside], error[inside], inside[inside]
    if not full:
        return q
    return dataclasses.replace(sol, q=q, error=error, inside=inside)
