"""The generic number of complex inverse-kinematics solutions of every R/A pattern of 1 to 6 joints,
and of the patterns with P-pairs in `WITH_SLIDES`, computed by the machinery `AChain.ik` uses
(apair.ik.homotopy): `make ik-counts` (python -m apair.ik.homotopy.counts) writes
generated/ik_counts.json, and `apair show ik_counts` prints it.

Each pattern gets a random design of generic geometry (no zero lengths, no parallel or
perpendicular axes). Its start system (the complete solution set at a generic complex pose, by
monodromy, see apair.ik.homotopy) is computed; for 6 joints the count is its size. A chain of n < 6
joints is tracked with 6 − n virtual joints; its count is the number of solutions with the virtual
joints at 0 at a generic pose of the chain's own (complex) image. A pattern and its reverse have
the same count (the inverse chain: T⁻¹ = A_n⁻¹ ⋯ A_1⁻¹, an inverted pair is a pair of the same
kind), so each pattern is computed once, under the first of the two in alphabetical order.

How each count is certified ("how"): by the trace test (apair.ik.homotopy.trace) for the start sets
it was run on (`--trace MAX_COUNT`: sets of up to MAX_COUNT solutions; its monodromy also adds any
start solution the runs missed), otherwise by two independent monodromy runs that found the same
number while one run on a second random design found no more (for 6R also the known 16 of Lee–Liang
and Raghavan–Roth; for n ≤ 4 the eliminations of apair.ik.elimination4 give an independent count,
checked by the tests). No design has more solutions than the generic count, and apair.ik.homotopy
certifies a user's start set that reaches it, so a count too small must not pass: the second design
is there to catch one. Agreeing runs are weaker than the trace test: solutions far out in the
complex, where paths lose digits, can be missed by all runs alike (before the tracker took the
residual in extended precision there, seven counts were one to eight short of round numbers).
"""

from __future__ import annotations

import itertools
import json
import sys
import time
from pathlib import Path

import numpy as np

from ...chain import AChain
from ...pair import APair
from .monodromy import monodromy, segment
from .problem import VIRTUAL_ZERO, Index, Problem, linear_pose
from .startsets import prepare
from .trace import certify
from .tracker import FAILED, OK, RETRIES

KNOWN = {"RRRRRR": 16}  # Lee & Liang 1988, Raghavan & Roth 1993
# Patterns with P-pairs (P: its slide the joint's variable): a SCARA's (its count for the pattern as
# written, as for every n < 6), the Stanford arm's and one with an A-pair (first of it and its reverse).
WITH_SLIDES = ("RRPR", "ARPRRR", "RRPRRR")


def patterns(max_n: int = 6) -> list[str]:
    """Every R/A pattern up to reversal (the first of p and p[::-1]), by length then alphabetically,
    with those of WITH_SLIDES after the R/A ones of their length."""
    out = []
    for n in range(1, max_n + 1):
        for letters in itertools.product("AR", repeat=n):
            p = "".join(letters)
            if p <= p[::-1]:
                out.append(p)
        out += [p for p in WITH_SLIDES if len(p) == n]
    return out


def design(pattern: str, seed: int = 0):
    """A chain of the pattern with random generic geometry (a P-pair's range ±1 m, which the
    counts do not depend on)."""
    if "P" in pattern:  # R/A patterns keep the designs their stored counts were computed on
        code = [int(pattern.translate(str.maketrans("RAP", "012")), 3), 3]
    else:
        code = [int(pattern.replace("A", "1").replace("R", "0"), 2)]
    rng = np.random.default_rng([seed, len(pattern), *code])
    n = len(pattern)
    pairs = [
        APair.revolute()
        if c == "R"
        else APair.prismatic()
        if c == "P"
        else APair(rng.uniform(0.2, 0.4), rng.uniform(0.15, 0.35))
        for c in pattern
    ]
    alpha = rng.uniform(0.3, 1.3, n) * rng.choice([-1, 1], n)
    return AChain(
        pairs,
        a=rng.uniform(0.3, 1.0, n),
        alpha=alpha,
        offset=rng.uniform(-0.5, 0.5, n),
        theta_offset=rng.uniform(-np.pi, np.pi, n),
        limits=[(-1.0, 1.0) if c == "P" else None for c in pattern],
    )


def reachable_pose(problem: Problem, rng) -> np.ndarray:
    """A generic complex pose (t, q) on the chain's own image: a random complex joint vector of the
    chain, the virtual joints at 0."""
    theta = np.zeros(problem.n, complex)
    theta[: problem.joints] = rng.uniform(-np.pi, np.pi, problem.joints) + 0.3j * rng.standard_normal(problem.joints)
    # (a P-pair's slide drawn alike: any complex value is a joint value)
    A, b = linear_pose(problem, theta)
    p, *_ = np.linalg.lstsq(A, -b, rcond=None)
    _, sv, Vh = np.linalg.svd(A)
    null = Vh[-1].conj()
    return p + (1.0 + 0.5j) * null / np.linalg.norm(null[3:])


