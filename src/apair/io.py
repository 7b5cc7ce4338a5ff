"""Chains from TOML files (the format is documented in README.md, "Chain files").

name = "a 2A-chain"            # optional
[[joint]]                      # one table per joint, base to tip
pair = "sinusoidal"            # "sinusoidal" | "general" | "revolute"
base_radius = 0.05             # A-pairs: triangle circumradii [m]
platform_radius = 0.05
leg_length = 0.08              # "general" only: L1 [m]
leg_mass = 0.0                 # optional [kg]; leg_radius = 0.0, thickness = 0.0 optional [m]
limits = [-1.0, 1.0]           # optional joint range [rad] (or limits_deg); default: the
                               # pair's collision limits (a full turn for an R-pair)
a = 0.3                        # DH link length [m]
alpha = 1.5707963267948966     # DH twist [rad], or alpha_deg = 90
offset = 0.0                   # c_i [m] (optional)
theta_offset = 0.0             # phi_i [rad] (optional), or theta_offset_deg
mass = 1.0                     # link i (optional): mass [kg], centre of mass in frame i [m],
com = [0.0, 0.0, 0.05]         # inertia about the centre of mass in frame i [kg m^2]:
inertia = [0.01, 0.01, 0.02]   # principal (Ixx, Iyy, Izz), six values (Ixx, Iyy, Izz, Ixy,
                               # Ixz, Iyz) or a 3x3 table
gravity = [0, 0, -9.81]        # top level, optional [m/s^2]
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .chain import AChain
from .link import Link
from .pair import KINDS, APair

_PAIR_KEYS = {
    "sinusoidal": {"base_radius", "platform_radius", "leg_mass", "leg_radius", "thickness"},
    "general": {"base_radius", "platform_radius", "leg_length", "leg_mass", "leg_radius", "thickness"},
    "revolute": set(),
}
_DH_KEYS = {"a", "alpha", "alpha_deg", "offset", "theta_offset", "theta_offset_deg", "limits", "limits_deg"}
_LINK_KEYS = {"mass", "com", "inertia"}


def _numbers(where: str, v: object, shapes: Sequence[tuple[int, ...]]) -> NDArray[np.float64]:
    try:
        arr = np.asarray(v, dtype=object)
    except ValueError:  # ragged nesting
        arr = np.empty(0, dtype=object)
    if arr.shape not in shapes or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in arr.flat):
        raise ValueError(f"{where}: expected numbers of shape {' or '.join(map(str, shapes))}, got {_short(v)}")
    return np.array([_number(where, x) for x in arr.flat]).reshape(arr.shape)


def _link(w: str, j: dict[str, Any]) -> Link:
    mass = _number(f"{w}.mass", j.get("mass", 0.0))
    com = _numbers(f"{w}.com", j.get("com", [0.0, 0.0, 0.0]), [(3,)])
    I = _numbers(f"{w}.inertia", j.get("inertia", [0.0, 0.0, 0.0]), [(3,), (6,), (3, 3)])
    if I.shape == (3,):
        I = np.diag(I)
    elif I.shape == (6,):
        xx, yy, zz, xy, xz, yz = I
        I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    try:
        return Link(mass, com, I)
    except ValueError as exc:
        raise ValueError(f"{w}.{exc}") from None


def _angle(where: str, j: dict[str, Any], key: str, default: float | None = None) -> float:
    if key in j and f"{key}_deg" in j:
        raise ValueError(f"{where}: give {key} or {key}_deg, not both")
    if f"{key}_deg" in j:
        v = j[f"{key}_deg"]
        _number(f"{where}.{key}_deg", v)
        return math.radians(v)
    if key in j:
        return _number(f"{where}.{key}", j[key])
    if default is None:
        raise ValueError(f"{where}: missing {key} (or {key}_deg)")
    return default


def _limits(where: str, j: dict[str, Any], pair: APair) -> tuple[float, float] | None:
    """A joint's explicit (lo, hi) in radians, or None; checked against the pair's collision-free
    range here, so that the message uses the file's key and units."""
    if "limits" in j and "limits_deg" in j:
        raise ValueError(f"{where}: give limits or limits_deg, not both")
    for key, unit, scale in (("limits", "rad", 1.0), ("limits_deg", "deg", math.pi / 180)):
        if key in j:
            lo, hi = _numbers(f"{where}.{key}", j[key], [(2,)])
            if not lo < hi:
                raise ValueError(f"{where}.{key}: expected lo < hi, got ({lo:g}, {hi:g}) {unit}")
            plo, phi = pair.motion_range()
            if lo * scale < plo or hi * scale > phi:
                raise ValueError(
                    f"{where}.{key}: ({lo:g}, {hi:g}) {unit} goes beyond the pair's collision-free "
                    f"range ({plo / scale:.6g}, {phi / scale:.6g}) {unit}"
                )
            return lo * scale, hi * scale
    return None


