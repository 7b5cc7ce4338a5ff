"""`apair compare`: the table, the JSON document (its chain volume exactly `apair workspace`'s at the
same samples and seed), the report and picture, and every bad input as one line on stderr with
exit status 2 (app.main's handling, with the command added to its list where it is not yet)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

from apair.cli import app
from apair.cli.compare import add_compare

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FOUR_A = EXAMPLES / "4a_chain.toml"


@pytest.fixture(autouse=True)
def with_compare(monkeypatch):
    if add_compare not in app.COMMANDS:
        monkeypatch.setattr(app, "COMMANDS", (*app.COMMANDS, add_compare))


def run(capsys, *argv):
    code = app.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """`apair compare 4a --json --out --picture` once: (exit status, stdout, stderr, folder)."""
    folder = tmp_path_factory.mktemp("compare")
    with pytest.MonkeyPatch.context() as mp:
        if add_compare not in app.COMMANDS:
            mp.setattr(app, "COMMANDS", (*app.COMMANDS, add_compare))
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = app.main(
                ["compare", str(FOUR_A), "--json", "--samples", "20000"]
                + ["--out", str(folder / "r.html"), "--picture", str(folder / "p.png")]
            )
    return code, out.getvalue(), err.getvalue(), folder


def test_json_volume_is_the_workspace_commands(written, capsys):
    code, out, err, folder = written
    assert code == 0, err
    doc = json.loads(out)
    code, ws_out, err = run(capsys, "workspace", FOUR_A, "--json", "--samples", "20000", "--quiet")
    assert code == 0, err
    ws = json.loads(ws_out)
    assert (doc["chain"]["volume"], doc["chain"]["volume_error"]) == (ws["volume"], ws["volume_error"])
    for who in ("chain", "twin"):
        for key in ("volume", "volume_error", "limits", "mass", "manipulability_median", "condition_median"):
            assert key in doc[who], (who, key)
        assert len(doc[who]["gravity_torque_max"]) == 4
    assert doc["twin"]["full_turn"] == [True] * 4
    assert doc["report"] == str(folder / "r.html") and doc["picture"] == str(folder / "p.png")


def test_report_and_picture_are_written(written):
    _, _, err, folder = written
    page = (folder / "r.html").read_text()
    assert "4A example beside its revolute twin" in page and "https:" not in page
    assert (folder / "p.png").read_bytes()[:4] == b"\x89PNG"
    assert "apair compare: workspace of the chain" in err  # the stages, without --quiet


def test_the_table(capsys):
    code, out, err = run(capsys, "compare", FOUR_A, "--samples", "8000", "--quiet")
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0].startswith("4A example beside its revolute twin (8000 workspace samples, seed 0")
    assert lines[1].split() == ["chain", "twin"]
    assert any(
        line.split()[:3] == ["joint", "ranges", "[deg]"] and line.endswith("full full full full") for line in lines
    )


def test_out_prints_where_and_refuses_to_replace(capsys, tmp_path):
    (tmp_path / "r.html").write_text("mine")
    code, out, err = run(capsys, "compare", FOUR_A, "--samples", "8000", "--out", tmp_path / "r.html", "--quiet")
    assert code == 2 and out == ""
    assert err.startswith("apair compare: error: --out: ") and "use --force" in err and err.count("\n") == 1
    assert (tmp_path / "r.html").read_text() == "mine"


@pytest.mark.parametrize(
    ("extra", "start"),
    [
        (["--twin", "helical"], "--twin: expected one of revolute"),
        (["--samples", "10"], "--samples: "),
        (["--seed", "-3"], "--seed: "),
        (["--scheduler", "nowhere"], "--scheduler: "),
        (["--path", "missing.csv"], "--path: cannot read"),
        (["--picture", "."], "--picture: "),
    ],
)
def test_bad_options_are_one_line(capsys, extra, start):
    code, out, err = run(capsys, "compare", FOUR_A, "--quiet", *extra)
    assert code == 2 and out == ""
    assert err.startswith(f"apair compare: error: {start}") and err.count("\n") == 1, err


def test_a_path_file(capsys, tmp_path):
    f = tmp_path / "line.csv"
    f.write_text("# x, y, z\n0.45, -0.42, 0.08\n0.0, 0.37, -0.2\n")
    code, out, err = run(capsys, "compare", FOUR_A, "--samples", "8000", "--path", f, "--json", "--quiet")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["shared"]["path"]["points"] == [[0.45, -0.42, 0.08], [0.0, 0.37, -0.2]]
    assert doc["chain"]["path"]["followed"] in (True, False)
