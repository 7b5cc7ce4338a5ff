"""Chains from TOML files (the format is documented in README.md, "Chain files").

name = "a 2A-chain"            # optional; description = "..." optional (may span lines)
[[joint]]                      # one table per joint, base to tip
pair = "sinusoidal"            # "sinusoidal" | "general" | "revolute" | "helical" | "prismatic"
base_radius = 0.05             # A-pairs: triangle circumradii [m]
platform_radius = 0.05
leg_length = 0.08              # "general" only: L1 [m]
leg_mass = 0.0                 # optional [kg]; leg_radius = 0.0, thickness = 0.0 optional [m]
limits = [-1.0, 1.0]           # optional joint range [rad] (or limits_deg); default: the
                               # pair's collision limits (a full turn for an R-pair); a
                               # "prismatic" pair's range [m], required (its joint variable is
                               # the slide d; its angle is theta_offset)
pitch = 0.002                  # "helical" only: d = pitch * theta [m/rad]
a = 0.3                        # DH link length [m]
alpha = 1.5707963267948966     # DH twist [rad], or alpha_deg = 90
offset = 0.0                   # c_i [m] (optional)
theta_offset = 0.0             # phi_i [rad] (optional), or theta_offset_deg
mass = 1.0                     # link i (optional): mass [kg], centre of mass in frame i [m],
com = [0.0, 0.0, 0.05]         # inertia about the centre of mass in frame i [kg m^2]:
inertia = [0.01, 0.01, 0.02]   # principal (Ixx, Iyy, Izz), six values (Ixx, Iyy, Izz, Ixy,
                               # Ixz, Iyz) or a 3x3 table
gravity = [0, 0, -9.81]        # top level, optional [m/s^2], in the world frame
[base]                         # optional: frame 0 in the world; [tool] likewise: the tool in frame n
xyz = [0.0, 0.0, 0.5]          # translation [m] (optional, default zeros)
rpy = [0.0, 0.0, 1.57]         # URDF roll-pitch-yaw [rad], R = Rz(yaw)·Ry(pitch)·Rx(roll)
                               # (optional, default zeros), or rpy_deg = [0, 0, 90]
"""

from __future__ import annotations

import difflib
import math
import os
import re
import reprlib
import tomllib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _validate as V
from .chain import MAX_JOINTS, AChain
from .collisions import check_design
from .frames import frame
from .link import Link
from .pair import KINDS, APair

_PAIR_KEYS = {
    "sinusoidal": {"base_radius", "platform_radius", "leg_mass", "leg_radius", "thickness"},
    "general": {"base_radius", "platform_radius", "leg_length", "leg_mass", "leg_radius", "thickness"},
    "revolute": set(),
    "helical": {"pitch"},
    "prismatic": set(),
}
_DH_KEYS = {"a", "alpha", "alpha_deg", "offset", "theta_offset", "theta_offset_deg", "limits", "limits_deg"}
_LINK_KEYS = {"mass", "com", "inertia"}
_JOINT_KEYS = set().union(*_PAIR_KEYS.values()) | _DH_KEYS | _LINK_KEYS | {"pair"}
_TOP_KEYS = {"name", "description", "gravity", "joint", "base", "tool"}
_FRAME_KEYS = {"xyz", "rpy", "rpy_deg"}
TURN = 2 * math.pi  # an angle in radians beyond ±TURN is surely one in degrees


def _key(k: str) -> str:
    """A key as a message prints it: plainly if it is a short run of printable characters, else
    its repr (shortened)."""
    plain = k.isprintable() and 0 < len(k) <= 40 and not any(c.isspace() for c in k)
    return k if plain else _short(k)


def _elsewhere(key: str, kind: str | None) -> str | None:
    """Where a key that is not valid here (a joint of `kind`, or the top of the file for None)
    belongs, as a message says it; None for a key valid nowhere."""
    if kind is None:
        return "belongs in a [[joint]] table" if key in _JOINT_KEYS else None
    if key in _TOP_KEYS:
        return "belongs at the top of the file, not in a [[joint]] table"
    kinds = [k for k in KINDS if key in _PAIR_KEYS[k]]
    return f"is not a key of a {kind} pair (only of a {' or '.join(kinds)} pair)" if kinds else None