def _number(where: str, v: object) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ValueError(f"{where}: expected a number, got {_short(v)}")
    try:
        x = float(v)
    except OverflowError:
        raise ValueError(f"{where}: {_short(v)} is too large for a double") from None
    if not math.isfinite(x):
        raise ValueError(f"{where}: expected a finite number, got {v!r}")
    return x


def _short(v: object, limit: int = 60) -> str:
    """repr(v), cut to `limit` characters (a value in an error message, not a dump)."""
    text = repr(v)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def chain_from_dict(data: dict[str, Any], where: str = "chain") -> AChain:
    """Build an AChain from the parsed TOML document."""
    unknown = set(data) - {"name", "joint", "description", "gravity"}
    if unknown:
        raise ValueError(f"{where}: unknown keys {sorted(unknown)}")
    joints = data.get("joint")
    if not isinstance(joints, list) or not joints:
        raise ValueError(f"{where}: needs at least one [[joint]] table")
    pairs, a, alpha, offset, theta_offset, links, limits = [], [], [], [], [], [], []
    for i, j in enumerate(joints):
        w = f"{where}: joint {i + 1}"
        if not isinstance(j, dict):
            raise ValueError(f"{w}: expected a [[joint]] table, got {_short(j)}")
        kind = j.get("pair")
        if kind not in KINDS:
            raise ValueError(f"{w}.pair: expected one of {KINDS}, got {_short(kind)}")
        allowed = _PAIR_KEYS[kind] | _DH_KEYS | _LINK_KEYS | {"pair"}
        unknown = set(j) - allowed
        if unknown:
            raise ValueError(f"{w}: keys {sorted(unknown)} are not valid for a {kind} pair")
        if kind == "revolute":
            pairs.append(APair.revolute())
        else:
            kw = {k: _number(f"{w}.{k}", j[k]) for k in _PAIR_KEYS[kind] if k in j}
            for req in ("base_radius", "platform_radius") + (("leg_length",) if kind == "general" else ()):
                if req not in kw:
                    raise ValueError(f"{w}: missing {req}")
            try:
                pairs.append(APair(**kw))
            except ValueError as exc:
                raise ValueError(f"{w}.{exc}") from None
        if "a" not in j:
            raise ValueError(f"{w}: missing a")
        a.append(_number(f"{w}.a", j["a"]))
        alpha.append(_angle(w, j, "alpha"))
        offset.append(_number(f"{w}.offset", j.get("offset", 0.0)))
        theta_offset.append(_angle(w, j, "theta_offset", 0.0))
        links.append(_link(w, j))
        limits.append(_limits(w, j, pairs[-1]))
    gravity = _numbers(f"{where}: gravity", data.get("gravity", [0.0, 0.0, -9.81]), [(3,)])
    try:
        return AChain(pairs, a, alpha, offset, theta_offset, links=links, gravity=gravity, limits=limits)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


MAX_FILE_BYTES = 16 * 2**20  # a chain file is a few kB; anything this large is not one


def load(path: str | os.PathLike[str]) -> AChain:
    """Read a chain from a TOML file (UTF-8, a byte-order mark allowed)."""
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"path: expected a file name, got {_short(path)}")
    p = Path(path)
    if not p.exists():
        raise ValueError(f"path: no such file {str(p)!r}")
    if p.is_dir():
        raise ValueError(f"path: {str(p)!r} is a folder, not a chain file")
    if not p.is_file():
        raise ValueError(f"path: {str(p)!r} is not a regular file (a FIFO, socket or device)")
    try:
        if p.stat().st_size > MAX_FILE_BYTES:
            raise ValueError(f"path: {str(p)!r} is larger than {MAX_FILE_BYTES // 2**20} MiB, not a chain file")
        data = tomllib.loads(p.read_text(encoding="utf-8-sig"))
    except UnicodeDecodeError as exc:
        raise ValueError(f"path: {p} is not UTF-8 text: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"path: {p} is not valid TOML: {exc}") from None
    except RecursionError:
        raise ValueError(f"path: {p} is nested too deeply to be a chain file") from None
    except OSError as exc:
        raise ValueError(f"path: cannot read {str(p)!r}: {exc.strerror or exc}") from None
    chain = chain_from_dict(data, where=str(p))
    name = data.get("name", p.stem)
    if not isinstance(name, str):
        raise ValueError(f"{p}: name: expected a string, got {_short(name)}")
    chain.name = name
    return chain
