"""MkDocs hook: the benchmark page's tables, rendered at build time from `make bench`'s results.

`docs/benchmarks.md` holds markers such as `<!-- bench:compiled -->`; each is replaced by a
Markdown table computed from `docs/benchmarks/results.json`, the file `bench/run.py` writes (and
`make bench` copies there). Nothing in the page's tables is typed by hand. A section the results
file lacks (a `--quick` or `--native-only` run, a peer that was not installed) is rendered as a
note saying so; an unknown marker fails the build.

Plain Python and the standard library only (mkdocs loads it through `hooks:` in mkdocs.yml).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

PAGE = "benchmarks.md"
RESULTS = "benchmarks/results.json"  # relative to docs_dir
MARKER = re.compile(r"<!--\s*bench:([a-z0-9-]+)\s*-->")
OPS = ("fk", "jacobian", "mass_matrix", "inverse_dynamics", "forward_dynamics")
OP_NAMES = {
    "fk": "forward kinematics",
    "jacobian": "Jacobian",
    "mass_matrix": "mass matrix",
    "inverse_dynamics": "inverse dynamics",
    "forward_dynamics": "forward dynamics",
    "inverse_dynamics_derivatives": "∂ inverse dynamics (∂τ/∂q, ∂τ/∂q′)",
    "forward_dynamics_derivatives": "∂ forward dynamics (∂q″/∂q, ∂q″/∂q′, M⁻¹)",
}
DERIVATIVE_OPS = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives")  # where a run measured them
PEERS = {
    "apair": "apair",
    "apair_specialised": "apair, specialised",
    "pinocchio": "Pinocchio C++",
    "casadi_design": "CasADi, design as inputs",
    "casadi_baked": "CasADi, design baked",
}
PY_COLUMNS = (
    ("c_batched", "C batched"),
    ("c_single", "C, 1 call"),
    ("c_single_api", "API, 1 call"),
    ("specialised_single_api", "specialised, 1 call"),
    ("numpy_batched", "NumPy batched"),
    ("lambdify_loop", "lambdify loop"),
    ("symengine_batched", "symengine"),
    ("pinocchio_per_call", "Pinocchio (Python)"),
)
PY_SINGLE = (
    ("fk", "`fk` / `framesForwardKinematics`"),
    ("jacobian", "`jacobian` / `computeFrameJacobian`"),
    ("mass_matrix", "`mass_matrix` / `crba`"),
    ("inverse_dynamics", "`inverse_dynamics` / `rnea`"),
    ("forward_dynamics", "`forward_dynamics` / `aba`"),
)


# ------------------------------------------------------------------------------------ formatting
def duration(ns: float) -> str:
    """A time per evaluation in ns, µs or ms, three significant digits (as bench/run.py prints it)."""
    if ns >= 1e6:
        return f"{ns / 1e6:.3g} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:.3g} µs"
    return f"{ns:.3g} ns"


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def missing(what: str) -> str:
    return f"!!! note\n    This results file has no {what}."


def _ms(x) -> str:
    if x is None:
        return "–"
    return f"{x / 1e3:.3g} s" if x >= 1e3 else f"{x:.3g} ms"


def _s(x) -> str:
    return "–" if x is None else f"{x:.3g} s"


# ------------------------------------------------------------------------------------ sections
def source(r: dict) -> str:
    src, machine, settings = r.get("source", {}), r.get("machine", {}), r.get("settings", {})
    parts = []
    if src:
        parts.append(
            f"**Results of {src.get('date', 'an undated run')}**"
            + (f" (commit `{src['commit']}`)" if src.get("commit") else "")
            + "."
        )
        if src.get("note"):
            parts.append(src["note"])
    if machine:
        parts.append("Machine: " + ", ".join(f"{k} {v}" for k, v in machine.items()) + ".")
    if settings:
        parts.append("Settings: " + ", ".join(f"{k} {v}" for k, v in settings.items()) + ".")
    return "\n".join(parts) if parts else missing("record of where it came from")


def _opts(tools: dict, prefix: str) -> list[str]:
    return sorted(name.split()[-1] for name in tools if name.split()[0] == prefix)


def compiled(r: dict) -> str:
    """apair's generic kernels against the peers, n = 6 R-chain, ns per evaluation, one table per -O."""
    tools = r.get("native", {}).get("R-chain", {}).get("tools", {})
    out = []
    for opt in _opts(tools, "apair"):
        me = tools[f"apair {opt}"]["ns"]
        peers = [p for p in ("pinocchio", "casadi_design", "casadi_baked") if f"{p} {opt}" in tools]
        rows = []
        for op in OPS + tuple(d for d in DERIVATIVE_OPS if d in me):
            cells = [OP_NAMES[op], f"{me[op]:.0f}"]
            for p in peers:
                t = tools[f"{p} {opt}"]["ns"].get(op)
                cells.append("–" if t is None else f"{t:.0f} ({me[op] / t:.2f})")
            rows.append(cells)
        out.append(table([opt, "apair"] + [PEERS[p] for p in peers], rows))
    return "\n\n".join(out) if out else missing("compiled comparison (bench/native.py)")


