"""One candidate design's evaluation: its chain built and checked, its constraints, its objectives
with the compiled kernels (`evaluate`, a pure function of the spec and the candidate, so that any
process, local or on a cluster, returns the same numbers).

- coverage: the fraction of the targets reached inside the joint ranges (apair.design.reach);
- volume: the reachable workspace's volume [m³] inside the ranges (`AChain.workspace` with
  VOLUME_SAMPLES samples, the spec's seed);
- gravity_torque_max: the largest gravity torque [N m] that holding the chain at a target needs,
  taking for each target the least over the joint vectors found that reach it (the nearest one
  found where none does), and the largest over the targets.

Constraints: min_clearance narrows each A-pair's range to where its legs (and plates) stay that far
apart (the collision limits of the pair with legs min_clearance/2 thicker and plates min_clearance
thicker); a pair that cannot keep the clearance even at θ = 0 violates it. leg_length bounds every
leg of every A-pair. A candidate that violates a constraint is not evaluated further.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._validate import shorten
from ..chain import AChain
from ..collisions import check_design, clearances
from ..io import chain_from_dict
from ..pair import APair
from .reach import Reach, reach
from .spec import Spec

VOLUME_SAMPLES = 20_000  # workspace samples for the volume objective (a few per cent)
VOLUME_RESOLUTION = 16
SHAPE_CAP = 1.0  # a target's excess counts at most this much in `Record.excess`


@dataclass(frozen=True)
class Record:
    """What one candidate scored: its objectives in the spec's order (None when it was not
    evaluated: an invalid chain, or a constraint violated), `violation` (0 when the constraints
    hold, else how far they fail, relative), `invalid` (why the chain is not valid, or None),
    `excess` (the targets' mean shortfall, each capped at SHAPE_CAP: a tie-break between designs
    that reach as many targets) and `reached` (targets reached)."""

    objectives: tuple[float, ...] | None
    violation: float = 0.0
    invalid: str | None = None
    excess: float = 0.0
    reached: int = 0

    @property
    def feasible(self) -> bool:
        return self.objectives is not None

    def to_json(self) -> dict[str, Any]:
        return {
            "objectives": None if self.objectives is None else list(self.objectives),
            "violation": self.violation,
            "invalid": self.invalid,
            "excess": self.excess,
            "reached": self.reached,
        }

    @classmethod
    def from_json(cls, doc: dict[str, Any]) -> Record:
        objectives = doc["objectives"]
        return cls(
            None if objectives is None else tuple(float(v) for v in objectives),
            float(doc["violation"]),
            doc["invalid"],
            float(doc["excess"]),
            int(doc["reached"]),
        )


class Infeasible(Exception):
    """A candidate that violates a constraint by `amount` (relative)."""

    def __init__(self, amount: float) -> None:
        super().__init__(amount)
        self.amount = amount


@lru_cache(maxsize=4096)
def _pair(kind: str, r_b: float, r_p: float, legs: float | None, mass: float, radius: float, plate: float) -> APair:
    """A pair by its parameters, kept: its collision limits are computed once in this process
    however many candidates share it."""
    if kind == "revolute":
        return APair.revolute()
    return APair(r_b, r_p, leg_length=legs, leg_mass=mass, leg_radius=radius, thickness=plate)


def _same(p: APair, margin: float = 0.0) -> APair:
    """The kept pair equal to p, its legs margin/2 and plates margin thicker."""
    legs = float(p.leg_lengths[0]) if p.kind == "general" else None
    return _pair(
        p.kind, p.base_radius, p.platform_radius, legs, p.leg_mass, p.leg_radius + margin / 2, p.thickness + margin
    )


def _explicit(joint: dict[str, Any]) -> tuple[float, float] | None:
    """A joint table's explicit range [rad] (checked already by io), or None."""
    if "limits" in joint:
        return float(joint["limits"][0]), float(joint["limits"][1])
    if "limits_deg" in joint:
        return math.radians(joint["limits_deg"][0]), math.radians(joint["limits_deg"][1])
    return None


def _clearance_shortfall(p: APair, margin: float) -> float:
    """How much clearance p lacks at θ = 0 for `margin`, relative to it."""
    legs, plate = clearances(p, 0.0)
    return max(margin - min(float(np.min(legs)), float(plate)), 0.0) / margin


def _leg_violation(pairs: list[APair], bounds: tuple[float, float] | None) -> float:
    """The legs' lengths outside bounds, summed relative to the bounds' width."""
    if bounds is None:
        return 0.0
    lo, hi = bounds
    out = 0.0
    for p in pairs:
        L = p.leg_lengths
        out += float(np.sum(np.maximum(lo - L, 0.0) + np.maximum(L - hi, 0.0))) / (hi - lo)
    return out


