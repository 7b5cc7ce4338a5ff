"""`apair fk`, `jacobian`, `dynamics` and `limits`: a chain file evaluated at one configuration,
and its joint ranges."""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..chain import AChain
from ..io import load
from ..kernels import backend
from . import args as A
from .output import add_json, emit, note, text_numbers

Sub = Any  # argparse's subparsers action (a private class)
DYNAMICS_UNITS = {
    "q": "rad",
    "qd": "rad/s",
    "qdd": "rad/s^2",
    "tau": "N m",
    "M": "kg m^2",
    "bias": "N m",
    "gravity": "N m",
}


def _configuration(args: argparse.Namespace, strict: bool) -> tuple[AChain, NDArray[np.float64]]:
    """The chain and its angles Q [rad] (given in degrees with --deg), one per joint, each within
    its pair's range of motion (`strict`: short of its end)."""
    chain = load(args.file)
    q = A.angles(chain, "Q", A.numbers("Q", args.q), args.deg, strict)
    return chain, q


def _outside(command: str, chain: AChain, q: NDArray[np.float64], deg: bool, what: str) -> list[dict[str, Any]]:
    """The joints beyond their limits (args.outside_limits), each also said in a note on stderr:
    the result is computed all the same, since the kinematics are defined there."""
    entries = A.outside_limits(chain, q)
    for entry in entries:
        note(command, f"{A.limits_text(entry, deg)} (see apair limits); the {what} is computed all the same")
    return entries


def _document(chain: AChain, units: dict[str, str], **values: Any) -> dict[str, Any]:
    """A command's JSON document: the chain, its joint count, the backend, the units, `values`."""
    return {"chain": chain.name, "n": chain.n, "backend": backend(), "units": units, **values}


def _header(chain: AChain, q: NDArray[np.float64]) -> str:
    unit = "rad" if all(p.kind != "prismatic" for p in chain.pairs) else "rad; m for slides"
    return f"{chain.name}: {chain.n} joints, q = {q} {unit} (backend: {backend()})"


def _cmd_fk(args: argparse.Namespace) -> int:
    chain, q = _configuration(args, strict=False)
    T = chain.fk(q)
    S = chain.fk_study(q)
    outside = _outside("fk", chain, q, args.deg, "pose")
    if args.json:
        emit(_document(chain, {"angles": "rad", "lengths": "m"}, q=q, T=T, study=S, outside_limits=outside))
        return 0
    with text_numbers():
        print(_header(chain, q))
        print("T =")
        print(T)
        print("Study point (x0 x1 x2 x3 y0 y1 y2 y3) =")
        print(S)
    return 0


def _cmd_jacobian(args: argparse.Namespace) -> int:
    chain, q = _configuration(args, strict=True)
    J = chain.jacobian(q)
    outside = _outside("jacobian", chain, q, args.deg, "Jacobian")
    if args.json:
        units = {"angles": "rad", "J": "rows v [m/rad], omega [rad/rad]"}
        emit(_document(chain, units, q=q, J=J, outside_limits=outside))
        return 0
    with text_numbers():
        print(_header(chain, q))
        print(
            f"J = (6 x {chain.n}, base frame, rows [v; omega]: v of frame {chain.n}'s origin [m/rad], omega [rad/rad])"
        )
        print(J)
    return 0


def _dynamics_inputs(args: argparse.Namespace, chain: AChain) -> dict[str, NDArray[np.float64]]:
    """--q, --qd (default 0) and --qdd or --tau, each one number per joint."""
    q = A.angles(chain, "--q", A.number_list("--q", args.q), False, strict=True)
    values = {"q": q, "qd": np.zeros(chain.n)}
    for key in ("qd", "qdd", "tau"):
        text = getattr(args, key)
        if text is not None:
            values[key] = A.joint_vector(chain, f"--{key}", A.number_list(f"--{key}", text))
    return values


def _dynamics(chain: AChain, x: dict[str, NDArray[np.float64]]) -> dict[str, Any]:
    """M, the bias and g at (q, qd), and the inverse dynamics (given qdd) or the forward (given tau)."""
    q, qd = x["q"], x["qd"]
    out: dict[str, Any] = {"M": chain.mass_matrix(q), "bias": chain.bias(q, qd), "gravity": chain.gravity_torques(q)}
    if "qdd" in x:
        return out | {"dynamics": "inverse", "qdd": x["qdd"], "tau": chain.inverse_dynamics(q, qd, x["qdd"])}
    if "tau" in x:
        return out | {"dynamics": "forward", "tau": x["tau"], "qdd": chain.forward_dynamics(q, qd, x["tau"])}
    return out | {"dynamics": None}


def _cmd_dynamics(args: argparse.Namespace) -> int:
    chain = load(args.file)
    x = _dynamics_inputs(args, chain)
    with A.named({"links": args.file}):  # forward dynamics: a link without mass or inertia
        out = _dynamics(chain, x)
    outside = _outside("dynamics", chain, x["q"], False, "dynamics")
    if args.json:
        emit(_document(chain, DYNAMICS_UNITS, q=x["q"], qd=x["qd"], **out, outside_limits=outside))
        return 0
    _print_dynamics(chain, x, out)
    return 0


