"""The design search on problems whose answer exists: the targets of a design inside the bounds are
reached from another start; the result does not depend on the Dask workers; an interrupted run
resumed ends where an uninterrupted one does; several objectives give a Pareto front; the
constraints hold in the design written."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import apair
from apair.collisions import clearances
from apair.design import design, load_spec
from apair.design import engine as engine_module
from apair.design.evaluate import evaluate
from apair.design.search import pareto, plan, weight_vectors
from apair.io import chain_from_dict, loads

ROOT = Path(__file__).resolve().parents[2]

VARY4 = """"joint.1.offset" = [0.0, 0.3]
"joint.2.a" = [0.1, 0.5]
"joint.3.a" = [0.1, 0.5]
"joint.2.base_radius" = [0.03, 0.08]"""
TWO = 'maximise = "coverage"\nminimise = "gravity_torque_max"'


@pytest.mark.parametrize("seed, vary", [(1, None), (2, VARY4)])
def test_the_search_reaches_the_targets_of_a_design_inside_the_bounds(problem, seed, vary):
    path = problem(seed=seed, budget=480, **({"vary": vary} if vary else {}))
    spec = load_spec(path)
    start = evaluate(spec, spec.x0)
    assert start.objectives[0] < 0.9  # the start design misses targets: the search has work to do
    result = design(path, workers=0)
    assert result.objectives["coverage"] >= 0.99
    assert result.reached == round(result.objectives["coverage"] * 30) and result.targets == 30
    assert result.evaluated <= spec.budget
    # the design written is an ordinary chain file: it reads back to the chain found, which reaches
    # the targets as scored
    chain = loads(result.text)
    assert [repr(p) for p in chain.pairs] == [repr(p) for p in result.chain.pairs]
    assert np.array_equal(chain.a, result.chain.a) and np.array_equal(chain.offset, result.chain.offset)
    x = np.array([result.values[v.name] for v in spec.variables])
    assert evaluate(spec, x).objectives == tuple(result.objectives.values())
    assert f"Reached: coverage {result.objectives['coverage']:.4g}" in result.text


def test_serial_and_two_dask_workers_give_the_same_result(problem, tmp_path):
    path = problem(objective=TWO, budget=45, targets=20)
    serial = design(path, workers=0, checkpoint=tmp_path / "serial.json")
    parallel = design(path, workers=2, checkpoint=tmp_path / "parallel.json")
    assert parallel.values == serial.values and parallel.objectives == serial.objectives
    assert parallel.evaluated == serial.evaluated == 45
    assert [p.values for p in parallel.front] == [p.values for p in serial.front]

    def evaluated(name):
        doc = json.loads((tmp_path / name).read_text())
        return sorted((tuple(e["x"]), json.dumps(e["record"])) for e in doc["evaluated"])

    assert evaluated("serial.json") == evaluated("parallel.json")  # every candidate, bit for bit


def test_an_interrupted_search_resumed_ends_where_an_uninterrupted_one_does(problem, tmp_path, monkeypatch):
    path = problem(objective=TWO, budget=54, targets=20)
    whole = design(path, workers=0, checkpoint=tmp_path / "whole.json")

    def stop_after(k):
        def progress(done, total, best):
            assert total == 54 and set(best) <= {"coverage", "gravity_torque_max"}
            if done >= k:
                raise KeyboardInterrupt

        return progress

    with pytest.raises(KeyboardInterrupt):
        design(path, workers=0, checkpoint=tmp_path / "cut.json", progress=stop_after(23))
    kept = json.loads((tmp_path / "cut.json").read_text())["evaluated"]
    assert len(kept) == 23  # the candidates done before the interruption
    calls = []
    real = engine_module.evaluate
    monkeypatch.setattr(engine_module, "evaluate", lambda spec, x: calls.append(1) or real(spec, x))
    resumed = design(path, workers=0, checkpoint=tmp_path / "cut.json", resume=True)
    assert resumed.values == whole.values and resumed.objectives == whole.objectives
    assert resumed.evaluated == whole.evaluated
    assert [p.objectives for p in resumed.front] == [p.objectives for p in whole.front]
    distinct = len(json.loads((tmp_path / "whole.json").read_text())["evaluated"])
    assert len(calls) == distinct - len(kept)  # nothing evaluated twice


def test_a_checkpoint_is_kept_from_being_replaced_or_resumed_by_another_spec(problem, tmp_path):
    import dataclasses

    path = problem(budget=18, targets=10)
    ckpt = tmp_path / "run.json"
    design(path, workers=0, checkpoint=ckpt)
    with pytest.raises(
        ValueError, match=r"checkpoint: '.*run\.json' holds an earlier run .*overwrite=True to start afresh"
    ):
        design(path, workers=0, checkpoint=ckpt)
    other = dataclasses.replace(load_spec(path), seed=9)
    with pytest.raises(ValueError, match=r"checkpoint: '.*run\.json' was written for another spec"):
        design(other, workers=0, checkpoint=ckpt, resume=True)
    design(other, workers=0, checkpoint=ckpt, overwrite=True)  # afresh
    ckpt.write_text("{not json")
    with pytest.raises(ValueError, match=r"checkpoint: '.*run\.json' cannot be resumed"):
        design(other, workers=0, checkpoint=ckpt, resume=True)
    with pytest.raises(ValueError, match=r"resume: there is no checkpoint to resume"):
        design(path, workers=0, resume=True)


@pytest.mark.parametrize(
    "kwargs, pattern",
    [
        ({"workers": -1}, r"workers: must be >= 0, got -1"),
        ({"workers": 2.5}, r"workers: expected an integer"),
        ({"workers": 1, "scheduler": "tcp://127.0.0.1:1"}, r"workers, scheduler: give one of them, not both"),
        ({"scheduler": "nowhere"}, r"scheduler: expected a Dask scheduler's address"),
        ({"workers": 0, "resume": "yes"}, r"resume: expected True or False"),
        ({"workers": 0, "progress": 3}, r"progress: expected a callable"),
    ],
)
def test_bad_arguments_are_refused_by_name(problem, kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        design(problem(budget=18, targets=5), **kwargs)


def test_several_objectives_give_a_pareto_front_of_undominated_designs(problem, tmp_path):
    path = problem(vary='"joint.2.a" = [0.1, 0.5]\n"joint.3.a" = [0.1, 0.5]', objective=TWO, budget=160, targets=15)
    spec = load_spec(path)
    assert [b for _, b in plan(spec)] == [80, 80]  # two weight vectors, half the budget each
    result = design(path, workers=0, checkpoint=tmp_path / "front.json")
    front = [(p.objectives["coverage"], p.objectives["gravity_torque_max"]) for p in result.front]
    assert len(front) >= 2
    assert front == sorted(front, key=lambda f: (-f[0], f[1]))  # best coverage first
    assert tuple(result.objectives.values()) in front  # the design written is on the front
    evaluated = json.loads((tmp_path / "front.json").read_text())["evaluated"]
    everything = [e["record"]["objectives"] for e in evaluated if e["record"]["objectives"] is not None]
    for cov, tau in front:  # no evaluated candidate dominates a front design
        assert not any(c >= cov and t <= tau and (c > cov or t < tau) for c, t in everything)
    csv = result.write_front(tmp_path / "front.csv").read_text().splitlines()
    assert csv[0] == "joint.2.a,joint.3.a,coverage,gravity_torque_max" and len(csv) == len(front) + 1
    assert float(csv[1].split(",")[2]) == front[0][0]
    png = result.plot_front(tmp_path / "front.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match=r"path: .*front\.png' exists"):
        result.plot_front(tmp_path / "front.png")


def test_weights_and_the_front_filter(problem):
    from apair.design.evaluate import Record

    assert [w.tolist() for w in weight_vectors(2)] == [[0, 1], [0.25, 0.75], [0.5, 0.5], [0.75, 0.25], [1, 0]]
    assert len(weight_vectors(3)) == 6 and all(abs(w.sum() - 1) < 1e-12 for w in weight_vectors(3))
    spec = load_spec(problem(objective=TWO, budget=18, targets=5))
    rows = {  # (coverage, torque): maximise the first, minimise the second
        0: (0.9, 5.0),
        1: (0.8, 3.0),
        2: (0.8, 4.0),  # dominated by 1
        3: (0.9, 5.0),  # the same point as 0: kept once
        4: (1.0, 9.0),
        5: (0.5, 3.0),  # dominated by 1
    }
    entries = [(np.array([float(k)]), Record(v)) for k, v in rows.items()]
    entries.append((np.array([9.0]), Record(None, violation=0.1)))  # infeasible: never on the front
    front = pareto(spec, entries)
    assert [tuple(r.objectives) for _, r in front] == [(1.0, 9.0), (0.9, 5.0), (0.8, 3.0)]
    assert front[1][0].tolist() == [0.0]


def test_constraints_hold_in_the_design_written(problem):
    clearance = 0.004
    path = problem(
        vary='"joint.2.a" = [0.1, 0.5]\n"joint.2.base_radius" = [0.03, 0.08]',
        budget=24,
        targets=10,
        extra=f"[constraints]\nmin_clearance = {clearance}\nleg_length = [0.05, 0.2]\n",
    )
    result = design(path, workers=0)
    doc = result.document["joint"]
    for i, pair in enumerate(result.chain.pairs):
        if pair.kind == "revolute":
            assert "limits" not in doc[i]
            continue
        lo, hi = doc[i]["limits"]
        free_lo, free_hi = pair.collision_limits()[:2]
        assert free_lo < lo < 0 < hi < free_hi  # narrower than where the legs touch
        legs, plates = clearances(pair, np.array([lo, hi]))
        assert np.min(legs) >= clearance - 1e-9 and np.min(plates) >= clearance - 1e-9
        assert np.all((pair.leg_lengths >= 0.05) & (pair.leg_lengths <= 0.2))
    assert "keep a clearance of 0.004 m" in result.text
    assert np.array_equal(loads(result.text).limits, result.chain.limits)


def test_constraints_no_candidate_meets_are_said_after_the_search(problem):
    path = problem(budget=18, targets=5, extra="[constraints]\nleg_length = [0.5, 0.6]\n")
    with pytest.raises(ValueError, match=r"constraints: none of the 18 candidates evaluated is feasible"):
        design(path, workers=0)


def test_the_volume_objective_grows_the_workspace(problem):
    path = problem(
        vary='"joint.2.a" = [0.1, 0.5]\n"joint.3.a" = [0.1, 0.5]', objective='maximise = "volume"', budget=16
    )
    spec = load_spec(path)
    start = evaluate(spec, spec.x0).objectives[0]
    result = design(path, workers=0)
    assert result.objectives["volume"] > 1.2 * start
    ws = apair.load(path.parent / "start.toml").workspace(samples=20_000, resolution=16, seed=spec.seed)
    assert ws.volume == pytest.approx(start)  # the objective is the chain's workspace volume


@pytest.mark.slow
def test_the_example_reaches_its_targets_and_the_design_that_made_them_reaches_all():
    """examples/design: 4 joints, six varied values, 60 points made by examples/4a_chain.toml (a
    design inside the bounds), the search from another design."""
    examples = ROOT / "examples"
    spec = load_spec(examples / "design" / "spec.toml")
    made_by = apair.load(examples / "4a_chain.toml")
    x = np.array([0.20, 0.06, 0.35, 0.05, 0.30, 0.05])  # the 4A example's values of the varied keys
    assert [v.name for v in spec.variables] == [
        "joint.1.offset",
        "joint.1.base_radius",
        "joint.2.a",
        "joint.2.base_radius",
        "joint.3.a",
        "joint.3.base_radius",
    ]
    assert np.array_equal(chain_from_dict(spec.decode(x)).a, made_by.a)
    assert evaluate(spec, x).objectives == (1.0,)
    assert evaluate(spec, spec.x0).objectives[0] < 0.8
    result = design(spec, workers=0)
    assert result.objectives["coverage"] >= 0.99 and result.targets == 60
