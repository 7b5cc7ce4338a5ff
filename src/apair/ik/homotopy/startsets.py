"""Start systems: a design's complete complex solution set at a generic complex pose
(`StartSystem`), prepared by independent monodromy runs (`prepare`), kept on disk under the
design's content hash (`start_system`), and the patterns' generic counts it is certified against
(`stored_counts`, `generic_count`).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from ...files import cache_root, toolkit_digest
from .monodromy import lost_paths, monodromy, segment
from .problem import Index, Problem, random_pose
from .tracker import OK, RETRIES

FORMAT = 3  # of the cached start systems
CHECK_LOOPS = 3  # loops after the runs in which no path may be lost for a certified start set


@dataclass
class StartSystem:
    """The complete complex solution set at a generic complex pose p0 (see apair.ik.homotopy)."""

    problem_key: str
    p0: np.ndarray  # (7,) complex
    solutions: np.ndarray  # (k, n) complex
    loops: int  # monodromy loops run
    runs: list  # solution counts of the independent runs
    certified: bool  # the trace test passed; without one: the count was stable and reproduced
    seconds: float
    trace: float = math.nan  # the trace test's relative deviation from affine (homotopy.trace); NaN: not run
    witnesses: int = 0  # the trace test's extra witness points
    generic: int = 0  # the pattern's generic count the set was prepared against (generic_count); 0: none known

    @property
    def count(self) -> int:
        return len(self.solutions)

    @property
    def traced(self) -> bool:
        """Whether a trace test has judged this set (then `certified` is its verdict)."""
        return not math.isnan(self.trace)

    @property
    def runs_agree(self) -> bool:
        """Whether two independent monodromy runs found the set's count on their own."""
        return sum(c == self.count for c in self.runs) >= 2

    @property
    def how(self) -> str:
        """How `certified` was decided, in words."""
        if self.traced:
            return (
                f"the trace test {'passed' if self.certified else 'failed'} (deviation {self.trace:.1e}, "
                f"{self.witnesses} witnesses)"
            )
        if self.generic and self.count == self.generic:
            return f"it has the pattern's generic count {self.generic} (apair show ik_counts), which no design exceeds"
        if self.generic and self.count > self.generic:
            return (
                f"it has more solutions than the pattern's generic count {self.generic}: a solution is "
                "counted twice (or the stored count is short)"
            )
        return (
            "two monodromy runs found it"
            if self.certified
            else "a path was lost in the check loops"
            if self.runs_agree
            else "the monodromy runs disagree"
        ) + (f" (the pattern's generic count is {self.generic})" if self.generic else "")

    def save(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        with open(tmp, "wb") as f:
            np.savez(
                f,
                format=FORMAT,
                problem_key=self.problem_key,
                p0=self.p0,
                solutions=self.solutions,
                loops=self.loops,
                runs=np.array(self.runs),
                certified=self.certified,
                seconds=self.seconds,
                trace=self.trace,
                witnesses=self.witnesses,
                generic=self.generic,
            )
        os.replace(tmp, path)

    @staticmethod
    def load(path: Path, key: str) -> StartSystem | None:
        try:
            with np.load(path, allow_pickle=False) as z:
                if int(z["format"]) != FORMAT or str(z["problem_key"]) != key:
                    return None
                return StartSystem(
                    key,
                    z["p0"],
                    z["solutions"],
                    int(z["loops"]),
                    [int(x) for x in z["runs"]],
                    bool(z["certified"]),
                    float(z["seconds"]),
                    float(z["trace"]),
                    int(z["witnesses"]),
                    int(z["generic"]),
                )
        except (OSError, ValueError, KeyError):
            return None


def prepare(problem: Problem, seed: int = 0, progress=None, runs: int = 4, generic: int = 0) -> StartSystem:
    """A start system: independent monodromy runs (each from its own random starting solution and
    pose), merged at the pose of the larger set (the other's solutions tracked there; where the
    union grows, monodromy continues from it), at most `runs`. generic: the pattern's generic count
    (generic_count; 0: not known), where monodromy stops and the set is certified (see
    apair.ik.homotopy). Below it, certified when two runs found the union's count on their own and
    CHECK_LOOPS more loops lose no path."""
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, problem.n, problem.joints, 17])
    p0, sols, loops = monodromy(problem, rng, progress=progress, target=generic)
    counts = [len(sols)]
    while len(counts) < runs and sum(c == len(sols) for c in counts) < 2 and not 0 < generic <= len(sols):
        q0, other, more = monodromy(problem, rng, progress=progress, target=generic)
        loops += more
        counts.append(len(other))
        if len(other) > len(sols):  # merge into the larger set, at its pose
            p0, sols, q0, other = q0, other, p0, sols
        end, status = segment(problem, q0, p0, other, rng)
        index = Index(problem)
        for s in sols:
            index.add(s)
        if sum(index.add(s) for s in end[status == OK]):  # the union is larger: loop again from it
            p0, sols, more = monodromy(problem, rng, progress=progress, p0=p0, known=index.rows, target=generic)
            loops += more
    if 0 < generic <= len(sols):  # all of them, or one counted twice: no loops decide more
        certified = len(sols) == generic
    else:
        # every solution is carried around CHECK_LOOPS more loops: a path that cannot be tracked (far
        # out in the complex, where digits are lost; diverging, where every solution is finite)
        # with any of RETRIES gammas marks a set whose missing members could hide there
        lost = 0
        for _ in range(CHECK_LOOPS):
            pa, pb = random_pose(rng), random_pose(rng)
            cur = sols
            for a, b in ((p0, pa), (pa, pb), (pb, p0)):
                cur, status = segment(problem, a, b, cur, rng, retries=RETRIES, finite=True)
                lost += int(np.sum(lost_paths(status, True)))
        certified = bool(sum(c == len(sols) for c in counts) >= 2 and lost == 0)
    return StartSystem(problem.key(), p0, sols, loops, counts, certified, time.perf_counter() - t0, generic=generic)


