"""The specification of a design search (a TOML file, paths relative to it), read and checked in
full before any search: every message names the spec's key.

    start = "start.toml"            # the chain file the search starts from
    seed = 3                        # optional, default 0
    budget = 1500                   # candidate designs evaluated at most
    [vary]                          # "joint.K.key" = [low, high], K from 1: a number of the chain file
    "joint.1.base_radius" = [0.03, 0.12]
    "joint.3.pair" = ["sinusoidal", "revolute"]     # or a choice among pair kinds
    [targets]                       # needed by coverage and gravity_torque_max
    points = "targets.csv"          # x,y,z per line [m]; or poses = "poses.csv" (R row by row, p)
    tolerance = 0.002               # [m]; tolerance_deg too for poses
    [objective]
    maximise = "coverage"           # and/or "volume"; minimise = "gravity_torque_max"; lists for several
    [constraints]                   # optional
    min_clearance = 0.005           # [m] between legs and between plates, inside the joint ranges
    leg_length = [0.05, 0.3]        # [m] every leg of every A-pair

A candidate design is a vector x: one entry per [vary] key, the number itself or, for a choice,
a position in [0, kinds) whose integer part picks the kind (`Spec.decode`).
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import hashlib
import json
import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _validate as V
from .._version import __version__
from ..io import _PAIR_KEYS, chain_from_dict, load
from ..pair import KINDS
from .targets import Targets, read_targets

FORMAT = 1  # of the checkpoint's fingerprint: a change in how candidates are evaluated bumps it
MAX_BUDGET = 1_000_000
MAX_SPEC_BYTES = 1 * 2**20
TOP_KEYS = ("start", "seed", "budget", "vary", "targets", "objective", "constraints")
# the numbers of a joint table that a search may vary, with their unit
NUMERIC_KEYS = {
    "base_radius": "m",
    "platform_radius": "m",
    "leg_length": "m",
    "leg_mass": "kg",
    "leg_radius": "m",
    "thickness": "m",
    "a": "m",
    "alpha": "rad",
    "alpha_deg": "deg",
    "offset": "m",
    "theta_offset": "rad",
    "theta_offset_deg": "deg",
    "mass": "kg",
}
SIBLING = {"alpha": "alpha_deg", "alpha_deg": "alpha", "theta_offset": "theta_offset_deg"}
SIBLING |= {"theta_offset_deg": "theta_offset"}
DEFAULTS = {"offset": 0.0, "theta_offset": 0.0, "theta_offset_deg": 0.0, "leg_mass": 0.0, "leg_radius": 0.0}
DEFAULTS |= {"thickness": 0.0, "mass": 0.0}
PAIR_KEYS = set().union(*_PAIR_KEYS.values())
REQUIRED = {
    "sinusoidal": ("base_radius", "platform_radius"),
    "general": ("base_radius", "platform_radius", "leg_length"),
}
OBJECTIVES = {"coverage": "maximise", "volume": "maximise", "gravity_torque_max": "minimise"}
NEEDS_TARGETS = ("coverage", "gravity_torque_max")
_NAME = re.compile(r"joint\.(\d+)\.(\w+)")


@dataclass(frozen=True)
class Variable:
    """One [vary] entry: joint (from 0) and key; [low, high] for a number, or `kinds` for a
    choice of pair; `start`: the start design's position."""

    name: str
    joint: int
    key: str
    low: float
    high: float
    start: float
    kinds: tuple[str, ...] = ()

    def value(self, x: float) -> float | str:
        """The chain file's value at position x: the number, or the kind chosen."""
        if self.kinds:
            return self.kinds[min(max(int(math.floor(x)), 0), len(self.kinds) - 1)]
        return float(x)


@dataclass(frozen=True)
class Objective:
    name: str
    sense: str  # "maximise" or "minimise"


@dataclass(frozen=True)
class Constraints:
    """min_clearance [m] kept between legs and between plates inside the joint ranges (0: none),
    leg_length (low, high) [m] of every leg of every A-pair (None: any)."""

    min_clearance: float = 0.0
    leg_length: tuple[float, float] | None = None


