"""`apair design` on the command line: the best design written, the objective printed, the
checkpoint beside the output, --resume, and every refusal one line on stderr with exit status 2."""

from __future__ import annotations

import json

import pytest

import apair
from apair.cli import app
from apair.cli import design as cli_design


@pytest.fixture
def main(monkeypatch):
    """apair's main with `design` among its commands (registered in app.COMMANDS or not yet)."""
    if cli_design.add_design not in app.COMMANDS:
        monkeypatch.setattr(app, "COMMANDS", (*app.COMMANDS, cli_design.add_design))
    return app.main


def one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("apair design: error: "), err
    return err


def test_design_writes_the_best_chain_file_and_prints_the_objective(main, problem, capsys):
    spec = problem(budget=18, targets=10)
    out = spec.parent / "best.toml"
    assert main(["design", str(spec), "--out", str(out), "--workers", "0", "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith(f"{spec}: coverage ") and f"best design written to {out}" in printed
    assert "joint.2.a = " in printed
    chain = apair.load(out)
    assert chain.name == "start" and chain.n == 3
    assert "# Reached: coverage" in out.read_text()
    assert (spec.parent / "best.checkpoint.json").exists()


def test_outputs_and_checkpoints_are_replaced_only_with_force_and_resumed_with_resume(main, problem, capsys):
    spec = problem(budget=18, targets=10)
    out = spec.parent / "best.toml"
    args = [str(spec), "--out", str(out), "--workers", "0", "--quiet"]
    assert main(["design", *args]) == 0
    first = out.read_text()
    capsys.readouterr()
    assert main(["design", *args]) == 2
    err = one_error_line(capsys)
    assert f"--out: '{out}' exists; use --force to replace it" in err
    out.unlink()
    assert main(["design", *args]) == 2
    err = one_error_line(capsys)
    assert "best.checkpoint.json' holds an earlier run of a search; use --resume to continue it or --force" in err
    assert main(["design", *args, "--resume"]) == 0  # every candidate answered from the checkpoint
    assert out.read_text() == first
    assert main(["design", *args, "--force"]) == 0
    assert out.read_text() == first  # afresh, to the same design


def test_progress_json_and_budget(main, problem, capsys):
    spec = problem(budget=300, targets=10)
    out = spec.parent / "best.toml"
    assert main(["design", str(spec), "--out", str(out), "--workers", "0", "--budget", "18", "--json"]) == 0
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    assert doc["budget"] == 18 and doc["evaluated"] <= 18 and doc["targets"] == 10
    assert doc["written"]["best"] == str(out) and 0 <= doc["objectives"]["coverage"] <= 1
    assert "candidates; best coverage" in captured.err  # the progress bar, on stderr


def test_several_objectives_write_the_pareto_front_beside_the_output(main, problem, capsys):
    spec = problem(budget=18, targets=10, objective='maximise = "coverage"\nminimise = "gravity_torque_max"')
    out = spec.parent / "best.toml"
    assert main(["design", str(spec), "--out", str(out), "--workers", "0", "--quiet"]) == 0
    assert "Pareto front: " in capsys.readouterr().out
    assert (spec.parent / "best.front.csv").read_text().startswith("joint.1.offset,joint.2.a,joint.3.a,coverage,")
    assert (spec.parent / "best.front.png").exists()


@pytest.mark.parametrize(
    "extra, pattern",
    [
        (["--workers", "-1"], r"--workers: must be >= 0, got -1"),
        (["--budget", "0"], r"--budget: must be >= 1, got 0"),
        (["--budget", "3"], r"budget: 3 is less than one population"),
        (["--scheduler", "nowhere"], r"--scheduler: expected a Dask scheduler's address"),
    ],
)
def test_bad_options_are_refused_in_one_line(main, problem, capsys, extra, pattern):
    import re

    spec = problem(budget=18, targets=5)
    assert main(["design", str(spec), "--out", str(spec.parent / "best.toml"), *extra]) == 2
    assert re.search(pattern, one_error_line(capsys))


def test_a_spec_that_cannot_run_is_refused_before_any_search(main, problem, capsys):
    spec = problem(budget=18, targets=5)
    (spec.parent / "targets.csv").write_text("x,y,z\n")
    assert main(["design", str(spec), "--out", str(spec.parent / "best.toml"), "--workers", "0"]) == 2
    assert "targets.points: 'targets.csv' holds no targets" in one_error_line(capsys)
    assert not (spec.parent / "best.checkpoint.json").exists()
    assert main(["design", str(spec.parent / "none.toml"), "--out", str(spec.parent / "best.toml")]) == 2
    assert "spec: " in one_error_line(capsys)