def stored_counts() -> list[dict]:
    """The generic counts of every pattern (generated/ik_counts.json, written by
    apair.ik.homotopy.counts)."""
    return json.loads(resources.files("apair.generated").joinpath("ik_counts.json").read_text())["counts"]


def generic_count(problem: Problem) -> int:
    """The certified generic number of solutions of the problem's pattern from the stored counts,
    or 0. For 6 joints the pattern or its reverse; for fewer, the start set with the virtual joints,
    stored for the pattern as written."""
    pattern = problem.pattern
    rows = stored_counts()
    names = {pattern, pattern[::-1]} if problem.joints == 6 else {pattern}
    return next((int(r["start_count"]) for r in rows if r["pattern"] in names and r["certified"]), 0)


# the modules whose code decides a start set: part of its cache key
DECIDERS = ("problem.py", "tracker.py", "monodromy.py", "startsets.py")


def _cache_path(problem: Problem) -> Path:
    here = Path(__file__).parent
    own = hashlib.sha256(b"".join((here / name).read_bytes() for name in DECIDERS)).hexdigest()
    h = hashlib.sha256((problem.key() + "\0" + toolkit_digest() + f"\0{FORMAT}\0{own}").encode()).hexdigest()[:16]
    return cache_root() / "ik" / f"{h}.npz"


def start_system(problem: Problem, progress=None, refresh: bool = False, certify=None) -> StartSystem:
    """The design's start system from the cache, or prepared now and cached. certify: a function
    (problem, start) -> start run on a set that no trace test has judged yet
    (apair.ik.homotopy.trace.certify), its verdict cached with the set."""
    path = _cache_path(problem)
    start = None
    if not refresh and path.exists():
        start = StartSystem.load(path, problem.key())
        if start is not None and (certify is None or start.traced):
            return start
    if start is None:
        start = prepare(problem, progress=progress, generic=generic_count(problem))
    if certify is not None:
        start = certify(problem, start, progress=progress)
    try:
        start.save(path)
    except OSError:
        pass  # a read-only cache: the start system is used without being kept
    return start
