"""`apair design`: a global search over a chain's design (apair.design), on Dask workers, with a
progress bar, a checkpoint beside the output (`--resume` continues an interrupted run) and the
best design written as a chain file (with several objectives the Pareto front too)."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .. import _validate as V
from ..files import target
from . import args as A
from .output import add_json, emit

Sub = Any  # argparse's subparsers action (a private class)
OPTIONS = {"path": "--out", "workers": "--workers", "scheduler": "--scheduler", "checkpoint": "--out"}


def outputs(out: Path) -> dict[str, Path]:
    """The files beside --out: the checkpoint, the Pareto front's CSV and picture."""
    stem = out.with_suffix("")
    return {
        "checkpoint": stem.with_name(stem.name + ".checkpoint.json"),
        "front_csv": stem.with_name(stem.name + ".front.csv"),
        "front_plot": stem.with_name(stem.name + ".front.png"),
    }


def text_progress(width: int = 30) -> Callable[[int, int, dict[str, float]], None]:
    """A progress bar on stderr: candidates done of the budget and the best objective so far."""

    def show(done: int, total: int, best: dict[str, float]) -> None:
        filled = int(width * min(done, total) / max(total, 1))
        said = ", ".join(f"{k} {v:.4g}" for k, v in best.items()) or "none feasible yet"
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} candidates; best {said}   ")
        sys.stderr.flush()

    return show


def _checked(args: argparse.Namespace) -> tuple[Any, Path, dict[str, Path]]:
    """The spec (with --budget put in) and every file the run writes, refused before the search."""
    from ..design import load_spec
    from ..design.spec import MAX_BUDGET

    spec = load_spec(args.spec)
    if args.budget is not None:
        spec = dataclasses.replace(spec, budget=V.integer("--budget", args.budget, maximum=MAX_BUDGET))
    with A.named(OPTIONS):
        out = target(args.out, args.force, ".toml")
        files = outputs(out)
        if len(spec.objectives) > 1:
            target(files["front_csv"], args.force, ".csv")
            target(files["front_plot"], args.force, ".png")
    if files["checkpoint"].exists() and not (args.resume or args.force):
        raise ValueError(
            f"--out: {str(files['checkpoint'])!r} holds an earlier run of a search; use --resume to continue "
            "it or --force to start afresh"
        )
    return spec, out, files


def _cmd_design(args: argparse.Namespace) -> int:
    from ..design import design

    spec, out, files = _checked(args)
    progress = None if args.quiet else text_progress()
    try:
        with A.named(OPTIONS):
            result = design(
                spec,
                workers=args.workers,
                scheduler=args.scheduler,
                resume=args.resume,
                progress=progress,
                checkpoint=files["checkpoint"],
                overwrite=args.force,
            )
    except KeyboardInterrupt:
        if progress:
            print(file=sys.stderr)
        print(
            f"apair design: the checkpoint {files['checkpoint']} keeps the candidates evaluated; --resume continues",
            file=sys.stderr,
        )
        raise
    if progress:
        print(file=sys.stderr)
    written = {"best": str(result.write(out, overwrite=args.force))}
    if result.front:
        written["front_csv"] = str(result.write_front(files["front_csv"], overwrite=args.force))
        written["front_plot"] = str(result.plot_front(files["front_plot"], overwrite=args.force))
    if args.json:
        emit(
            {
                "spec": spec.where,
                "units": {"volume": "m^3", "gravity_torque_max": "N m", "seconds": "s"},
                "objectives": result.objectives,
                "reached": result.reached,
                "targets": result.targets,
                "values": result.values,
                "evaluated": result.evaluated,
                "budget": spec.budget,
                "seconds": result.seconds,
                "front": len(result.front),
                "written": written,
                "checkpoint": str(files["checkpoint"]),
            }
        )
        return 0
    print(
        f"{spec.where}: {result.summary} after {result.evaluated} candidates ({result.seconds:.1f} s); "
        f"best design written to {written['best']}"
    )
    for key, value in result.values.items():
        print(f"  {key} = {value if isinstance(value, str) else f'{value:.6g}'}")
    if result.front:
        print(
            f"  Pareto front: {len(result.front)} designs written to {written['front_csv']} and {written['front_plot']}"
        )
    return 0


def add_design(sub: Sub) -> None:
    p = sub.add_parser(
        "design",
        help="search a chain's design space for the best design (differential evolution on Dask)",
        description="Vary a chain file's numbers (and pair kinds) within the bounds of a spec file to "
        "reach its targets, a workspace volume or low gravity torques; the candidates are evaluated on "
        "Dask workers (all cores by default). Writes the best design as a chain file; with several "
        "objectives the Pareto front too (OUT.front.csv and OUT.front.png). The candidates evaluated "
        "are kept in OUT.checkpoint.json: --resume continues an interrupted run to the same result.",
    )
    p.add_argument("spec", metavar="SPEC.toml", help="a design spec file (docs/how-to/design.md)")
    p.add_argument("--out", required=True, metavar="BEST.toml", help="the best design's chain file")
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="Dask worker processes on this machine (default: one per core; 0: none)",
    )
    where.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask scheduler at this address")
    p.add_argument("--resume", action="store_true", help="continue the run kept in OUT.checkpoint.json")
    p.add_argument("--force", action="store_true", help="replace existing output files and checkpoint")
    p.add_argument("--budget", type=int, metavar="N", help="candidates to evaluate at most (instead of the spec's)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_json(p)
    p.set_defaults(func=_cmd_design)