@dataclass(frozen=True, eq=False)
class Spec:
    """A checked design search (see the module docstring); `where` names it in messages."""

    where: str
    start_name: str
    start: dict[str, Any]
    seed: int
    budget: int
    variables: tuple[Variable, ...]
    objectives: tuple[Objective, ...]
    targets: Targets | None = None
    constraints: Constraints = field(default_factory=Constraints)

    @property
    def bounds(self) -> list[tuple[float, float]]:
        return [(v.low, v.high) for v in self.variables]

    @property
    def x0(self) -> NDArray[np.float64]:
        """The start design's position."""
        return np.array([v.start for v in self.variables])

    def values(self, x: NDArray[np.float64]) -> dict[str, float | str]:
        """{vary key: the chain file's value} of candidate x."""
        return {v.name: v.value(float(xi)) for v, xi in zip(self.variables, x)}

    def decode(self, x: NDArray[np.float64]) -> dict[str, Any]:
        """The chain file's document of candidate x: the start's, the pair kinds chosen first (a
        joint keeps only the keys its kind takes), then the numbers put in (an angle replaces its
        other unit)."""
        data = copy.deepcopy(self.start)
        joints = data["joint"]
        for v, xi in zip(self.variables, x):
            if v.kinds:
                _set_kind(joints[v.joint], str(v.value(float(xi))))
        for v, xi in zip(self.variables, x):
            j = joints[v.joint]
            if not v.kinds and _applies(v.key, j["pair"]):
                j.pop(SIBLING.get(v.key, ""), None)
                j[v.key] = float(xi)
        return data

    def fingerprint(self) -> str:
        """SHA-256 of everything that decides the search's candidates and their evaluation: a
        checkpoint is resumed only by the spec that wrote it."""
        doc = {
            "format": FORMAT,
            "apair": __version__,
            "start": self.start,
            "seed": self.seed,
            "budget": self.budget,
            "variables": [dataclasses.asdict(v) for v in self.variables],
            "objectives": [dataclasses.asdict(o) for o in self.objectives],
            "targets": None if self.targets is None else self.targets.digest(),
            "constraints": dataclasses.asdict(self.constraints),
        }
        text = json.dumps(doc, sort_keys=True, default=repr, allow_nan=True)
        return hashlib.sha256(text.encode()).hexdigest()


def _applies(key: str, kind: str) -> bool:
    """Whether a joint of this pair kind has the key."""
    return key not in PAIR_KEYS or key in _PAIR_KEYS[kind]


def _set_kind(joint: dict[str, Any], kind: str) -> None:
    joint["pair"] = kind
    for k in [k for k in joint if k in PAIR_KEYS and k not in _PAIR_KEYS[kind]]:
        del joint[k]


# ------------------------------------------------------------------------------------------- reading
def load_spec(spec: object) -> Spec:
    """A Spec from a spec file's name (paths in it relative to its folder), a mapping of its
    contents (paths relative to the working folder) or a Spec (returned as it is)."""
    if isinstance(spec, Spec):
        return spec
    if isinstance(spec, Mapping):
        return _from_dict(dict(spec), "spec", Path.cwd())
    if not isinstance(spec, (str, os.PathLike)):
        raise ValueError(f"spec: expected a spec file's name, a mapping or a Spec, got {V.shorten(repr(spec))}")
    p = Path(spec)
    if not p.is_file():
        raise ValueError(f"spec: {str(p)!r} {'is a folder' if p.is_dir() else 'does not exist'}")
    where = V.replace_refused(str(p))
    if p.stat().st_size > MAX_SPEC_BYTES:
        raise ValueError(f"{where}: larger than {MAX_SPEC_BYTES // 2**20} MiB, not a spec file")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8-sig"))
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{where}: not valid TOML: {V.shorten(str(exc), 200)}") from None
    return _from_dict(data, where, p.parent)


def _check_keys(where: str, data: Mapping[str, Any], valid: tuple[str, ...]) -> None:
    for key in data:
        if key not in valid:
            near = difflib.get_close_matches(key, valid, n=1)
            hint = f"; did you mean {near[0]}?" if near else f" (expected {', '.join(valid)})"
            raise ValueError(f"{where}: unknown key {V.shorten(repr(key))}{hint}")


def _from_dict(data: dict[str, Any], where: str, base: Path) -> Spec:
    _check_keys(where, data, TOP_KEYS)
    for key in ("start", "budget", "vary", "objective"):
        if key not in data:
            raise ValueError(f"{where}: missing {key}")
    start_name, start = _start(where, data["start"], base)
    seed = V.seed(data.get("seed", 0), f"{where}: seed")
    budget = V.integer(f"{where}: budget", data["budget"], maximum=MAX_BUDGET)
    objectives = _objectives(f"{where}: objective", data["objective"])
    targets = None
    if "targets" in data:
        targets = read_targets(f"{where}: targets", data["targets"], base)
    needs = [o.name for o in objectives if o.name in NEEDS_TARGETS]
    if targets is None and needs:
        raise ValueError(f'{where}: targets: missing; the objective {needs[0]} needs targets (points = "file.csv")')
    constraints = _constraints(f"{where}: constraints", data.get("constraints", {}))
    variables = _variables(f"{where}: vary", data["vary"], start)
    spec = Spec(where, start_name, start, seed, budget, variables, objectives, targets, constraints)
    _check_feasible(spec)
    return spec


