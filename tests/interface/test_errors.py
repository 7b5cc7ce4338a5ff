"""Clear errors, not tracebacks, and no file lost (issue: the defects found by a new user's trial).

Every bad input here ends in a one-line message that names the argument (or, on the command line,
a non-zero exit with such a line on stderr); no picture or generated file a user owns is replaced
or deleted without being asked.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import apair
from apair import cli, plots

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "4a_chain.toml"
GENERAL = (
    '[[joint]]\npair = "general"\nbase_radius = 0.05\nplatform_radius = 0.04\nleg_length = 0.06\na = 0.1\nalpha = 0\n'
)


def run_cli(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def assert_one_line_error(code, err, *words):
    assert code != 0
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in lines[0], (w, lines[0])


# ----------------------------------------------------------------------------- item 8: pictures
def test_plot_without_extension_does_not_replace_the_png(tmp_path, capsys):
    (tmp_path / "out.png").write_bytes(b"mine")
    f = tmp_path / "g.toml"
    f.write_text(GENERAL)
    code, _, err = run_cli(capsys, "limits", f, "--plot", tmp_path / "out")
    assert_one_line_error(code, err, "out.png", "exists")
    assert (tmp_path / "out.png").read_bytes() == b"mine"
    code, out, _ = run_cli(capsys, "limits", f, "--plot", tmp_path / "out", "--force")
    assert code == 0 and (tmp_path / "out.png").read_bytes()[:4] == b"\x89PNG"


def test_clearance_refuses_an_existing_file_and_any_symlink(tmp_path):
    pair = apair.APair(0.05, 0.04)
    (tmp_path / "c.png").write_bytes(b"mine")
    with pytest.raises(ValueError, match="^path: .*c.png.* exists"):
        plots.clearance(pair, tmp_path / "c")
    target = tmp_path / "elsewhere.png"
    (tmp_path / "link.png").symlink_to(target)  # dangling
    with pytest.raises(ValueError, match="^path: .*link.png.* exists"):
        plots.clearance(pair, tmp_path / "link.png")
    assert not target.exists()
    plots.clearance(pair, tmp_path / "link.png", overwrite=True)  # the link itself is replaced
    assert not target.exists() and not (tmp_path / "link.png").is_symlink()
    with pytest.raises(ValueError, match="^path: .* must end in .png"):
        plots.clearance(pair, tmp_path / "c.jpg")
    (tmp_path / "d.png").mkdir()
    with pytest.raises(ValueError, match="^path: .* is a folder"):
        plots.clearance(pair, tmp_path / "d.png", overwrite=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.png", "d.png", "link.png"]  # no temporary left


def test_workspace_plot_refused_before_the_run(tmp_path, capsys):
    (tmp_path / "ws.png").write_bytes(b"mine")
    code, _, err = run_cli(capsys, "workspace", EXAMPLE, "--plot", tmp_path / "ws", "--quiet")
    assert_one_line_error(code, err, "exists")
    assert (tmp_path / "ws.png").read_bytes() == b"mine"


# ----------------------------------------------------------------------------- item 9: codegen --out
@pytest.mark.slow
def test_codegen_refuses_a_folder_it_did_not_create(tmp_path):
    mine = tmp_path / "notes.txt"
    mine.write_text("keep me")
    res = subprocess.run(
        [sys.executable, "-m", "codegen", "--out", str(tmp_path), "--only", "apair_collisions"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
    )
    assert res.returncode == 2 and "not written by codegen" in res.stderr and "Traceback" not in res.stderr
    assert mine.read_text() == "keep me" and sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


def test_codegen_clean_removes_only_its_own_files(tmp_path):
    from codegen.emitter import write

    out = tmp_path / "gen"
    files = {"manifest.json": '{"content_hash": "x", "kernels": {}, "files": ["a.txt", "manifest.json"]}', "a.txt": "a"}
    write(files, out)
    (out / "users.txt").write_text("keep me")
    write({"manifest.json": '{"content_hash": "x", "kernels": {}, "files": ["manifest.json"]}'}, out)
    assert not (out / "a.txt").exists()  # ours, no longer produced
    assert (out / "users.txt").read_text() == "keep me"


# ----------------------------------------------------------------------------- item 10: clear errors
@pytest.mark.parametrize(
    "text, words",
    [
        (GENERAL.replace("a = 0.1", "a = 1" + "0" * 400), ["joint 1.a", "too large"]),
        ("x = " + "[" * 3000 + "]" * 3000 + "\n", ["nested too deeply"]),
        (
            "\ufeff"
            + GENERAL.replace("general", "revolute").replace(
                "base_radius = 0.05\nplatform_radius = 0.04\nleg_length = 0.06\n", ""
            ),
            None,
        ),  # a BOM is fine
    ],
)
def test_chain_files_that_used_to_raise(tmp_path, capsys, text, words):
    f = tmp_path / "c.toml"
    f.write_text(text, encoding="utf-8")
    code, out, err = run_cli(capsys, "fk", f, "0.1")
    if words is None:
        assert code == 0 and "T =" in out
    else:
        assert_one_line_error(code, err, *words)


def test_folders_fifos_and_none_as_chain_files(tmp_path, capsys):
    code, _, err = run_cli(capsys, "fk", tmp_path, "0.1")
    assert_one_line_error(code, err, "is a folder")
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    code, _, err = run_cli(capsys, "fk", fifo, "0.1")
    assert_one_line_error(code, err, "not a regular file")
    with pytest.raises(ValueError, match="^path: expected a file name, got None"):
        apair.load(None)


@pytest.mark.slow
def test_unreachable_scheduler_and_bogus_engine(capsys):
    chain = apair.load(EXAMPLE)
    with pytest.raises(ValueError, match="^engine: expected"):
        chain.workspace(samples=4000, engine="bogus")
    code, _, err = run_cli(
        capsys, "workspace", EXAMPLE, "--scheduler", "tcp://127.0.0.1:9", "--quiet", "--samples", "4000"
    )
    assert_one_line_error(code, err, "engine: cannot reach a Dask scheduler")


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(rounds=0.5), "rounds"),
        (dict(resolution=8.9), "resolution"),
        (dict(samples=1e4 + 0.5), "samples"),
        (dict(resolution=3000), "resolution"),
        (dict(rounds=True), "rounds"),
    ],
)
def test_workspace_arguments_are_checked_not_truncated(kwargs, name):
    chain = apair.load(EXAMPLE)
    with pytest.raises(ValueError, match=f"^{name}: "):
        chain.workspace(**kwargs)


def test_too_many_dimensions_and_complex_values_are_refused():
    chain = apair.load(EXAMPLE)
    deep = np.zeros((1,) * 30 + (4,))
    with pytest.raises(ValueError, match="^q: expected at most"):
        chain.fk(deep)
    for call in (
        lambda: chain.fk(np.zeros(4) + 1j),
        lambda: apair.APair(0.05 + 0j, 0.04),
        lambda: chain.ik(chain.fk(np.zeros(4)) + 0j),
    ):
        with pytest.raises(ValueError, match="real numbers"):
            call()


def test_broken_pipe_ends_quietly():
    """`apair kernels | head -1`: no traceback when the reader goes away."""
    res = subprocess.run(f"{sys.executable} -m apair kernels | head -1", shell=True, capture_output=True, text=True)
    assert res.stdout.count("\n") == 1 and res.stderr == "", res.stderr


# ----------------------------------------------------------------------------- item 16: IK on an unreachable pose
def test_unreachable_pose_is_reported_inside_the_limits_and_flagged(capsys):
    chain = apair.load(EXAMPLE)
    T = chain.fk([0.3, -0.5, 0.8, 1.1])
    far = T.copy()
    far[0, 3] += 0.05
    code, out, _ = run_cli(capsys, "ik", EXAMPLE, *far.ravel())
    assert code == 1 and "nearest pose found inside the joint limits" in out
    from apair.ik import distance

    _, _, q = distance(chain, far)
    assert chain.within_limits(q)
    code, out, _ = run_cli(capsys, "ik", EXAMPLE, *T.ravel())
    assert code == 0 and "within the joint limits" in out
    outside = chain.fk([0.3, -0.5, 0.8, 2.5])  # joint 4 beyond its ±120° collision limit
    code, out, _ = run_cli(capsys, "ik", EXAMPLE, *outside.ravel())
    assert code == 0 and "OUTSIDE the joint limits" in out
    assert not chain.ik(outside, full=True).inside.all()


# ----------------------------------------------------------------------------- item 17: no compiler
def _build(tmp_path, **env):
    return subprocess.run(
        [
            sys.executable,
            "setup.py",
            "-q",
            "build_ext",
            "--build-lib",
            str(tmp_path / "lib"),
            "--build-temp",
            str(tmp_path / "tmp"),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=dict(os.environ, **env),
        timeout=300,
    )


def test_a_missing_compiler_is_said_at_install_time(tmp_path):
    res = _build(tmp_path, CC=str(tmp_path / "no-such-cc"))
    assert res.returncode != 0
    assert "the C kernels could not be compiled" in res.stderr and "APAIR_NO_C=1" in res.stderr
    res = _build(tmp_path, APAIR_NO_C="1")
    assert res.returncode == 0 and "installing without the compiled C kernels" in res.stdout
    assert not list((tmp_path).rglob("_native*.so"))


# ----------------------------------------------------------------------------- item 13: numbering, imports
def test_joints_and_legs_are_numbered_from_one(capsys):
    code, out, _ = run_cli(capsys, "limits", EXAMPLE)
    assert code == 0 and "joint 1:" in out and "joint 4:" in out and "joint 0" not in out
    what = apair.APair(0.05, 0.04, leg_radius=0.004).collision_limits().what
    i, j = (int(k) for k in what.split()[1::2])
    assert 1 <= i < j <= 6


def test_import_apair_gives_plots():
    res = subprocess.run(
        [sys.executable, "-c", "import apair; print(apair.plots.chain_picture.__name__)"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0 and res.stdout.strip() == "chain_picture"
