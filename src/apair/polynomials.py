"""The derived polynomial sets in generated/polynomials, loaded back as sympy objects (sympy is
imported by `load` only)."""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from importlib.resources.abc import Traversable
from typing import TYPE_CHECKING, Any

from ._validate import shorten

if TYPE_CHECKING:
    import sympy as sp


def _dir() -> Traversable:
    return resources.files("apair.generated").joinpath("polynomials")


def names() -> list[str]:
    """Names of the derived polynomial sets."""
    return sorted(p.name[:-5] for p in _dir().iterdir() if p.name.endswith(".json"))


@cache
def raw(name: str) -> dict[str, Any]:
    if name not in names():
        raise ValueError(f"name: no derived polynomial set {shorten(repr(name))}; known: {', '.join(names())}")
    return json.loads(_dir().joinpath(f"{name}.json").read_text())


def text(name: str, fmt: str = "txt") -> str:
    """The rendered text ("txt") or LaTeX ("tex") of a set."""
    if fmt not in ("txt", "tex"):
        raise ValueError(f"fmt: expected 'txt' or 'tex', got {shorten(repr(fmt))}")
    raw(name)
    return _dir().joinpath(f"{name}.{fmt}").read_text()


def load(name: str) -> dict[str, sp.Expr | sp.Eq]:
    """{label: expression} of a set; an entry written `lhs = rhs` loads as sympy.Eq(lhs, rhs).

    Symbols carry the assumptions the derivation gave them (real, positive), so the loaded objects
    compare equal to the derived ones.
    """
    import sympy as sp  # sympy (seconds to import) only when a set is loaded as sympy objects
    from sympy.parsing.sympy_parser import parse_expr

    data = raw(name)
    local = {}
    for s, kind in data["symbols"].items():
        local[s] = sp.Symbol(s, **({kind: True} if kind != "complex" else {}))
    out = {}
    for e in data["entries"]:
        lhs = parse_expr(e["lhs"], local_dict=local)
        out[e["label"]] = (
            lhs if e["rhs"] is None else sp.Eq(lhs, parse_expr(e["rhs"], local_dict=local), evaluate=False)
        )
    return out
