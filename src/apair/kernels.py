"""The generated kernels, behind one call interface, from C (ctypes) or from NumPy.

`call(name, *inputs)` evaluates kernel `name` over leading batch axes of its inputs and returns
its outputs. The C library (`apair._libapair`, built from generated/c at install time) is the
default; the generated NumPy kernels are used on request (`set_backend("numpy")` or the
environment variable APAIR_BACKEND=numpy) or when the library is missing, which is said once.
Kernel signatures come from generated/manifest.json, so nothing here is written per kernel.
"""
from __future__ import annotations

import ctypes
import importlib.machinery
import json
import os
import warnings
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

_BACKENDS = ("c", "numpy")
_state = {"backend": None, "warned": False}


@lru_cache(maxsize=None)
def manifest() -> dict:
    """Names, inputs, outputs and op counts of every generated kernel."""
    return json.loads(resources.files("apair.generated").joinpath("manifest.json").read_text())


def _library_path() -> Path | None:
    pkg = Path(__file__).parent
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = pkg / f"_libapair{suffix}"
        if path.exists():
            return path
    return None


@lru_cache(maxsize=None)
def _library():
    """The ctypes handle of the compiled kernels, or None (with the reason)."""
    path = _library_path()
    if path is None:
        return None, "the compiled C library apair._libapair is not installed"
    try:
        return ctypes.CDLL(str(path)), None
    except OSError as exc:  # pragma: no cover - depends on the platform
        return None, f"the C library {path} could not be loaded: {exc}"


def c_available() -> bool:
    return _library()[0] is not None


def set_backend(name: str | None) -> None:
    """Choose "c" or "numpy" for every later kernel call (None: the default, C when present)."""
    if name is not None and name not in _BACKENDS:
        raise ValueError(f"backend: expected one of {_BACKENDS} or None, got {name!r}")
    if name == "c" and not c_available():
        raise ValueError(f"backend: 'c' requested but {_library()[1]}")
    _state["backend"] = name


def backend() -> str:
    """The backend in use: the explicit choice, else APAIR_BACKEND, else C when it is installed."""
    choice = _state["backend"] or os.environ.get("APAIR_BACKEND") or None
    if choice is not None:
        if choice not in _BACKENDS:
            raise ValueError(f"APAIR_BACKEND: expected one of {_BACKENDS}, got {choice!r}")
        if choice == "c" and not c_available():
            raise ValueError(f"APAIR_BACKEND: 'c' requested but {_library()[1]}")
        return choice
    if c_available():
        return "c"
    if not _state["warned"]:
        warnings.warn(f"apair: {_library()[1]}; using the NumPy kernels", RuntimeWarning, stacklevel=3)
        _state["warned"] = True
    return "numpy"


@lru_cache(maxsize=None)
def _c_functions(name: str):
    lib = _library()[0]
    spec = manifest()["kernels"][name]
    prefix = manifest()["prefix"]
    n_in, n_out = len(spec["inputs"]), len(spec["outputs"])
    single = getattr(lib, prefix + name)
    single.argtypes = [ctypes.c_void_p] * (n_in + n_out)
    single.restype = None
    batch = getattr(lib, prefix + name + "_batch")
    batch.argtypes = [ctypes.c_size_t] + [ctypes.c_void_p, ctypes.c_ssize_t] * n_in + [ctypes.c_void_p] * n_out
    batch.restype = None
    return single, batch


@lru_cache(maxsize=None)
def _numpy_function(name: str):
    from apair.generated.numpy import KERNELS

    return KERNELS[name]


def _call_c(name: str, inputs: list[np.ndarray]):
    spec = manifest()["kernels"][name]
    shapes = [tuple(a["shape"]) for a in spec["inputs"]]
    batch = np.broadcast_shapes(*(x.shape[: x.ndim - len(s)] for x, s in zip(inputs, shapes)))
    outs = [np.empty(batch + tuple(a["shape"])) for a in spec["outputs"]]
    single, batched = _c_functions(name)
    if batch == ():
        args = [np.ascontiguousarray(x) for x in inputs]
        single(*[x.ctypes.data for x in args], *[o.ctypes.data for o in outs])
        return outs
    count = int(np.prod(batch))
    argv = [ctypes.c_size_t(count)]
    keep = []
    for x, s in zip(inputs, shapes):
        size = int(np.prod(s))
        if x.ndim == len(s):  # one value for the whole batch
            x = np.ascontiguousarray(x)
            stride = 0
        else:
            x = np.ascontiguousarray(np.broadcast_to(x, batch + s)).reshape(count, size)
            stride = size
        keep.append(x)
        argv += [x.ctypes.data, stride]
    batched(*argv, *[o.ctypes.data for o in outs])
    return outs


def call(name: str, *inputs) -> list[np.ndarray]:
    """Evaluate kernel `name`; inputs are float64 arrays with the kernel's trailing shapes."""
    inputs = [np.asarray(x, dtype=np.float64) for x in inputs]
    if backend() == "c":
        return _call_c(name, inputs)
    out = _numpy_function(name)(*inputs)
    return list(out) if isinstance(out, tuple) else [out]
