"""`apair import urdf`: a chain file from a robot's URDF (the serial path from a base link to a tip
link, R-pairs with exact DH constants, base and tool frames, merged link inertias)."""

from __future__ import annotations

import argparse
import math
import re
import time
from typing import Any

from ..chain import MAX_JOINTS
from ..pair import KINDS
from . import args as A

Sub = Any  # argparse's subparsers action (a private class)
_SPEC = re.compile(r"\s*(\d+)\s*:\s*([A-Za-z_]+)\s*((?:,[^,]*)*)")


def _value(spec: str, key: str, text: str) -> object:
    """A key's value in an --apair spec: a number, or for limits/limits_deg LO:HI or none."""
    if key in ("limits", "limits_deg"):
        if text.strip().lower() == "none":
            return None
        parts = text.split(":")
        try:
            lo, hi = (float(p) for p in parts)
        except ValueError:
            raise ValueError(f"--apair {spec}: {key}: expected LO:HI or none, got {text!r}") from None
        return [lo, hi]
    try:
        x = float(text)
    except ValueError:
        raise ValueError(f"--apair {spec}: {key}: expected a number, got {text!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"--apair {spec}: {key}: expected a finite number, got {text!r}")
    return x


def parse_apair(specs: list[str] | None) -> dict[int, dict[str, object]]:
    """--apair K:KIND,key=value,... (repeatable) as load_urdf's `pairs`."""
    out: dict[int, dict[str, object]] = {}
    for spec in specs or []:
        m = _SPEC.fullmatch(spec)
        if not m:
            raise ValueError(
                f"--apair: expected K:KIND[,key=value,...] (e.g. 2:sinusoidal,base_radius=0.06), got {spec!r}"
            )
        k, kind = int(m[1]), m[2]
        if kind not in KINDS:
            raise ValueError(f"--apair {spec}: unknown pair kind {kind!r} (one of {', '.join(KINDS)})")
        if k in out:
            raise ValueError(f"--apair: joint {k} is given twice")
        table: dict[str, object] = {"pair": kind}
        for item in filter(None, (s.strip() for s in m[3].split(","))):
            key, eq, text = item.partition("=")
            key = key.strip()
            if not eq or not key:
                raise ValueError(f"--apair {spec}: expected key=value, got {item!r}")
            if key in table:
                raise ValueError(f"--apair {spec}: {key} is given twice")
            table[key] = _value(spec, key, text)
        out[k] = table
    return out


def _cmd_import(args: argparse.Namespace) -> int:
    from ..files import target, write_text
    from ..urdf import to_toml

    t0 = time.perf_counter()
    pairs = parse_apair(args.apair)
    with A.named({"path": "--out"}):
        target(args.out, args.force, ".toml")  # refused before any work
    try:
        with A.named({"path": "FILE", "tip": "--tip", "base": "--base"}):
            text = to_toml(args.file, args.tip, args.base, pairs or None)
    except ValueError as exc:
        message = str(exc)
        m = re.match(r"pairs(?:\[(\d+)\])?: (.*)", message, re.DOTALL)
        if m:  # the API names its `pairs` argument; say the option
            spec = next((s for s in args.apair or [] if m[1] and s.strip().startswith(f"{m[1]}:")), None)
            raise ValueError(f"--apair{' ' + spec if spec else ''}: {m[2]}") from None
        raise
    with A.named({"path": "--out"}):
        path = write_text(args.out, text, args.force, ".toml")
    joints = text.count("[[joint]]")
    print(f"apair import: {args.tip}: chain file written to {path} ({joints} joints; {time.perf_counter() - t0:.2f} s)")
    return 0


def add_import(sub: Sub) -> None:
    p = sub.add_parser(
        "import",
        help="a chain file from another tool's model: urdf (a robot's URDF)",
        description="Write a chain file of a URDF robot's serial path from --base (default: the root "
        "link) to --tip: one R-pair per revolute or continuous joint with exact DH constants (the "
        "joint angles are the URDF's), [base] and [tool] frames, and each link's mass, centre of mass "
        "and inertia merged from the URDF links it moves. Prismatic, floating, planar and mimic "
        f"joints on the path are refused, and so are paths of more than {MAX_JOINTS} joints.",
    )
    p.add_argument("format", choices=["urdf"], help="the format (urdf: a robot's URDF file)")
    p.add_argument("file", help="the URDF file (meshes are not read)")
    p.add_argument("--tip", required=True, metavar="LINK", help="the link the chain ends at")
    p.add_argument("--base", metavar="LINK", help="the link the chain starts at (default: the root link)")
    p.add_argument("--out", required=True, metavar="CHAIN.toml", help="the chain file to write (.toml)")
    p.add_argument(
        "--apair",
        action="append",
        metavar="K:KIND,key=value,...",
        help="replace joint K by a pair of KIND (sinusoidal, general, revolute) with its chain-file keys, "
        "e.g. 2:sinusoidal,base_radius=0.06,platform_radius=0.05; limits=LO:HI (rad), limits_deg=LO:HI or "
        "limits=none set its range (default: the URDF's); repeatable",
    )
    p.add_argument("--force", action="store_true", help="replace an existing file")
    p.set_defaults(func=_cmd_import)
