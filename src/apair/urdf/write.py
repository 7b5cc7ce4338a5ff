"""The chain file of a converted URDF (docs/reference/chain-files.md), every value commented with
where it came from, and the same tables as a dict for `apair.io.chain_from_dict`."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..io import TURN
from ..pair import KINDS
from .dh import Converted, ConvertedJoint
from .parse import Matrix, matrix_rpy

# the keys an A-pair replacing a joint (`pairs`, `--apair`) may set: its kind's keys and the range
PAIR_KEYS = {
    "sinusoidal": ("base_radius", "platform_radius", "leg_mass", "leg_radius", "thickness"),
    "general": ("base_radius", "platform_radius", "leg_length", "leg_mass", "leg_radius", "thickness"),
    "revolute": (),
    "helical": ("pitch",),
    "prismatic": (),
}
RANGE_KEYS = ("limits", "limits_deg")
_NORMAL = {
    "skew": "x along the common normal of axes {i} and {j}, from axis {i} to axis {j}",
    "intersecting": "axes {i} and {j} intersect: a = 0, x = z{i1} x z{i} normalised",
    "parallel": "axes {i} and {j} are parallel: the common normal through frame {i1}'s origin (offset 0)",
    "coincident": "axes {i} and {j} are one line: a = 0, offset 0, x as frame {i1}'s",
    "last": "frame {i}: z on axis {i}, origin nearest the tip link's origin, x after the tip link's",
}


def _num(x: float) -> str:
    x = float(x)
    return "0.0" if x == 0 else repr(x)


def _vec(v: Any) -> str:
    return "[" + ", ".join(_num(x) for x in np.asarray(v, float).ravel()) + "]"


def _limits(joint: ConvertedJoint) -> dict[str, list[float]]:
    if joint.limits is None:
        return {}
    lo, hi = joint.limits
    if joint.type == "prismatic":  # metres
        return {"limits": [lo, hi]}
    if max(abs(lo), abs(hi)) > TURN:  # beyond a turn: the radians key would be refused as degrees
        return {"limits_deg": [math.degrees(lo), math.degrees(hi)]}
    return {"limits": [lo, hi]}


def check_pairs(conv: Converted, pairs: Mapping[int, Mapping[str, Any]] | None) -> dict[int, dict[str, Any]]:
    """`pairs` (joint number from 1 → {"pair": kind, key: value, ...}) checked for shape: joints
    that exist, a kind, and only that kind's keys and a range."""
    if pairs is None:
        return {}
    if not isinstance(pairs, Mapping):
        raise ValueError(f"pairs: expected a mapping of joint number to pair table, got {type(pairs).__name__}")
    out: dict[int, dict[str, Any]] = {}
    for k, spec in pairs.items():
        if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k <= conv.n:
            raise ValueError(f"pairs: joint {k!r} is not a joint of the chain (1 to {conv.n})")
        w = f"pairs[{k}]"
        if not isinstance(spec, Mapping):
            raise ValueError(f"{w}: expected a table {{'pair': kind, ...}}, got {type(spec).__name__}")
        kind = spec.get("pair")
        if kind not in KINDS:
            raise ValueError(f"{w}: pair: expected one of {', '.join(KINDS)}, got {kind!r}")
        allowed = set(PAIR_KEYS[kind]) | set(RANGE_KEYS) | {"pair"}
        extra = sorted(set(spec) - allowed)
        if extra:
            raise ValueError(
                f"{w}: {extra[0]!r} is not a key of a {kind} pair (its keys: {', '.join(PAIR_KEYS[kind]) or 'none'}; "
                "and limits or limits_deg)"
            )
        out[k] = dict(spec)
    return out


def joint_tables(conv: Converted, pairs: Mapping[int, Mapping[str, Any]] | None = None) -> list[dict[str, Any]]:
    """The [[joint]] tables of the chain, each joint an R-pair unless `pairs` replaces it (its
    range then the one given, else the URDF's)."""
    chosen = check_pairs(conv, pairs)
    tables = []
    for i, joint in enumerate(conv.joints, start=1):
        t: dict[str, Any] = {"pair": "prismatic" if joint.type == "prismatic" else "revolute"}
        spec = chosen.get(i, {})
        t.update({k: v for k, v in spec.items() if k not in RANGE_KEYS})
        t.update(a=joint.a, alpha=joint.alpha, offset=joint.offset, theta_offset=joint.theta_offset)
        ranges = {k: v for k, v in spec.items() if k in RANGE_KEYS and v is not None}
        same_unit = (t["pair"] == "prismatic") == (joint.type == "prismatic")  # a range in m or in rad
        t.update(ranges if any(k in spec for k in RANGE_KEYS) else _limits(joint) if same_unit else {})
        body = joint.body
        t["mass"] = body.mass
        if body.mass > 0 or np.any(body.inertia):
            t["com"] = body.com.tolist()
            t["inertia"] = body.inertia.tolist()
        tables.append(t)
    return tables


