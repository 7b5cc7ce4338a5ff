"""`python -m codegen [--out DIR] [--only NAME ...] [--jobs N]`: run the derivations and write generated/.

The work is split into jobs: one per derivation, or one per part for a derivation that declares
`PARTS` (then `derive(part)` returns that part's sets and specs). Each job derives, lowers (CSE)
and prints its kernels in a worker process (lowering/); the results are put back in the canonical
order (derivation, then part), so the output does not depend on which worker finished first. The
backends then render them (render.py: C, NumPy, JavaScript, the polynomial sets, the manifest).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from . import derivation
from .backends.polynomials import render as render_polynomials
from .lowering import lower
from .output import OutputError, write
from .render import render_all

DERIVATIONS = (
    "apair_collisions",
    "apair_pair",
    "apair_dynamics",
    "chain_kinematics",
    "chain_dynamics",
    "chain_dynamics_derivatives",
    "chain_variety",
    "chain_ik",
    "chain_ik6r",
    "chain_ik1a5r",
    "chain_ik_wrist",
    "chain_ik_parallel",
    "chain_ik_three_parallel",
    "chain_ik_parallel_apair",
    "chain_ik_wrist_apair",
)
# The derivations whose kernels a derivation's kernels call (`Call`): --only runs them too.
NEEDS = {"chain_dynamics_derivatives": ("chain_dynamics",)}
ROOT = Path(__file__).resolve().parent.parent
# Rough cost of each job on one core [s], for scheduling the longest first.
COST = {
    ("chain_dynamics", 7): 55,
    ("chain_dynamics", 6): 40,
    ("chain_dynamics", 5): 28,
    ("chain_dynamics", 4): 20,
    ("chain_dynamics", "check"): 15,
    ("chain_dynamics_derivatives", 7): 35,
    ("chain_dynamics_derivatives", 6): 22,
    ("chain_dynamics_derivatives", 5): 14,
    ("chain_dynamics_derivatives", 4): 8,
    ("apair_dynamics", None): 9,
    ("apair_pair", None): 8,
    ("chain_variety", None): 7,
    ("chain_dynamics", 3): 6,
    ("chain_kinematics", None): 6,
    ("chain_ik", None): 20,
    ("chain_ik6r", None): 3,
    ("chain_ik1a5r", 1): 12,
    ("chain_ik1a5r", 2): 12,
    ("chain_ik1a5r", 3): 12,
    ("chain_ik_wrist", None): 2,
    ("chain_ik_parallel", None): 2,
    ("chain_ik_three_parallel", None): 1,
    ("chain_ik_parallel_apair", None): 2,
    ("chain_ik_wrist_apair", None): 2,
}


def jobs(names) -> list[tuple[str, object]]:
    """(derivation, part) pairs in canonical order; part None for a derivation without PARTS."""
    out = []
    for name in names:
        module = derivation(name)
        out += [(name, part) for part in getattr(module, "PARTS", (None,))]
    return out


def run_job(name: str, part) -> tuple[float, dict[str, str], list]:
    """Derive one job and lower its kernels: (seconds, polynomial files, lowered kernels)."""
    t0 = time.perf_counter()
    module = derivation(name)
    sets, specs, _facts = module.derive() if part is None else module.derive(part)
    return time.perf_counter() - t0, render_polynomials(sets), [lower(s) for s in specs]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m codegen", description=__doc__)
    ap.add_argument("--out", type=Path, default=ROOT / "generated", help="output folder (default: generated/)")
    ap.add_argument("--only", nargs="*", choices=sorted(DERIVATIONS), help="run only these derivations (no clean-up)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes (default: all cores)")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        ap.error(f"--jobs: expected a positive number, got {args.jobs}")
    t_start = time.perf_counter()
    only = None if args.only is None else {m for name in args.only for m in (name, *NEEDS.get(name, ()))}
    todo = jobs([name for name in DERIVATIONS if name in only] if only else DERIVATIONS)
    order = sorted(range(len(todo)), key=lambda i: -COST.get(todo[i], 1))
    results = [None] * len(todo)
    if args.jobs == 1:
        for i in order:
            results[i] = run_job(*todo[i])
    else:
        with ProcessPoolExecutor(max_workers=min(args.jobs, len(todo))) as pool:
            futures = {i: pool.submit(run_job, *todo[i]) for i in order}
            for i, f in futures.items():
                results[i] = f.result()
    lowered, poly_files = {}, {}
    for (name, part), (seconds, polys, kernels) in zip(todo, results):
        lowered.setdefault(name, []).extend(kernels)
        poly_files.update(polys)
        label = name if part is None else f"{name} [{part}]"
        print(
            f"derived and lowered {label}: {len(kernels)} kernels, {len(polys) // 3} polynomial sets ({seconds:.1f} s)",
            file=sys.stderr,
        )
    t0 = time.perf_counter()
    files = render_all(lowered, poly_files)
    try:
        changed = write(files, args.out, clean=args.only is None)
    except OutputError as exc:
        print(f"python -m codegen: error: {exc}", file=sys.stderr)
        return 2
    print(
        f"emitted {len(files)} files ({time.perf_counter() - t0:.1f} s; {time.perf_counter() - t_start:.1f} s "
        f"in all with {args.jobs} jobs); changed: {len(changed)}",
        file=sys.stderr,
    )
    for c in changed:
        print(f"  {c}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
