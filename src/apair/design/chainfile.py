"""A chain file's TOML text from its document (the dict that apair.io.chain_from_dict reads):
comments first, then the top-level keys, then one [[joint]] table per joint, its keys in the
order of the format's description. Floats are written in Python's shortest round-trip form, so
the file reads back to the same numbers bit for bit; strings as TOML basic strings.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import Any

TOP_ORDER = ("name", "description", "gravity")
JOINT_ORDER = (
    "pair",
    "base_radius",
    "platform_radius",
    "leg_length",
    "leg_mass",
    "leg_radius",
    "thickness",
    "limits",
    "limits_deg",
    "a",
    "alpha",
    "alpha_deg",
    "offset",
    "theta_offset",
    "theta_offset_deg",
    "mass",
    "com",
    "inertia",
)


def value(v: object) -> str:
    """A TOML value: a string, a bool, an integer, a finite float or a list of them."""
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)  # JSON's escapes are TOML basic-string escapes
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"chain file: {v!r} has no place in a chain file (finite numbers only)")
        return repr(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(value(x) for x in v) + "]"
    raise ValueError(f"chain file: cannot write a {type(v).__name__} value")


def _ordered(table: dict[str, Any], order: Sequence[str]) -> list[str]:
    """The table's keys: those of `order` in that order, then any others sorted."""
    return [k for k in order if k in table] + sorted(k for k in table if k not in order)


def dumps(doc: dict[str, Any], comments: Sequence[str] = ()) -> str:
    """The chain file's text of `doc`, after `comments` (each a line, written after "# ")."""
    lines = [f"# {c}".rstrip() for c in comments]
    top = {k: v for k, v in doc.items() if k != "joint"}
    lines += [f"{k} = {value(top[k])}" for k in _ordered(top, TOP_ORDER)]
    for joint in doc.get("joint", []):
        lines += ["", "[[joint]]"] + [f"{k} = {value(joint[k])}" for k in _ordered(joint, JOINT_ORDER)]
    return "\n".join(lines) + "\n"
