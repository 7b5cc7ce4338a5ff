"""The twin of a chain: the same DH constants and links, every A-pair replaced by a pair of another
kind (today an R-pair: the legs and plates gone, so the joint turns fully), and what `compare`
uses of a chain."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, Protocol, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import shorten
from ..pair import APair
from ..workspace import Workspace

TWINS = ("revolute",)  # the kinds a twin's pairs may be (issue "Bring your own robot" adds more)


class Chain(Protocol):
    """What `compare` uses of an `apair.AChain` (it takes the chain as an argument and never
    imports apair.chain, which delegates `AChain.compare` to it)."""

    @property
    def n(self) -> int: ...
    @property
    def pairs(self) -> Sequence[APair]: ...
    @property
    def links(self) -> Sequence[Any]: ...
    @property
    def a(self) -> NDArray[np.float64]: ...
    @property
    def alpha(self) -> NDArray[np.float64]: ...
    @property
    def offset(self) -> NDArray[np.float64]: ...
    @property
    def theta_offset(self) -> NDArray[np.float64]: ...
    @property
    def gravity(self) -> NDArray[np.float64]: ...
    @property
    def base(self) -> NDArray[np.float64]: ...
    @property
    def tool(self) -> NDArray[np.float64]: ...
    @property
    def limits(self) -> NDArray[np.float64]: ...
    def hard_limits(self) -> NDArray[np.float64]: ...
    def fk(self, q: ArrayLike) -> NDArray[np.float64]: ...
    def jacobian(self, q: ArrayLike) -> NDArray[np.float64]: ...
    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]: ...
    def gravity_torques(self, q: ArrayLike) -> NDArray[np.float64]: ...
    def inverse_dynamics(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]: ...
    def energy(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]: ...
    def ik(self, T: ArrayLike, tol: float = ..., *, full: bool, within_limits: bool = ...) -> Any: ...
    def within_limits(self, q: ArrayLike) -> NDArray[np.bool_]: ...
    def workspace(
        self,
        samples: int = ...,
        resolution: int = ...,
        rounds: int = ...,
        poses: bool = ...,
        engine: object = ...,
        seed: int = ...,
        progress: Callable[[int, int], object] | None = ...,
    ) -> Workspace: ...


def kind(twin: object) -> str:
    """The twin's pair kind: one of TWINS (None: "revolute")."""
    if twin is None:
        return "revolute"
    if not isinstance(twin, str) or twin not in TWINS:
        raise ValueError(
            f"twin: expected one of {', '.join(TWINS)} (the kinds a twin is built of), got {shorten(repr(twin))}"
        )
    return twin


def name_of(chain: object) -> str:
    """A chain's name (set by apair.load), or "chain" for one made in code."""
    return str(getattr(chain, "name", "") or "chain")


def build(chain: Chain, twin: str = "revolute") -> Chain:
    """The twin of `chain`: each A-pair replaced by an R-pair at the same DH constants and link,
    without limits (it turns fully); an R-, H- or P-pair stays, with its explicit limits, if any.
    Built by the chain's base class (the last class before `object` in its MRO: AChain, also for a
    chain on its own compiled kernels), so this module need not import apair.chain."""
    kind(twin)
    pairs = [APair.revolute() if p.is_apair else p for p in chain.pairs]
    hard = chain.hard_limits()
    limits = [
        (float(lo), float(hi)) if not p.is_apair and math.isfinite(lo) and math.isfinite(hi) else None
        for p, (lo, hi) in zip(chain.pairs, hard)
    ]
    base = cast(Callable[..., Chain], type(chain).__mro__[-2])
    out = base(
        pairs,
        chain.a,
        chain.alpha,
        chain.offset,
        chain.theta_offset,
        links=chain.links,
        gravity=chain.gravity,
        limits=limits,
        base=chain.base,
        tool=chain.tool,
    )
    cast(Any, out).name = f"{name_of(chain)} ({twin} twin)"
    return out
