"""The targets of a design search: points (x, y, z) or poses (R row by row, then p) in the base
frame, one per line of a CSV file, with the tolerance within which a target counts as reached.

A file may hold blank lines, `#` comments and one header line of names before the numbers; every
other line must hold exactly the numbers of one target, finite, separated by commas. A pose's
rotation must be orthonormal with determinant 1 (within ROTATION_TOL).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._validate import shorten

MAX_TARGETS = 100_000  # targets in one file (each costs a few IK solves per candidate design)
MAX_BYTES = 64 * 2**20
ROTATION_TOL = 1e-6  # largest entry of |R Rᵀ − I| of a pose target
WIDTH = {"points": 3, "poses": 12}
SHAPE = {"points": "3 numbers (x, y, z)", "poses": "12 numbers (R row by row, then p)"}


@dataclass(frozen=True, eq=False)
class Targets:
    """What the design should reach: `values` (m, 3) points or (m, 4, 4) poses [m], within
    `tolerance` [m] (and `tolerance_deg` of rotation for poses); `source`: the file as named."""

    kind: str
    values: NDArray[np.float64]
    tolerance: float
    tolerance_deg: float | None
    source: str

    def __len__(self) -> int:
        return len(self.values)

    def digest(self) -> dict[str, Any]:
        """What identifies the targets in a checkpoint: kind, tolerances and the numbers' hex."""
        return {
            "kind": self.kind,
            "tolerance": self.tolerance,
            "tolerance_deg": self.tolerance_deg,
            "values": [float(x).hex() for x in self.values.ravel()],
        }


def _positive(where: str, table: dict[str, Any], key: str) -> float:
    """A positive finite number under `key`."""
    if key not in table:
        raise ValueError(f"{where}.{key}: missing (the distance within which a target counts as reached)")
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not v > 0:
        raise ValueError(f"{where}.{key}: expected a positive number, got {shorten(repr(v))}")
    return float(v)


def read_targets(where: str, table: object, base: Path) -> Targets:
    """The [targets] table (`where` names it in messages): points = "file" or poses = "file",
    relative to `base`, and tolerance [m] (tolerance_deg too for poses)."""
    if not isinstance(table, dict):
        raise ValueError(f"{where}: expected a table, got {shorten(repr(table))}")
    kinds = [k for k in WIDTH if k in table]
    if len(kinds) != 1:
        raise ValueError(f'{where}: give points = "file.csv" or poses = "file.csv" (exactly one)')
    kind = kinds[0]
    valid = {kind, "tolerance"} | ({"tolerance_deg"} if kind == "poses" else set())
    unknown = sorted(set(table) - valid)
    if unknown:
        extra = " (rotations are checked for poses only)" if unknown == ["tolerance_deg"] else ""
        raise ValueError(
            f"{where}: unknown key {shorten(repr(unknown[0]))}{extra}; expected {', '.join(sorted(valid))}"
        )
    name = table[kind]
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"{where}.{kind}: expected a file name, got {shorten(repr(name))}")
    tolerance = _positive(where, table, "tolerance")
    tolerance_deg = _positive(where, table, "tolerance_deg") if kind == "poses" else None
    rows = _rows(f"{where}.{kind}", base / name, name, WIDTH[kind])
    values = rows if kind == "points" else _poses(f"{where}.{kind}", name, rows)
    return Targets(kind, values, tolerance, tolerance_deg, name)


def _text(where: str, path: Path, name: str) -> str:
    """The file's text, refused (naming it) when it is missing, not a file, too large or not UTF-8."""
    shown = shorten(repr(name))
    if not path.is_file():
        why = "is a folder" if path.is_dir() else "does not exist"
        raise ValueError(f"{where}: {shown} {why} (relative to {shorten(repr(str(path.parent)))})")
    if path.stat().st_size > MAX_BYTES:
        raise ValueError(f"{where}: {shown} is larger than {MAX_BYTES // 2**20} MiB, not a targets file")
    try:
        return path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where}: {shown} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except OSError as exc:
        raise ValueError(f"{where}: cannot read {shown}: {exc.strerror or exc}") from None


def _rows(where: str, path: Path, name: str, width: int) -> NDArray[np.float64]:
    """(m, width): the numbers of every target line of the file (see the module docstring)."""
    shape = SHAPE["points" if width == 3 else "poses"]
    out: list[list[float]] = []
    seen_data = False
    for k, line in enumerate(_text(where, path, name).splitlines(), start=1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        words = [w.strip() for w in text.split(",")]
        numbers = _numbers(words)
        if numbers is None and not seen_data and any(c.isalpha() for c in text):
            seen_data = True  # a header of names (x,y,z), before the first numbers only
            continue
        seen_data = True
        if numbers is None:
            bad = next(w for w in words if _number(w) is None)
            raise ValueError(f"{where}: {shorten(repr(name))} line {k}: {shorten(repr(bad))} is not a finite number")
        if len(numbers) != width:
            raise ValueError(f"{where}: {shorten(repr(name))} line {k}: expected {shape}, got {len(numbers)}")
        out.append(numbers)
        if len(out) > MAX_TARGETS:
            raise ValueError(f"{where}: {shorten(repr(name))} holds more than {MAX_TARGETS} targets")
    if not out:
        raise ValueError(f"{where}: {shorten(repr(name))} holds no targets (expected lines of {shape})")
    return np.array(out)


def _number(word: str) -> float | None:
    try:
        x = float(word)
    except ValueError:
        return None
    return x if math.isfinite(x) else None


def _numbers(words: list[str]) -> list[float] | None:
    """The words as finite numbers, or None if any is not one."""
    out = [_number(w) for w in words]
    return None if any(x is None for x in out) else [x for x in out if x is not None]


def _poses(where: str, name: str, rows: NDArray[np.float64]) -> NDArray[np.float64]:
    """(m, 4, 4) transforms of the rows (R row by row, then p), each R a rotation."""
    T = np.zeros((len(rows), 4, 4))
    T[:, :3, :3] = rows[:, :9].reshape(-1, 3, 3)
    T[:, :3, 3] = rows[:, 9:]
    T[:, 3, 3] = 1.0
    R = T[:, :3, :3]
    off = np.abs(R @ R.transpose(0, 2, 1) - np.eye(3)).max(axis=(1, 2))
    bad = (off > ROTATION_TOL) | (np.linalg.det(R) < 0)
    if bad.any():
        k = int(np.argmax(bad))
        why = (
            "a reflection (determinant -1)"
            if off[k] <= ROTATION_TOL
            else f"not orthonormal (|R R^T - I| = {off[k]:.2g})"
        )
        raise ValueError(f"{where}: {shorten(repr(name))} target {k + 1}: the rotation is {why}")
    return T
