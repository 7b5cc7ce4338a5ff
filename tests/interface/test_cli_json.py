"""`--json` on every command that prints numbers: one JSON document on stdout with the numbers the
Python API computes (to the last bit), errors still one line on stderr; without it the text is
what the commands printed before `--json` existed."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from apair_test_helpers import arm_toml

import apair
from apair.cli import main
from apair.kernels import backend, manifest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CHAIN2, CHAIN4 = EXAMPLES / "2a_chain.toml", EXAMPLES / "4a_chain.toml"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def document(capsys, *argv, code: int = 0) -> dict:
    """The JSON document a command prints with --json (strict JSON: no NaN or Infinity tokens)."""
    got, out, err = run(capsys, *argv, "--json")
    assert got == code, err
    return json.loads(out, parse_constant=lambda name: pytest.fail(f"non-standard JSON token {name}"))


def printed(array: np.ndarray) -> str:
    """An array as the text commands print it."""
    with np.printoptions(precision=12, suppress=True, floatmode="maxprec"):
        return str(array)


# ----------------------------------------------------------------------------- fk


def test_fk_json_matches_api(capsys):
    chain = apair.load(CHAIN4)
    q = np.radians([10.0, -20.0, 30.0, 45.0])
    doc = document(capsys, "fk", CHAIN4, "10", "-20", "30", "45", "--deg")
    assert doc["chain"] == chain.name and doc["n"] == 4 and doc["backend"] == backend()
    assert doc["units"]["angles"] == "rad" and doc["units"]["lengths"] == "m"
    np.testing.assert_array_equal(doc["q"], q)
    np.testing.assert_array_equal(doc["T"], chain.fk(q))
    np.testing.assert_array_equal(doc["study"], chain.fk_study(q))
    assert doc["outside_limits"] == []


def test_fk_json_names_the_joints_outside_the_limits(capsys):
    chain = apair.load(CHAIN2)
    doc = document(capsys, "fk", CHAIN2, "0.5", "-3")
    np.testing.assert_array_equal(doc["T"], chain.fk([0.5, -3.0]))
    [entry] = doc["outside_limits"]
    assert entry["joint"] == 2 and entry["q"] == -3.0
    assert entry["limits"] == chain.hard_limits()[1].tolist()


def test_fk_text_unchanged(capsys):
    chain = apair.load(CHAIN2)
    q = np.array([0.1, 0.2])
    code, out, err = run(capsys, "fk", CHAIN2, "0.1", "0.2")
    assert code == 0 and err == ""
    assert out.splitlines() == [
        f"{chain.name}: 2 joints, q = {printed(q)} rad (backend: {backend()})",
        "T =",
        *printed(chain.fk(q)).splitlines(),
        "Study point (x0 x1 x2 x3 y0 y1 y2 y3) =",
        *printed(chain.fk_study(q)).splitlines(),
    ]


# ----------------------------------------------------------------------------- ik


def test_ik_json_matches_api(capsys):
    chain = apair.load(CHAIN4)
    T = chain.fk([0.3, -0.5, 0.8, 1.1])
    doc = document(capsys, "ik", CHAIN4, *[repr(float(x)) for x in T.ravel()], "--deg")
    sol = chain.ik(T, full=True)
    assert doc["reachable"] is True and doc["units"]["angles"] == "rad"
    assert doc["method"] == sol.method and doc["certified"] == sol.certified
    assert doc["complex_count"] == sol.complex_count
    assert len(doc["solutions"]) == len(sol.q) >= 1
    for s, q, e, ok in zip(doc["solutions"], sol.q, sol.error, sol.inside):
        np.testing.assert_array_equal(s["q"], q)
        np.testing.assert_array_equal(s["q_deg"], np.degrees(q))
        assert s["error"] == e and s["within_limits"] == bool(ok)


def test_ik_json_unreachable(capsys):
    chain = apair.load(CHAIN4)
    T = chain.fk([0.3, -0.5, 0.8, 1.1])
    T[2, 3] += 0.05
    doc = document(capsys, "ik", CHAIN4, *[repr(float(x)) for x in T.ravel()], code=1)
    assert doc["reachable"] is False and doc["solutions"] == []
    nearest = doc["nearest"]
    assert len(nearest["q"]) == 4 and 0 < nearest["distance_m"] <= 0.05 + 1e-9
    assert nearest["distance_rad"] >= 0


def test_ik_text_unchanged(capsys):
    chain = apair.load(CHAIN2)
    q = np.array([0.3, -0.4])
    T = chain.fk(q)
    code, out, _ = run(capsys, "ik", CHAIN2, *[repr(float(x)) for x in T.ravel()], "--deg")
    assert code == 0
    sol = chain.ik(T, full=True)
    head, *rows = out.splitlines()
    assert head == f"{chain.name}: 1 real solution(s) of 1 complex, by elimination; angles in rad and deg"
    assert rows == [
        f"  q = {printed(sol.q[0])}  = {printed(np.degrees(sol.q[0]))} deg   |fk(q) - T| = {sol.error[0]:.1e}   "
        "within the joint limits"
    ]


# ----------------------------------------------------------------------------- limits


def test_limits_json_matches_api(capsys):
    chain = apair.load(CHAIN4)
    doc = document(capsys, "limits", CHAIN4)
    assert doc["chain"] == chain.name and doc["units"]["limits"] == "rad"
    assert [j["joint"] for j in doc["joints"]] == [1, 2, 3, 4]
    np.testing.assert_array_equal([j["limits"] for j in doc["joints"]], chain.limits)
    np.testing.assert_array_equal([j["limits_deg"] for j in doc["joints"]], np.degrees(chain.limits))
    assert [j["what"] for j in doc["joints"]] == [p.collision_limits().what for p in chain.pairs]


def test_limits_text_unchanged(capsys):
    chain = apair.load(CHAIN4)
    code, out, _ = run(capsys, "limits", CHAIN4)
    assert code == 0
    lim = np.degrees(chain.limits)
    assert out.splitlines() == [
        f"{chain.name}: joint ranges [deg] (explicit, or where the legs or plates first touch)",
        *(
            f"  joint {i + 1}: {lo:+10.4f} .. {hi:+10.4f}   {p.collision_limits().what}"
            for i, ((lo, hi), p) in enumerate(zip(lim, chain.pairs))
        ),
    ]


# ----------------------------------------------------------------------------- workspace

WORKSPACE = ("--samples", "4000", "--resolution", "8", "--quiet")


def test_workspace_json_matches_api(capsys):
    chain = apair.load(CHAIN2)
    doc = document(capsys, "workspace", CHAIN2, *WORKSPACE)
    ws = chain.workspace(samples=4000, resolution=8)
    assert doc["chain"] == chain.name and doc["units"]["voxel"] == "m"
    assert doc["samples"] == len(ws.points) and doc["dimension"] == ws.dimension
    assert doc["voxel"] == ws.voxel and doc["boundary_voxels"] == len(ws.boundary)
    assert doc["volume"] == ws.volume and doc["measure"] == ws.measure and doc["summary"] == ws.summary
    np.testing.assert_array_equal(doc["bounding_box"]["min"], ws.points.min(axis=0))
    np.testing.assert_array_equal(doc["bounding_box"]["max"], ws.points.max(axis=0))


def test_workspace_text_unchanged(capsys):
    chain = apair.load(CHAIN2)
    code, out, _ = run(capsys, "workspace", CHAIN2, *WORKSPACE)
    assert code == 0
    ws = chain.workspace(samples=4000, resolution=8)
    lo, hi = ws.points.min(axis=0), ws.points.max(axis=0)
    assert out.splitlines() == [
        f"{chain.name}: workspace {ws.summary} from {len(ws.points)} samples; voxel {ws.voxel:.3g} m, "
        f"{len(ws.boundary)} boundary voxels",
        f"  bounding box [m]: x {lo[0]:+.4f} .. {hi[0]:+.4f}, y {lo[1]:+.4f} .. {hi[1]:+.4f}, "
        f"z {lo[2]:+.4f} .. {hi[2]:+.4f}",
    ]


# ----------------------------------------------------------------------------- ik-prepare


def test_ik_prepare_json_matches_api(capsys, tmp_path):
    path = arm_toml(tmp_path)
    doc = document(capsys, "ik-prepare", path, "--quiet")
    start = apair.load(path).prepare_ik()  # from the cache the command filled
    assert doc["chain"] == "arm" and doc["count"] == start.count == 16
    assert doc["certified"] == start.certified and doc["how"] == start.how
    assert doc["runs"] == list(start.runs) and doc["loops"] == start.loops
    assert doc["seconds"] == start.seconds and doc["units"]["seconds"] == "s"


def test_ik_prepare_text(capsys, tmp_path):
    path = arm_toml(tmp_path)
    code, out, _ = run(capsys, "ik-prepare", path, "--quiet")
    assert code == 0
    start = apair.load(path).prepare_ik()
    assert out == (
        f"arm: start system of 16 complex solutions, certified complete: {start.how}; runs found {start.runs} "
        f"in {start.loops} loops ({start.seconds:.1f} s to compute; cached)\n"
        f"kinematic family: {apair.load(path).kinematic_family().describe()}\n"
    )


# ----------------------------------------------------------------------------- kernels


def test_kernels_json_matches_the_manifest(capsys):
    doc = document(capsys, "kernels")
    kernels = manifest()["kernels"]
    assert "after CSE" in doc["counted"]
    assert doc["kernels"].keys() == kernels.keys()
    for name, k in doc["kernels"].items():
        assert k["ops_per_item"] == kernels[name]["ops_per_item"] and k["own_ops"] == kernels[name]["ops"]
        assert k["inputs"] == [{"name": a["name"], "shape": a["shape"]} for a in kernels[name]["inputs"]]
        assert k["outputs"] == [{"name": a["name"], "shape": a["shape"]} for a in kernels[name]["outputs"]]
    assert doc["kernels"]["bias6"]["composite"] is True and doc["kernels"]["fk6"]["composite"] is False


# ----------------------------------------------------------------------------- jacobian, dynamics


def test_jacobian_json_matches_api(capsys):
    chain = apair.load(CHAIN4)
    q = np.array([0.3, -0.5, 0.8, 1.1])
    doc = document(capsys, "jacobian", CHAIN4, "0.3", "-0.5", "0.8", "1.1")
    np.testing.assert_array_equal(doc["q"], q)
    np.testing.assert_array_equal(doc["J"], chain.jacobian(q))
    assert "rad" in doc["units"]["J"] and doc["outside_limits"] == []


@pytest.mark.parametrize("given", ["qdd", "tau", None])
def test_dynamics_json_matches_api(capsys, given):
    chain = apair.load(CHAIN2)
    q, qd, x = np.array([0.3, -0.4]), np.array([0.5, -1.5]), np.array([2.0, -0.25])
    extra = [] if given is None else [f"--{given}", "2,-0.25"]
    doc = document(capsys, "dynamics", CHAIN2, "--q", "0.3,-0.4", "--qd", "0.5,-1.5", *extra)
    assert doc["units"]["q"] == "rad" and doc["units"]["tau"] == "N m"
    np.testing.assert_array_equal(doc["q"], q)
    np.testing.assert_array_equal(doc["qd"], qd)
    np.testing.assert_array_equal(doc["M"], chain.mass_matrix(q))
    np.testing.assert_array_equal(doc["bias"], chain.bias(q, qd))
    np.testing.assert_array_equal(doc["gravity"], chain.gravity_torques(q))
    if given == "qdd":
        assert doc["dynamics"] == "inverse"
        np.testing.assert_array_equal(doc["qdd"], x)
        np.testing.assert_array_equal(doc["tau"], chain.inverse_dynamics(q, qd, x))
    elif given == "tau":
        assert doc["dynamics"] == "forward"
        np.testing.assert_array_equal(doc["tau"], x)
        np.testing.assert_array_equal(doc["qdd"], chain.forward_dynamics(q, qd, x))
    else:
        assert doc["dynamics"] is None and "tau" not in doc and "qdd" not in doc


# ----------------------------------------------------------------------------- errors, non-finite numbers


@pytest.mark.parametrize(
    "argv",
    [
        ["fk", CHAIN2, "0.1"],
        ["ik", CHAIN4, "1", "0", "0"],
        ["limits", EXAMPLES / "missing.toml"],
        ["jacobian", CHAIN2, "x", "0"],
        ["dynamics", CHAIN2, "--q", "0"],
    ],
)
def test_json_errors_stay_one_line_on_stderr(capsys, argv):
    code, out, err = run(capsys, *argv, "--json")
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith(f"apair {argv[0]}: error: ")


def test_non_finite_numbers_are_strings():
    from apair.cli.output import jsonable

    doc = jsonable({"a": np.array([1.5, math.inf, -math.inf, math.nan]), "b": np.float64(0.1), "c": np.int64(3)})
    assert doc == {"a": [1.5, "Infinity", "-Infinity", "NaN"], "b": 0.1, "c": 3}
    assert [float(x) for x in doc["a"][1:3]] == [math.inf, -math.inf] and math.isnan(float(doc["a"][3]))
    json.dumps(doc, allow_nan=False)  # strict JSON
