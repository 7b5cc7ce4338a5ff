"""The command line's arguments as numbers: joint vectors, poses, option lists, each checked
against the chain with errors that name the argument as the user typed it (Q, POSE, --q) and
number joints from 1."""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._validate import shorten
from ..chain import AChain
from .output import angle, told

# argparse takes these words as values, not as unknown options: negative numbers in exponent form
# (-1e-3, -2.5E+4), -inf and -nan, and comma-separated lists that start with one (--q -0.1,0.2)
_NUMBER = r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf|infinity|nan"
NEGATIVE_NUMBER = re.compile(rf"^-(?:{_NUMBER})(?:\s*,\s*[-+]?(?:{_NUMBER}))*$", re.IGNORECASE)


def numbers(name: str, words: Sequence[str]) -> NDArray[np.float64]:
    """Command-line words as finite floats; a word that is not one is an error naming `name`."""
    out = []
    for word in words:
        try:
            x = float(word)
        except ValueError:
            raise ValueError(f"{name}: {shorten(repr(word))} is not a number") from None
        if not math.isfinite(x):
            raise ValueError(f"{name}: {shorten(repr(word))} is not a finite number")
        out.append(x)
    return np.array(out)


def number_list(name: str, text: str) -> NDArray[np.float64]:
    """An option's comma-separated numbers (`--q 0.1,-0.2`); an empty entry is an error."""
    words = [w.strip() for w in text.split(",")]
    if "" in words:
        raise ValueError(f"{name}: expected numbers separated by commas, got {shorten(repr(text))}")
    return numbers(name, words)


def joint_vector(chain: AChain, name: str, x: NDArray[np.float64], what: str = "values") -> NDArray[np.float64]:
    """x, refused unless it has one entry per joint of the chain."""
    if x.shape != (chain.n,):
        raise ValueError(f"{name}: {chain.name} has {chain.n} joints, got {x.size} {what}")
    return x


def angles(chain: AChain, name: str, x: NDArray[np.float64], deg: bool, strict: bool) -> NDArray[np.float64]:
    """Joint angles [rad] from the user's numbers (degrees with `deg`), one per joint, each within
    its pair's range of motion (`check_pair_ranges`)."""
    q = joint_vector(chain, name, np.radians(x) if deg else x, "angles")
    check_pair_ranges(chain, q, name, deg, strict)
    return q


def check_pair_ranges(chain: AChain, q: NDArray[np.float64], name: str, deg: bool, strict: bool) -> None:
    """Refuse an angle past its pair's range of motion (a general A-pair whose legs are short
    turns only to ±theta_limit, mod one turn), naming the joint from 1; with `strict` also one
    at the range end, where d'(θ) is unbounded (the Jacobian and the dynamics)."""
    for i, pair in enumerate(chain.pairs):
        limit = pair.theta_limit
        if limit is None:
            continue
        wrapped = abs(q[i] - 2 * math.pi * round(q[i] / (2 * math.pi)))
        if wrapped < limit:
            continue
        at = f"{name}: joint {i + 1} at {angle(q[i], deg)}"
        try:
            pair.law(q[i])  # the pair's own test, which takes an angle past the end by rounding only
        except ValueError:
            turn = "360 deg" if deg else "2 pi"
            raise ValueError(f"{at} is outside its pair's range |theta| <= {angle(limit, deg)} (mod {turn})") from None
        if strict:
            raise ValueError(f"{at} is at its pair's range end {angle(limit, deg)}, where d'(theta) is unbounded")


def outside_limits(chain: AChain, q: NDArray[np.float64]) -> list[dict[str, Any]]:
    """The joints (numbered from 1) beyond the ranges that stop them (`chain.hard_limits`: explicit
    limits, where legs or plates collide): {"joint", "q", "limits"} [rad]; a free joint never."""
    return [
        {"joint": i + 1, "q": float(q[i]), "limits": [float(lo), float(hi)]}
        for i, (lo, hi) in enumerate(chain.hard_limits())
        if not lo <= q[i] <= hi
    ]


def limits_text(entry: dict[str, Any], deg: bool) -> str:
    """`joint 2 at 3 rad is outside its limits [-2.0944 rad, 2.0944 rad]` for an outside_limits entry."""
    lo, hi = (angle(x, deg) for x in entry["limits"])
    return f"joint {entry['joint']} at {angle(entry['q'], deg)} is outside its limits [{lo}, {hi}]"


def pose(words: Sequence[str]) -> NDArray[np.float64]:
    """POSE: a 4x4 transform row by row (16 numbers, or the top 12) or a Study point (8)."""
    x = numbers("POSE", words)
    if len(x) == 16:
        return x.reshape(4, 4)
    if len(x) == 12:  # the top three rows of the transform
        return np.vstack([x.reshape(3, 4), [0.0, 0.0, 0.0, 1.0]])
    if len(x) == 8:
        return x
    raise ValueError(
        f"POSE: expected 16 (or 12) numbers of a 4x4 transform, row by row, or the 8 of a Study point, got {len(x)}"
    )


_ITEM = re.compile(r"(\w+)\[(?:\.\.\., )?(\d+)\]")  # an argument's item: pairs[0], q[..., 2]


@contextmanager
def named(options: Mapping[str, str], joints: Mapping[str, str] | None = None) -> Iterator[None]:
    """Errors of the API calls inside name the API's argument first (`T: ...`, the project's
    convention); these say the command line's name for it instead: `options` maps argument to
    name ({"T": "POSE"}), `joints` a per-joint argument to the name before `joint i + 1`
    ({"pairs": FILE}: `pairs[0]: ...` becomes `FILE: joint 1: ...`)."""
    try:
        yield
    except ValueError as exc:
        argument, sep, rest = told(exc).partition(": ")
        item = _ITEM.fullmatch(argument)
        if sep and argument in options:
            raise ValueError(f"{options[argument]}: {rest}") from None
        if sep and item and joints and item[1] in joints:
            raise ValueError(f"{joints[item[1]]}: joint {int(item[2]) + 1}: {rest}") from None
        raise
