"""The `apair` command line: inspect derived polynomials, evaluate chains, run the demonstration."""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from collections.abc import Callable, Sequence
from typing import cast

import numpy as np
from numpy.typing import NDArray

from . import polynomials
from ._version import __version__
from .io import load
from .kernels import backend, manifest


def _cmd_list(args: argparse.Namespace) -> int:
    for name in polynomials.names():
        data = polynomials.raw(name)
        print(f"{name:16s} {len(data['entries']):3d} entries  {data['title']}")
    return 0


def _cmd_show(args: argparse.Namespace) -> int:
    if args.name == "ik_counts":
        return _show_ik_counts(args)
    if args.json:
        print(json.dumps(polynomials.raw(args.name), indent=1))
    else:
        print(polynomials.text(args.name, "tex" if args.latex else "txt"), end="")
    return 0


def _show_ik_counts(args: argparse.Namespace) -> int:
    from .ik.homotopy import stored_counts

    rows = stored_counts()
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    print(
        "Generic number of complex inverse-kinematics solutions of R/A chains (A: sinusoidal A-pair,\n"
        "R: R-pair; a pattern and its reverse have the same count). n < 6: at a pose of the chain's own\n"
        "image. Computed by apair.ik.homotopy.counts (make ik-counts) with the homotopy machinery of chain.ik;\n"
        "'how' lists the start set's monodromy runs (for n < 6 the 6-joint set with virtual joints);\n"
        "certified: by the trace test where 'how' names one, else two runs found the count and a run\n"
        "on a second design found no more (weaker).\n"
        "No design has more solutions than its pattern's count, so chain.ik takes a start set that\n"
        "reaches it as complete."
    )
    print(f"{'pattern':8s} {'count':>6s}  {'certified':9s}  how")
    for r in rows:
        print(f"{r['pattern']:8s} {r['count']:6d}  {'yes' if r['certified'] else 'no':9s}  {r['how']}")
    return 0


def _cmd_ik_prepare(args: argparse.Namespace) -> int:
    from .ik.homotopy.trace import MAX_SOLUTIONS

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

    start = chain.prepare_ik(progress=progress, refresh=args.refresh, trace=args.trace)
    if progress:
        print(file=sys.stderr)
    state = f"{'certified' if start.certified else 'NOT certified'} complete: {start.how}"
    if not start.traced and start.count <= MAX_SOLUTIONS and start.generic != start.count:
        state += "; --trace runs the trace test"
    print(
        f"{chain.name}: start system of {start.count} complex solutions, {state}; runs found {start.runs} "
        f"in {start.loops} loops ({start.seconds:.1f} s to compute; cached)"
    )
    return 0


def _parse_numbers(name: str, values: Sequence[str]) -> NDArray[np.float64]:
    """Command-line words as floats; a word that is not a number is an error naming `name`."""
    out = []
    for v in values:
        try:
            out.append(float(v))
        except ValueError:
            raise ValueError(f"{name}: {v!r} is not a number") from None
    return np.array(out)


def _parse_angles(values: Sequence[str], deg: bool) -> NDArray[np.float64]:
    q = _parse_numbers("Q", values)
    return np.radians(q) if deg else q


def _cmd_fk(args: argparse.Namespace) -> int:
    chain = load(args.file)
    q = _parse_angles(args.q, args.deg)
    if q.shape != (chain.n,):
        raise ValueError(f"Q: {chain.name} has {chain.n} joints, got {q.size} angles")
    T = chain.fk(q)
    S = chain.fk_study(q)
    with np.printoptions(precision=12, suppress=True, floatmode="maxprec"):
        print(f"{chain.name}: {chain.n} joints, q = {q} rad (backend: {backend()})")
        print("T =")
        print(T)
        print("Study point (x0 x1 x2 x3 y0 y1 y2 y3) =")
        print(S)
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    motion = polynomials.load("apair_motion")
    print("The A-pair, derived from the six leg constraints of a Griffis-Duffy platform:")
    for label in (
        "consistency",
        "a",
        "b",
        "pair_quadric",
        "law",
        "sinusoidal_L1",
        "sinusoidal_amplitude",
        "law_sinusoidal",
    ):
        e = motion[label]
        print(f"  {label:22s} {e.lhs} = {e.rhs}" if hasattr(e, "rhs") else f"  {label:22s} {e} = 0")
    if args.file:
        chain = load(args.file)
        q = np.linspace(0.3, -0.4, chain.n)
        T = chain.fk(q)
        with np.printoptions(precision=6, suppress=True):
            print(f"\n{chain.name} ({args.file}), q = {q} rad, backend {backend()}:")
            print(T)
            print("Jacobian:")
            print(chain.jacobian(q))
    return 0


