"""The global search: SciPy's differential evolution (scipy.optimize.differential_evolution) over
the varied values, its population evaluated in parallel by the Engine (`workers=` a map, updating
"deferred": each generation is proposed whole, then evaluated, so the run depends on its seed only,
not on how many workers evaluate it or in which order they finish).

Why differential evolution: it needs no derivatives and no smoothness (coverage is a step
function of the design), works in a box (the [vary] bounds) and takes a choice among pair kinds
as a position whose integer part picks it; it is elitist (the best design found is in its final
population), part of SciPy (a dependency already) and deterministic for a seed with a parallel
map. CMA-ES assumes a smooth landscape and a continuous space; Optuna's TPE would add a dependency
whose per-trial cost grows with the trials.

What it minimises (`Scorer`): an objective to maximise enters negated, volume and torque divided by
the start design's value (a scale, so that several objectives weigh alike); coverage gets a
tie-break, SHAPE_WEIGHT·excess/targets, less than one target's worth, that leads the search
towards the targets still missed. A candidate that violates a constraint scores INFEASIBLE plus its
violation, an invalid chain INVALID: worse than any feasible one.

Several objectives: the budget is split among weight vectors spread over the simplex, each one a
run minimising the achievement function (Wierzbicki) max_i w_i (f_i − r_i) + RHO Σ_i w_i (f_i − r_i)
from the start design's point r; every minimiser of it is Pareto optimal, on convex and non-convex
parts of the front alike. The front is the non-dominated set of every feasible candidate
evaluated; the best design is the front's minimiser of the function with equal weights.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .engine import Engine
from .evaluate import Record
from .spec import Spec

POP_PER_VARIABLE = 10  # population = this × the varied values, where the budget allows
MIN_POPULATION = 8
MIN_GENERATIONS = 10  # a smaller population where the budget would give fewer generations
SHAPE_WEIGHT = 0.5
INFEASIBLE = 1e6
INVALID = 2e6
RHO = 0.05
CLIP = 1e5  # a scaled objective's magnitude at most (a start value near 0 would make it huge)
STRATEGY = "best1bin"  # differential evolution's (SciPy's default): mutation, recombination too
MUTATION = (0.5, 1.0)
RECOMBINATION = 0.7
LATTICE = {1: 1, 2: 4, 3: 2}  # simplex divisions of the weight vectors, by objective count (else 1)


class Scorer:
    """The numbers the optimiser minimises (see the module docstring), scaled by `start`."""

    def __init__(self, spec: Spec, start: Record) -> None:
        self.sign = np.array([-1.0 if o.sense == "maximise" else 1.0 for o in spec.objectives])
        self.coverage = np.array([o.name == "coverage" for o in spec.objectives])
        scale = np.ones(len(spec.objectives))
        if start.objectives is not None:
            values = np.abs(np.array(start.objectives))
            scale = np.where(self.coverage | (values == 0), 1.0, values)
        self.scale = scale
        self.targets = len(spec.targets) if spec.targets is not None else 1
        self.ref = self.parts(start) if start.objectives is not None else np.zeros(len(scale))
        single = len(spec.objectives) == 1
        self.optimum = -1.0 if single and self.coverage[0] else -math.inf

    def parts(self, r: Record) -> NDArray[np.float64]:
        """The objectives, scaled, to be minimised (each feasible one in about [−1, 1])."""
        assert r.objectives is not None
        f = np.clip(self.sign * np.array(r.objectives) / self.scale, -CLIP, CLIP)
        return f + self.coverage * SHAPE_WEIGHT * r.excess / self.targets

    def fitness(self, r: Record, w: NDArray[np.float64] | None = None) -> float:
        """One number: the scaled objective (w None, one objective) or the achievement function."""
        if r.invalid is not None:
            return INVALID
        if r.objectives is None:
            return INFEASIBLE + r.violation
        f = self.parts(r)
        if w is None:
            return float(f[0])
        d = w * (f - self.ref)
        return float(d.max() + RHO * d.sum())


def weight_vectors(m: int) -> list[NDArray[np.float64]]:
    """Weights on the simplex lattice with LATTICE[m] divisions (one objective: [1])."""
    h = LATTICE.get(m, 1)
    out = [np.array(c, dtype=float) / h for c in itertools.product(range(h + 1), repeat=m) if sum(c) == h]
    if h == 1 and m > 1:
        out.append(np.full(m, 1.0 / m))
    return out


def popsize(n: int, budget: int) -> int:
    """DE's population per varied value (the population is that times n)."""
    least = math.ceil(MIN_POPULATION / n)
    return max(least, min(POP_PER_VARIABLE, budget // (MIN_GENERATIONS * n)))


def plan(spec: Spec) -> list[tuple[NDArray[np.float64] | None, int]]:
    """(weights or None, budget) of each run; refuses a budget below one population."""
    n = len(spec.variables)
    least = math.ceil(MIN_POPULATION / n) * n
    if spec.budget < least:
        raise ValueError(
            f"{spec.where}: budget: {spec.budget} is less than one population of the search "
            f"({least} candidates for {n} varied values)"
        )
    if len(spec.objectives) == 1:
        return [(None, spec.budget)]
    every = weight_vectors(len(spec.objectives))
    k = max(1, min(len(every), spec.budget // (least * MIN_GENERATIONS)))
    chosen = [every[int(i)] for i in np.linspace(0, len(every) - 1, k).round()] if k > 1 else [np.ones(len(every[0]))]
    return [(w / w.sum(), spec.budget // k) for w in chosen]


@dataclass
class Outcome:
    """The best candidate and its Record, the evaluations made, and (several objectives) the
    Pareto front: (x, Record) of the non-dominated feasible candidates."""

    x: NDArray[np.float64]
    record: Record
    evaluations: int
    front: list[tuple[NDArray[np.float64], Record]]


class Scores:
    """DE's map (its `workers`): the candidates evaluated by the engine, then scored. The Scorer
    is made from the first batch, whose first member is the start design (DE's x0; as DE hands it
    back through its scaling to [0, 1], within a rounding of the start file's values)."""

    def __init__(self, spec: Spec, engine: Engine) -> None:
        self.spec, self.engine = spec, engine
        self.scorer: Scorer | None = None
        self.weights: NDArray[np.float64] | None = None

    def __call__(self, _func: object, xs: Iterable[NDArray[np.float64]]) -> list[float]:
        batch = [np.asarray(x, dtype=np.float64) for x in xs]
        records = self.engine(batch)
        if self.scorer is None:
            start = int(np.argmin([np.abs(x - self.spec.x0).max() for x in batch]))
            self.scorer = Scorer(self.spec, records[start])
        return [self.scorer.fitness(r, self.weights) for r in records]

    def solved(self, intermediate_result: Any) -> bool:
        """DE's callback: stop where nothing can be better (every target reached)."""
        return self.scorer is not None and bool(intermediate_result.fun <= self.scorer.optimum)


def _evolve(spec: Spec, scores: Scores, budget: int, run: int) -> Any:
    """One differential-evolution run of `budget` evaluations at most; scipy's result."""
    from scipy.optimize import differential_evolution

    n = len(spec.variables)
    p = popsize(n, budget)

    def unused(x: NDArray[np.float64]) -> float:
        raise AssertionError("differential_evolution evaluates through `workers`")

    return differential_evolution(
        unused,
        spec.bounds,
        maxiter=budget // (p * n) - 1,
        popsize=p,
        strategy=STRATEGY,
        mutation=MUTATION,
        recombination=RECOMBINATION,
        tol=0.0,
        atol=0.0,
        rng=np.random.default_rng([spec.seed, run]),
        callback=scores.solved,
        polish=False,
        init="latinhypercube",
        updating="deferred",
        workers=scores,
        x0=spec.x0,
    )


def run(spec: Spec, engine: Engine) -> Outcome:
    """The search (see the module docstring)."""
    scores = Scores(spec, engine)
    results = []
    for k, (w, budget) in enumerate(plan(spec)):
        scores.weights = w
        results.append(_evolve(spec, scores, budget, k))
    evaluations = sum(int(r.nfev) for r in results)
    scorer = scores.scorer
    assert scorer is not None  # every run evaluates its first population
    if len(spec.objectives) == 1:
        x = np.asarray(results[0].x, dtype=np.float64)
        record = engine.checkpoint.get(x)  # evaluated: DE's best is a member of its population
        return Outcome(x, record if record is not None else engine([x])[0], evaluations, [])
    equal = np.full(len(spec.objectives), 1.0 / len(spec.objectives))
    front = pareto(spec, list(engine.checkpoint.items()))
    pool = front or list(engine.checkpoint.items())
    x, record = min(pool, key=lambda e: (scorer.fitness(e[1], equal), tuple(e[0])))
    return Outcome(x, record, evaluations, front)


def pareto(spec: Spec, entries: list[tuple[NDArray[np.float64], Record]]) -> list[tuple[NDArray[np.float64], Record]]:
    """The feasible entries that no other dominates (at least as good in every objective, better
    in one), in the order of their first objective (best first), then of x; duplicates once."""
    feasible = [(x, r) for x, r in entries if r.objectives is not None]
    if not feasible:
        return []
    sign = np.array([-1.0 if o.sense == "maximise" else 1.0 for o in spec.objectives])
    F = np.array([r.objectives for _, r in feasible]) * sign
    le = np.all(F[:, None, :] <= F[None, :, :], axis=2)
    lt = np.any(F[:, None, :] < F[None, :, :], axis=2)
    dominated = np.any(le & lt, axis=0)
    keep = sorted((tuple(F[i]), tuple(feasible[i][0]), i) for i in np.flatnonzero(~dominated))
    seen: set[tuple[float, ...]] = set()
    out = []
    for f, _, i in keep:
        if f not in seen:
            seen.add(f)
            out.append(feasible[i])
    return out
