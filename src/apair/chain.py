"""`AChain`: a serial chain of R- and A-pairs in the DH convention of docs/conventions.md §3.

Joint i: A_i(θ_i) = Rz(θ_i + φ_i) · Tz(c_i + d_i(θ_i)) · Tx(a_i) · Rx(α_i). Each method evaluates
the joints' law values (cos(θ/2), sin(θ/2), d, d', d'') with their pairs' kernels and hands them
to one generated chain kernel for n joints (derivations/chain_kinematics.py, chain_dynamics.py),
in one native call (apair.kernels.native_chain) when the inputs are canonical float64 arrays;
otherwise the validating path checks and converts them first. Batches stay in the kernels.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal, cast, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _validate as V
from . import derivatives as D
from .files import write_text
from .frames import EYE4, FramedLocal, check_frame, inverse
from .hold import held_ik
from .ik.families import Classification, classify
from .kernels import call, chain_kernel, native_chain
from .link import Link
from .pair import APair
from .study import from_matrix, multiply, normalise

if TYPE_CHECKING:
    from .compare import Comparison
    from .ik import LocalSolution, Solution, Solver
    from .ik.homotopy import StartSystem
    from .kernels import FastPath
    from .simulate import Trajectory
    from .variety import Variety
    from .workspace import Workspace

MAX_JOINTS = 7
MAX_ITER = 100_000  # ik_local: Levenberg-Marquardt steps per seed, a bound on the work asked for
# The kernel-backed methods in the order of their native fast path (apair.kernels.native_chain):
# (kernel family, whether a joint at its range end is refused because d' is unbounded there).
METHODS = (
    ("fk", False),
    ("fk_study", False),
    ("jacobian", True),
    ("mass_matrix", True),
    ("coriolis", True),
    ("gravity", True),
    ("bias", True),
    ("inverse_dynamics", True),
    ("forward_dynamics", True),
    ("energy", True),
    ("inverse_dynamics_derivatives", True),  # with mass_matrix (apair.derivatives.KERNELS_OF)
    ("forward_dynamics_derivatives", True),
    ("jacobian_dot", True),
)


class AChain:
    """A chain of `pairs` with DH constants a (link lengths), alpha (twists), offset (c),
    theta_offset (φ). Angles in radians, lengths in metres. `limits`: per joint an explicit range
    (lo, hi) or None for the pair's own (see `limits`). `base`, `tool`: 4×4 rigid transforms (None:
    the identity) of the DH frame 0 in the world and of the tool in frame n (docs/conventions.md,
    "Base and tool frames"): fk, fk_study, the Jacobian, ik and ik_local are of the tool in the
    world, `gravity` is in the world."""

    _name: str | None = None
    # base and tool frames: None for the identity; _framed whether either is not
    _base_T: NDArray[np.float64] | None = None
    _tool_T: NDArray[np.float64] | None = None
    _framed: bool = False

    @property
    def name(self) -> str | None:
        """The chain's name (a chain file's `name` or file stem; None on a chain made here until
        set); a text field (docs/conventions.md): control characters are refused."""
        return self._name

    @name.setter
    def name(self, value: str) -> None:
        self._name = V.text("name", value)

    _ik: Solver | None = None  # the solver, made by the first ik (dropped when pickled)
    _local_ik: Any = None  # ik_local's native fast path (apair._native.LocalIK), set up by its first call
    _ik_fast: Any = None  # ik's native fast path for a closed form (apair._native.ClosedIK), set with _ik

    def __init__(
        self,
        pairs: Iterable[APair],
        a: ArrayLike,
        alpha: ArrayLike,
        offset: ArrayLike | None = None,
        theta_offset: ArrayLike | None = None,
        links: Iterable[Link] | None = None,
        gravity: ArrayLike = (0.0, 0.0, -9.81),
        limits: Iterable[ArrayLike | None] | None = None,
        base: ArrayLike | None = None,
        tool: ArrayLike | None = None,
    ) -> None:
        try:
            pair_list = list(pairs)
        except TypeError as exc:
            raise ValueError(f"pairs: expected a sequence of APair, got {V.shorten(repr(pairs))}") from exc
        n = len(pair_list)
        if not 1 <= n <= MAX_JOINTS:
            raise ValueError(f"pairs: a chain has 1 to {MAX_JOINTS} pairs, got {n}")
        for i, p in enumerate(pair_list):
            if not isinstance(p, APair):
                raise ValueError(f"pairs[{i}]: expected an APair, got {type(p).__name__}")
        self.pairs: list[APair] = pair_list
        self.a = V.vector("a", a, n)
        self.alpha = V.vector("alpha", alpha, n)
        self.offset = np.zeros(n) if offset is None else V.vector("offset", offset, n)
        self.theta_offset = np.zeros(n) if theta_offset is None else V.vector("theta_offset", theta_offset, n)
        V.in_range("a", self.a, "m")
        V.in_range("offset", self.offset, "m")
        self._dh = np.ascontiguousarray(np.stack([self.a, self.alpha, self.offset, self.theta_offset], axis=1))
        if links is None:
            links = [Link(0.0) for _ in range(n)]
        try:
            link_list = list(links)
        except TypeError as exc:
            raise ValueError(f"links: expected a sequence of Link, got {V.shorten(repr(links))}") from exc
        if len(link_list) != n:
            raise ValueError(f"links: expected {n} links (one per pair), got {len(link_list)}")
        for i, link in enumerate(link_list):
            if not isinstance(link, Link):
                raise ValueError(f"links[{i}]: expected a Link, got {type(link).__name__}")
        self.links: list[Link] = link_list
        self.gravity = V.vector("gravity", gravity, 3)
        V.in_range("gravity", self.gravity, "m/s^2")
        self._links = np.ascontiguousarray(np.stack([link.as_row() for link in links]))
        self._legs = np.array([[p.leg_mass, p.base_radius, p.platform_radius] for p in pair_list])
        self._turning = np.array([p.turning for p in pair_list])  # dθ/dq: 0 for a P-pair
        self._revolute = all(p.kind == "revolute" for p in pair_list)  # kernels.REVOLUTE's forms
        self._base_T, self._tool_T = check_frame("base", base), check_frame("tool", tool)
        self._framed = self._base_T is not None or self._tool_T is not None
        # the kernels' gravity is in the DH base frame (frame 0): Rbᵀ·g
        g0 = self.gravity if self._base_T is None else self._base_T[:3, :3].T @ self.gravity
        self._gravity = np.ascontiguousarray(g0)
        if self._framed:
            self._set_frames()
        self._law_groups = self._group_laws()
        self._ranged = [i for i, p in enumerate(pair_list) if p.theta_limit is not None]  # angles to check
        self._ik: Solver | None = None  # the inverse-kinematics solver, built on the first call of ik()
        self._explicit_limits = V.joint_limits(pair_list, limits)
        self._use(self._native_chain())

    def _use(self, fast: FastPath) -> None:
        """Take `fast` (kernels.native_chain) as the methods' fast path; its bound call is kept,
        since an attribute lookup less is measurable at single calls. With base or tool frames,
        the call goes through `_framed_call`, which composes them with fk, fk_study, jacobian."""
        self._fast = fast
        self._call = self._framed_call if self._framed else fast.call

    # ----------------------------------------------------------------------------- base and tool
    @property
    def base(self) -> NDArray[np.float64]:
        """(4, 4): the pose of the DH frame 0 in the world (a copy; the identity if none)."""
        return np.eye(4) if self._base_T is None else self._base_T.copy()

    @property
    def tool(self) -> NDArray[np.float64]:
        """(4, 4): the pose of the tool in the DH frame n (a copy; the identity if none)."""
        return np.eye(4) if self._tool_T is None else self._tool_T.copy()

    def _set_frames(self) -> None:
        """The frames' derived constants: the transforms (identity for none), their Study points
        and inverses, the tool's offset (None if zero)."""
        B = EYE4 if self._base_T is None else self._base_T
        T = EYE4 if self._tool_T is None else self._tool_T
        self._B, self._T = B, T
        self._B_study, self._T_study = from_matrix(B), from_matrix(T)
        self._B_inv, self._T_inv = inverse(B), inverse(T)
        self._tool_offset = None if not T[:3, 3].any() else T[:3, 3].copy()

    def _framed_call(self, method: int, *args: Any) -> NDArray[np.float64] | None:
        """The fast path of a chain with frames: the kernels' result, composed (`_compose`)."""
        out: NDArray[np.float64] | None = self._fast.call(method, *args)
        if out is None or method > 2:
            return out
        return self._compose(method, out, args[0])

    def _compose(self, method: int, out: NDArray[np.float64], q: Any) -> NDArray[np.float64]:
        """fk (0), fk_study (1) or jacobian (2) of the DH chain at q, made the tool's in the world:
        base · fk · tool; the Study points' product; the Jacobian of the tool's origin (v + ω × r,
        r = R_n · tool offset), both row blocks rotated by the base."""
        if method == 0:
            return self._B @ out @ self._T
        if method == 1:
            return multiply(multiply(self._B_study, out), self._T_study)
        Jv, Jw = out[..., :3, :], out[..., 3:, :]
        if self._tool_offset is not None:
            F = self._fast.call(0, q)
            if F is None:
                F = self._evaluate(0, "fk", q, (self._dh,), strict=False, framed=False)
            r = F[..., :3, :3] @ self._tool_offset
            Jv = Jv + np.cross(Jw, r[..., :, None], axis=-2)  # v + ω × r, column by column
        Rb = self._B[:3, :3]
        return np.concatenate([Rb @ Jv, Rb @ Jw], axis=-2)

    def _dh_chain(self) -> AChain:
        """This chain without its frames, gravity in frame 0 (the same dynamics): the chain that
        ik and ik_local solve for T_dh = base⁻¹ · T · tool⁻¹ (the joint values are the same)."""
        if not self._framed:
            return self
        plain = object.__new__(AChain)  # a plain AChain even of a SpecialisedChain: no code reloaded
        plain.__dict__.update(self.__dict__)
        plain.__dict__.update(_base_T=None, _tool_T=None, _framed=False, _ik=None, _local_ik=None, _ik_fast=None)
        plain.gravity = self._gravity.copy()
        plain._use(self._fast)
        return plain

    def _to_dh(self, T: NDArray[np.float64]) -> NDArray[np.float64]:
        """World poses of the tool (..., 4, 4) → poses of frame n in frame 0: base⁻¹ · T · tool⁻¹."""
        out: NDArray[np.float64] = self._B_inv @ T @ self._T_inv
        return out

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        del state["_fast"], state["_call"]  # native objects: rebuilt on unpickling
        for key in ("_local_ik", "_ik", "_ik_fast"):  # ik_local's and ik's solvers and fast paths: built again
            state.pop(key, None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._use(self._native_chain())

    @property
    def limits(self) -> NDArray[np.float64]:
        """(n, 2): each joint's range [rad; m for a P-pair]: the explicit one if given, else the pair's collision
        limits (`APair.collision_limits`), within its range of motion; a free joint gets one turn
        (−π, π)."""
        out = self.hard_limits()
        out[~np.isfinite(out).all(axis=1)] = -math.pi, math.pi
        return out

    def hard_limits(self) -> NDArray[np.float64]:
        """(n, 2): the ranges that physically stop each joint (explicit, collision limits, range
        ends), ±inf for a joint that turns freely (as `simulate` uses them)."""
        out = np.empty((self.n, 2))
        for i, lim in enumerate(self._explicit_limits):
            out[i] = lim if lim is not None else self.pairs[i].motion_range()
        return out

    @property
    def n(self) -> int:
        return len(self.pairs)

    def __repr__(self) -> str:
        frames = "".join(
            f", {key}={T.tolist()}" for key, T in (("base", self._base_T), ("tool", self._tool_T)) if T is not None
        )
        return (
            f"AChain({self.pairs!r}, a={self.a.tolist()}, alpha={self.alpha.tolist()}, "
            f"offset={self.offset.tolist()}, theta_offset={self.theta_offset.tolist()}, "
            f"links={self.links!r}, gravity={self.gravity.tolist()}{frames})"
        )

    def _q(self, q: ArrayLike, name: str = "q") -> NDArray[np.float64]:
        return V.real_array(name, q, trailing=(self.n,))

    def _group_laws(self) -> list[tuple[str, NDArray[np.intp], list[NDArray[np.float64]]]]:
        """One call per law kernel (APair.law_kernel): (kernel, joint indices, parameters (k, 1))."""
        by_kernel: dict[str, list[int]] = {}
        for i, p in enumerate(self.pairs):
            by_kernel.setdefault(p.law_kernel[0], []).append(i)
        groups: list[tuple[str, NDArray[np.intp], list[NDArray[np.float64]]]] = []
        for kernel, idx in sorted(by_kernel.items()):
            values = np.array([self.pairs[i].law_kernel[1] for i in idx])
            groups.append(
                (kernel, np.array(idx), [np.ascontiguousarray(values[:, [k]]) for k in range(values.shape[1])])
            )
        return groups

    def _native_chain(self) -> FastPath:
        """The native fast path of the methods (apair.kernels.native_chain): per method its
        chain kernel (`_kernel`), fed by the pairs' law kernels."""
        return native_chain(
            self.n,
            [(tuple(self._kernel(k) for k in D.kernels_of(family)), strict) for family, strict in METHODS],
            [p.law_kernel for p in self.pairs],
            [p.theta_limit if p.theta_limit is not None else math.inf for p in self.pairs],
            dict(zip(("dh", "turning", "links", "legs", "gravity"), self._body)),
        )

    def _kernel(self, family: str) -> str:
        """The name of this chain's kernel of `family` (kernels.chain_kernel)."""
        return chain_kernel(family, self.n, self._revolute)

    def law(self, q: ArrayLike) -> NDArray[np.float64]:
        """(..., n, 3): each joint's (d, d', d'') at q."""
        return self._law(self._snapped(self._q(q)))[..., 2:]

    def _snapped(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """A validated q with the angles past a range end by rounding put on it (each pair with
        a restricted range checks its angles)."""
        for i in self._ranged:
            snapped = self.pairs[i]._theta(q[..., i], name=f"q[..., {i}] (joint {i + 1})")
            if not np.array_equal(snapped, q[..., i]):
                q = q.copy()
                q[..., i] = snapped
        return q

    def _law(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(..., n, 5): the chain kernels' law input (cos(θ/2), sin(θ/2), d, d', d'') of a
        validated, snapped q."""
        out = np.empty(q.shape + (5,))
        for kernel, idx, params in self._law_groups:
            out[..., idx, :] = call(kernel, q[..., idx, None], *params)[0]
        return out

    def _state(self, q: ArrayLike, strict: bool = True, **named: ArrayLike) -> list[NDArray[np.float64]]:
        """Validated, snapped q and the named (n,)-arrays (qd, qdd, tau), broadcast to one batch
        shape, C-contiguous; with `strict`, a joint at its range end (where d' is unbounded) is
        refused."""
        arrays = [self._snapped(self._q(q))] + [self._q(x, name) for name, x in named.items()]
        try:
            shape = np.broadcast_shapes(*(x.shape for x in arrays))
        except ValueError:
            first = next(iter(named))
            raise ValueError(f"{first}: batch shape does not match q: {[x.shape for x in arrays]}") from None
        arrays = [np.ascontiguousarray(np.broadcast_to(x, shape)) for x in arrays]
        for i in self._ranged if strict else ():  # at the range end (up to rounding) d' is unbounded
            t = arrays[0][..., i]
            t = np.abs(t - 2 * np.pi * np.round(t / (2 * np.pi)))
            if np.any(t >= cast(float, self.pairs[i].theta_limit)):  # _ranged: the pairs with a limit
                raise ValueError("q: a joint is at its pair's limit, where d'(theta) is unbounded")
        return arrays

    def _evaluate(
        self,
        method: int,
        family: str,
        q: ArrayLike,
        design: Sequence[NDArray[np.float64]],
        strict: bool = True,
        framed: bool = True,
        **named: ArrayLike,
    ) -> NDArray[np.float64]:
        """The validating path of a method: checks and converts the inputs (a ValueError names
        the argument), then the fast path again, else the law kernels and the generic kernel of
        `family` with the `design` inputs after the state; with `framed`, the base and tool frames
        composed (`_compose`)."""
        arrays = self._state(q, strict, **named)
        out = self._fast.call(method, *arrays)
        if out is None:
            law = self._law(arrays[0])
            if strict and not np.isfinite(law).all():
                raise ValueError("q: a joint is at its pair's limit, where d'(theta) is unbounded")
            out = call(self._kernel(family), law, *arrays[1:], *design)[0]
        if framed and self._framed and method <= 2:
            out = self._compose(method, out, arrays[0])
        return out

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """(..., 4, 4): the pose of the tool in the world, base · (frame n in frame 0) · tool; q is
        (n,) or (..., n)."""
        out = self._call(0, q)
        return out if out is not None else self._evaluate(0, "fk", q, (self._dh,), strict=False)

    def fk_study(self, q: ArrayLike) -> NDArray[np.float64]:
        """(..., 8): the Study point (x0..x3, y0..y3) of fk(q) (the tool in the world), with |x| = 1;
        (x, y) ~ (−x, −y)."""
        out = self._call(1, q)
        return normalise(out if out is not None else self._evaluate(1, "fk_study", q, (self._dh,), strict=False))

    def jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """(..., 6, n): geometric Jacobian in the world frame, rows [v; ω] (v of the tool's origin;
        without base and tool frames, of frame n's origin in frame 0)."""
        out = self._call(2, q)
        return out if out is not None else self._evaluate(2, "jacobian", q, self._body[:2])

    # ----------------------------------------------------------------------------- dynamics
    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """(..., n, n): M(θ), legs included."""
        out = self._call(3, q)
        return out if out is not None else self._evaluate(3, "mass_matrix", q, self._body[:4])

    def coriolis_matrix(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """(..., n, n): C(θ, θ') in Christoffel form (Ṁ − 2C is skew-symmetric)."""
        out = self._call(4, q, qd)
        return out if out is not None else self._evaluate(4, "coriolis", q, self._body[:4], qd=qd)

    def gravity_torques(self, q: ArrayLike) -> NDArray[np.float64]:
        """(..., n): g(θ) = ∂V/∂θ."""
        out = self._call(5, q)
        return out if out is not None else self._evaluate(5, "gravity", q, self._body)

    def bias(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """(..., n): C(θ, θ')θ' + g(θ)."""
        out = self._call(6, q, qd)
        return out if out is not None else self._evaluate(6, "bias", q, self._body, qd=qd)

    def inverse_dynamics(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """(..., n): τ = M(θ)θ'' + C(θ, θ')θ' + g(θ), torques about the pair axes."""
        out = self._call(7, q, qd, qdd)
        return out if out is not None else self._evaluate(7, "inverse_dynamics", q, self._body, qd=qd, qdd=qdd)

    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> NDArray[np.float64]:
        """(..., n): θ'' = M⁻¹(τ − C θ' − g), by a Cholesky factorisation of M inside one kernel."""
        out = self._call(8, q, qd, tau)
        if out is None:
            out = self._evaluate(8, "forward_dynamics", q, self._body, qd=qd, tau=tau)
            if not np.isfinite(out).all():
                raise ValueError(
                    "links: the mass matrix is not positive definite at this q "
                    "(give every moving body mass and inertia)"
                )
        return out

    def inverse_dynamics_derivatives(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> D.Triple:
        """(∂τ/∂θ, ∂τ/∂θ', M), each (..., n, n), [i, k] = ∂τ_i/∂x_k; exact (apair.derivatives)."""
        return D.inverse_dynamics_derivatives(self, q, qd, qdd, 10)

    def jacobian_dot(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """(..., 6, n): dJ/dt of `jacobian` moving at qd (J̇q' is the tool's acceleration bias)."""
        return D.jacobian_dot(self, q, qd, 12)

    def forward_dynamics_derivatives(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> D.Triple:
        """(∂θ''/∂θ, ∂θ''/∂θ', M⁻¹ = ∂θ''/∂τ), each (..., n, n), at θ'' = forward_dynamics(q, qd, tau)."""
        return D.forward_dynamics_derivatives(self, q, qd, tau, 11)

    def energy(self, q: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
        """(..., 2): kinetic and potential energy (T, V) [J], legs included; V of gravity (in the
        world) is zero with every body at the origin of frame 0."""
        out = self._call(9, q, qd)
        return out if out is not None else self._evaluate(9, "energy", q, self._body, qd=qd)

    @property
    def _body(self) -> tuple[NDArray[np.float64], ...]:
        return self._dh, self._turning, self._links, self._legs, self._gravity

    def specialise(self, kernels: Iterable[str] | None = None) -> AChain:
        """This chain with its design built into its own kernels (`apair codegen`'s C, compiled
        once into the cache, see apair.files.cache_root, and found again by content hash):
        the same methods, faster. `kernels`: a subset of fk, fk_study, jacobian, mass_matrix, coriolis,
        gravity_torques, bias, inverse_dynamics, forward_dynamics, energy (default: these), and
        inverse_dynamics_derivatives, forward_dynamics_derivatives (minutes to derive: only when named);
        the others stay generic. Without a C compiler it warns once and uses the generic kernels
        (`.specialised` says which). Base and tool frames are built in (apair.specialise)."""
        from .specialise import check_frames

        check_frames(self)
        return SpecialisedChain(self, kernels)

    def to_casadi(self) -> dict[str, Any]:
        """{name: casadi.Function}: fk, jacobian, mass_matrix, inverse_dynamics, forward_dynamics as
        SX graphs of the generated kernels (apair.symbolic; needs apair[casadi])."""
        from .symbolic import to_casadi

        return to_casadi(self)

    def to_mjcf(
        self,
        q: ArrayLike | None = None,
        path: str | os.PathLike[str] | None = None,
        overwrite: bool = False,
        collisions: bool = False,
        limits: bool = True,
        outside_limits: bool = False,
    ) -> str:
        """The MuJoCo model (MJCF) of the mechanism, every A-pair as its Griffis-Duffy platform with
        six legs closed by equality constraints (apair.mjcf); keyframe 0 is q (default: all zero).
        `limits`: the hinges carry the chain's collision limits as ranges (False: none). A q past
        those limits (legs colliding) is refused unless `outside_limits`. Written to `path` too if
        given (an existing file only with overwrite=True). Returns the XML."""
        from . import mjcf

        collisions = V.flag("collisions", collisions)
        xml = mjcf.to_mjcf(
            self,
            q,
            name=getattr(self, "name", None) or "apair chain",
            collisions=collisions,
            limits=limits,
            outside_limits=outside_limits,
        )
        if path is not None:
            write_text(path, xml, overwrite, ".xml")
        return xml

    def to_html(self, path: str | os.PathLike[str] | None = None, overwrite: bool = False, workspace: int = 0) -> str:
        """The interactive 3D viewer of the chain as one offline HTML page (apair.view); written to
        `path` too if given (an existing file only with overwrite=True). Returns the HTML."""
        from . import view

        html = view.to_html(self, workspace)
        if path is not None:
            write_text(path, html, overwrite, ".html")
        return html

    def simulate(
        self,
        q0: ArrayLike,
        qd0: ArrayLike,
        t: ArrayLike,
        tau: ArrayLike | Callable[[float, NDArray[np.float64], NDArray[np.float64]], ArrayLike] | None = None,
        rtol: float = 1e-10,
        atol: float = 1e-12,
        method: str = "DOP853",
        limits: str = "stop",
    ) -> Trajectory:
        """Integrate the equations of motion from (q0, qd0) and report the state at times `t`.

        tau: None (free motion), an array (n,), or a callable tau(t, q, qd) -> (n,).
        Adaptive Runge-Kutta (scipy.integrate.solve_ivp) over the generated kernels.
        limits: "stop" ends the run where a joint first reaches a limit of `hard_limits` (the
        event's state is the last sample; `Trajectory.stop` says which joint, which side, when);
        "ignore" passes through explicit and collision limits (range ends still stop it).
        Returns a `Trajectory` with t, q, qd, the energies T, V along it, and `stop`.
        """
        from .simulate import simulate

        return simulate(self, q0, qd0, t, tau, rtol=rtol, atol=atol, method=method, limits=limits)

    # ----------------------------------------------------------------------------- varieties
    def constraint_variety(self, max_degree: int = 4, seed: int = 0) -> Variety:
        """2-pair chains: homogeneous sympy.Poly in x0..y3 (the Study quadric included) that
        generate every form of degree ≤ max_degree vanishing on all poses of the chain.

        The result is a list with `.degree`, `.hilbert`, `.dims`, `.exact` and `.residual`
        (see apair.variety): exact for rational designs, floating point otherwise.
        """
        from .variety import constraint_variety

        max_degree = V.integer("max_degree", max_degree, minimum=1, maximum=4)
        return constraint_variety(self, max_degree=max_degree, seed=V.seed(seed))

    # ----------------------------------------------------------------------------- inverse kinematics
    @overload
    def ik(
        self,
        T: ArrayLike,
        tol: float = ...,
        full: Literal[False] = ...,
        within_limits: bool = ...,
        fix: Mapping[int, float] | None = ...,
    ) -> NDArray[np.float64]: ...
    @overload
    def ik(
        self,
        T: ArrayLike,
        tol: float = ...,
        *,
        full: Literal[True],
        within_limits: bool = ...,
        fix: Mapping[int, float] | None = ...,
    ) -> Solution: ...
    @overload
    def ik(
        self,
        T: ArrayLike,
        tol: float,
        full: Literal[True],
        within_limits: bool = ...,
        fix: Mapping[int, float] | None = ...,
    ) -> Solution: ...
    @overload
    def ik(
        self,
        T: ArrayLike,
        tol: float = ...,
        full: bool = ...,
        within_limits: bool = ...,
        fix: Mapping[int, float] | None = ...,
    ) -> NDArray[np.float64] | Solution: ...
    def ik(
        self,
        T: ArrayLike,
        tol: float = 1e-9,
        full: bool = False,
        within_limits: bool = False,
        fix: Mapping[int, float] | None = None,
    ) -> NDArray[np.float64] | Solution:
        """All real joint vectors q (k, n) with fk(q) = T, each verified (largest entry of
        |fk(q) − T| ≤ tol); (0, n) when T is out of reach. T: a 4×4 transform or a Study point,
        the tool's pose in the world (with frames: solved for frame n's pose base⁻¹·T·tool⁻¹ in frame
        0, where `error` is measured). within_limits=True keeps the solutions inside `limits`.

        Chains of 1 to 6 sinusoidal A-, R- or P-pairs (7 with `fix`; P-pairs by the homotopy, any n,
        their slides in m, any real value). Otherwise n ≤ 4 by kinematic mapping (see
        apair.ik.elimination4): the left half's constraint variety on the right part's image,
        eliminated to eigenvalue and univariate problems. 5 and 6 R-pairs by the 6R elimination
        (apair.ik.elimination6r) where it certifies its 16 solutions, chains with one A-pair by
        theirs (apair.ik.elimination1a5r); otherwise by parameter homotopy (apair.ik.homotopy) from the
        design's start system (`prepare_ik`, cached). Angles in (−2π, 2π] for A-pairs, (−π, π] for R.
        fix={k: value, ...} (joints from 1): those joints held at those values [rad], the rest solved
        (needed for 7 joints, whose poses have a continuum of solutions: ik_local gives the one
        nearest a seed). The held joint's transform is folded into the base (k = 1), the tool
        (k = n) or, exactly, into the DH constants of its neighbours (`apair.hold`): a chain of n − len(fix)
        joints, solved as above; q (k, n) has q[:, k − 1] = value and `error` is measured on this
        chain. Refused (one line) where joints k − 1 and k + 1 are nearly parallel at that value.
        full=True returns an `apair.ik.Solution` with the same q: error, candidates, complex_count
        (the solutions over the complex numbers), `inside` (whether each solution is within
        `limits`), `certified` (the set is proven complete, an empty one included; False where it
        may be incomplete: a local search supplied the solutions (n ≤ 4), or the start set or the
        paths did not account for every solution (n = 5, 6)), `method` ("closed form", "elimination",
        "homotopy", "local search" or "reach bound"), `note` (why it is not certified, how it was at a
        singular pose, or a continuum's member given) and `family` (the chain's kinematic family).
        It costs twice the plain answer for n ≤ 4, nothing more for n = 5, 6; a closed form answers
        a plain float64 pose with the default flags in a few µs (apair._native.ClosedIK)."""
        if self._ik_fast is not None and full is False and within_limits is False and fix is None:  # closed forms
            if (out := self._ik_fast.call(T, tol)) is not None:  # None: a pose the validating path must see
                return out[0]
        from .ik import Solver

        tol = V.scalar("tol", tol, positive=True)
        full, within_limits = V.flag("full", full), V.flag("within_limits", within_limits)
        if fix is not None:
            return held_ik(self, T, tol, full, within_limits, fix, AChain)
        if self.n > 6:
            raise ValueError(
                f"fix: a {self.n}-joint chain reaches a pose along a continuum of joint vectors: hold a "
                "joint with ik(T, fix={k: value}) (k from 1) or take the solution nearest a seed with ik_local(T, q0)"
            )
        if self._ik is None:
            self._ik = Solver(self._dh_chain())
            self._ik_fast = None if self._framed else self._ik.fast
        if self._framed:
            from .ik.poses import pose_matrix

            dtype = getattr(T, "dtype", None)
            T = self._to_dh(pose_matrix(T))
            if dtype is not None and np.dtype(dtype).kind == "f" and np.dtype(dtype).itemsize < 8:
                T = T.astype(dtype)  # a rounded pose stays one: the solver's tolerance floor for it
        sol = self._ik.solve(T, tol=tol, count_complex=full)
        if not (full or within_limits):
            return sol.q
        inside = self.within_limits(sol.q)
        if within_limits:
            sol = dataclasses.replace(sol, q=sol.q[inside], error=sol.error[inside])
            inside = inside[inside]
        return dataclasses.replace(sol, inside=inside) if full else sol.q

    def kinematic_family(self) -> Classification:
        """The chain's kinematic family and its R twin's (which axes are parallel or meet; EAIK's families): apair.ik.families."""
        return classify(self)

    def prepare_ik(
        self, progress: Callable[[int, int], object] | None = None, refresh: bool = False, trace: bool = False
    ) -> StartSystem:
        """n = 5, 6 or a P-pair: the design's homotopy start system (every complex solution at a generic
        complex pose, by monodromy), cached (`apair ik-prepare`). trace: also run the trace test
        (apair.ik.homotopy.trace: seconds up to 48 solutions, minutes and maybe no verdict for more,
        refused above 200), whose verdict is cached with the set as its `certified`. Returns
        `apair.ik.homotopy.StartSystem` (.count, .certified, .runs, .loops, .seconds, .trace)."""
        from .ik import homotopy

        if not 5 <= self.n <= 6 and not (self.n < 5 and any(p.kind == "prismatic" for p in self.pairs)):
            raise ValueError(
                f"chain: start systems are for 5 and 6 joints (this chain has {self.n}; its ik is "
                + ("solved by elimination)" if self.n < 5 else "solved with fix={k: value}, one joint held)")
            )
        from .ik.homotopy import trace as trace_test

        certify: Callable[..., StartSystem] | None = trace_test.certify if trace else None
        return homotopy.start_system(
            homotopy.Problem.of(self._dh_chain()), progress=progress, refresh=refresh, certify=certify
        )

    def ik_local(self, T: ArrayLike, q0: ArrayLike, tol: float = 1e-10, max_iter: int = 100) -> LocalSolution:
        """The solution nearest (in the damped least-squares sense) to each seed: Levenberg-Marquardt
        from q0 (n,) or (..., n) to T (4, 4) or (..., 4, 4), broadcast together, every step kept inside
        `limits`; in C on the fk and Jacobian kernels. Returns `apair.ik.LocalSolution` (q, residual =
        largest entry of |fk(q) − T|, converged = residual ≤ tol). Any n, any pairs. One float64 pose
        and seed take one native call once the first call has set the chain's fast path up
        (apair.ik.local.local_solver); the same numbers. With base or tool frames T is the tool's pose
        in the world, solved for base⁻¹·T·tool⁻¹ (the residual is measured there)."""
        if self._local_ik is not None:
            out: LocalSolution | None = self._local_ik.call(T, q0, tol, max_iter)
            if out is not None:
                return out
        from .ik.local import ik_local, local_solver

        plain = self._dh_chain()
        if self._framed:
            from .ik.poses import check_matrix

            T = V.real_array("T", T)
            if T.shape[-2:] != (4, 4):
                raise ValueError(f"T: expected a 4x4 transform or an array of them (..., 4, 4), got shape {T.shape}")
            T = self._to_dh(check_matrix(T))
        out = ik_local(plain, T, q0, tol=tol, max_iter=V.integer("max_iter", max_iter, maximum=MAX_ITER))
        if self._local_ik is None:
            fast = local_solver(plain, MAX_ITER)
            self._local_ik = FramedLocal(fast, self._B_inv, self._T_inv) if self._framed and fast is not None else fast
        return out

    def workspace(
        self,
        samples: int = 300_000,
        resolution: int = 24,
        rounds: int = 4,
        poses: bool = False,
        engine: object = None,
        seed: int = 0,
        progress: Callable[[int, int], object] | None = None,
    ) -> Workspace:
        """The reachable workspace of the tool's origin (in the world) inside `limits` (apair.workspace):
        `.points`, `.boundary`, `.volume`, `.volume_error` (one standard uncertainty), `.plot(path)`.
        engine: None (this process), "threads"/"processes" (local Dask) or a dask.distributed
        scheduler address or Client; the result does not depend on it."""
        from .workspace import workspace

        return workspace(
            self,
            samples=samples,
            resolution=resolution,
            rounds=rounds,
            poses=V.flag("poses", poses),
            engine=engine,
            seed=V.seed(seed),
            progress=progress,
        )

    def compare(
        self,
        twin: str | None = None,
        samples: int = 300_000,
        seed: int = 0,
        path: ArrayLike | None = None,
        engine: object = None,
        progress: Callable[[str], object] | None = None,
    ) -> Comparison:
        """This chain beside its twin (apair.compare): every A-pair an R-pair (twin=None: "revolute")
        at the same DH constants and links, measured on the same work: workspaces, joint ranges,
        dexterity, gravity and path torques, mass, ik counts. samples, seed, engine: the workspaces'
        (the chain's volume is workspace(samples=samples, seed=seed)'s); path: points (k, 3) [m] of
        the common end-effector path (default: a straight line through both workspaces). Returns
        `apair.compare.Comparison` (.table(), .as_dict(), .report(path), .picture(path))."""
        from .compare import compare

        return compare(self, twin=twin, samples=samples, seed=seed, path=path, engine=engine, progress=progress)

    def within_limits(self, q: ArrayLike) -> NDArray[np.bool_]:
        """(...): whether each joint vector lies inside `limits` (bounds included)."""
        q = self._q(q)
        lim = self.limits
        return np.all((q >= lim[:, 0]) & (q <= lim[:, 1]), axis=-1)


class SpecialisedChain(AChain):
    """An AChain whose kernel-backed methods chosen (fk ... energy, the dynamics' derivatives) run the
    chain's own specialised C kernels (AChain.specialise, built by apair.specialise); everything else
    is the AChain's. Where they cannot be had (no C compiler), the generic kernels serve (warned once)."""

    def __init__(self, chain: AChain, kernels: Iterable[str] | None = None) -> None:
        from .specialise import check_kernels, content_hash

        self.__dict__.update({k: v for k, v in chain.__dict__.items() if k not in ("_fast", "_call")})
        self._kernels = check_kernels(kernels)
        self.content_hash = content_hash(chain, self._kernels)
        self._attach()

    def _attach(self) -> None:
        """The specialised fast path (building it on first use; the references of its self-test
        come from the generic kernels, which serve until then)."""
        from .specialise import load

        self._use(self._native_chain())
        fast = load(self, METHODS, self._kernels)
        self.specialised = fast is not None
        if fast is not None:
            self._use(fast)

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._attach()

    def __repr__(self) -> str:
        return f"{super().__repr__()}.specialise()"
