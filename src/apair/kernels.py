"""The generated kernels, behind one call interface, from C (apair._native) or from NumPy.

`call(name, *inputs)` evaluates kernel `name` over leading batch axes of its inputs and returns
its outputs. The C kernels, through the extension module `apair._native` (built from generated/c
at install time), are the default; the generated NumPy kernels are used on request
(`set_backend("numpy")` or the environment variable APAIR_BACKEND=numpy) or when the extension is
missing, which is said once. Kernel signatures come from generated/manifest.json and the C
registry, so nothing here is written per kernel.
"""

from __future__ import annotations

import importlib
import json
import os
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from functools import cache
from importlib import resources
from types import ModuleType
from typing import Any, Protocol, TypedDict

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import shorten

_BACKENDS = ("c", "numpy")


class _State(TypedDict):
    backend: str | None  # the explicit choice (set_backend)
    warned: bool  # the missing extension has been reported
    resolved: str | None  # the backend in use, None until the next kernel call


_state: _State = {"backend": None, "warned": False, "resolved": None}


@cache
def manifest() -> dict[str, Any]:
    """Names, inputs, outputs and op counts of every generated kernel."""
    data: dict[str, Any] = json.loads(resources.files("apair.generated").joinpath("manifest.json").read_text())
    return data


@cache
def _native() -> tuple[Any, str | None]:
    """The extension module with the compiled kernels, or None (with the reason). Any: the module is
    untyped (a C extension)."""
    try:
        module = importlib.import_module("apair._native")
    except ImportError as exc:
        return None, f"the compiled C kernels (apair._native) are not installed ({exc})"
    m = manifest()
    built = (module.content_hash, getattr(module, "sources_hash", None))
    if built != (m["content_hash"], m["sources_hash"]):
        return None, (
            f"the compiled C kernels (apair._native, content {built[0]}, sources {built[1]}) were built "
            f"from other generated C sources than the manifest's (content {m['content_hash']}, sources "
            f"{m['sources_hash']}): reinstall apair"
        )
    return module, None


def c_available() -> bool:
    return _native()[0] is not None


def native_module() -> tuple[ModuleType | None, str | None]:
    """(apair._native, None) where the compiled C kernels are installed, else (None, why not): for
    the code that calls the extension's own functions whatever the backend (AChain.ik_local)."""
    return _native()


def native_in_use() -> ModuleType | None:
    """apair._native where the C backend is in use, else None: the inverse kinematics' C steps,
    each with a NumPy twin that serves where this is None."""
    return _native()[0] if backend() == "c" else None


def set_backend(name: str | None) -> None:
    """Choose "c" or "numpy" for every later kernel call (None: the default, which reads
    APAIR_BACKEND again and otherwise takes C when present)."""
    if name is not None and name not in _BACKENDS:
        raise ValueError(f"backend: expected one of {_BACKENDS} or None, got {shorten(repr(name))}")
    if name == "c" and not c_available():
        raise ValueError(f"backend: 'c' requested but {_native()[1]}")
    _state["backend"] = name
    _state["resolved"] = None
    _enable_fast_paths(False)  # until the next kernel call resolves the backend again


def _enable_fast_paths(flag: bool) -> None:
    """Whether the chains' native fast paths (native_chain) may evaluate: only with the C backend."""
    native = _native()[0]
    if native is not None:
        native.enable(flag)


def backend() -> str:
    """The backend in use: the explicit choice, else APAIR_BACKEND (read on the first kernel call
    and after set_backend(None)), else C when it is installed."""
    resolved = _state["resolved"]
    if resolved is None:
        resolved = _state["resolved"] = _resolve_backend()
        _enable_fast_paths(resolved == "c")
    return resolved


def _resolve_backend() -> str:
    choice = _state["backend"] or os.environ.get("APAIR_BACKEND") or None
    if choice is not None:
        if choice not in _BACKENDS:
            raise ValueError(f"APAIR_BACKEND: expected one of {_BACKENDS}, got {shorten(repr(choice))}")
        if choice == "c" and not c_available():
            raise ValueError(f"APAIR_BACKEND: 'c' requested but {_native()[1]}")
        return choice
    if c_available():
        return "c"
    if not _state["warned"]:
        warnings.warn(f"apair: {_native()[1]}; using the NumPy kernels", RuntimeWarning, stacklevel=4)
        _state["warned"] = True
    return "numpy"


@cache
def _c_table(native: ModuleType) -> dict[str, int]:
    """Kernel name → registry index of the extension module, built whole before it is returned
    (threads calling for the first time never see a half-filled table)."""
    return {n: i for i, n in enumerate(native.names())}


def _c_index(native: ModuleType, name: str) -> int:
    """The registry index of kernel `name` in the extension module."""
    try:
        return _c_table(native)[name]
    except KeyError:
        raise ValueError(f"kernel: no generated kernel called {shorten(repr(name))}") from None


@cache
def _numpy_function(name: str) -> Callable[..., Any]:
    from apair.generated.numpy import KERNELS

    function: Callable[..., Any] = KERNELS[name]
    return function