def count(pattern: str, seed: int = 0, progress=None, trace_upto: int = 0) -> dict:
    """The generic count of one pattern, with how it was obtained; the trace test judges start
    sets of at most trace_upto solutions."""
    t0 = time.perf_counter()
    chain = design(pattern, seed)
    problem = Problem.of(chain)
    start = prepare(problem, seed=seed, progress=progress)
    traced = start.count <= trace_upto
    if traced:
        start = certify(problem, start)
    if chain.n == 6:
        found = start.count
    else:
        rng = np.random.default_rng([seed, 99])
        p1 = reachable_pose(problem, rng)
        index = Index(problem)
        for _ in range(RETRIES + 1):
            end, status = segment(problem, start.p0, p1, start.solutions, rng)
            for e in end[status == OK]:
                if np.all(np.abs(np.exp(1j * e[problem.joints :]) - 1) <= VIRTUAL_ZERO):
                    index.add(e)
            if np.all(status != FAILED):
                break
        found = len(index.rows)
    how = f"monodromy: {len(start.runs)} runs found {start.runs}"
    if traced:
        how += (
            f"; trace test {'passed' if start.certified else 'FAILED'} (deviation {start.trace:.0e}, "
            f"{start.witnesses} witnesses)"
        )
        certified = start.certified
    else:
        # a second design: it has at most the generic count, so a run that finds more shows the
        # first design's runs all missed solutions (a count too small would certify incomplete sets)
        other = Problem.of(design(pattern, seed + 1))
        second = len(monodromy(other, np.random.default_rng([seed + 1, 23]), progress=progress)[1])
        how += f"; a second design: one run found {second}"
        certified = start.runs_agree and second <= start.count
    if pattern in KNOWN:
        how += f"; known: {KNOWN[pattern]}"
    return {
        "pattern": pattern,
        "joints": len(pattern),
        "count": found,
        "start_count": start.count,
        "certified": bool(certified and KNOWN.get(pattern, found) == found),
        "traced": traced,
        "how": how,
        "seconds": round(time.perf_counter() - t0, 1),
    }


def main(argv=None) -> int:
    """`python -m apair.ik.homotopy.counts OUT.json [MAX_N] [--trace MAX_COUNT] [--update | --only P,Q,...]`:
    every pattern's count, one line each as it goes; --trace: the trace test judges start sets of at
    most MAX_COUNT solutions; --update: only the rows of OUT.json whose start sets it judges are
    computed again; --only: only the rows of the patterns named (each as stored: the first of it and
    its reverse)."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m apair.ik.homotopy.counts")
    parser.add_argument("out", type=Path)
    parser.add_argument("max_n", type=int, nargs="?", default=6)
    parser.add_argument("--trace", type=int, default=0, metavar="MAX_COUNT")
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--update", action="store_true")
    group.add_argument("--only", type=lambda s: s.upper().split(","), default=None, metavar="P,Q,...")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    known = patterns(args.max_n)
    for p in args.only or ():
        if p not in known:
            parser.error(
                f"--only: {p!r} is not a stored pattern of 1 to {args.max_n} joints (A and R, the first "
                f"of a pattern and its reverse, or one of {', '.join(WITH_SLIDES)})"
            )
    old = {}
    if args.update or args.only:
        if not args.out.is_file():
            parser.error(f"out: {args.out} does not exist (--update and --only change its rows)")
        old = {r["pattern"]: r for r in json.loads(args.out.read_text())["counts"]}
    rows = []
    for p in known:
        if p in old and (p not in args.only if args.only else old[p]["start_count"] > args.trace):
            rows.append({**old[p], "traced": old[p].get("traced", False)})
            continue
        r = count(p, trace_upto=args.trace)
        rows.append(r)
        print(f"{p:6s} {r['count']:6d}  (start set {r['start_count']}, {r['how']}, {r['seconds']} s)", flush=True)
        _write(args.out, rows, old)
    _write(args.out, rows, old)
    return 0


def _write(out: Path, rows: list[dict], old: dict) -> None:
    """The rows computed so far, then the stored rows not reached yet (or beyond MAX_N)."""
    done = {r["pattern"] for r in rows}
    out.write_text(json.dumps({"counts": rows + [r for p, r in old.items() if p not in done]}, indent=1) + "\n")


if __name__ == "__main__":
    sys.exit(main())
