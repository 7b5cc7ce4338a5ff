"""`apair list`, `show`, `variety`, `kernels` and `demo`: what was derived and generated."""

from __future__ import annotations

import argparse
import json
from typing import Any

import numpy as np

from .. import polynomials
from ..io import load
from ..kernels import backend, manifest
from .output import add_json, emit

Sub = Any  # argparse's subparsers action (a private class)
# how `apair kernels` counts (generated/manifest.json's ops_per_item, what docs/benchmarks.md shows)
COUNTED = (
    "operations per evaluation after CSE, as the code generator counts them (manifest ops_per_item): per "
    "item of a batch that shares one design (work on the design alone done once per batch), the "
    "operations of the kernels a kernel calls counted in"
)

HEADER = (
    "(operations per item after CSE: a batch sharing one design does the design's own work once; callees counted in)"
)


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
    from ..ik.homotopy import stored_counts

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


def _cmd_variety(args: argparse.Namespace) -> int:
    import sympy as sp

    chain = load(args.file)
    V = chain.constraint_variety()
    if args.json:
        equations = [{"degree": P.total_degree(), "terms": len(P.terms()), "expr": sp.sstr(P.as_expr())} for P in V]
        emit(
            {
                "chain": chain.name,
                "exact": V.exact,
                "degree": V.degree,
                "residual": V.residual,
                "hilbert": V.hilbert,
                "dims": V.dims,
                "equations": equations,
            }
        )
        return 0
    kind = "exact" if V.exact else f"floating point, residual {V.residual:.2e}"
    print(f"{chain.name}: constraint variety ({kind}); surface of degree {V.degree}")
    print("Hilbert function: " + ", ".join(f"HF({k}) = {v}" for k, v in V.hilbert.items()))
    for i, P in enumerate(V):
        body = sp.latex(P.as_expr()) if args.latex else sp.sstr(P.as_expr())
        print(f"[{i}] degree {P.total_degree()}, {len(P.terms())} terms\n  {body}")
    return 0


def _kernel_rows() -> dict[str, dict[str, Any]]:
    """Per generated kernel: its operation count per item (COUNTED), its own count (the manifest's
    ops: everything it computes itself, the design-only work included, its callees not),
    whether it is a composite (no operation of its own: all in the kernels it calls), and its
    inputs and outputs with their shapes."""
    rows = {}
    for name, k in sorted(manifest()["kernels"].items()):
        rows[name] = {
            "ops_per_item": k["ops_per_item"],
            "own_ops": k["ops"],
            "composite": k["ops"] == 0 and k["ops_per_item"] > 0,
            "inputs": [{"name": a["name"], "shape": a["shape"]} for a in k["inputs"]],
            "outputs": [{"name": a["name"], "shape": a["shape"]} for a in k["outputs"]],
        }
    return rows


def _cmd_kernels(args: argparse.Namespace) -> int:
    rows = _kernel_rows()
    if args.json:
        emit({"counted": COUNTED, "kernels": rows})
        return 0
    print(f"{'kernel':18s} {'ops':>5s}  {HEADER}")
    for name, k in rows.items():
        ins = ", ".join(f"{a['name']}{tuple(a['shape'])}" for a in k["inputs"])
        outs = ", ".join(f"{a['name']}{tuple(a['shape'])}" for a in k["outputs"])
        composite = "   composite: its operations are those of the kernels it calls" if k["composite"] else ""
        print(f"{name:18s} {k['ops_per_item']:5d} ops  ({ins}) -> {outs}{composite}")
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


def add_list(sub: Sub) -> None:
    p = sub.add_parser("list", help="list the derived polynomial sets")
    p.set_defaults(func=_cmd_list)


def add_show(sub: Sub) -> None:
    p = sub.add_parser("show", help="print a derived polynomial set")
    p.add_argument(
        "name", help="a set from `apair list`, e.g. apair_motion, or ik_counts (the inverse kinematics solution counts)"
    )
    g = p.add_mutually_exclusive_group()
    g.add_argument("--latex", action="store_true", help="LaTeX instead of text")
    g.add_argument("--json", action="store_true", help="the machine-readable form")
    p.set_defaults(func=_cmd_show)


def add_variety(sub: Sub) -> None:
    p = sub.add_parser("variety", help="the constraint variety of a 2-pair chain file")
    p.add_argument("file", help="a chain TOML file with two joints")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--latex", action="store_true", help="equations in LaTeX")
    g.add_argument("--json", action="store_true", help="machine-readable")
    p.set_defaults(func=_cmd_variety)


def add_kernels(sub: Sub) -> None:
    p = sub.add_parser("kernels", help="list the generated kernels with their operation counts")
    add_json(p)
    p.set_defaults(func=_cmd_kernels)


def add_demo(sub: Sub) -> None:
    p = sub.add_parser("demo", help="print the derived A-pair law and, given a chain file, one pose")
    p.add_argument("file", nargs="?", help="a chain TOML file")
    p.set_defaults(func=_cmd_demo)