def _cmd_variety(args: argparse.Namespace) -> int:
    import sympy as sp

    chain = load(args.file)
    V = chain.constraint_variety()
    if args.json:
        print(
            json.dumps(
                {
                    "chain": chain.name,
                    "exact": V.exact,
                    "degree": V.degree,
                    "residual": V.residual,
                    "hilbert": V.hilbert,
                    "dims": V.dims,
                    "equations": [
                        {"degree": P.total_degree(), "terms": len(P.terms()), "expr": sp.sstr(P.as_expr())} for P in V
                    ],
                },
                indent=1,
            )
        )
        return 0
    kind = "exact" if V.exact else f"floating point, residual {V.residual:.2e}"
    print(f"{chain.name}: constraint variety ({kind}); surface of degree {V.degree}")
    print("Hilbert function: " + ", ".join(f"HF({k}) = {v}" for k, v in V.hilbert.items()))
    for i, P in enumerate(V):
        body = sp.latex(P.as_expr()) if args.latex else sp.sstr(P.as_expr())
        print(f"[{i}] degree {P.total_degree()}, {len(P.terms())} terms\n  {body}")
    return 0


def _parse_pose(values: Sequence[str]) -> NDArray[np.float64]:
    x = _parse_numbers("POSE", values)
    if len(x) == 16:
        return x.reshape(4, 4)
    if len(x) == 12:  # the top three rows of the transform
        return np.vstack([x.reshape(3, 4), [0.0, 0.0, 0.0, 1.0]])
    if len(x) == 8:
        return x
    raise ValueError(
        f"POSE: expected 16 (or 12) numbers of a 4x4 transform, row by row, or the 8 of a Study point, got {len(x)}"
    )


def _cmd_ik(args: argparse.Namespace) -> int:
    from .ik import distance

    chain = load(args.file)
    T = _parse_pose(args.pose)
    sol = chain.ik(T, full=True)
    with np.printoptions(precision=12, suppress=True, floatmode="maxprec"):
        if len(sol.q) == 0:
            dp, dr, q = distance(chain, T)
            why = "" if sol.certified else " (not certified complete)"
            print(
                f"{chain.name}: the pose is unreachable{why}. The nearest pose found inside the joint limits "
                f"(q = {q} rad) is {dp:.3e} m and {dr:.3e} rad away."
            )
            return 1
        complete = "" if sol.certified else "; not certified complete"
        count = f" of {sol.complex_count} complex" if sol.complex_count is not None else ""
        print(
            f"{chain.name}: {len(sol.q)} real solution(s){count}, by {sol.method}{complete}; angles in rad"
            f"{' and deg' if args.deg else ''}"
        )
        for q, e, ok in zip(sol.q, sol.error, cast(NDArray[np.bool_], sol.inside)):  # set by full=True
            extra = f"  = {np.degrees(q)} deg" if args.deg else ""
            print(f"  q = {q}{extra}   |fk(q) - T| = {e:.1e}   {'within' if ok else 'OUTSIDE'} the joint limits")
    return 0


def _cmd_limits(args: argparse.Namespace) -> int:
    chain = load(args.file)
    lim = chain.limits
    print(f"{chain.name}: joint ranges [deg] (explicit, or where the legs or plates first touch)")
    for i, p in enumerate(chain.pairs):
        what = "explicit" if chain._explicit_limits[i] is not None else p.collision_limits().what
        print(f"  joint {i + 1}: {np.degrees(lim[i, 0]):+10.4f} .. {np.degrees(lim[i, 1]):+10.4f}   {what}")
    if args.plot is not None:  # an empty name is refused, not ignored
        from .plots import clearance

        k = next((i for i, p in enumerate(chain.pairs) if p.kind != "revolute"), None)
        if k is None:
            raise ValueError("file: the chain has no A-pair to plot")
        print(f"clearance of joint {k + 1} written to {clearance(chain.pairs[k], args.plot, overwrite=args.force)}")
    return 0


