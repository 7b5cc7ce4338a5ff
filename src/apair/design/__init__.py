"""Design search: `design(spec)` varies a chain file's numbers (and pair kinds) within bounds to
reach targets, a workspace volume or low gravity torques, by a global optimiser (SciPy's
differential evolution) whose candidates are evaluated in parallel on Dask (`apair design`).

The modules, from the top: search (the optimiser, the scores, the Pareto front) over engine (where
candidates are evaluated: this process or Dask workers, through the checkpoint), result (the
files written), checkpoint (the evaluated candidates, on disk), evaluate (one candidate: its
chain, constraints, objectives), reach (which targets a chain reaches), chainfile (a chain file's
text), spec (the search's TOML file, checked) over targets (the targets' CSV files).
"""

from __future__ import annotations

import os
import time

from .. import _validate as V
from ..io import chain_from_dict
from .checkpoint import Checkpoint
from .engine import Engine, Progress, client_for
from .evaluate import build
from .result import DesignResult, FrontPoint
from .search import Outcome, plan, run
from .spec import Spec, load_spec

__all__ = ["DesignResult", "FrontPoint", "Spec", "design", "load_spec"]


def design(
    spec: str | os.PathLike[str] | dict[str, object] | Spec,
    workers: int | None = None,
    scheduler: object = None,
    resume: bool = False,
    progress: Progress | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
) -> DesignResult:
    """Search the design space of `spec` (a spec file, its contents as a mapping, or a Spec from
    `load_spec`; see apair.design.spec) and return the best design found (`DesignResult`).

    workers: Dask worker processes on this machine (None: one per core; 0: none, all in this
    process); scheduler: instead, a Dask scheduler's address or a Client. The result does not
    depend on either. checkpoint: a JSON file that keeps the candidates evaluated (every few
    seconds and when the search stops); resume=True continues the run it holds (afresh where
    there is none yet), to the same result as an uninterrupted run; an existing one is otherwise
    replaced only with overwrite=True. progress: called as progress(done, budget, best) after each
    candidate, best the best value of each objective so far.
    Everything in the spec is checked before the search: one ValueError naming the key."""
    s = load_spec(spec)
    resume, overwrite = V.flag("resume", resume), V.flag("overwrite", overwrite)
    if progress is not None and not callable(progress):
        raise ValueError(f"progress: expected a callable progress(done, budget, best) or None, got {progress!r}")
    plan(s)  # a budget too small for one population is refused now
    store = Checkpoint.open(checkpoint, s.fingerprint(), resume, overwrite)
    started = time.perf_counter()
    with client_for(workers, scheduler) as client:
        engine = Engine(s, store, client, progress, s.budget)
        try:
            outcome = run(s, engine)
        finally:
            store.save()
    return _result(s, outcome, time.perf_counter() - started)


def _result(s: Spec, outcome: Outcome, seconds: float) -> DesignResult:
    """The DesignResult of the search's outcome; refused when no candidate was feasible."""
    r, x = outcome.record, outcome.x
    if r.objectives is None:
        why = r.invalid or f"it violates the constraints by {r.violation:.3g} (relative)"
        raise ValueError(
            f"{s.where}: constraints: none of the {outcome.evaluations} candidates evaluated is feasible "
            f"(the nearest: {why}); relax the constraints or the bounds"
        )
    document, _ = build(s, x)
    chain = chain_from_dict(document, "the best design")
    names = [o.name for o in s.objectives]
    front = [FrontPoint(s.values(fx), dict(zip(names, fr.objectives or ()))) for fx, fr in outcome.front]
    return DesignResult(
        spec=s,
        chain=chain,
        document=document,
        values=s.values(x),
        objectives=dict(zip(names, r.objectives)),
        reached=r.reached if s.targets is not None else None,
        targets=len(s.targets) if s.targets is not None else None,
        evaluated=outcome.evaluations,
        seconds=seconds,
        front=front,
    )
