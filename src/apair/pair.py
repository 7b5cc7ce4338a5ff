"""`APair`: one algebraic screw pair (the self-motion of a Griffis-Duffy platform), or an R-pair.

The pair's constants (L2, a, b, h) and its law d(θ), d'(θ), d''(θ) come from the generated kernels
of derivations/apair_pair.py; this module only validates and dispatches.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from functools import cached_property
from typing import TYPE_CHECKING, cast, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _validate as V
from .kernels import call

if TYPE_CHECKING:
    from .collisions import CollisionLimits
    from .link import Link

KINDS = ("sinusoidal", "general", "revolute", "helical", "prismatic")
A_KINDS = ("sinusoidal", "general")  # the A-pairs: a Griffis-Duffy platform with legs
_SINUSOIDAL_RTOL = 1e-12  # |a - b| <= this * b: the leg length is the sinusoidal one


def _length(name: str, value: ArrayLike, positive: bool = False) -> float:
    """A length [m]: 0 (unless positive) or of magnitude in the range apair computes in
    (V.LENGTH_RANGE), where the pair's constants (squares and products of lengths) and a chain's
    dynamics stay normal doubles."""
    x = V.scalar(name, value, positive=positive, nonnegative=True)
    V.in_range(name, x, "m")
    return x


def _last_true(pred: Callable[[float], bool], lo: float, hi: float) -> float:
    """The double x in [lo, hi) with pred(x) true and pred(next double above x) false, given
    pred(lo) true, pred(hi) false and 0 <= lo < hi: bisection over the doubles' bit patterns (for
    x >= 0 they are ordered as the values), so at most 64 steps. For a pred that is true then false
    along the doubles (monotone), x is the largest double at which pred holds."""
    i, j = (struct.unpack("<q", struct.pack("<d", x))[0] for x in (lo, hi))
    while j - i > 1:
        m = (i + j) // 2
        if pred(struct.unpack("<d", struct.pack("<q", m))[0]):
            i = m
        else:
            j = m
    return float(struct.unpack("<d", struct.pack("<q", i))[0])


class APair:
    """An A-pair with base/platform circumradii r_b, r_p and leg length L1 (None: sinusoidal).

    leg_mass and leg_radius describe the legs (uniform rods; used by dynamics and collisions), and
    thickness the plates (slabs about the planes of the leg end points; used by collisions).
    `APair.revolute()`, `APair.helical(pitch)` and `APair.prismatic()` are the lower pairs a chain
    may mix with A-pairs (no legs): the joint variable is the angle θ of an R-, A- or H-pair, the
    slide d [m] of a P-pair (whose angle is the joint's constant theta_offset).
    """

    def __init__(
        self,
        base_radius: ArrayLike,
        platform_radius: ArrayLike,
        leg_length: ArrayLike | None = None,
        leg_mass: ArrayLike = 0.0,
        leg_radius: ArrayLike = 0.0,
        thickness: ArrayLike = 0.0,
    ) -> None:
        r_b = _length("base_radius", base_radius, positive=True)
        r_p = _length("platform_radius", platform_radius, positive=True)
        self.leg_mass = V.scalar("leg_mass", leg_mass, nonnegative=True)
        V.in_range("leg_mass", self.leg_mass, "kg")
        self.leg_radius = _length("leg_radius", leg_radius)
        self.thickness = _length("thickness", thickness)
        self._limits: CollisionLimits | None = None
        self.base_radius, self.platform_radius = r_b, r_p
        radii = np.array([r_b, r_p])
        if leg_length is None:
            L1, L2, a, b, h = call("design_sinusoidal", radii)[0]
            self.kind = "sinusoidal"
        else:
            L1 = _length("leg_length", leg_length, positive=True)
            L2_sq, a, b, a_plus_b = call("design_general", radii, [L1])[0]
            if not a_plus_b > 0 or not a + b > 0 or not L2_sq > 0:  # a + b: d(0)² as the law forms it
                lo = math.sqrt(r_b**2 + r_p**2 / 4 - r_b * r_p) if r_b**2 + r_p**2 / 4 > r_b * r_p else 0.0
                raise ValueError(
                    f"leg_length: L1 = {L1} admits no real pose of this pair (need a + b > 0, i.e. "
                    f"L1 > {lo:.6g} for base_radius={r_b}, platform_radius={r_p})"
                )
            L2 = math.sqrt(L2_sq)
            self.kind = "sinusoidal" if abs(a - b) <= _SINUSOIDAL_RTOL * b else "general"
            h = math.sqrt(2 * b) if self.kind == "sinusoidal" else None
        self._L: tuple[float, float] | None = (float(L1), float(L2))
        self.a, self.b = float(a), float(b)
        self._h: float | None = float(h) if h is not None else None

    @classmethod
    def revolute(cls) -> APair:
        """An R-pair: no translation (d ≡ 0) and no legs."""
        return cls._lower("revolute")

    @classmethod
    def helical(cls, pitch: ArrayLike) -> APair:
        """An H-pair: d = pitch·θ [m], pitch in m/rad (the lead per turn is 2π·pitch); no legs."""
        p = V.scalar("pitch", pitch)
        V.in_range("pitch", p, "m/rad")
        self = cls._lower("helical")
        self.pitch = p
        return self

    @classmethod
    def prismatic(cls) -> APair:
        """A P-pair: the joint variable is the slide d [m] along the axis, the angle is constant
        (the joint's theta_offset); no legs. Its chain needs its range (limits, in metres)."""
        return cls._lower("prismatic")

    @classmethod
    def _lower(cls, kind: str) -> APair:
        self = cls.__new__(cls)
        self.kind = kind
        self.base_radius = self.platform_radius = 0.0
        self.leg_mass = self.leg_radius = self.thickness = 0.0
        self._limits = None
        self._L = None
        self.a = self.b = 0.0
        self._h = 0.0 if kind == "revolute" else None
        return self

    pitch = 0.0  # m/rad: a helical pair's (d = pitch·θ)

    @property
    def is_apair(self) -> bool:
        """Whether this is an A-pair (sinusoidal or general, with legs), not a lower pair."""
        return self.kind in A_KINDS

    @property
    def turning(self) -> float:
        """dθ/dq: 1 where the joint variable q is the angle, 0 for a P-pair (q is the slide)."""
        return 0.0 if self.kind == "prismatic" else 1.0

    def __repr__(self) -> str:
        if self.kind == "revolute":
            return "APair.revolute()"
        if self.kind == "prismatic":
            return "APair.prismatic()"
        if self.kind == "helical":
            return f"APair.helical({self.pitch!r})"
        extra = "" if self.kind == "sinusoidal" else f", leg_length={cast(tuple[float, float], self._L)[0]!r}"
        for key in ("leg_mass", "leg_radius", "thickness"):  # every parameter off its default
            if getattr(self, key) != 0.0:
                extra += f", {key}={getattr(self, key)!r}"
        return f"APair({self.base_radius!r}, {self.platform_radius!r}{extra})"

    @property
    def amplitude(self) -> float:
        """The platform's rise d(0) − min d over the motion: h = √(2 r_b r_p) for a sinusoidal pair,
        0 for an R-pair; a P- or H-pair's d is unbounded (ValueError)."""
        if self.kind in ("helical", "prismatic"):
            raise ValueError(f"amplitude: a {self.kind} pair's translation is unbounded")
        if self._h is not None:
            return self._h
        return math.sqrt(self.a + self.b) - math.sqrt(max(self.a - self.b, 0.0))

    @property
    def leg_lengths(self) -> NDArray[np.float64]:
        """(6,): three legs of length L1 (base vertices), three of length L2; empty for an R-pair."""
        if self._L is None:
            return np.zeros(0)
        return np.repeat(np.array(self._L), 3)

    @cached_property
    def theta_limit(self) -> float | None:
        """|θ| ≤ arccos(−a/b) for a general pair with a < b: the largest double at which
        a + b cos θ ≥ 0 still holds in floating point as the law kernel forms it (so d(theta_limit)
        ≈ 0 is defined, within √(b ε) of zero); None where θ is unbounded. Found by bisection over
        the doubles in [0, π] (at most 64 steps for any design) and cached: near the minimum leg
        length arccos(−a/b) is off by up to 1e11 doubles, too many to step through."""
        if self.kind == "general" and self.a < self.b:
            return _last_true(lambda th: self._gap(th) >= 0, 0.0, math.pi)
        return None

    def _gap(self, theta: float) -> float:
        """a + b cos θ as the law kernel forms it, from cos and sin of θ/2."""
        c, s = math.cos(theta / 2), math.sin(theta / 2)
        return self.a + self.b * (c * c - s * s)

    def collision_limits(self) -> CollisionLimits:
        """(theta_min, theta_max, what touches first): the collision-free range of θ around 0, where
        the legs (cylinders of radius leg_radius) or the plates (thickness) first touch, found by
        exact root isolation on the derived contact polynomials (apair.collisions). Infinite for an
        R-pair. Raises ValueError when the pair cannot move at all."""
        if self._limits is None:
            from .collisions import limits

            self._limits = limits(self)
        return self._limits

    def motion_range(self) -> tuple[float, float]:
        """The collision-free range of θ within the pair's range of motion (±inf where it turns
        freely): what an explicit joint range may narrow but not exceed."""
        lo, hi, _ = self.collision_limits()
        if self.theta_limit is not None:
            lo, hi = max(lo, -self.theta_limit), min(hi, self.theta_limit)
        return lo, hi

    def _theta(self, theta: ArrayLike, name: str = "theta") -> NDArray[np.float64]:
        """θ validated; for a pair with a limited range, angles past the range end by no more than
        rounding (a + b cos θ ≥ −4ε(|a| + b)) are put on it, anything further is refused."""
        th = V.real_array(name, theta)
        if self.kind == "general" and self.a < self.b:
            c, s = np.cos(th / 2), np.sin(th / 2)
            gap = self.a + self.b * (c * c - s * s)  # as the law kernel forms it
            bad = gap < 0
            if np.any(bad):
                far = gap < -4 * np.finfo(float).eps * (abs(self.a) + self.b)
                if np.any(far):
                    raise ValueError(
                        f"{name}: outside this pair's range |theta| <= {self.theta_limit:.12g} (mod 2 pi), "
                        f"e.g. {float(th[far].flat[0]):.12g}"
                    )
                turns = 2 * np.pi * np.round(th / (2 * np.pi))
                th = np.where(bad, turns + np.copysign(cast(float, self.theta_limit), th - turns), th)
        return th

    def law(self, theta: ArrayLike, name: str = "theta") -> NDArray[np.float64]:
        """(..., 3): d(θ), d'(θ), d''(θ); broadcasts over θ."""
        return self._law(self._theta(theta, name))[..., 2:]

    @property
    def law_kernel(self) -> tuple[str, tuple[float, ...]]:
        """The generated kernel of this pair's law values (cos(θ/2), sin(θ/2), d, d', d'') and
        its parameters after θ."""
        if self.kind in ("revolute", "prismatic"):
            return f"law_{self.kind}", ()
        if self.kind == "helical":
            return "law_helical", (self.pitch,)
        if self.kind == "sinusoidal":
            return "law_sinusoidal", (cast(float, self._h),)
        return "law_general", (self.a, self.b)

    def _law(self, th: NDArray[np.float64]) -> NDArray[np.float64]:
        """(..., 5): the law values of validated angles."""
        kernel, params = self.law_kernel
        return call(kernel, th[..., None], *([x] for x in params))[0]

    @overload
    def translation(self, theta: float) -> float: ...
    @overload
    def translation(self, theta: ArrayLike) -> float | NDArray[np.float64]: ...
    def translation(self, theta: ArrayLike) -> float | NDArray[np.float64]:
        """d(θ) [m], broadcasting over θ (a float for a scalar θ)."""
        d = self.law(theta)[..., 0]
        return float(d) if d.ndim == 0 else d

    def dynamics(
        self,
        theta: ArrayLike,
        qd: ArrayLike = 0.0,
        qdd: ArrayLike = 0.0,
        platform: Link | None = None,
        g: ArrayLike = 9.81,
    ) -> NDArray[np.float64]:
        """(..., 4): (τ, J, J'/2, G) of this pair alone with a vertical axis and gravity g along −z:
        τ = J(θ)θ'' + ½J'(θ)θ'² + G(θ). `platform` is a Link in the platform frame (default: none),
        the legs are this pair's. See `apair show apair_dynamics` for the closed forms."""
        from .link import Link

        if self.kind == "prismatic":
            raise ValueError("dynamics: a prismatic pair does not turn; use a one-joint AChain for its dynamics")
        if platform is None:
            platform = Link(0.0)
        if not isinstance(platform, Link):
            raise ValueError(f"platform: expected a Link, got {type(platform).__name__}")
        th = self._theta(theta)
        qd = V.real_array("qd", qd)
        qdd = V.real_array("qdd", qdd)
        g = V.scalar("g", g)
        try:
            shape = np.broadcast_shapes(th.shape, qd.shape, qdd.shape)
        except ValueError:
            raise ValueError(
                f"qd: shapes {th.shape}, {qd.shape}, {qdd.shape} of theta, qd, qdd do not broadcast"
            ) from None
        th, qd, qdd = (np.broadcast_to(x, shape) for x in (th, qd, qdd))
        law = self._law(th)[..., 2:]
        if np.any(~np.isfinite(law)):
            raise ValueError("theta: at the pair's limit, where d'(theta) is unbounded")
        row = platform.as_row()
        plat = np.array([row[0], row[1], row[2], row[3], row[6]])
        legs = np.array([self.leg_mass, self.base_radius, self.platform_radius])
        return call("pair_dynamics", th[..., None], qd[..., None], qdd[..., None], law, plat, legs, [g])[0]

    def leg_endpoints(self, theta: ArrayLike) -> NDArray[np.float64]:
        """(..., 6, 2, 3): [base point, platform point] of each leg in the pair's base frame."""
        th = self._theta(theta)
        if not self.is_apair:
            return np.zeros(th.shape + (0, 2, 3))
        d = self._law(th)[..., 2]
        return call("pair_legs", th[..., None], d[..., None], [self.base_radius, self.platform_radius])[0]
