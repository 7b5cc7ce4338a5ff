"""Input checks shared by the runtime: every failure is a ValueError that names the argument."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

MAX_DIMS = 24  # batch axes plus a kernel's own (at most 3) stay within NumPy's 32 (and 64) dimensions


def real_array(
    name: str, value: object, *, trailing: tuple[int, ...] | None = None, ndim_max: int | None = None
) -> NDArray[np.float64]:
    """A finite float64 array; `trailing` fixes the last axes' shape."""
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError, OverflowError, RecursionError) as exc:
        raise ValueError(f"{name}: expected an array of real numbers ({type(exc).__name__}: {exc})") from None
    if raw.dtype.kind not in "iuf":  # no booleans, complex numbers, strings or objects
        raise ValueError(f"{name}: expected real numbers, got {raw.dtype.name} values {value!r}")
    arr = raw.astype(np.float64, copy=False)
    if trailing is not None:
        k = len(trailing)
        if arr.ndim < k or arr.shape[arr.ndim - k :] != trailing:
            want = "(" + ", ".join(["..."] + [str(t) for t in trailing]) + ")"
            raise ValueError(f"{name}: expected shape {want}, got {arr.shape}")
    if arr.ndim > MAX_DIMS:
        raise ValueError(f"{name}: expected at most {MAX_DIMS} dimensions, got {arr.ndim}")
    if ndim_max is not None and arr.ndim > ndim_max:
        raise ValueError(f"{name}: expected at most {ndim_max} dimensions, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ValueError(f"{name}: contains NaN or infinite values")
    return arr


def scalar(name: str, value: object, *, positive: bool = False, nonnegative: bool = False) -> float:
    """A finite real scalar, optionally > 0 or ≥ 0."""
    arr = real_array(name, value)
    if arr.ndim != 0:
        raise ValueError(f"{name}: expected a scalar, got shape {arr.shape}")
    x = float(arr)
    if positive and not x > 0:
        raise ValueError(f"{name}: must be > 0, got {x}")
    if nonnegative and not x >= 0:
        raise ValueError(f"{name}: must be >= 0, got {x}")
    return x


def vector(name: str, value: object, n: int) -> NDArray[np.float64]:
    """A finite vector of exactly n entries (a scalar is not accepted)."""
    arr = real_array(name, value)
    if arr.shape != (n,):
        raise ValueError(f"{name}: expected shape ({n},), got {arr.shape}")
    return arr


def integer(name: str, value: object, minimum: int = 1) -> int:
    """An integer ≥ minimum; a float is accepted only when it is a whole number (8.9 is refused,
    not truncated)."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected an integer, got {value!r}")
    if isinstance(value, (int, np.integer)):
        out = int(value)
    else:
        x = scalar(name, value)
        if x != int(x):
            raise ValueError(f"{name}: expected an integer, got {value!r}")
        out = int(x)
    if out < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {out}")
    return out