def frame_table(T: Matrix) -> dict[str, list[float]]:
    return {"xyz": T[:3, 3].tolist(), "rpy": list(matrix_rpy(T[:3, :3]))}


def is_identity(T: Matrix) -> bool:
    return bool(np.array_equal(T, np.eye(4)))


def text(conv: Converted, pairs: Mapping[int, Mapping[str, Any]] | None = None) -> str:
    """The chain file: name, description, [base], [tool] (left out where the frame is the
    identity) and one commented [[joint]] table per joint."""
    tables = joint_tables(conv, pairs)
    names = [j.name for j in conv.joints]
    lines = [
        f"# {conv.robot}: links {conv.base_link} -> {conv.tip_link} of {conv.source}, converted by apair import urdf.",
        "# DH constants (docs/conventions.md §3) of the URDF's joint axes at q = 0: the joint angles are the",
        "# URDF's own (sign and zero); pose of the tip link in the base link = base * A_1 ... A_n * tool.",
        "# Links: mass, centre of mass and inertia about it in DH frame i, merged from the URDF links that",
        "# joint i moves (fixed children and joints off the path locked at 0). Gravity: -z of the base link.",
        f"name = {_string(conv.robot)}",
        f"description = {_string(f'{conv.robot} from {conv.source}: {conv.base_link} to {conv.tip_link}, joints ' + ', '.join(names))}",
        "",
    ]
    for key, T, what in (
        ("base", conv.base, f"DH frame 0 in link {conv.base_link}'s frame"),
        ("tool", conv.tool, f"link {conv.tip_link}'s frame in DH frame {conv.n}"),
    ):
        if is_identity(T):
            lines += [f"# [{key}]: {what} is the identity", ""]
            continue
        f = frame_table(T)
        lines += [
            f"[{key}]  # {what}",
            f"xyz = {_vec(f['xyz'])}  # m",
            f"rpy = {_vec(f['rpy'])}  # rad, R = Rz(y) Ry(p) Rx(r)",
            "",
        ]
    for i, (joint, t) in enumerate(zip(conv.joints, tables), start=1):
        fixed = f"; fixed joints folded in before it: {', '.join(joint.fixed)}" if joint.fixed else ""
        lines.append(f"[[joint]]  # joint {i}: URDF joint {joint.name} ({joint.type}){fixed}")
        kind = t["pair"]
        own = "prismatic" if joint.type == "prismatic" else "revolute"
        lines.append(
            f"pair = {_string(kind)}" + ("" if kind == own else f"  # --apair: replaces the URDF's {joint.type} joint")
        )
        for key in PAIR_KEYS[kind]:
            if key in t:
                lines.append(f"{key} = {_num(t[key])}  # --apair")
        normal = _NORMAL[joint.normal].format(i=i, j=i + 1, i1=i - 1)
        lines.append(f"a = {_num(t['a'])}  # m; {normal}")
        lines.append(f"alpha = {_num(t['alpha'])}  # rad, from z{i - 1} to z{i} about x{i}")
        lines.append(f"offset = {_num(t['offset'])}  # m, along z{i - 1} to the foot of x{i}")
        zero = "at URDF displacement 0" if joint.type == "prismatic" else "at URDF angle 0"
        lines.append(f"theta_offset = {_num(t['theta_offset'])}  # rad: the angle from x{i - 1} to x{i} {zero}")
        for key in RANGE_KEYS:
            if key in t:
                source = (
                    "--apair"
                    if i in check_pairs(conv, pairs) and key in (pairs or {}).get(i, {})
                    else (f"URDF <limit lower upper>{' in degrees (beyond a turn)' if key == 'limits_deg' else ''}")
                )
                lines.append(f"{key} = {_vec(t[key])}  # {source}")
        if not any(key in t for key in RANGE_KEYS):
            lines.append(
                "# no limits: " + ("continuous joint" if joint.type == "continuous" else "the pair's own range")
            )
        body = joint.body
        massless = f"; massless: {', '.join(body.massless)}" if body.massless else ""
        lines.append(f"mass = {_num(t['mass'])}  # kg, links {', '.join(body.links)}{massless}")
        if "com" in t:
            lines.append(f"com = {_vec(t['com'])}  # m, in DH frame {i}")
            rows = ", ".join(_vec(r) for r in t["inertia"])
            lines.append(f"inertia = [{rows}]  # kg m^2, about the centre of mass, in DH frame {i}")
        lines.append("")
    if conv.tip_fixed:
        lines.append(f"# fixed joints after joint {conv.n}, folded into [tool]: {', '.join(conv.tip_fixed)}")
    return "\n".join(lines).rstrip("\n") + "\n"


def _string(s: str) -> str:
    """A TOML basic string (the text has no control characters: io refuses them)."""
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'
