"""The comparison as rows of words: (what, the chain's, the twin's), for the text table and the
report's table."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

import numpy as np

from .result import Findings, Measures, PathRun

Row = tuple[str, str, str]


def num(x: float | None, digits: int = 3) -> str:
    """A number to `digits` significant digits ("-" for None, "inf" for infinity)."""
    if x is None:
        return "-"
    if not math.isfinite(x):
        return "inf" if x > 0 else "-inf" if x < 0 else "nan"
    return f"{x:.{digits}g}"


def joints(values: Iterable[float], digits: int = 3) -> str:
    """Per-joint numbers, space-separated; one below 1e-12 of the row's largest is rounding, shown
    as 0 (a vertical R-pair's gravity torque)."""
    row = [float(v) for v in values]
    top = max((abs(v) for v in row if math.isfinite(v)), default=0.0)
    return " ".join("0" if abs(v) <= 1e-12 * top else num(v, digits) for v in row)


def _workspace(m: Measures) -> str:
    ws = m.workspace
    if ws.dimension == 3:
        return f"{num(ws.volume)} ± {num(ws.volume_error, 2)}"
    unit = "m" if ws.dimension == 1 else "m^2"
    return f"{'curve' if ws.dimension == 1 else 'surface'}, {num(ws.measure)} {unit}"


def ranges(m: Measures) -> str:
    """Each joint's range in degrees: "full" for a joint that turns fully, ±x for a symmetric one."""
    out = []
    for free, (lo, hi) in zip(m.full_turn, np.degrees(m.limits)):
        out.append("full" if free else f"±{num(hi, 4)}" if math.isclose(-lo, hi) else f"{num(lo, 4)}..{num(hi, 4)}")
    return " ".join(out)


def _spread(m: Measures, what: str) -> str:
    p5, p50, p95 = m.percentiles(what)
    return f"{num(p5)} / {num(p50)} / {num(p95)}"


def _span(counts: list[int]) -> str:
    lo, hi = min(counts), max(counts)
    return str(lo) if lo == hi else f"{lo}-{hi}"


def _ik(m: Measures) -> str:
    if not m.ik_real_counts:
        return "- (n > 4)" if len(m.pairs) > 4 else "- (P-, H- or general pairs)"
    return f"{m.ik_complex_count}; {_span(m.ik_real_counts)} ({_span(m.ik_real_inside_counts)} inside limits)"


def _path(run: PathRun, what: str) -> str:
    if not run.followed:
        return "not followed"
    if what == "peak":
        return joints(run.peak_torque if run.peak_torque is not None else [])
    return num(run.energy)


def rows(f: Findings) -> list[Row]:
    """The table's rows: (what [unit], the chain's, the twin's)."""
    c, t, s = f.chain, f.twin, f.shared
    pair: list[tuple[str, Callable[[Measures], str]]] = [
        ("workspace: volume [m^3] (or area)", _workspace),
        ("joint ranges [deg]", ranges),
        ("axial travel per joint [mm]", lambda m: joints(1e3 * m.axial_travel)),
        ("mass, legs included [kg]", lambda m: f"{num(m.mass)} (legs {num(m.leg_mass)})"),
        ("mean joint inertia [kg m^2]", lambda m: joints(m.inertia_mean)),
        ("manipulability 5% / median / 95%", lambda m: _spread(m, "manipulability")),
        ("condition number 5% / median / 95%", lambda m: _spread(m, "condition")),
        ("near a singularity [% of samples]", lambda m: num(100 * m.near_singular)),
        ("max |gravity torque| [N m]", lambda m: joints(m.gravity_torque_max)),
        ("RMS gravity torque [N m]", lambda m: joints(m.gravity_torque_rms)),
        ("ik solutions: complex; real", _ik),
        ("path: peak |torque| [N m]", lambda m: _path(m.path, "peak")),
        ("path: energy [J]", lambda m: _path(m.path, "energy")),
    ]
    out: list[Row] = [(what, how(c), how(t)) for what, how in pair]
    out.insert(1, ("reached by it alone [% of both]", num(100 * s.only_chain), num(100 * s.only_twin)))
    return out


def table(f: Findings) -> str:
    """The comparison as aligned text: a title line, the rows, the path's fate and the settings."""
    s = f.settings
    head = (
        f"{f.chain.name} beside its {s['twin']} twin ({s['samples']} workspace samples, seed {s['seed']}, "
        f"{s['seconds']:.1f} s)"
    )
    body = [("", "chain", "twin"), *rows(f)]
    w0 = max(len(r[0]) for r in body)
    w1 = max(len(r[1]) for r in body)
    lines = [head] + [f"  {a:<{w0}}  {b:<{w1}}  {c}".rstrip() for a, b, c in body]
    lines += [f"  {n}" for n in notes(f)]
    return "\n".join(lines)


def notes(f: Findings) -> list[str]:
    """What the table needs said: the path, the grid, the scale and the threshold."""
    s, sh = f.settings, f.shared
    out = []
    if sh.path_corners is not None:
        a, b = (" ".join(f"{x:+.3f}" for x in p) for p in sh.path_corners[[0, -1]])
        length = float(np.linalg.norm(np.diff(sh.path_corners, axis=0), axis=1).sum())
        inner = len(sh.path_corners) - 2
        via = f" through {inner} corner{'s' if inner > 1 else ''}" if inner else ""
        out.append(f"path: {length:.3f} m from ({a}) to ({b}) m{via} in {s['duration']:g} s, quintic timing")
    for m, who in ((f.chain, "chain"), (f.twin, "twin")):
        if not m.path.followed:
            out.append(f"path not followed by the {who}: {m.path.reason}")
    out.append(f"workspaces compared on voxels of {sh.voxel:.3g} m (the coarser volume voxel)")
    out.append(
        f"dexterity over {s['dexterity_samples']} joint samples, translations in units of {s['length_scale']:.3g} m "
        f"(scale-free); near a singularity: sigma_min/sigma_max < {s['singular_threshold']:g}"
    )
    return out