def _cmd_workspace(args: argparse.Namespace) -> int:
    from .workspace import text_progress

    chain = load(args.file)
    if args.plot is not None:  # an empty name is refused, not ignored
        from .files import target

        target(args.plot, args.force)  # refuse before the long run, not after it
    ws = chain.workspace(
        samples=args.samples,
        resolution=args.resolution,
        engine=args.scheduler,
        progress=text_progress() if not args.quiet else None,
    )
    print(
        f"{chain.name}: workspace {ws.summary} from {len(ws.points)} samples; voxel {ws.voxel:.3g} m, "
        f"{len(ws.boundary)} boundary voxels"
    )
    lo, hi = ws.points.min(axis=0), ws.points.max(axis=0)
    print(
        f"  bounding box [m]: x {lo[0]:+.4f} .. {hi[0]:+.4f}, y {lo[1]:+.4f} .. {hi[1]:+.4f}, "
        f"z {lo[2]:+.4f} .. {hi[2]:+.4f}"
    )
    if args.plot is not None:
        print(f"  picture written to {ws.plot(args.plot, overwrite=args.force)}")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    chain = load(args.file)
    q = None if args.q is None else _parse_angles(args.q.split(","), args.deg)
    from . import mjcf
    from .files import write_text

    xml = mjcf.to_mjcf(chain, q, name=chain.name or os.path.basename(args.file), collisions=args.collisions)
    out = write_text(args.out, xml, args.force, ".xml")
    legs = sum(6 for p in chain.pairs if p.kind != "revolute")
    print(
        f"{chain.name}: MuJoCo model written to {out} ({chain.n} pairs, {legs} legs closed by "
        f"{legs} connect constraints; keyframe 0 at q = {np.round(q if q is not None else np.zeros(chain.n), 6).tolist()})"
    )
    return 0


def _cmd_view(args: argparse.Namespace) -> int:
    from . import view

    chain = load(args.file)
    if not 0 <= args.workspace <= view.MAX_WORKSPACE_POINTS:
        raise ValueError(
            f"--workspace: expected a number of samples from 0 to {view.MAX_WORKSPACE_POINTS}, got {args.workspace}"
        )
    out = view.write(chain, args.out, overwrite=args.force, workspace=args.workspace)
    print(f"{chain.name}: viewer written to {out} (open it in a browser; it needs no network)")
    return 0


def _cmd_kernels(args: argparse.Namespace) -> int:
    for name, k in sorted(manifest()["kernels"].items()):
        ins = ", ".join(f"{a['name']}{tuple(a['shape'])}" for a in k["inputs"])
        outs = ", ".join(f"{a['name']}{tuple(a['shape'])}" for a in k["outputs"])
        print(f"{name:18s} {k['ops']:5d} ops  ({ins}) -> {outs}")
    return 0


def _cmd_codegen(args: argparse.Namespace) -> int:
    import time

    from . import specialise

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
    for note in notes:
        print(f"  {note}")
    return 0


