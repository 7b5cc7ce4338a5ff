"""`make bench`: timings of the runtime, written to bench/results.json and printed.

Inverse kinematics (issue 4): the median wall time per pose of `AChain.ik` (every real solution,
verified), after the per-chain set-up, for the example chains and for random generic 4A designs.
"""
from __future__ import annotations

import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import apair

ROOT = Path(__file__).resolve().parent.parent


def random_4a(rng) -> apair.AChain:
    pairs = [apair.APair(*rng.uniform(0.03, 0.1, 2)) for _ in range(4)]
    return apair.AChain(pairs, rng.uniform(0.1, 0.4, 4), rng.uniform(-1.5, 1.5, 4), rng.uniform(-0.1, 0.1, 4),
                        rng.uniform(-1.0, 1.0, 4))


def time_ik(chains, poses_per_chain: int, rng) -> dict:
    times, setup, solutions = [], [], []
    for chain in chains:
        Ts = chain.fk(rng.uniform(-np.pi, np.pi, (poses_per_chain, chain.n)))
        t0 = time.perf_counter()
        chain.ik(Ts[0])  # first call: builds the chain's solver
        setup.append(time.perf_counter() - t0)
        for T in Ts:
            t0 = time.perf_counter()
            q = chain.ik(T)
            times.append(time.perf_counter() - t0)
            solutions.append(len(q))
    ms = np.array(times) * 1e3
    return {"poses": len(times), "median_ms": float(np.median(ms)), "p10_ms": float(np.percentile(ms, 10)),
            "p90_ms": float(np.percentile(ms, 90)), "max_ms": float(ms.max()),
            "first_call_ms": float(statistics.median(setup) * 1e3),
            "solutions_per_pose": float(np.mean(solutions))}


def main() -> int:
    rng = np.random.default_rng(0)
    results = {"machine": {"python": sys.version.split()[0], "platform": platform.platform(),
                           "numpy": np.__version__, "backend": apair.backend()}, "ik": {}}
    cases = {
        "4A random generic designs (10 x 50 poses)": ([random_4a(rng) for _ in range(10)], 50),
        "examples/4a_chain.toml (parallel axes)": ([apair.load(ROOT / "examples/4a_chain.toml")], 200),
        "examples/2a_chain.toml": ([apair.load(ROOT / "examples/2a_chain.toml")], 200),
    }
    print("inverse kinematics, time per pose (all real solutions, each verified by fk):")
    for name, (chains, k) in cases.items():
        r = time_ik(chains, k, rng)
        results["ik"][name] = r
        print(f"  {name:45s} median {r['median_ms']:6.2f} ms  (p10 {r['p10_ms']:.2f}, p90 {r['p90_ms']:.2f}, "
              f"first call {r['first_call_ms']:.1f} ms, {r['solutions_per_pose']:.2f} solutions/pose)")
    out = ROOT / "bench" / "results.json"
    out.write_text(json.dumps(results, indent=1) + "\n")
    print(f"written to {out.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
