"""The `apair` command line, through apair.cli.main and once as `python -m apair`."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import apair
from apair.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CHAIN2, CHAIN4 = EXAMPLES / "2a_chain.toml", EXAMPLES / "4a_chain.toml"
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def printed_block(out: str, start: str, stop: str | None) -> np.ndarray:
    """The numbers printed between the line `start` and the line beginning with `stop`."""
    body = out.split(start + "\n", 1)[1]
    if stop is not None:
        body = body.split(stop, 1)[0]
    return np.array([float(x) for x in re.findall(NUMBER, body)])


def test_list(capsys):
    code, out, err = run(capsys, "list")
    assert code == 0 and err == ""
    names = [line.split()[0] for line in out.splitlines()]
    assert names == apair.polynomials.names()
    assert "apair_motion" in names and "gdp_legs" in names


def test_show_text(capsys):
    code, out, err = run(capsys, "show", "apair_motion")
    assert code == 0 and err == ""
    assert out == apair.polynomials.text("apair_motion", "txt")
    assert "[consistency]" in out and "L1**2 - L2**2" in out


def test_show_latex(capsys):
    code, out, _ = run(capsys, "show", "apair_motion", "--latex")
    assert code == 0
    assert out == apair.polynomials.text("apair_motion", "tex")
    assert "\\begin{description}" in out


def test_show_json(capsys):
    code, out, _ = run(capsys, "show", "gdp_legs", "--json")
    assert code == 0
    data = json.loads(out)
    assert data == apair.polynomials.raw("gdp_legs")
    labels = [e["label"] for e in data["entries"]]
    assert "study_quadric" in labels and sum(lab.startswith("leg_") for lab in labels) == 6


def test_show_latex_and_json_exclusive(capsys):
    with pytest.raises(SystemExit) as info:
        main(["show", "apair_motion", "--latex", "--json"])
    assert info.value.code == 2


def test_kernels(capsys):
    code, out, _ = run(capsys, "kernels")
    assert code == 0
    rows = {line.split()[0]: line for line in out.splitlines()}
    for n in range(1, 7):
        assert {f"fk{n}", f"fk_study{n}", f"jacobian{n}"} <= rows.keys()
    assert "law_sinusoidal" in rows and "-> law(5,)" in rows["law_sinusoidal"]
    assert re.search(r"fk2\s+\d+ ops", rows["fk2"])


@pytest.mark.parametrize("angles, deg", [(["0.1", "0.2"], False), (["10", "20"], True), (["-0.3", "1.25"], False)])
def test_fk_matches_api(capsys, angles, deg):
    code, out, err = run(capsys, "fk", CHAIN2, *angles, *(["--deg"] if deg else []))
    assert code == 0 and err == ""
    q = np.radians(np.array(angles, float)) if deg else np.array(angles, float)
    chain = apair.load(CHAIN2)
    assert out.startswith(f"{chain.name}: 2 joints")
    T = printed_block(out, "T =", "Study point").reshape(4, 4)
    np.testing.assert_allclose(T, chain.fk(q), rtol=0, atol=1e-11)
    S = printed_block(out, "Study point (x0 x1 x2 x3 y0 y1 y2 y3) =", None)
    np.testing.assert_allclose(S, chain.fk_study(q), rtol=0, atol=1e-11)


def test_fk_deg_differs_from_rad(capsys):
    _, rad, _ = run(capsys, "fk", CHAIN2, "10", "20")
    _, deg, _ = run(capsys, "fk", CHAIN2, "--deg", "10", "20")
    T_deg = printed_block(deg, "T =", "Study point").reshape(4, 4)
    np.testing.assert_allclose(T_deg, apair.load(CHAIN2).fk(np.radians([10.0, 20.0])), atol=1e-11)
    assert not np.allclose(printed_block(rad, "T =", "Study point"), T_deg.ravel())


def test_demo(capsys):
    code, out, err = run(capsys, "demo", CHAIN4)
    assert code == 0 and err == ""
    assert "law_sinusoidal" in out and "d = h*cos(theta/2)" in out
    assert "4A example" in out and "Jacobian:" in out
    chain = apair.load(CHAIN4)
    q = np.linspace(0.3, -0.4, 4)
    assert f"{chain.name} ({CHAIN4}), q = " in out
    after = out.split(f"({CHAIN4}), q = ", 1)[1].split("\n", 1)[1]  # the lines after the pose header
    T = np.array([float(x) for x in re.findall(NUMBER, after.split("Jacobian:")[0])]).reshape(4, 4)
    np.testing.assert_allclose(T, chain.fk(q), atol=1e-6)
    J = np.array([float(x) for x in re.findall(NUMBER, after.split("Jacobian:")[1])]).reshape(6, 4)
    np.testing.assert_allclose(J, chain.jacobian(q), atol=1e-6)


def test_demo_without_file(capsys):
    code, out, _ = run(capsys, "demo")
    assert code == 0 and "consistency" in out and "Jacobian" not in out


@pytest.mark.parametrize(
    "argv, command, message",
    [
        (["fk", CHAIN2, "0.1"], "fk", r"Q: 2A example has 2 joints, got 1 angles"),
        (["fk", CHAIN2, "0.1", "0.2", "0.3"], "fk", r"Q: 2A example has 2 joints, got 3 angles"),
        (["fk", CHAIN2, "0.1", "abc"], "fk", r"Q: 'abc' is not a number"),
        (["fk", CHAIN2, "0.1", "nan"], "fk", r"Q: 'nan' is not a finite number"),
        (["show", "nope"], "show", r"name: no derived polynomial set 'nope'"),
        (["show", "nope", "--json"], "show", r"name: no derived polynomial set 'nope'"),
        (["fk", EXAMPLES / "missing.toml", "0.1"], "fk", r"path: no such file .*missing\.toml"),
        (["demo", EXAMPLES / "missing.toml"], "demo", r"path: no such file .*missing\.toml"),
        (["ik", CHAIN4, "1", "0", "0"], "ik", r"POSE: expected 16 \(or 12\) numbers"),
        (["ik", CHAIN4, *"1 0 0 0 0 1 0 0 0 0 1 x".split()], "ik", r"POSE: 'x' is not a number"),
        (["ik", CHAIN4, *"1 0 0 0 0 1 0 0 0 0 2 0".split()], "ik", r"POSE: the rotation part is not a proper rotation"),
    ],
)
def test_error_exits(capsys, argv, command, message):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert out == "" or command == "demo"  # demo prints the law before it loads the file
    assert re.match(rf"apair {command}: error: {message}", err), err


def test_bad_chain_file(capsys, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('[[joint]]\npair = "spiral"\na = 0.1\nalpha = 0\n')
    code, out, err = run(capsys, "fk", path, "0.1")
    assert code == 2 and out == ""
    assert "joint 1.pair" in err and "spiral" in err


def test_module_entry_point():
    ok = subprocess.run(
        [sys.executable, "-m", "apair", "fk", str(CHAIN2), "0.1", "0.2"], capture_output=True, text=True, timeout=120
    )
    assert ok.returncode == 0, ok.stderr
    T = printed_block(ok.stdout, "T =", "Study point").reshape(4, 4)
    np.testing.assert_allclose(T, apair.load(CHAIN2).fk([0.1, 0.2]), atol=1e-11)
    bad = subprocess.run([sys.executable, "-m", "apair", "show", "nope"], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "apair show: error: name:" in bad.stderr
    ver = subprocess.run([sys.executable, "-m", "apair", "--version"], capture_output=True, text=True, timeout=120)
    assert ver.returncode == 0 and ver.stdout.strip() == f"apair {apair.__version__}"


@pytest.mark.parametrize("form", ["matrix", "rows", "study"])
def test_ik_reachable(capsys, form):
    chain = apair.load(CHAIN4)
    q = np.array([0.3, -0.5, 0.8, 1.1])
    T = chain.fk(q)
    pose = {"matrix": T.ravel(), "rows": T[:3].ravel(), "study": chain.fk_study(q)}[form]
    code, out, err = run(capsys, "ik", CHAIN4, *[repr(float(x)) for x in pose], "--deg")
    assert code == 0 and err == ""
    assert "1 real solution(s) of 1 complex, by elimination" in out
    found = np.array([float(x) for x in re.findall(NUMBER, out.split("q = [", 1)[1].split("]", 1)[0])])
    np.testing.assert_allclose(found, q, atol=1e-9)


def test_ik_unreachable_says_how_far(capsys):
    chain = apair.load(CHAIN4)
    T = chain.fk([0.3, -0.5, 0.8, 1.1])
    T[2, 3] += 0.05
    code, out, err = run(capsys, "ik", CHAIN4, *[repr(float(x)) for x in T.ravel()])
    assert code == 1 and err == ""
    m = re.search(rf"unreachable. The nearest pose found .* is ({NUMBER}) m and ({NUMBER}) rad away", out)
    assert m, out
    assert 0 < float(m.group(1)) <= 0.05 + 1e-9