def _print_dynamics(chain: AChain, x: dict[str, NDArray[np.float64]], out: dict[str, Any]) -> None:
    """The text of `apair dynamics`: the inputs, M, the bias, g, and tau or qdd."""
    with text_numbers():
        given = ", ".join(f"{k} = {v} {DYNAMICS_UNITS[k]}" for k, v in x.items())
        print(f"{chain.name}: {chain.n} joints, {given} (backend: {backend()})")
        print("M (mass matrix) [kg m^2] =")
        print(out["M"])
        print("bias C(q, qd) qd + g(q) [N m] =")
        print(out["bias"])
        print("gravity g(q) [N m] =")
        print(out["gravity"])
        if out["dynamics"] == "inverse":
            print("tau = M qdd + bias (inverse dynamics) [N m] =")
            print(out["tau"])
        elif out["dynamics"] == "forward":
            print("qdd = M^-1 (tau - bias) (forward dynamics) [rad/s^2] =")
            print(out["qdd"])


def _cmd_limits(args: argparse.Namespace) -> int:
    chain = load(args.file)
    lim = chain.limits
    joints = [
        {
            "joint": i + 1,
            "limits": lim[i],
            "limits_deg": None if p.kind == "prismatic" else np.degrees(lim[i]),  # a slide's range is in m
            "what": "explicit" if chain._explicit_limits[i] is not None else p.collision_limits().what,
        }
        for i, p in enumerate(chain.pairs)
    ]
    plot = _clearance_plot(args, chain)
    slides = any(p.kind == "prismatic" for p in chain.pairs)
    if args.json:
        units = {"limits": "rad", "limits_deg": "deg"}
        if slides:  # the units of a chain without slides stay as they were
            units = {"limits": "rad (m for a prismatic joint)", "limits_deg": "deg (none for a prismatic joint)"}
        emit({"chain": chain.name, "units": units, "joints": joints, "plot": plot})
        return 0
    unit = "deg; mm for slides" if slides else "deg"
    print(f"{chain.name}: joint ranges [{unit}] (explicit, or where the legs or plates first touch)")
    for j, p in zip(joints, chain.pairs):
        lo, hi = np.asarray(j["limits"]) * 1000 if p.kind == "prismatic" else j["limits_deg"]
        print(f"  joint {j['joint']}: {lo:+10.4f} .. {hi:+10.4f}   {j['what']}")
    if plot is not None:
        print(f"clearance of joint {plot['joint']} written to {plot['path']}")
    return 0


def _clearance_plot(args: argparse.Namespace, chain: AChain) -> dict[str, Any] | None:
    """--plot: the clearance of the first A-pair, written; {"joint", "path"}, or None without --plot."""
    if args.plot is None:  # an empty name is refused, not ignored
        return None
    from ..plots import clearance

    k = next((i for i, p in enumerate(chain.pairs) if p.is_apair), None)
    if k is None:
        raise ValueError("file: the chain has no A-pair to plot")
    return {"joint": k + 1, "path": str(clearance(chain.pairs[k], args.plot, overwrite=args.force))}


def add_fk(sub: Sub) -> None:
    p = sub.add_parser("fk", help="forward kinematics of a chain file at joint angles Q")
    p.add_argument("file", help="a chain TOML file (docs/reference/chain-files.md)")
    p.add_argument("q", nargs="+", metavar="Q", help="joint angles (radians unless --deg)")
    p.add_argument("--deg", action="store_true", help="angles in degrees")
    add_json(p)
    p.set_defaults(func=_cmd_fk)


def add_jacobian(sub: Sub) -> None:
    p = sub.add_parser("jacobian", help="the geometric Jacobian (6 x n, rows [v; omega]) of a chain file at Q")
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("q", nargs="+", metavar="Q", help="joint angles (radians unless --deg)")
    p.add_argument("--deg", action="store_true", help="angles in degrees (the Jacobian stays per radian)")
    add_json(p)
    p.set_defaults(func=_cmd_jacobian)


def add_dynamics(sub: Sub) -> None:
    p = sub.add_parser(
        "dynamics",
        help="mass matrix, bias and gravity torques of a chain file, and inverse or forward dynamics",
        description="M(q), the bias C(q, qd) qd + g(q) and the gravity torques g(q); with --qdd the "
        "inverse dynamics tau = M qdd + bias, with --tau the forward dynamics qdd = M^-1 (tau - bias). "
        "Radians, rad/s, rad/s^2, N m.",
    )
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("--q", required=True, metavar="Q1,Q2,...", help="joint angles [rad]")
    p.add_argument("--qd", metavar="QD1,QD2,...", help="joint velocities [rad/s] (default 0)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--qdd", metavar="QDD1,QDD2,...", help="joint accelerations [rad/s^2]: print tau")
    g.add_argument("--tau", metavar="TAU1,TAU2,...", help="joint torques [N m]: print qdd")
    add_json(p)
    p.set_defaults(func=_cmd_dynamics)


def add_limits(sub: Sub) -> None:
    p = sub.add_parser("limits", help="joint ranges of a chain file: explicit, or the pairs' collision limits")
    p.add_argument("file", help="a chain TOML file")
    p.add_argument("--plot", metavar="PNG", help="plot the clearance of the first A-pair against theta")
    p.add_argument("--force", action="store_true", help="replace an existing plot file")
    add_json(p)
    p.set_defaults(func=_cmd_limits)