def build(spec: Spec, x: NDArray[np.float64]) -> tuple[dict[str, Any], AChain]:
    """Candidate x's chain file document and its chain, ready for evaluation: raises ValueError for
    an invalid chain and Infeasible for a violated constraint. Under min_clearance the document's
    A-pairs carry explicit limits: the narrowed ranges, so that the chain file keeps the clearance."""
    data = spec.decode(x)
    plain = chain_from_dict(data, "candidate")
    c = spec.constraints
    violation = _leg_violation(plain.pairs, c.leg_length)
    limits: list[tuple[float, float] | None] = [_explicit(j) for j in data["joint"]]
    if c.min_clearance > 0:
        for i, p in enumerate(plain.pairs):
            if p.kind == "revolute":
                continue
            wide = _same(p, c.min_clearance)
            try:
                check_design(wide)
            except ValueError:
                violation += _clearance_shortfall(p, c.min_clearance)
                continue
            lo, hi = wide.motion_range()
            if limits[i] is not None:
                lo, hi = max(lo, limits[i][0]), min(hi, limits[i][1])  # type: ignore[index]
            if not lo < hi:
                violation += 1.0
                continue
            limits[i] = (lo, hi)
            data["joint"][i].pop("limits_deg", None)
            data["joint"][i]["limits"] = [lo, hi]
    if violation > 0:
        raise Infeasible(violation)
    pairs = [_same(p) for p in plain.pairs]
    chain = AChain(
        pairs,
        plain.a,
        plain.alpha,
        plain.offset,
        plain.theta_offset,
        links=plain.links,
        gravity=plain.gravity,
        limits=limits,
        base=plain.base,
        tool=plain.tool,
    )
    chain.limits  # noqa: B018  the collision limits: a pair that cannot move is refused here
    return data, chain


def targets_scale(spec: Spec) -> float:
    """The targets' size [m] (their largest distance from the base, 1 without any): the unit of
    a target's excess, the same for every candidate."""
    if spec.targets is None:
        return 1.0
    t = spec.targets.values
    pts = t if t.ndim == 2 else t[:, :3, 3]
    return float(np.max(np.linalg.norm(pts, axis=1))) or 1.0


def evaluate(spec: Spec, x: NDArray[np.float64]) -> Record:
    """Candidate x's Record (see the module docstring)."""
    try:
        _, chain = build(spec, np.asarray(x, dtype=float))
    except Infeasible as exc:
        return Record(None, violation=exc.amount)
    except (ValueError, RuntimeError) as exc:  # RuntimeError: collision limits that cannot be resolved
        return Record(None, invalid=shorten(str(exc), 200))
    found = None if spec.targets is None else reach(chain, spec.targets, targets_scale(spec), spec.seed)
    values = tuple(_objective(o.name, chain, found, spec.seed) for o in spec.objectives)
    if found is None:
        return Record(values)
    excess = float(np.mean(np.minimum(found.excess, SHAPE_CAP)))
    return Record(values, excess=excess, reached=int(found.reached.sum()))


def evaluate_many(spec: Spec, xs: list[NDArray[np.float64]]) -> list[Record]:
    """The Records of several candidates (one Dask task)."""
    return [evaluate(spec, x) for x in xs]


def _objective(name: str, chain: AChain, found: Reach | None, seed: int) -> float:
    if name == "coverage":
        return float(np.mean(found.reached)) if found is not None else 0.0
    if name == "volume":
        return _volume(chain, seed)
    return _gravity_torque_max(chain, found)


def _volume(chain: AChain, seed: int) -> float:
    """The workspace volume [m³]; 0 for a curve or a surface."""
    try:
        ws = chain.workspace(samples=VOLUME_SAMPLES, resolution=VOLUME_RESOLUTION, seed=seed)
    except ValueError:  # every sample at one point
        return 0.0
    return float(ws.volume) if ws.dimension == 3 and ws.volume is not None else 0.0


def _gravity_torque_max(chain: AChain, found: Reach | None) -> float:
    """The largest over targets of the least over its joint vectors of max_i |g_i(q)| [N m]."""
    if found is None:
        return 0.0
    g = np.abs(chain.gravity_torques(np.concatenate(found.q))).max(axis=1)
    ends = np.cumsum([len(q) for q in found.q])
    return float(max(part.min() for part in np.split(g, ends[:-1])))
