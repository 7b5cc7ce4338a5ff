"""Input checks shared by the runtime: every failure is a ValueError that names the argument."""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

MAX_DIMS = 24  # batch axes plus a kernel's own (at most 3) stay within NumPy's 32 (and 64) dimensions


# The range apair computes in: every length [m], mass [kg] and acceleration [m/s²] is 0 or of
# magnitude in [1e-40, 1e40]; inertias [kg m²] in [1e-120, 1e120]. Products of a few of them (a mass
# matrix entry: mass × length²; a volume: length³) then stay normal doubles, so every finite input
# gives finite output (docs/conventions.md, "Units and ranges").
LENGTH_RANGE = (1e-40, 1e40)
INERTIA_RANGE = (1e-120, 1e120)


def in_range(name: str, value: ArrayLike, unit: str, bounds: tuple[float, float] = LENGTH_RANGE) -> None:
    """Refuses an entry that is neither 0 nor of magnitude within bounds, naming it and the range."""
    lo, hi = bounds
    arr = np.asarray(value, float)
    mag = np.abs(arr)
    bad = (mag != 0) & ((mag < lo) | (mag > hi))
    if bad.any():
        at = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"[{', '.join(map(str, at))}]" if at else ""
        raise ValueError(
            f"{name}{where}: {float(arr[at]):.6g} {unit} is outside the range apair computes in "
            f"(0, or {lo:g} to {hi:g} {unit} in magnitude)"
        )


def shorten(text: str, limit: int = 80) -> str:
    """One line of at most `limit` characters, for a value quoted in an error message."""
    line = " ".join(text.split())
    return line if len(line) <= limit else line[: limit - 3] + "..."


# Characters no text field holds: control characters (C0, tab and newlines included, DEL, C1), lone
# surrogates (no UTF-8 file can hold them) and Unicode's 66 non-characters (U+FDD0..U+FDEF and the
# last two code points of every plane). Writers of XML, JSON, HTML, C or TOML could not carry them
# intact, and a terminal would act on them. A multi-line field (a description) takes tab and newline.
_NONCHARACTERS = "\ufdd0-\ufdef" + "".join(f"{chr(p + 0xFFFE)}{chr(p + 0xFFFF)}" for p in range(0, 0x110000, 0x10000))
_REFUSED_TEXT = re.compile(f"[\x00-\x1f\x7f-\x9f\ud800-\udfff{_NONCHARACTERS}]")
_REFUSED_LINES = re.compile(f"[\x00-\x08\x0b-\x1f\x7f-\x9f\ud800-\udfff{_NONCHARACTERS}]")


def _what(ch: str) -> str:
    """The kind of a refused character, for a message."""
    if "\ud800" <= ch <= "\udfff":
        return "lone surrogate"
    return "control character" if ord(ch) <= 0x9F else "non-character"


def text(name: str, value: object, *, multiline: bool = False) -> str:
    """A text field (a chain's name, its description): a str without the characters that
    `_REFUSED_TEXT` lists (`multiline`: tab and newline allowed). The message names the field,
    the code point and where it is (character k, counted from 1), never the character itself."""
    if not isinstance(value, str):
        raise ValueError(f"{name}: expected a string, got {shorten(repr(value))}")
    bad = (_REFUSED_LINES if multiline else _REFUSED_TEXT).search(value)
    if bad is not None:
        k, line = bad.start(), value.count("\n", 0, bad.start())
        column = k - value.rfind("\n", 0, k)  # from 1 (rfind gives -1 on the first line)
        where = f"line {line + 1}, character {column}" if line else f"character {column}"
        raise ValueError(
            f"{name}: holds the {_what(bad.group())} U+{ord(bad.group()):04X} at {where}; use printable characters"
        )
    return value


def replace_refused(value: str) -> str:
    """value with every character that a one-line text field refuses replaced by U+FFFD: a
    default made of text nobody typed (a file name) is made usable, not refused."""
    return _REFUSED_TEXT.sub("\ufffd", value)


def real_array(
    name: str, value: object, *, trailing: tuple[int, ...] | None = None, ndim_max: int | None = None
) -> NDArray[np.float64]:
    """A finite float64 array; `trailing` fixes the last axes' shape."""
    if isinstance(value, np.ma.MaskedArray):
        raise ValueError(f"{name}: masked arrays are not accepted (the mask would be ignored); pass plain values")
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError, OverflowError, RecursionError) as exc:
        raise ValueError(
            f"{name}: expected an array of real numbers ({type(exc).__name__}: {shorten(str(exc))})"
        ) from None
    if raw.dtype.kind not in "iuf":  # no booleans, complex numbers, strings or objects
        raise ValueError(f"{name}: expected real numbers, got {raw.dtype.name} values {shorten(repr(value))}")
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


def flag(name: str, value: object) -> bool:
    """A bool (numpy's too): 'no', 0 or None are refused, not read as true or false."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected True or False, got {shorten(repr(value))}")
    return bool(value)


SEED_MAX = 2**63 - 1


def seed(value: object, name: str = "seed") -> int:
    """A random seed: an integer in [0, 2**63 - 1] (None is refused: results are reproducible)."""
    return integer(name, value, minimum=0, maximum=SEED_MAX)


def integer(name: str, value: object, minimum: int = 1, maximum: int | None = None) -> int:
    """An integer in [minimum, maximum]; a float is accepted only when it is a whole number (8.9 is
    refused, not truncated). Every count a user passes has a maximum: the work it asks for."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected an integer, got {value!r}")
    if isinstance(value, (int, np.integer)):
        out = int(value)
    else:
        x = scalar(name, value)
        if x != int(x):
            raise ValueError(f"{name}: expected an integer, got {shorten(repr(value))}")
        out = int(x)
    if out < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {out}")
    if maximum is not None and out > maximum:
        raise ValueError(f"{name}: must be <= {maximum}, got {shorten(str(out))}")
    return out


def joint_limits(pairs: Sequence[Any], limits: Iterable[ArrayLike | None] | None) -> list[tuple[float, float] | None]:
    """A chain's explicit joint ranges (one (lo, hi) or None per pair, None: the pair's own), checked:
    lo < hi within the pair's range of motion (`motion_range()`), and given for every P-pair."""
    n = len(pairs)
    if limits is None:
        limits = [None] * n
    try:
        entries = list(limits)
    except TypeError as exc:
        raise ValueError(f"limits: expected one (lo, hi) or None per pair, got {shorten(repr(limits))}") from exc
    if len(entries) != n:
        raise ValueError(f"limits: expected {n} entries (one per pair), got {len(entries)}")
    out: list[tuple[float, float] | None] = []
    for i, lim in enumerate(entries):
        if lim is None and pairs[i].kind == "prismatic":
            raise ValueError(f"limits[{i}]: joint {i + 1} is prismatic: give its range (lo, hi) in metres")
        if lim is None:
            out.append(None)
            continue
        lo, hi = vector(f"limits[{i}]", lim, 2)
        if not lo < hi:
            raise ValueError(f"limits[{i}]: expected lo < hi, got ({lo}, {hi})")
        plo, phi = pairs[i].motion_range()
        if lo < plo or hi > phi:
            raise ValueError(
                f"limits[{i}]: ({lo:.6g}, {hi:.6g}) rad goes beyond joint {i + 1}'s collision-free "
                f"range ({plo:.6g}, {phi:.6g}) rad"
            )
        out.append((float(lo), float(hi)))
    return out