def _guessed(keys: Sequence[str], valid: set[str]) -> str:
    """The words for keys valid nowhere: `unknown key k; did you mean g?` (or `unknown keys k1
    (did you mean g?), k2`), g the nearest valid key where one is near."""
    guesses = [(_key(k), difflib.get_close_matches(k, sorted(valid), n=1)) for k in keys]
    if len(guesses) == 1:
        k, near = guesses[0]
        return f"unknown key {k}" + (f"; did you mean {near[0]}?" if near else "")
    return "unknown keys " + ", ".join(k + (f" (did you mean {near[0]}?)" if near else "") for k, near in guesses)


def _check_keys(where: str, keys: Sequence[str], valid: set[str], kind: str | None = None) -> None:
    """Refuses the keys not in `valid`, each with the place it belongs to (`_elsewhere`) or the
    nearest valid key as a hint (`_guessed`); at most three are named."""
    unknown = sorted(set(keys) - valid)
    if not unknown:
        return
    named = unknown[:3]
    placed = [(k, _elsewhere(k, kind)) for k in named]
    said = [f"{_key(k)} {place}" for k, place in placed if place is not None]
    guess = [k for k, place in placed if place is None]
    if guess:
        said.append(_guessed(guess, valid))
    more = f" (and {len(unknown) - 3} more)" if len(unknown) > 3 else ""
    raise ValueError(f"{where}: {'; '.join(said)}{more}")


def _toml_value(v: object) -> str:
    """A number or list of numbers as TOML writes it (for a hint)."""
    if isinstance(v, list):
        return "[" + ", ".join(map(_toml_value, v)) + "]"
    return _short(v)


def _check_turn(where: str, key: str, raw: object, values: NDArray[np.float64]) -> None:
    """Refuses an angle in radians beyond a turn: surely degrees given under the radians key."""
    if np.any(np.abs(values) > TURN):
        shown = _toml_value(raw)
        raise ValueError(
            f"{where}.{key}: {shown} is more than a turn (2 pi) in radians; did you mean {key}_deg = {shown}?"
        )


def _fits(v: object, shape: tuple[int, ...]) -> bool:
    """Whether v is nested lists of exactly this shape; looks at no more entries than the shape
    has, so a list of a million entries costs no more than a short one."""
    if not shape:
        return not isinstance(v, (list, tuple))
    return isinstance(v, (list, tuple)) and len(v) == shape[0] and all(_fits(x, shape[1:]) for x in v)


def _numbers(where: str, v: object, shapes: Sequence[tuple[int, ...]]) -> NDArray[np.float64]:
    if not any(_fits(v, shape) for shape in shapes):  # sizes first: nothing is converted before
        size = f" of {len(v)} entries" if isinstance(v, (list, tuple)) else ""
        raise ValueError(f"{where}: expected numbers of shape {' or '.join(map(str, shapes))}, got {_short(v)}{size}")
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
        x = _number(f"{where}.{key}", j[key])
        _check_turn(where, key, j[key], np.array(x))
        return x
    if default is None:
        raise ValueError(f"{where}: missing {key} (or {key}_deg)")
    return default


def _limits(where: str, j: dict[str, Any], pair: APair) -> tuple[float, float] | None:
    """A joint's explicit (lo, hi) in radians (metres for a P-pair), or None; checked against the
    pair's collision-free range here, so that the message uses the file's key and units."""
    if "limits" in j and "limits_deg" in j:
        raise ValueError(f"{where}: give limits or limits_deg, not both")
    if pair.kind == "prismatic":
        if "limits_deg" in j:
            raise ValueError(f"{where}.limits_deg: a prismatic joint's range is in metres: give limits")
        if "limits" not in j:
            raise ValueError(f"{where}: missing limits (a prismatic joint's range [lo, hi] in metres)")
        lo, hi = _numbers(f"{where}.limits", j["limits"], [(2,)])
        V.in_range(f"{where}.limits", np.array([lo, hi]), "m")
        if not lo < hi:
            raise ValueError(f"{where}.limits: expected lo < hi, got ({lo:g}, {hi:g}) m")
        return lo, hi
    for key, unit, scale in (("limits", "rad", 1.0), ("limits_deg", "deg", math.pi / 180)):
        if key in j:
            lo, hi = values = _numbers(f"{where}.{key}", j[key], [(2,)])
            if key == "limits":
                _check_turn(where, key, j[key], values)
            if not lo < hi:
                raise ValueError(f"{where}.{key}: expected lo < hi, got ({lo:g}, {hi:g}) {unit}")
            try:
                plo, phi = pair.motion_range()
            except ValueError as exc:
                raise ValueError(f"{where}.{exc}") from None
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


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxtuple, _REPR.maxdict, _REPR.maxstring, _REPR.maxother = 3, 6, 6, 4, 40, 40