def floors(r: dict) -> str:
    """The trigonometric floor of the compiled kernels: sincos alone, the law kernels."""
    rows = []
    for label, res in r.get("native", {}).items():
        if not isinstance(res, dict) or "tools" not in res:
            continue
        for name, t in res["tools"].items():
            ns = t["ns"]
            if "trig_floor" in ns:
                rows.append(
                    [
                        f"{label}, {name} (n = {res['n']})",
                        f"{ns['trig_floor']:.0f}",
                        "–" if "law_kernels" not in ns else f"{ns['law_kernels']:.0f}",
                        f"{ns['fk']:.0f}",
                    ]
                )
    if not rows:
        return missing("trigonometric floor")
    return table(["chain, build", "sincos of the half angles alone [ns]", "the law kernels [ns]", "fk [ns]"], rows)


def ops(r: dict) -> str:
    native = r.get("native", {})
    mine = native.get("apair_ops_per_item")
    if not mine:
        return missing("operation counts")
    theirs = native.get("R-chain", {}).get("casadi_ops", {})
    rows = [[OP_NAMES[op], str(mine[op]), str(theirs.get(op, "–"))] for op in OPS if op in mine]
    return table(["n = 6", "apair (after CSE, per batch item)", "CasADi SX, design as inputs"], rows)


def achains(r: dict) -> str:
    """apair alone on the A-chains (legs with mass): generic and specialised kernels."""
    rows = []
    for label, res in r.get("native", {}).items():
        if label == "R-chain" or not isinstance(res, dict) or "tools" not in res:
            continue
        tools = res["tools"]
        for opt in _opts(tools, "apair"):
            gen = tools[f"apair {opt}"]["ns"]
            spec = tools.get(f"apair_specialised {opt}", {}).get("ns")
            for op in OPS:
                s = "–" if spec is None else f"{spec[op]:.0f} ({spec[op] / gen[op]:.2f})"
                rows.append([f"`{label}` (n = {res['n']})", opt, OP_NAMES[op], f"{gen[op]:.0f}", s])
    if not rows:
        return missing("A-chain section of the compiled comparison")
    return table(["chain", "-O", "operation", "generic [ns]", "specialised [ns] (ratio)"], rows)


def specialised(r: dict) -> str:
    """The chain's own code against CasADi's C with the same constants baked in (R-chain, n = 6)."""
    tools = r.get("native", {}).get("R-chain", {}).get("tools", {})
    opts = [o for o in _opts(tools, "apair_specialised") if f"casadi_baked {o}" in tools]
    if not opts:
        return missing("specialised code beside CasADi's baked code")
    header = ["n = 6 R-chain"]
    for o in opts:
        header += [f"specialised {o}", f"CasADi baked {o}", "ratio"]
    rows = []
    for op in OPS:
        cells = [OP_NAMES[op]]
        for o in opts:
            a, b = tools[f"apair_specialised {o}"]["ns"][op], tools[f"casadi_baked {o}"]["ns"][op]
            cells += [f"{a:.0f}", f"{b:.0f}", f"{a / b:.2f}"]
        rows.append(cells)
    return table(header, rows)


def python_single(r: dict) -> str:
    """Python single calls of the chain API against Pinocchio's Python binding, median ns."""
    six = r.get("kernels", {}).get("6", {})
    if not six:
        return missing("Python timings for n = 6")
    rows = []
    for op, label in PY_SINGLE:
        row = six.get(op, {})
        pin = row.get("pinocchio_per_call", {}).get("median_ns")
        cells = [label]
        for key in ("c_single_api", "specialised_single_api"):
            t = row.get(key, {}).get("median_ns")
            cells.append("–" if t is None else f"{t:.0f}" + (f" ({t / pin:.2f})" if pin else ""))
        cells.append("–" if pin is None else f"{pin:.0f}")
        rows.append(cells)
    derivatives = r.get("derivatives_single", {})
    for op, peer in zip(DERIVATIVE_OPS, ("computeRNEADerivatives", "computeABADerivatives")):
        row = derivatives.get(op)
        if row is None:
            continue
        t, pin = row["c_single_api"]["median_ns"], row.get("pinocchio_per_call", {}).get("median_ns")
        cells = [f"`{op}` / `{peer}`", f"{t:.0f}" + (f" ({t / pin:.2f})" if pin else ""), "–"]
        rows.append(cells + ["–" if pin is None else f"{pin:.0f}"])
    return table(
        ["n = 6, ns (ratio to Pinocchio)", "generic chain", "specialised chain", "Pinocchio's Python binding"], rows
    )


