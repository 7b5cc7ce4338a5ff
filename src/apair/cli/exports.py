"""`apair export`, `view` and `codegen`: the chain written in other forms, each to the file or
folder given by --out."""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..chain import AChain
from ..io import load
from . import args as A

Sub = Any  # argparse's subparsers action (a private class)
DEPRECATED_OUT = "OUT as a positional argument is deprecated; use --out"


def _export_out(args: argparse.Namespace) -> str:
    """The file to write: --out, or the deprecated positional OUT (not both)."""
    if args.out_positional is not None and args.out is not None:
        raise ValueError("--out: given twice (OUT and --out); give --out only")
    out: str | None = args.out if args.out is not None else args.out_positional
    if out is None:
        raise ValueError("--out: the model file to write (.xml) is required")
    return out


def _keyframe(args: argparse.Namespace, chain: AChain) -> NDArray[np.float64] | None:
    """--q [rad, or deg with --deg] within the pairs' ranges, and within the joint limits (explicit,
    or where legs or plates collide) unless --outside-limits."""
    if args.q is None:
        return None
    q = A.angles(chain, "--q", A.number_list("--q", args.q), args.deg, strict=False)
    outside = A.outside_limits(chain, q)
    if outside and not args.outside_limits:
        raise ValueError(
            f"--q: {A.limits_text(outside[0], args.deg)} (see apair limits); use --outside-limits to export it anyway"
        )
    return q


def _cmd_export(args: argparse.Namespace) -> int:
    from .. import mjcf
    from ..files import write_text

    out = _export_out(args)
    chain = load(args.file)
    q = _keyframe(args, chain)
    with A.named({"q": "--q", "path": "--out"}):
        xml = mjcf.to_mjcf(
            chain,
            q,
            name=chain.name or os.path.basename(args.file),
            collisions=args.collisions,
            limits=not args.no_limits,
            outside_limits=args.outside_limits,
        )
        path = write_text(out, xml, args.force, ".xml")
    legs = sum(6 for p in chain.pairs if p.is_apair)
    print(
        f"{chain.name}: MuJoCo model written to {path} ({chain.n} pairs, {legs} legs closed by "
        f"{legs} connect constraints; keyframe 0 at q = {np.round(q if q is not None else np.zeros(chain.n), 6).tolist()})"
    )
    if args.out_positional is not None:  # after the work: an error stays the one line on stderr
        print(f"apair export: {DEPRECATED_OUT}", file=sys.stderr)
    return 0


def _cmd_view(args: argparse.Namespace) -> int:
    from .. import view

    chain = load(args.file)
    if not 0 <= args.workspace <= view.MAX_WORKSPACE_POINTS:
        raise ValueError(
            f"--workspace: expected a number of samples from 0 to {view.MAX_WORKSPACE_POINTS}, got {args.workspace}"
        )
    with A.named({"path": "--out"}):
        out = view.write(chain, args.out, overwrite=args.force, workspace=args.workspace)
    print(f"{chain.name}: viewer written to {out} (open it in a browser; it needs no network)")
    return 0


def _cmd_codegen(args: argparse.Namespace) -> int:
    from .. import specialise

    t0 = time.perf_counter()
    chain = load(args.file)
    name = specialise.check_prefix(args.prefix) if args.prefix else specialise.prefix_from(args.file)
    kernels = None if args.kernels is None else [k.strip() for k in args.kernels.split(",") if k.strip()]
    changed = specialise.write_code(
        chain, args.out, name, os.path.basename(args.file), kernels, title=chain.name, force=args.force
    )
    notes = [c for c in changed if c.startswith("kept ")]
    print(
        f"apair codegen: {name} ({chain.n} joints) in {args.out}: {len(changed) - len(notes)} files written, "
        f"changed or removed ({time.perf_counter() - t0:.1f} s)"
    )
    for kept in notes:
        print(f"  {kept}")
    return 0


def add_export(sub: Sub) -> None:
    p = sub.add_parser(
        "export",
        help="the chain in another tool's format: mjcf (a MuJoCo model)",
        description="Write a MuJoCo model (MJCF) of the chain's mechanism: every A-pair as its "
        "Griffis-Duffy platform, legs as bodies closed by equality constraints, motors on the pair axes.",
    )
    p.add_argument("format", choices=["mjcf"], help="the format (mjcf: MuJoCo XML)")
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("out_positional", nargs="?", metavar="OUT", help="deprecated: use --out")
    p.add_argument("--out", metavar="XML", help="the file to write (.xml)")
    p.add_argument("--q", metavar="Q1,Q2,...", help="the configuration of keyframe 0 (radians unless --deg; default 0)")
    p.add_argument("--deg", action="store_true", help="--q in degrees")
    p.add_argument(
        "--outside-limits",
        action="store_true",
        help="write a --q beyond the joint limits (where legs or plates collide) all the same",
    )
    p.add_argument("--no-limits", action="store_true", help="hinges without ranges (default: the joint limits)")
    p.add_argument("--collisions", action="store_true", help="let plates and legs collide (off by default)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    p.set_defaults(func=_cmd_export)


def add_view(sub: Sub) -> None:
    p = sub.add_parser(
        "view",
        help="an interactive 3D view of a chain file: one offline HTML page",
        description="Write one self-contained HTML page: the mechanism in 3D (plates, legs, links, "
        "frames), a slider per joint within the chain's limits, the end-effector pose and each "
        "pair's clearance, computed in the page by the generated JavaScript kernels.",
    )
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("--out", default="view.html", metavar="HTML", help="the page to write (default view.html)")
    p.add_argument("--workspace", type=int, default=0, metavar="N", help="also N sampled end-effector points")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    p.set_defaults(func=_cmd_view)


def add_codegen(sub: Sub) -> None:
    p = sub.add_parser(
        "codegen",
        help="C and NumPy code for one chain file, its design built in",
        description="Write NAME.h, NAME.c (C99, libm), NAME.py (NumPy), NAME_selftest.c, "
        "CMakeLists.txt (target NAME::NAME) and NAME.pc.in for the chain into --out.",
    )
    p.add_argument("file", help="a chain TOML file")
    p.add_argument(
        "--out", required=True, metavar="DIR", help="output folder: new, empty, or written by an earlier apair codegen"
    )
    p.add_argument("--prefix", metavar="NAME", help="name of the files and functions (default: from the file name)")
    p.add_argument(
        "--kernels",
        metavar="LIST",
        help="comma-separated subset of fk, fk_study, jacobian, mass_matrix, coriolis, gravity_torques, "
        "bias, inverse_dynamics, forward_dynamics, energy, inverse_dynamics_derivatives, "
        "forward_dynamics_derivatives (default: all but the two derivatives, which take minutes to derive)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="replace files in --out that an earlier apair codegen did not write (never through a link)",
    )
    p.set_defaults(func=_cmd_codegen)