def _canonical(name: str, inputs: Sequence[ArrayLike]) -> list[NDArray[np.float64]]:
    """The inputs as float64 arrays (native byte order, aligned, C-contiguous) with one common
    batch shape (or none)."""
    spec = _input_spec(name, inputs)
    arrays = [_float64(name, a["name"], x) for x, a in zip(inputs, spec)]
    shapes = [tuple(a["shape"]) for a in spec]
    for x, s, a in zip(arrays, shapes, spec):
        if x.ndim < len(s) or x.shape[x.ndim - len(s) :] != s:
            raise ValueError(f"{name}: input {a['name']} must end in shape {s}, got {x.shape}")
    batch = np.broadcast_shapes(*(x.shape[: x.ndim - len(s)] for x, s in zip(arrays, shapes)))
    return [
        np.require(x if x.ndim == len(s) else np.broadcast_to(x, batch + s), requirements=("C", "A"))
        for x, s in zip(arrays, shapes)
    ]


def _input_spec(name: str, inputs: Sequence[ArrayLike]) -> list[dict[str, Any]]:
    """The manifest's input list of kernel `name`, checked against the number of inputs given."""
    spec: list[dict[str, Any]] = manifest()["kernels"][name]["inputs"]
    if len(inputs) != len(spec):
        raise TypeError(f"{name}: expected {len(spec)} inputs, got {len(inputs)}")
    return spec


def _float64(kernel: str, arg: str, x: ArrayLike) -> NDArray[np.float64]:
    """x as a native-endian float64 array; complex, boolean or non-numeric input is refused (a
    silent cast would drop imaginary parts or turn True into 1.0)."""
    arr = np.asarray(x)
    if arr.dtype.kind not in "iuf":
        raise ValueError(f"{kernel}: input {arg} must be real numbers, got dtype {arr.dtype}")
    return arr.astype(np.float64, copy=False)


def call(name: str, *inputs: ArrayLike) -> list[NDArray[np.float64]]:
    """Evaluate kernel `name`; inputs are float64 arrays with the kernel's trailing shapes."""
    if backend() == "c":
        native = _native()[0]
        index = _c_index(native, name)
        out: list[NDArray[np.float64]] | None = native.call(index, *inputs)
        if out is None:  # some input needs converting or broadcasting first
            out = native.call(index, *_canonical(name, inputs))
            if out is None:
                raise ValueError(f"{name}: the inputs do not fit the kernel's shapes after broadcasting")
        return out
    spec = _input_spec(name, inputs)
    arrays = [_float64(name, a["name"], x) for x, a in zip(inputs, spec)]
    result = _numpy_function(name)(*arrays)
    return list(result) if isinstance(result, tuple) else [result]


# The chain-kernel families with a form for chains of R-pairs (<family>_revolute<n>: the generic
# kernel without its slide, pitch and leg terms, with the same inputs), which such chains call.
REVOLUTE = frozenset(
    {
        "fk",
        "jacobian",
        "mass_matrix",
        "inverse_dynamics",
        "forward_dynamics",
        "inverse_dynamics_derivatives",
        "forward_dynamics_derivatives",
    }
)


def chain_kernel(family: str, n: int, revolute: bool) -> str:
    """The name of the n-joint chain kernel of `family`: its form for chains of R-pairs where it has
    one (REVOLUTE) and `revolute` (every pair of the chain an R-pair), else the generic kernel."""
    return f"{family}_revolute{n}" if revolute and family in REVOLUTE else f"{family}{n}"


class FastPath(Protocol):
    """A chain's native fast path (`native_chain`)."""

    def call(self, method: int, *inputs: ArrayLike) -> NDArray[np.float64] | None: ...


class _NoFastPath:
    """The stand-in for a chain's native fast path where the C kernels are not installed."""

    @staticmethod
    def call(method: int, *inputs: ArrayLike) -> None:
        return None


def native_chain(
    n: int,
    methods: Iterable[tuple[str | tuple[str, ...], bool]],
    laws: Iterable[tuple[str, Sequence[float]]],
    limits: Iterable[float],
    design: Mapping[str, NDArray[np.float64]],
    keep: object = None,
    table: tuple[int, Sequence[str]] | None = None,
) -> FastPath:
    """A chain's native fast path (apair._native.Chain): `methods` = [(kernel name or names,
    strict)], each a registry kernel or, with `table` = (address, names), an entry of a loaded
    registry of specialised kernels (AChain.specialise) where it has one; a method of several
    kernels returns their outputs as one tuple; `laws` = per joint (law kernel name, params), or []
    when no kernel takes law values (each law's law_<kind>_d3 kernel comes along, for the kernels
    that take d'''); `limits` = per joint |θ| range (inf: none); `design` = the arrays the kernels
    take by name; `keep`: what must outlive the kernels. Its call(method, q, ...) returns None
    whenever the caller must validate first (or the backend is NumPy)."""
    native = _native()[0]
    if native is None:
        return _NoFastPath()
    generic = lambda name: native.kernel_address(_c_index(native, name))
    index = {} if table is None else {name: i for i, name in enumerate(table[1])}
    address = lambda name: table[0] + index[name] * native.KERNEL_SIZE if table and name in index else generic(name)
    names = _c_table(native)
    return native.Chain(
        n,
        [
            (tuple(address(k) for k in ((name,) if isinstance(name, str) else name)), bool(strict))
            for name, strict in methods
        ],
        [
            (generic(name), tuple(float(x) for x in params), generic(f"{name}_d3") if f"{name}_d3" in names else None)
            for name, params in laws
        ],
        [float(x) for x in limits],
        dict(design),
        keep,
    )