def python(r: dict) -> str:
    """Every way to evaluate from Python, per n: medians per evaluation."""
    kernels = r.get("kernels", {})
    if not kernels:
        return missing("Python timings")
    out = []
    for n in sorted(kernels, key=int):
        rows_in = kernels[n]
        cols = [(k, h) for k, h in PY_COLUMNS if any(k in row for row in rows_in.values())]
        rows = []
        for op in OPS:
            row = rows_in.get(op)
            if row is None:
                continue
            rows.append(
                [OP_NAMES[op], str(row["ops"])]
                + ["–" if k not in row else duration(row[k]["median_ns"]) for k, _ in cols]
            )
        out.append(table([f"n = {n}", "ops"] + [h for _, h in cols], rows))
    return "\n\n".join(out)


def batch_scaling(r: dict) -> str:
    scaling = r.get("batch_scaling")
    if not scaling:
        return missing("batch-size scaling")
    sizes = sorted({int(s) for rows in scaling.values() for s in rows})
    rows = [
        [f"`{name}`"] + ["–" if str(s) not in by else duration(by[str(s)]["median_ns"]) for s in sizes]
        for name, by in scaling.items()
    ]
    return table(["C kernel, per item"] + [f"batch of {s:,}" for s in sizes], rows)


def ik4(r: dict) -> str:
    ik = r.get("ik")
    if not ik:
        return missing("4-joint inverse kinematics")
    rows = [
        [f"{name} ({v['poses']} poses)", _ms(v.get("median_ms")), _ms(v.get("p90_ms")), _ms(v.get("max_ms"))]
        for name, v in ik.items()
    ]
    return table(["chain", "median", "p90", "worst"], rows)


def ik6(r: dict) -> str:
    ik = r.get("ik6")
    if not ik:
        return missing("6-joint inverse kinematics")
    rows = []
    for pattern, v in ik.items():
        start = (
            f"{v['start_count']}"
            + (", certified" if v.get("start_certified") else ", not certified")
            + f" ({_s(v.get('prepare_s'))})"
        )
        trace = "–" if v.get("trace_s") is None else _s(v["trace_s"])
        routes = ", ".join(f"{k} {c}" for k, c in sorted(v.get("methods", {}).items()))
        rows.append(
            [
                f"`{pattern}`, {v['poses']} poses",
                start,
                trace,
                _ms(v.get("median_ms")),
                _ms(v.get("max_ms")),
                f"{v['round_trips_found']} / {v['poses']} ({v['certified_poses']} certified)",
                routes,
            ]
        )
    return table(
        [
            "chain (random design)",
            "start set (prepared once)",
            "trace test",
            "median per pose",
            "worst",
            "round trips found",
            "route",
        ],
        rows,
    )


def misc(r: dict) -> str:
    rows = []
    loc = r.get("ik_local")
    if loc:
        rows.append(
            [
                "`ik_local`, n = 6, seeds within 0.3 rad",
                f"{loc['us_per_converged']:.3g} µs per converged solve"
                + (f", {loc['converged']:.0%} converge" if "converged" in loc else ""),
            ]
        )
    if r.get("make_generate_s") is not None:
        rows.append(["`make generate` (every derivation and kernel)", _s(r["make_generate_s"])])
    if r.get("codegen_6_s") is not None:
        rows.append(["`apair codegen` of a 6-joint A-chain, every kernel, fresh process", _s(r["codegen_6_s"])])
    return table(["what", "time"], rows) if rows else missing("other timings")


def _targets(items: list | None, what: str) -> str:
    if not items:
        return missing(what)
    rows = [[t["target"], f"{t['measured']:.3g}", "met" if t["met"] else "**missed**"] for t in items]
    return table(["target", "measured", ""], rows)


SECTIONS = {
    "source": source,
    "compiled": compiled,
    "floors": floors,
    "ops": ops,
    "achains": achains,
    "specialised": specialised,
    "python-single": python_single,
    "python": python,
    "batch-scaling": batch_scaling,
    "ik4": ik4,
    "ik6": ik6,
    "misc": misc,
    "targets-compiled": lambda r: _targets(r.get("native_targets"), "compiled targets"),
    "targets": lambda r: _targets(r.get("targets"), "targets from Python"),
}


def render(markdown: str, results: dict) -> str:
    """Replace every `<!-- bench:NAME -->` marker by its table; an unknown NAME is an error."""

    def one(m: re.Match) -> str:
        name = m.group(1)
        if name not in SECTIONS:
            raise ValueError(f"{PAGE}: unknown benchmark section {name!r} (known: {', '.join(SECTIONS)})")
        return SECTIONS[name](results)

    return MARKER.sub(one, markdown)


def load(docs_dir) -> dict:
    return json.loads((Path(docs_dir) / RESULTS).read_text())


# ------------------------------------------------------------------------------------ mkdocs events
def on_page_markdown(markdown: str, page, config, files) -> str:
    if page.file.src_uri != PAGE:
        return markdown
    from mkdocs.exceptions import PluginError

    try:
        return render(markdown, load(config["docs_dir"]))
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise PluginError(f"benchmark tables: {exc}") from exc
