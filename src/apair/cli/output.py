"""What the commands print: JSON documents for scripts (`--json`), notes and error lines on stderr,
and the command line's wording of the API's refusals.

JSON: numbers at full precision (Python's shortest round-trip form), arrays as nested lists,
non-finite numbers as the strings "NaN", "Infinity", "-Infinity" (strict JSON has no token for
them; Python's float() and JavaScript's Number() read those strings back).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from contextlib import AbstractContextManager
from typing import Any

import numpy as np

from ..files import Refusal

# the command line's option for each API argument that lifts a refusal (files.Refusal)
OPTION_OF = {"overwrite": "--force", "outside_limits": "--outside-limits"}
_NON_FINITE = {math.inf: "Infinity", -math.inf: "-Infinity"}


def text_numbers() -> AbstractContextManager[object]:
    """How arrays are printed as text: 12 decimals, no exponent for small values."""
    return np.printoptions(precision=12, suppress=True, floatmode="maxprec")


def add_json(parser: argparse.ArgumentParser) -> None:
    """The option --json of a command that prints numbers."""
    parser.add_argument("--json", action="store_true", help="print one JSON document instead of text (for scripts)")


def jsonable(value: object) -> Any:
    """`value` with NumPy arrays and scalars as lists and Python numbers, non-finite floats as
    strings: what json.dumps(allow_nan=False) takes."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        x = float(value)
        return x if math.isfinite(x) else _NON_FINITE.get(x, "NaN")
    return value


def emit(doc: dict[str, Any]) -> None:
    """Print `doc` as one JSON document on stdout."""
    print(json.dumps(jsonable(doc), indent=1, allow_nan=False))


def note(command: str, text: str) -> None:
    """A note on stderr that does not stop the command (stdout keeps its format)."""
    print(f"apair {command}: note: {text}", file=sys.stderr)


def angle(x: float, deg: bool) -> str:
    """An angle [rad] for a message, in the unit the user gave angles in."""
    return f"{math.degrees(x):.6g} deg" if deg else f"{x:.6g} rad"


def told(exc: BaseException) -> str:
    """An error's message as the command line says it: a refusal names the option that lifts it."""
    if isinstance(exc, Refusal) and exc.argument in OPTION_OF:
        return exc.told(OPTION_OF[exc.argument])
    return str(exc)


def one_line(exc: BaseException) -> str:
    """told(exc) on one line of at most 400 characters."""
    text = " ".join(told(exc).split())
    return text if len(text) <= 400 else text[:397] + "..."
