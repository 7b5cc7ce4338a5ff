"""`apair compare`: a chain file beside its twin (every A-pair an R-pair at the same DH constants
and links), as a table, a JSON document or an HTML report."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..compare import compare
from ..compare.path import read_csv
from ..files import target
from ..io import load
from . import args as A
from .output import add_json, emit

Sub = Any  # argparse's subparsers action (a private class)
# the API's arguments as the command line names them (A.named)
OPTIONS = {"twin": "--twin", "samples": "--samples", "seed": "--seed", "engine": "--scheduler", "path": "--path"}


def _check_outputs(args: argparse.Namespace) -> None:
    """--out and --picture refused (a folder, an existing file without --force) before the run."""
    for option, value, suffix in (("--out", args.out, ".html"), ("--picture", args.picture, ".png")):
        if value is not None:
            with A.named({"path": option}):
                target(value, args.force, suffix)


def _progress(args: argparse.Namespace) -> Any:
    """The stages on stderr, unless --quiet."""
    if args.quiet:
        return None
    return lambda words: print(f"apair compare: {words} ...", file=sys.stderr, flush=True)


def _cmd_compare(args: argparse.Namespace) -> int:
    chain = load(args.file)
    _check_outputs(args)
    with A.named({"path": "--path"}):
        path = None if args.path is None else read_csv(args.path)
    with A.named(OPTIONS):
        result = compare(
            chain,
            twin=args.twin,
            samples=args.samples,
            seed=args.seed,
            path=path,
            engine=args.scheduler,
            progress=_progress(args),
        )
    written = {}
    for key, option, value, write in (
        ("report", "--out", args.out, result.report),
        ("picture", "--picture", args.picture, result.picture),
    ):
        if value is not None:
            with A.named({"path": option}):
                written[key] = str(write(value, overwrite=args.force))
    if args.json:
        emit(result.as_dict() | {"report": written.get("report"), "picture": written.get("picture")})
    elif args.out is None:
        print(result.table())
    for key, where in written.items():
        if not args.json:
            print(f"{key} written to {where}")
    return 0


def add_compare(sub: Sub) -> None:
    p = sub.add_parser(
        "compare",
        help="a chain file beside its twin of R-pairs: workspace, ranges, dexterity, torques, mass, ik",
        description="The chain beside its twin, every A-pair replaced by an R-pair at the same DH constants "
        "and links (legs and plates gone), measured on the same work: workspace volume and the share only "
        "one reaches, joint ranges and axial travel, manipulability and condition number, gravity "
        "torques, the torques and energy of a common end-effector path, mass, ik solution counts.",
    )
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("--twin", default="revolute", metavar="KIND", help="the pair kind of the twin (revolute)")
    p.add_argument("--out", metavar="REPORT.html", help="write one self-contained HTML report (instead of the table)")
    p.add_argument("--picture", metavar="PNG", help="write the report's main picture (sections, manipulability)")
    p.add_argument("--force", action="store_true", help="replace an existing report or picture")
    p.add_argument("--samples", type=int, default=300_000, help="workspace samples per chain (default 300000)")
    p.add_argument("--seed", type=int, default=0, help="seed of every random choice (default 0)")
    p.add_argument(
        "--path", metavar="POSES.csv", help="the common end-effector path: x, y, z [m] per line (default: a line)"
    )
    p.add_argument(
        "--scheduler", metavar="ADDRESS", help="workspaces on a dask.distributed scheduler (or 'threads', 'processes')"
    )
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    add_json(p)
    p.set_defaults(func=_cmd_compare)
