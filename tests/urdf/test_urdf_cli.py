"""`apair import urdf`: the chain file written, refusals on one line, the time on the UR5."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from robots import J, robots_dir, urdf, write

import apair
from apair.cli import app, importer
from apair.urdf import load_urdf


@pytest.fixture
def run(monkeypatch, capsys):
    """main() with `import` among the commands (whether or not app.py registers it yet)."""
    if importer.add_import not in app.COMMANDS:
        monkeypatch.setattr(app, "COMMANDS", (*app.COMMANDS, importer.add_import))

    def go(*argv: str) -> tuple[int, str, str]:
        code = app.main(list(argv))
        out, err = capsys.readouterr()
        return code, out, err

    return go


def test_ur5_import(run, tmp_path) -> None:
    urdf_path = robots_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
    out = tmp_path / "ur5.toml"
    # its time (< 1 s for the Panda) is measured by make bench, not here: a shared machine's load decides a timed test
    code, stdout, err = run("import", "urdf", str(urdf_path), "--tip", "tool0", "--out", str(out))
    assert code == 0, err
    assert f"chain file written to {out} (6 joints;" in stdout
    chain = apair.load(out)  # the file reads back, [tool] included, into load_urdf's chain
    ref = load_urdf(urdf_path, "tool0")
    q = np.random.default_rng(0).uniform(-3, 3, (5, 6))
    assert np.abs(chain.fk(q) - ref.fk(q)).max() < 1e-15
    assert np.abs(chain.mass_matrix(q) - ref.mass_matrix(q)).max() < 1e-15
    assert chain.name == "ur5"
    # an existing file only with --force
    code, _, err = run("import", "urdf", str(urdf_path), "--tip", "tool0", "--out", str(out))
    assert code == 2 and "exists; use --force to replace it" in err and err.count("\n") == 1
    code, _, err = run("import", "urdf", str(urdf_path), "--tip", "tool0", "--out", str(out), "--force")
    assert code == 0, err


def test_apair_option(run, tmp_path) -> None:
    joints = [
        J(f"j{i}", "revolute", f"l{i}", f"l{i + 1}", (0.0, 0.0, 0.2), (0.0, 1.0 * i, 0.0), (0.0, 0.0, 1.0), (-1.0, 1.0))
        for i in range(3)
    ]
    path = str(write(tmp_path, urdf("r3", "l0", joints, {})))
    out = tmp_path / "r3.toml"
    code, _, err = run(
        "import",
        "urdf",
        path,
        "--tip",
        "l3",
        "--out",
        str(out),
        "--apair",
        "2:sinusoidal,base_radius=0.06,platform_radius=0.05",
        "--apair",
        "3:sinusoidal,base_radius=0.05,platform_radius=0.05,limits=none",
    )
    assert code == 0, err
    doc = tomllib.loads(out.read_text())
    assert [j["pair"] for j in doc["joint"]] == ["revolute", "sinusoidal", "sinusoidal"]
    assert doc["joint"][1]["limits"] == [-1.0, 1.0] and "limits" not in doc["joint"][2]
    chain = apair.load(out)
    assert chain.pairs[1].base_radius == 0.06


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("2", r"--apair: expected K:KIND\[,key=value,\.\.\.\] \(e\.g\. 2:sinusoidal,base_radius=0\.06\), got '2'"),
        (
            "2:spiral",
            r"--apair 2:spiral: unknown pair kind 'spiral' \(one of sinusoidal, general, revolute, helical, prismatic\)",
        ),
        ("2:sinusoidal,base_radius", r"--apair 2:sinusoidal,base_radius: expected key=value, got 'base_radius'"),
        ("2:sinusoidal,base_radius=x", r"--apair 2:sinusoidal,base_radius=x: base_radius: expected a number, got 'x'"),
        ("2:sinusoidal,base_radius=inf", r"base_radius: expected a finite number, got 'inf'"),
        ("2:sinusoidal,limits=1", r"--apair 2:sinusoidal,limits=1: limits: expected LO:HI or none, got '1'"),
        ("7:sinusoidal", r"--apair: joint 7 is not a joint of the chain \(1 to 3\)"),
        (
            "2:sinusoidal,base_radius=0.06,platform_radius=0.05,limits=-3:3",
            r"--apair 2:sinusoidal,base_radius=0\.06,platform_radius=0\.05,limits=-3:3: limits: \(-3, 3\) rad goes beyond the pair's collision-free range",
        ),
        (
            "2:sinusoidal,leg_length=0.1",
            r"--apair 2:sinusoidal,leg_length=0\.1: 'leg_length' is not a key of a sinusoidal pair",
        ),
        ("2:sinusoidal,base_radius=0.06", r"--apair 2:sinusoidal,base_radius=0\.06: missing platform_radius$"),
    ],
)
def test_apair_option_refused(run, tmp_path, spec: str, message: str) -> None:
    joints = [
        J(f"j{i}", "revolute", f"l{i}", f"l{i + 1}", (0.0, 0.0, 0.2), (0.0, 1.0 * i, 0.0), (0.0, 0.0, 1.0), (-1.0, 1.0))
        for i in range(3)
    ]
    path = str(write(tmp_path, urdf("r3", "l0", joints, {})))
    code, out, err = run("import", "urdf", path, "--tip", "l3", "--out", str(tmp_path / "x.toml"), "--apair", spec)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("apair import: error: ")
    import re

    assert re.search(message, err), err
    assert not (tmp_path / "x.toml").exists()


def test_refusals_name_the_option(run, tmp_path) -> None:
    panda = robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    code, _, err = run("import", "urdf", str(panda), "--tip", "panda_lnk6", "--out", str(tmp_path / "p.toml"))
    assert code == 2 and "--tip: " in err and "did you mean 'panda_link6'?" in err
    code, _, err = run(
        "import", "urdf", str(panda), "--tip", "panda_link6", "--base", "nope", "--out", str(tmp_path / "p.toml")
    )
    assert code == 2 and "--base: " in err and "has no link 'nope'" in err
    code, _, err = run("import", "urdf", str(panda), "--tip", "panda_link6", "--out", str(tmp_path / "p.txt"))
    assert code == 2 and "--out: " in err and "must end in .toml" in err
    code, out, err = run("import", "urdf", str(panda), "--tip", "panda_link6", "--out", str(tmp_path / "p"))
    assert code == 0 and (tmp_path / "p.toml").exists(), err