def _start(where: str, name: object, base: Path) -> tuple[str, dict[str, Any]]:
    """The start chain file: loaded (its own checks, named by the file) and its TOML document."""
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"{where}: start: expected a chain file's name, got {V.shorten(repr(name))}")
    path = base / name
    if not path.is_file():
        raise ValueError(f"{where}: start: {name!r} does not exist (relative to {str(base)!r})")
    load(path)  # every check of a chain file, its messages naming the file
    return name, tomllib.loads(path.read_text(encoding="utf-8-sig"))


def _objectives(where: str, table: object) -> tuple[Objective, ...]:
    if not isinstance(table, dict):
        raise ValueError(f"{where}: expected a table (maximise = ..., minimise = ...)")
    _check_keys(where, table, ("maximise", "minimise"))
    out: list[Objective] = []
    for sense in ("maximise", "minimise"):
        names = table.get(sense, [])
        names = [names] if isinstance(names, str) else names
        if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
            raise ValueError(f"{where}.{sense}: expected an objective's name or a list of them")
        for name in names:
            if name not in OBJECTIVES:
                near = difflib.get_close_matches(name, list(OBJECTIVES), n=1)
                hint = f"; did you mean {near[0]}?" if near else f" (expected one of {', '.join(OBJECTIVES)})"
                raise ValueError(f"{where}.{sense}: unknown objective {V.shorten(repr(name))}{hint}")
            if OBJECTIVES[name] != sense:
                raise ValueError(f"{where}.{sense}: {name} is to be {OBJECTIVES[name][:-1]}ed, not {sense[:-1]}ed")
            if any(o.name == name for o in out):
                raise ValueError(f"{where}.{sense}: {name} is named twice")
            out.append(Objective(name, sense))
    if not out:
        raise ValueError(f'{where}: no objective (e.g. maximise = "coverage")')
    return tuple(out)


def _constraints(where: str, table: object) -> Constraints:
    if not isinstance(table, dict):
        raise ValueError(f"{where}: expected a table, got {V.shorten(repr(table))}")
    _check_keys(where, table, ("min_clearance", "leg_length"))
    clearance = 0.0
    if "min_clearance" in table:
        clearance = V.scalar(f"{where}.min_clearance", _plain(table["min_clearance"]), nonnegative=True)
        V.in_range(f"{where}.min_clearance", clearance, "m")
    legs = None
    if "leg_length" in table:
        lo, hi = _range(f"{where}.leg_length", table["leg_length"])
        if not lo > 0:
            raise ValueError(f"{where}.leg_length: the lower end must be > 0, got {lo:g}")
        legs = (lo, hi)
    return Constraints(clearance, legs)


def _plain(v: object) -> object:
    """v, or a string in place of a bool (which V's checks would read as 0 or 1)."""
    return repr(v) if isinstance(v, bool) else v


def _range(where: str, v: object) -> tuple[float, float]:
    """[low, high]: two finite numbers, low < high."""
    if not isinstance(v, list) or len(v) != 2 or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in v):
        raise ValueError(f"{where}: expected [low, high], two numbers, got {V.shorten(repr(v))}")
    lo, hi = (float(x) for x in v)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"{where}: expected finite numbers, got {V.shorten(repr(v))}")
    if not lo < hi:
        raise ValueError(
            f"{where}: expected low < high, got [{lo:g}, {hi:g}] (a fixed value belongs in the start file)"
        )
    return lo, hi


def _variables(where: str, table: object, start: dict[str, Any]) -> tuple[Variable, ...]:
    if not isinstance(table, dict) or not table:
        raise ValueError(f'{where}: expected a table of "joint.K.key" = [low, high], at least one')
    joints = start["joint"]
    out = [_variable(where, name, v, joints) for name, v in table.items()]
    seen: dict[tuple[int, str], str] = {}
    for v in out:
        for key in (v.key, SIBLING.get(v.key, "")):
            if (v.joint, key) in seen:
                raise ValueError(f'{where}: "{v.name}" and "{seen[(v.joint, key)]}" vary the same value')
        seen[(v.joint, v.key)] = v.name
    for v in out:
        _check_applies(where, v, out, joints[v.joint])
    return tuple(out)