class _Parser(argparse.ArgumentParser):
    """argparse's parser that takes every negative number as a value, exponent form included
    (`-1e-3`, `-2.5E+4`, `-inf`): the standard one reads those as unknown options."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self._negative_number_matcher = _NEGATIVE_NUMBER


_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="apair", description="Kinematics of A-pairs and A-chains.")
    ap.add_argument("--version", action="version", version=f"apair {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("list", help="list the derived polynomial sets")
    p.set_defaults(func=_cmd_list)
    p = sub.add_parser("show", help="print a derived polynomial set")
    p.add_argument(
        "name", help="a set from `apair list`, e.g. apair_motion, or ik_counts (the inverse kinematics solution counts)"
    )
    g = p.add_mutually_exclusive_group()
    g.add_argument("--latex", action="store_true", help="LaTeX instead of text")
    g.add_argument("--json", action="store_true", help="the machine-readable form")
    p.set_defaults(func=_cmd_show)
    p = sub.add_parser("fk", help="forward kinematics of a chain file at joint angles Q")
    p.add_argument("file", help="a chain TOML file (docs/reference/chain-files.md)")
    p.add_argument("q", nargs="+", metavar="Q", help="joint angles (radians unless --deg)")
    p.add_argument("--deg", action="store_true", help="angles in degrees")
    p.set_defaults(func=_cmd_fk)
    p = sub.add_parser("variety", help="the constraint variety of a 2-pair chain file")
    p.add_argument("file", help="a chain TOML file with two joints")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--latex", action="store_true", help="equations in LaTeX")
    g.add_argument("--json", action="store_true", help="machine-readable")
    p.set_defaults(func=_cmd_variety)
    p = sub.add_parser("ik", help="all inverse kinematics solutions of a chain file at a pose")
    p.add_argument("file", help="a chain TOML file (1 to 6 sinusoidal A-pairs or R-pairs)")
    p.add_argument(
        "pose",
        nargs="+",
        metavar="POSE",
        help="a 4x4 transform row by row (16 numbers, or the top 12) or a Study point (8)",
    )
    p.add_argument("--deg", action="store_true", help="also print the angles in degrees")
    p.set_defaults(func=_cmd_ik)
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
    p.set_defaults(func=_cmd_ik_prepare)
    p = sub.add_parser("limits", help="joint ranges of a chain file: explicit, or the pairs' collision limits")
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("--plot", metavar="PNG", help="plot the clearance of the first A-pair against theta")
    p.add_argument("--force", action="store_true", help="replace an existing plot file")
    p.set_defaults(func=_cmd_limits)
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
    p.set_defaults(func=_cmd_workspace)
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
        "bias, inverse_dynamics, forward_dynamics, energy (default: all)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="replace files in --out that an earlier apair codegen did not write (never through a link)",
    )
    p.set_defaults(func=_cmd_codegen)
    p = sub.add_parser(
        "export",
        help="the chain in another tool's format: mjcf (a MuJoCo model)",
        description="Write a MuJoCo model (MJCF) of the chain's mechanism: every A-pair as its "
        "Griffis-Duffy platform, legs as bodies closed by equality constraints, motors on the pair axes.",
    )
    p.add_argument("format", choices=["mjcf"], help="the format (mjcf: MuJoCo XML)")
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("out", help="the file to write (.xml)")
    p.add_argument("--q", metavar="Q1,Q2,...", help="the configuration of keyframe 0 (radians unless --deg; default 0)")
    p.add_argument("--deg", action="store_true", help="--q in degrees")
    p.add_argument("--collisions", action="store_true", help="let plates and legs collide (off by default)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    p.set_defaults(func=_cmd_export)
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
    p = sub.add_parser("kernels", help="list the generated kernels with their operation counts")
    p.set_defaults(func=_cmd_kernels)
    p = sub.add_parser("demo", help="print the derived A-pair law and, given a chain file, one pose")
    p.add_argument("file", nargs="?", help="a chain TOML file")
    p.set_defaults(func=_cmd_demo)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; every failure ends in a one-line message and a non-zero exit, never a
    traceback: 2 for bad input, 1 for an unreachable pose, 141 when the reader of the output went
    away (`apair kernels | head`), 130 on Ctrl-C, 3 for an internal error."""
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        code = args.func(args)
        sys.stdout.flush()
        return code
    except BrokenPipeError:
        # the reader closed the pipe: stop quietly, and keep Python from complaining at exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except KeyboardInterrupt:
        print(f"apair {args.command}: interrupted", file=sys.stderr)
        return 130
    except (ValueError, OSError) as exc:
        print(f"apair {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except Exception as exc:
        print(
            f"apair {args.command}: internal error: {type(exc).__name__}: {_one_line(exc)} "
            "(please report this with the command line)",
            file=sys.stderr,
        )
        return 3


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text if len(text) <= 400 else text[:397] + "..."


if __name__ == "__main__":
    sys.exit(main())
