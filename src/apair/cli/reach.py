"""`apair ik`, `ik-prepare` and `workspace`: which joint vectors reach a pose, and which poses the
chain reaches."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from ..io import load
from . import args as A
from .output import add_json, emit, text_numbers

if TYPE_CHECKING:
    from ..ik import Solution
    from ..ik.families import Classification
    from ..ik.local import Nearest

Sub = Any  # argparse's subparsers action (a private class)


def _cmd_ik(args: argparse.Namespace) -> int:
    from ..ik.local import nearest as nearest_pose

    chain = load(args.file)
    T = A.pose(args.pose)
    with A.named({"T": "POSE", "fix": "--fix"}, joints={"pairs": args.file}):
        sol = chain.ik(T, full=True, fix=_held(args.fix, args.deg))
        nearest = None if len(sol.q) else nearest_pose(chain, T)
    inside = cast(NDArray[np.bool_], sol.inside)  # set by full=True
    if args.json:
        emit(_ik_document(args, chain.name, sol, inside, nearest))
        return 0 if nearest is None else 1
    with text_numbers():
        if nearest is not None:
            why = (
                ""
                if sol.certified
                else f" (not certified complete: {sol.note})"
                if sol.note
                else " (not certified complete)"
            )
            print(
                f"{chain.name}: the pose is unreachable{why}. The nearest pose found inside the joint limits "
                f"(q = {nearest.q} rad) is {nearest.position:.3e} m and {nearest.rotation:.3e} rad away "
                f"(distance {nearest.distance:.3e}, one radian weighing as {nearest.scale:.3g} m)."
            )
            return 1
        complete = (
            "" if sol.certified else f"; not certified complete: {sol.note}" if sol.note else "; not certified complete"
        )
        count = f" of {sol.complex_count} complex" if sol.complex_count is not None else ""
        family = f"; family {sol.family}" if sol.family not in ("", "unclassified") else ""
        print(
            f"{chain.name}: {len(sol.q)} real solution(s){count}, by {sol.method}{complete}{family}; angles in rad"
            f"{' and deg' if args.deg else ''}"
        )
        for q, e, ok in zip(sol.q, sol.error, inside):
            extra = f"  = {np.degrees(q)} deg" if args.deg else ""
            print(f"  q = {q}{extra}   |fk(q) - T| = {e:.1e}   {'within' if ok else 'OUTSIDE'} the joint limits")
    return 0


def _ik_document(
    args: argparse.Namespace,
    name: str | None,
    sol: Solution,
    inside: NDArray[np.bool_],
    nearest: Nearest | None,
) -> dict[str, Any]:
    """`apair ik --json`: the solutions (q_deg too with --deg), or the nearest pose found."""
    solutions = []
    for q, e, ok in zip(sol.q, sol.error, inside):
        entry: dict[str, Any] = {"q": q, "error": e, "within_limits": ok}
        if args.deg:
            entry["q_deg"] = np.degrees(q)
        solutions.append(entry)
    doc: dict[str, Any] = {
        "chain": name,
        "units": {"angles": "rad", "q_deg": "deg", "error": "largest entry of |fk(q) - T|"},
        "reachable": nearest is None,
        "solutions": solutions,
        "complex_count": sol.complex_count,
        "method": sol.method,
        "certified": sol.certified,
        "note": sol.note,
        "family": sol.family,
    }
    if nearest is not None:
        doc["nearest"] = {
            "q": nearest.q,
            "distance_m": nearest.position,
            "distance_rad": nearest.rotation,
            "distance": nearest.distance,
            "length_scale_m": nearest.scale,
        }
    return doc


def _cmd_ik_prepare(args: argparse.Namespace) -> int:
    from ..ik.homotopy.trace import MAX_SOLUTIONS

    chain = load(args.file)
    if chain.n < 5:
        raise ValueError(
            f"{args.file}: {chain.n} joints; start systems are for 5 and 6 joints (fewer are solved "
            "by elimination, nothing to prepare)"
        )
    progress: Callable[[int, int], None] | None = None
    if not args.quiet:

        def show(loops: int, count: int) -> None:
            print(f"\rmonodromy: loop {loops:4d}, {count:6d} points", end="", file=sys.stderr, flush=True)

        progress = show

    family = chain.kinematic_family()
    start = chain.prepare_ik(progress=progress, refresh=args.refresh, trace=args.trace)
    if progress:
        print(file=sys.stderr)
    if args.json:
        emit(
            {
                "chain": chain.name,
                "units": {"seconds": "s"},
                "count": start.count,
                "certified": start.certified,
                "how": start.how,
                "traced": start.traced,
                "trace_deviation": start.trace if start.traced else None,
                "generic": start.generic or None,
                "runs": start.runs,
                "loops": start.loops,
                "seconds": start.seconds,
                "family": _family_document(family),
            }
        )
        return 0
    state = f"{'certified' if start.certified else 'NOT certified'} complete: {start.how}"
    if not start.traced and start.count <= MAX_SOLUTIONS and start.generic != start.count:
        state += "; --trace runs the trace test"
    print(
        f"{chain.name}: start system of {start.count} complex solutions, {state}; runs found {start.runs} "
        f"in {start.loops} loops ({start.seconds:.1f} s to compute; cached)"
    )
    print(f"kinematic family: {family.describe()}")
    return 0


def _family_document(family: Classification) -> dict[str, Any]:
    """The chain's kinematic family for --json: its key, conditions, EAIK's name, its R twin's and
    the joints whose slide breaks the twin's, and the axes' facts (joints from 1)."""
    f, twin = family.family, family.twin
    facts = family.facts
    pairs = lambda flags: [[k + 1, k + 2] for k, x in enumerate(flags) if x]
    return {
        "key": family.key,
        "conditions": f.conditions if f else "",
        "eaik": f.eaik if f else "",
        "reversed": f.reversed if f else False,
        "twin": twin.key if twin else "unclassified",
        "broken_by": list(family.broken_by),
        "parallel": pairs(facts.parallel),
        "meeting": pairs(facts.meeting),
        "spherical": [[k + 1, k + 2, k + 3] for k, x in enumerate(facts.spherical) if x],
        "sliding": family.sliding_joints(),
        "description": family.describe(),
    }


def _cmd_workspace(args: argparse.Namespace) -> int:
    from ..workspace import text_progress

    chain = load(args.file)
    if args.plot is not None:  # an empty name is refused, not ignored
        from ..files import target

        target(args.plot, args.force)  # refuse before the long run, not after it
    ws = chain.workspace(
        samples=args.samples,
        resolution=args.resolution,
        engine=args.scheduler,
        progress=text_progress() if not args.quiet else None,
    )
    lo, hi = ws.points.min(axis=0), ws.points.max(axis=0)
    plot = None if args.plot is None else str(ws.plot(args.plot, overwrite=args.force))
    if args.json:
        emit(
            {
                "chain": chain.name,
                "units": {
                    "volume": "m^3",
                    "measure": "m (a curve) or m^2 (a surface)",
                    "voxel": "m",
                    "bounding_box": "m",
                },
                "summary": ws.summary,
                "dimension": ws.dimension,
                "volume": ws.volume,
                "volume_error": ws.volume_error,
                "measure": ws.measure,
                "samples": len(ws.points),
                "voxel": ws.voxel,
                "boundary_voxels": len(ws.boundary),
                "bounding_box": {"min": lo, "max": hi},
                "plot": plot,
            }
        )
        return 0
    print(
        f"{chain.name}: workspace {ws.summary} from {len(ws.points)} samples; voxel {ws.voxel:.3g} m, "
        f"{len(ws.boundary)} boundary voxels"
    )
    print(
        f"  bounding box [m]: x {lo[0]:+.4f} .. {hi[0]:+.4f}, y {lo[1]:+.4f} .. {hi[1]:+.4f}, "
        f"z {lo[2]:+.4f} .. {hi[2]:+.4f}"
    )
    if plot is not None:
        print(f"  picture written to {plot}")
    return 0


def add_ik(sub: Sub) -> None:
    p = sub.add_parser("ik", help="all inverse kinematics solutions of a chain file at a pose")
    p.add_argument("file", help="a chain TOML file (1 to 6 sinusoidal A-pairs or R-pairs; 7 with --fix)")
    p.add_argument(
        "pose",
        nargs="+",
        metavar="POSE",
        help="a 4x4 transform row by row (16 numbers, or the top 12) or a Study point (8)",
    )
    p.add_argument("--deg", action="store_true", help="also print the angles in degrees (and read --fix in degrees)")
    p.add_argument(
        "--fix",
        action="append",
        default=[],
        metavar="K=VALUE",
        help="hold joint K (from 1) at VALUE [rad, or deg with --deg] and solve for the others; repeatable",
    )
    add_json(p)
    p.set_defaults(func=_cmd_ik)


def _held(words: list[str], deg: bool) -> dict[int, float] | None:
    """--fix K=VALUE words as {K: value [rad]}; None when none is given."""
    held: dict[int, float] = {}
    for word in words:
        key, sep, value = word.partition("=")
        try:
            k, x = int(key), float(value)
        except ValueError:
            k, x = 0, float("nan")
        if not sep or k < 1 or not np.isfinite(x) or k in held:
            raise ValueError(
                f"--fix: expected K=VALUE with a joint K from 1 (once each) and a finite value, got {word!r}"
            )
        held[k] = float(np.radians(x)) if deg else x
    return held or None


def add_ik_prepare(sub: Sub) -> None:
    p = sub.add_parser(
        "ik-prepare",
        help="the homotopy start system of a 5- or 6-joint chain file (cached)",
        description="Find every complex inverse-kinematics solution at a generic complex pose by "
        "monodromy and cache it under the design's content hash, so that `ik` need not.",
    )
    p.add_argument("file", help="a chain TOML file (5 or 6 sinusoidal A-pairs or R-pairs)")
    p.add_argument("--refresh", action="store_true", help="compute it again even if it is cached")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.add_argument(
        "--trace",
        action="store_true",
        help="also certify the set by the trace test (seconds for up to 48 solutions, minutes and "
        "possibly no verdict for more, refused above 200; cached)",
    )
    add_json(p)
    p.set_defaults(func=_cmd_ik_prepare)


def add_workspace(sub: Sub) -> None:
    p = sub.add_parser("workspace", help="reachable workspace of a chain file: volume, boundary, picture")
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("--plot", metavar="PNG", help="write a 3D view and cross-sections")
    p.add_argument("--force", action="store_true", help="replace an existing picture")
    p.add_argument("--samples", type=int, default=300_000, help="joint samples (default 300000)")
    p.add_argument("--resolution", type=int, default=24, help="voxels along the longest side (default 24)")
    p.add_argument(
        "--scheduler", metavar="ADDRESS", help="run on a dask.distributed scheduler (or 'threads', 'processes')"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_json(p)
    p.set_defaults(func=_cmd_workspace)