def _variable(where: str, name: str, value: object, joints: list[dict[str, Any]]) -> Variable:
    w = f'{where}."{V.shorten(name, 60)}"'
    m = _NAME.fullmatch(name)
    if m is None:
        raise ValueError(f'{w}: expected a key "joint.K.key" (K from 1, e.g. "joint.1.base_radius")')
    k, key = int(m[1]), m[2]
    if not 1 <= k <= len(joints):
        raise ValueError(f"{w}: the start chain has joints 1 to {len(joints)}, not {k}")
    joint = joints[k - 1]
    if key == "pair":
        if not isinstance(value, list) or len(value) < 2 or not all(isinstance(x, str) for x in value):
            raise ValueError(f"{w}: expected a list of two or more pair kinds (of {', '.join(KINDS)})")
        for kind in value:
            if kind not in KINDS:
                raise ValueError(f"{w}: {V.shorten(repr(kind))} is not a pair kind (expected {', '.join(KINDS)})")
        if len(set(value)) != len(value):
            raise ValueError(f"{w}: a kind is named twice")
        if joint["pair"] not in value:
            raise ValueError(f"{w}: the start's {joint['pair']} pair is not among the choices")
        return Variable(name, k - 1, key, 0.0, float(len(value)), value.index(joint["pair"]) + 0.5, tuple(value))
    if key not in NUMERIC_KEYS:
        near = difflib.get_close_matches(key, list(NUMERIC_KEYS) + ["pair"], n=1)
        hint = f"; did you mean {near[0]}?" if near else ""
        raise ValueError(f"{w}: {key} cannot be varied (the numbers {', '.join(NUMERIC_KEYS)} or pair can){hint}")
    lo, hi = _range(w, value)
    if NUMERIC_KEYS[key] == "rad" and max(abs(lo), abs(hi)) > 2 * math.pi:
        raise ValueError(f'{w}: [{lo:g}, {hi:g}] is more than a turn in radians; did you mean "joint.{k}.{key}_deg"?')
    return Variable(name, k - 1, key, lo, hi, _start_value(w, joint, key, lo, hi))


def _start_value(where: str, joint: dict[str, Any], key: str, lo: float, hi: float) -> float:
    """The start design's value of a varied number (converted from its other unit, or the
    default), refused outside [lo, hi]; the middle for a key that its pair kind does not have."""
    if not _applies(key, joint["pair"]):
        return 0.5 * (lo + hi)
    other = SIBLING.get(key)
    if key in joint:
        x, said = float(joint[key]), ""
    elif other in joint:
        x = float(math.radians(joint[other]) if key in ("alpha", "theta_offset") else math.degrees(joint[other]))
        said = f" (its {other} = {joint[other]!r})"
    elif key in DEFAULTS:
        x, said = DEFAULTS[key], " (the default)"
    else:
        return 0.5 * (lo + hi)
    if not lo <= x <= hi:
        raise ValueError(f"{where}: the start design's value {x:.6g}{said} lies outside [{lo:g}, {hi:g}]")
    return x


def _check_applies(where: str, v: Variable, every: list[Variable], joint: dict[str, Any]) -> None:
    """A pair's key varied on a joint whose possible kinds have it; every kind that a choice
    may pick has its required keys (from the start or varied)."""
    choice = next((c for c in every if c.kinds and c.joint == v.joint), None)
    kinds = choice.kinds if choice else (joint["pair"],)
    varied = {c.key for c in every if c.joint == v.joint}
    name = f'{where}."{v.name}"'
    if not v.kinds and not any(_applies(v.key, kind) for kind in kinds):
        owners = [k for k in KINDS if _applies(v.key, k)]
        raise ValueError(
            f"{name}: joint {v.joint + 1} is a {' or '.join(kinds)} pair, which has no {v.key} (a {' or '.join(owners)} pair has)"
        )
    if v.kinds:
        for kind in v.kinds:
            for key in REQUIRED.get(kind, ()):
                given = key in varied or (key in joint and _applies(key, joint["pair"]))
                if not given:
                    raise ValueError(f'{name}: a {kind} pair needs {key}: vary "joint.{v.joint + 1}.{key}" too')


def _check_feasible(spec: Spec) -> None:
    """The start design and every varied value's ends (the others at the start's) give valid
    chains, and so does every kind of a choice: bounds that make the chain invalid are said here,
    before any search."""
    x0 = spec.x0
    for i, v in enumerate(spec.variables):
        x = _reference(spec, x0, v)
        points = [(float(k) + 0.5, f"a {kind} pair") for k, kind in enumerate(v.kinds)] or [
            (v.low, f"{v.low:g} (its low end)"),
            (v.high, f"{v.high:g} (its high end)"),
        ]
        for value, said in points:
            x[i] = value
            try:
                chain_from_dict(spec.decode(x), "chain")
            except ValueError as exc:
                why = str(exc).removeprefix("chain: ")
                raise ValueError(f'{spec.where}: vary."{v.name}": {said} gives an invalid chain: {why}') from None


def _reference(spec: Spec, x0: NDArray[np.float64], v: Variable) -> NDArray[np.float64]:
    """x0, with the joint's kind (if chosen) one that has v's key."""
    x = x0.copy()
    for i, c in enumerate(spec.variables):
        if c.kinds and c.joint == v.joint and not v.kinds and not _applies(v.key, str(c.value(x[i]))):
            x[i] = next(k for k, kind in enumerate(c.kinds) if _applies(v.key, kind)) + 0.5
    return x