def _short(v: object, limit: int = 60) -> str:
    """repr(v), cut to `limit` characters (a value in an error message, not a dump); reprlib's, so
    that a list of a million entries costs no more than a short one."""
    text = _REPR.repr(v)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _pair(w: str, j: dict[str, Any], kind: str) -> APair:
    """Joint j's pair, with the design checks that later commands would otherwise fail on
    (legs or plates that overlap: `check_design`), named by the file's keys."""
    if kind == "revolute":
        return APair.revolute()
    if kind == "prismatic":
        return APair.prismatic()
    if kind == "helical":
        if "pitch" not in j:
            raise ValueError(f"{w}: missing pitch (d = pitch * theta, m/rad)")
        try:
            return APair.helical(_number(f"{w}.pitch", j["pitch"]))
        except ValueError as exc:
            raise ValueError(f"{w}.{exc}") from None
    kw = {k: _number(f"{w}.{k}", j[k]) for k in _PAIR_KEYS[kind] if k in j}
    for req in ("base_radius", "platform_radius") + (("leg_length",) if kind == "general" else ()):
        if req not in kw:
            raise ValueError(f"{w}: missing {req}")
    try:
        pair = APair(**kw)
        check_design(pair)
    except ValueError as exc:
        raise ValueError(f"{w}.{exc}") from None
    return pair


def _joint(w: str, j: object) -> tuple[APair, float, float, float, float, Link]:
    """(pair, a, alpha, offset, theta_offset, link) of one [[joint]] table."""
    if not isinstance(j, dict):
        raise ValueError(f"{w}: expected a [[joint]] table, got {_short(j)}")
    kind = j.get("pair")
    if kind not in KINDS:
        near = difflib.get_close_matches(kind, KINDS, n=1) if isinstance(kind, str) else []
        hint = f"; did you mean {near[0]}?" if near else ""
        raise ValueError(f"{w}.pair: expected one of {KINDS}, got {_short(kind)}{hint}")
    _check_keys(w, list(j), _PAIR_KEYS[kind] | _DH_KEYS | _LINK_KEYS | {"pair"}, kind)
    pair = _pair(w, j, kind)
    if "a" not in j:
        raise ValueError(f"{w}: missing a")
    a, offset = _number(f"{w}.a", j["a"]), _number(f"{w}.offset", j.get("offset", 0.0))
    V.in_range(f"{w}.a", np.array(a), "m")  # AChain checks them too, but names a[i], not the key
    V.in_range(f"{w}.offset", np.array(offset), "m")
    return pair, a, _angle(w, j, "alpha"), offset, _angle(w, j, "theta_offset", 0.0), _link(w, j)


def _frame(where: str, table: str, data: dict[str, Any]) -> NDArray[np.float64] | None:
    """The transform of the [base] or [tool] table (`table`), None without one: xyz [m] and rpy
    [rad] or rpy_deg, both optional (zeros)."""
    if table not in data:
        return None
    w = f"{where}: {table}"
    t = data[table]
    if not isinstance(t, dict):
        raise ValueError(f"{w}: expected a [{table}] table (xyz, rpy or rpy_deg), got {_short(t)}")
    unknown = sorted(set(t) - _FRAME_KEYS)
    if unknown:
        more = f" (and {len(unknown) - 3} more)" if len(unknown) > 3 else ""
        raise ValueError(f"{w}: {_guessed(unknown[:3], _FRAME_KEYS)}{more}")
    if "rpy" in t and "rpy_deg" in t:
        raise ValueError(f"{w}: give rpy or rpy_deg, not both")
    xyz = _numbers(f"{w}.xyz", t.get("xyz", [0.0, 0.0, 0.0]), [(3,)])
    V.in_range(f"{w}.xyz", xyz, "m")
    if "rpy_deg" in t:
        rpy = np.radians(_numbers(f"{w}.rpy_deg", t["rpy_deg"], [(3,)]))
    else:
        rpy = _numbers(f"{w}.rpy", t.get("rpy", [0.0, 0.0, 0.0]), [(3,)])
        _check_turn(w, "rpy", t.get("rpy"), rpy)
    return frame(xyz, rpy)


