"""The design search at the issue's size, timed: `apair design` with a budget of 1500 candidates for
a 4-joint chain (examples/design: six varied values) and 60 point targets, on 1 and on 2 Dask
worker processes; the issue's targets are 20 minutes at most and a speed-up of 1.7 or more.

The targets are 57 of examples/design/targets.csv (made by a design inside the bounds) and 3 points
beyond any design's reach: no candidate reaches all 60, so the search never stops early and
evaluates its whole budget. Each cluster is started and warmed up (apair imported, the collision
polynomials loaded) before the clock starts; the time is the search's, wall clock. Beside it: the
workers' CPU seconds, the load average, the share of a core each worker had (other processes on
the machine take the rest) and the speed-up by CPU time (the first run's work over the busiest
worker's of the last: what a core per worker would give). Both runs must give the same design.

    python bench/design_bench.py [--candidates 1500] [--workers 1,2] [--out FILE.json]

bench/run.py calls `time_design` and `design_targets`.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from dask.distributed import Client, LocalCluster

from apair.design import design, load_spec
from apair.design.evaluate import evaluate
from apair.design.targets import read_targets

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "design"
FAR = 3.0  # [m] from the base: beyond the reach of every design within the example's bounds
LIMIT_S = 20 * 60
SPEEDUP = 1.7


def design_problem(folder: Path) -> Path:
    """The benchmark's spec in `folder`: the example's start and spec, its first 57 targets and 3
    beyond reach. Returns the spec's path."""
    for name in ("spec.toml", "start.toml"):
        shutil.copy(EXAMPLE / name, folder / name)
    rows = read_targets("targets", {"points": "targets.csv", "tolerance": 1.0}, EXAMPLE).values
    far = FAR * np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    points = np.concatenate([rows[:57], far])
    lines = ["x,y,z"] + [",".join(repr(float(v)) for v in p) for p in points]
    (folder / "targets.csv").write_text("\n".join(lines) + "\n")
    return folder / "spec.toml"


def time_design(candidates: int = 1500, workers: tuple[int, ...] = (1, 2), quick: bool = False) -> dict:
    """Seconds of the search on each worker count, the speed-up of the last over the first, and
    what the search reached (the same on every count, checked)."""
    if quick:
        candidates = min(candidates, 120)
    out: dict = {"candidates": candidates, "joints": 4, "targets": 60, "cpu_count": os.cpu_count()}
    out |= {"seconds": {}, "worker_cpu_s": {}, "main_cpu_s": {}, "load_average": {}}
    with tempfile.TemporaryDirectory() as tmp:
        spec = dataclasses.replace(load_spec(design_problem(Path(tmp))), budget=candidates)
        out["varied"] = len(spec.variables)
        results = {}
        for n in workers:
            with (
                LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    silence_logs=logging.CRITICAL,
                ) as cluster,
                Client(cluster) as client,
            ):
                client.run(evaluate, spec, spec.x0)  # apair imported, the collision polynomials loaded
                cpu0, load0 = client.run(time.process_time), os.getloadavg()[0]
                t0, main0 = time.perf_counter(), time.process_time()
                r = design(spec, scheduler=client)
                out["seconds"][str(n)] = time.perf_counter() - t0
                cpu = {k: v - cpu0[k] for k, v in client.run(time.process_time).items()}
                out["worker_cpu_s"][str(n)] = sorted(cpu.values())
                out["main_cpu_s"][str(n)] = time.process_time() - main0
                out["load_average"][str(n)] = [load0, os.getloadavg()[0]]
            results[n] = r
            print(f"design search, {n} worker(s): {out['seconds'][str(n)]:.1f} s, {r.summary}", file=sys.stderr)
        first = results[workers[0]]
        out["same_result"] = all(
            r.values == first.values and r.objectives == first.objectives for r in results.values()
        )
        out["evaluated"] = first.evaluated
        out["objectives"] = first.objectives
        a, b = str(workers[0]), str(workers[-1])
        out["speedup"] = out["seconds"][a] / out["seconds"][b]
        # how much of a core each worker had (other processes on the machine take the rest), and
        # the speed-up the work's division would give with a core per worker
        out["core_share"] = {
            n: sum(out["worker_cpu_s"][n]) / (len(out["worker_cpu_s"][n]) * t) for n, t in out["seconds"].items()
        }
        out["speedup_by_cpu"] = sum(out["worker_cpu_s"][a]) / max(out["worker_cpu_s"][b])
        out["workers"] = list(workers)
    return out


def design_targets(r: dict) -> list[dict]:
    """The issue's targets, met or missed, with the measured numbers."""
    n = r["candidates"]
    slowest = max(r["seconds"].values())
    return [
        {
            "target": f"apair design, {n} candidates, 4 joints, 60 point targets: <= 20 min",
            "measured": slowest / 60,
            "met": slowest <= LIMIT_S * n / 1500,
        },
        {
            "target": f"apair design on {r['workers'][-1]} Dask workers >= {SPEEDUP}x faster than on {r['workers'][0]}",
            "measured": r["speedup"],
            "met": r["speedup"] >= SPEEDUP,
        },
        {
            "target": "apair design: the same design on every worker count",
            "measured": r["same_result"],
            "met": r["same_result"],
        },
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="bench/design_bench.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("--candidates", type=int, default=1500)
    ap.add_argument("--workers", default="1,2", help="worker counts, comma-separated (default 1,2)")
    ap.add_argument("--out", type=Path, help="write the results as JSON here")
    args = ap.parse_args(argv)
    r = time_design(args.candidates, tuple(int(w) for w in args.workers.split(",")))
    for t in design_targets(r):
        print(f"  [{'met' if t['met'] else 'MISSED'}] {t['target']}: {t['measured']:.3g}")
    if args.out:
        args.out.write_text(json.dumps(r, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