def chain_from_dict(data: dict[str, Any], where: str = "chain") -> AChain:
    """Build an AChain from the parsed TOML document (named by its `name` if it has one). Keys
    and text fields are checked first, then sizes (the number of joints, every list's shape),
    before any work on the contents, and the joints' ranges last (they need the pairs' collision
    limits, the slow part). `where` begins every message (the file's name)."""
    _check_keys(where, list(data), _TOP_KEYS)
    name = data.get("name")
    if name is not None:
        V.text(f"{where}: name", name)
    if "description" in data:
        V.text(f"{where}: description", data["description"], multiline=True)
    joints = data.get("joint")
    if not isinstance(joints, list) or not joints:
        raise ValueError(f"{where}: needs at least one [[joint]] table")
    if len(joints) > MAX_JOINTS:
        raise ValueError(f"{where}: pairs: a chain has 1 to {MAX_JOINTS} pairs, got {len(joints)} [[joint]] tables")
    gravity = _numbers(f"{where}: gravity", data.get("gravity", [0.0, 0.0, -9.81]), [(3,)])
    V.in_range(f"{where}: gravity", gravity, "m/s^2")
    base, tool = _frame(where, "base", data), _frame(where, "tool", data)
    names = [f"{where}: joint {i + 1}" for i in range(len(joints))]
    pairs, a, alpha, offset, theta_offset, links = zip(*(_joint(w, j) for w, j in zip(names, joints)))
    limits = [_limits(w, j, pair) for w, j, pair in zip(names, joints, pairs)]
    try:
        chain = AChain(
            pairs, a, alpha, offset, theta_offset, links=links, gravity=gravity, limits=limits, base=base, tool=tool
        )
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    if name is not None:
        chain.name = name
    return chain


MAX_FILE_BYTES = 16 * 2**20  # a chain file is a few kB; anything this large is not one


def _toml_reason(exc: tomllib.TOMLDecodeError) -> str:
    """tomllib's message with its place as "(line L, column C)" or "(at the end of the file)"."""
    msg = str(exc)
    at = re.fullmatch(r"(.*) \(at line (\d+), column (\d+)\)", msg, re.DOTALL)
    if at:
        return f"{at[1]} (line {at[2]}, column {at[3]})"
    return re.sub(r" \(at end of document\)$", " (at the end of the file)", msg)


def _parse(text: str, where: str) -> dict[str, Any]:
    """The TOML document of a chain file's text; `where` names the file in messages."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{where}: not valid TOML: {V.shorten(_toml_reason(exc), 200)}") from None
    except RecursionError:
        raise ValueError(f"{where}: nested too deeply to be a chain file") from None


def _printed(path: Path) -> str:
    """A file's name as messages print it: plainly, or as its repr if it holds a character that
    a text field refuses (a newline would break the one-line message)."""
    text = str(path)
    return text if V.replace_refused(text) == text else V.shorten(repr(text), 120)


def loads(text: str, where: str = "chain") -> AChain:
    """Read a chain from the text of a chain file; `where` begins every message (a file name).
    The chain is named by the text's `name`, and has no name without one."""
    V.text("where", where)
    if not isinstance(text, str):
        raise ValueError(f"text: expected the text of a chain file (a str), got {type(text).__name__}")
    if len(text) > MAX_FILE_BYTES:
        raise ValueError(f"text: longer than {MAX_FILE_BYTES // 2**20} MiB, not a chain file")
    return chain_from_dict(_parse(text, where), where)


def load(path: str | os.PathLike[str]) -> AChain:
    """Read a chain from a TOML file (UTF-8, a byte-order mark allowed). The chain is named by
    the file's `name`, or else by the file's name without its suffix (characters a name cannot
    hold replaced by U+FFFD)."""
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"path: expected a file name, got {_short(path)}")
    p = Path(path)
    if not p.exists():
        raise ValueError(f"path: no such file {str(p)!r}")
    if p.is_dir():
        raise ValueError(f"path: {str(p)!r} is a folder, not a chain file")
    if not p.is_file():
        raise ValueError(f"path: {str(p)!r} is not a regular file (a FIFO, socket or device)")
    where = _printed(p)
    try:
        if p.stat().st_size > MAX_FILE_BYTES:
            raise ValueError(f"path: {str(p)!r} is larger than {MAX_FILE_BYTES // 2**20} MiB, not a chain file")
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except OSError as exc:
        raise ValueError(f"path: cannot read {str(p)!r}: {exc.strerror or exc}") from None
    data = _parse(text, where)
    chain = chain_from_dict(data, where)
    if "name" not in data:
        chain.name = V.replace_refused(p.stem)
    return chain
