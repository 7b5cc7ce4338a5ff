"""The commands `apair jacobian` and `apair dynamics`, the joint-limit notes and refusals of `fk` and
`export`, the output option `--out`, the wording of the command line's errors (its own options,
joints from 1) and `apair kernels`' operation counts; every number against the Python API."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import apair
from apair import files, mjcf
from apair.cli import main
from apair.kernels import manifest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CHAIN2, CHAIN4 = EXAMPLES / "2a_chain.toml", EXAMPLES / "4a_chain.toml"
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
# a general A-pair whose range of motion is limited (|theta| <= theta_limit), then an R-pair
GENERAL = (
    '[[joint]]\npair = "general"\nbase_radius = 0.05\nplatform_radius = 0.04\nleg_length = 0.06\n'
    "a = 0.1\nalpha = 0\nmass = 1.0\ninertia = [0.01, 0.01, 0.01]\n"
    '[[joint]]\npair = "revolute"\na = 0.1\nalpha = 0\nmass = 1.0\ninertia = [0.01, 0.01, 0.01]\n'
)


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, *argv) -> str:
    """The command's error line: exit status 2, nothing on stdout, one line on stderr."""
    code, out, err = run(capsys, *argv)
    assert code == 2, (code, out, err)
    assert out == "" and err.count("\n") == 1 and "Traceback" not in err, err
    return err


def numbers_after(out: str, header: str) -> np.ndarray:
    """The numbers of the block printed after the line that starts with `header`, up to the next
    line that does not start with a bracket or a blank."""
    lines = out.split("\n")
    start = next(i for i, line in enumerate(lines) if line.startswith(header)) + 1
    block = []
    for line in lines[start:]:
        if not line.startswith(("[", " ")):
            break
        block.append(line)
    return np.array([float(x) for x in re.findall(NUMBER, " ".join(block))])


@pytest.fixture
def general(tmp_path):
    path = tmp_path / "general.toml"
    path.write_text(GENERAL)
    return path


# ----------------------------------------------------------------------------- apair jacobian


@pytest.mark.parametrize("angles, deg", [(["0.3", "-0.5", "0.8", "1.1"], False), (["10", "-20", "30", "45"], True)])
def test_jacobian_matches_api(capsys, angles, deg):
    code, out, err = run(capsys, "jacobian", CHAIN4, *angles, *(["--deg"] if deg else []))
    assert code == 0 and err == ""
    chain = apair.load(CHAIN4)
    q = np.array(angles, float)
    q = np.radians(q) if deg else q
    assert out.startswith(f"{chain.name}: 4 joints")
    J = numbers_after(out, "J =").reshape(6, 4)
    np.testing.assert_allclose(J, chain.jacobian(q), rtol=0, atol=1e-11)


def test_jacobian_wrong_count_names_q(capsys):
    err = one_line_error(capsys, "jacobian", CHAIN2, "0.1", "0.2", "0.3")
    assert err.startswith("apair jacobian: error: Q: ") and "2 joints" in err and "3" in err


def test_jacobian_at_a_pairs_range_end_names_the_joint(capsys, general):
    limit = apair.load(general).pairs[0].theta_limit
    err = one_line_error(capsys, "jacobian", general, repr(limit), "0")
    assert err.startswith("apair jacobian: error: Q: joint 1 ") and "range end" in err
    assert "q[" not in err and "np." not in err


# ----------------------------------------------------------------------------- apair dynamics


def test_dynamics_inverse_matches_api(capsys):
    chain = apair.load(CHAIN2)
    q, qd, qdd = np.array([0.3, -0.4]), np.array([0.5, -1.5]), np.array([2.0, -0.25])
    code, out, err = run(capsys, "dynamics", CHAIN2, "--q", "0.3,-0.4", "--qd", "0.5,-1.5", "--qdd", "2,-0.25")
    assert code == 0 and err == ""
    np.testing.assert_allclose(numbers_after(out, "M "), chain.mass_matrix(q).ravel(), rtol=0, atol=1e-12)
    np.testing.assert_allclose(numbers_after(out, "bias "), chain.bias(q, qd), rtol=0, atol=1e-12)
    np.testing.assert_allclose(numbers_after(out, "gravity "), chain.gravity_torques(q), rtol=0, atol=1e-12)
    tau = chain.inverse_dynamics(q, qd, qdd)
    np.testing.assert_allclose(numbers_after(out, "tau "), tau, rtol=0, atol=1e-12)
    assert "forward dynamics" not in out


def test_dynamics_forward_matches_api(capsys):
    chain = apair.load(CHAIN4)
    q, qd, tau = np.array([0.1, 0.2, -0.3, 0.4]), np.zeros(4), np.array([1.0, -2.0, 0.5, 0.0])
    code, out, err = run(capsys, "dynamics", CHAIN4, "--q", "0.1,0.2,-0.3,0.4", "--tau", "1,-2,0.5,0")
    assert code == 0 and err == ""
    qdd = chain.forward_dynamics(q, qd, tau)
    np.testing.assert_allclose(numbers_after(out, "qdd "), qdd, rtol=0, atol=1e-12)
    np.testing.assert_allclose(numbers_after(out, "bias "), chain.bias(q, qd), rtol=0, atol=1e-12)
    assert "inverse dynamics" not in out


def test_dynamics_without_qdd_or_tau_prints_m_bias_gravity(capsys):
    chain = apair.load(CHAIN2)
    code, out, _ = run(capsys, "dynamics", CHAIN2, "--q", "-0.2,0.7")
    assert code == 0
    q = np.array([-0.2, 0.7])
    np.testing.assert_allclose(numbers_after(out, "bias "), chain.bias(q, np.zeros(2)), rtol=0, atol=1e-12)
    assert "inverse dynamics" not in out and "forward dynamics" not in out


@pytest.mark.parametrize(
    "extra, option",
    [
        (["--q", "0.1"], "--q"),
        (["--q", "0.1,0.2", "--qd", "1,2,3"], "--qd"),
        (["--q", "0.1,0.2", "--qdd", "1"], "--qdd"),
        (["--q", "0.1,0.2", "--tau", "1,2,3"], "--tau"),
        (["--q", "0.1,x"], "--q"),
        (["--q", "0.1,0.2", "--qd", "nan,0"], "--qd"),
    ],
)
def test_dynamics_bad_lengths_name_the_option(capsys, extra, option):
    err = one_line_error(capsys, "dynamics", CHAIN2, *extra)
    assert err.startswith(f"apair dynamics: error: {option}: "), err


def test_dynamics_qdd_and_tau_are_exclusive(capsys):
    with pytest.raises(SystemExit) as info:
        main(["dynamics", str(CHAIN2), "--q", "0,0", "--qdd", "0,0", "--tau", "0,0"])
    assert info.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err


# ----------------------------------------------------------------------------- joint limits


def test_fk_outside_the_limits_prints_the_pose_and_a_note(capsys):
    chain = apair.load(CHAIN2)
    code, out, err = run(capsys, "fk", CHAIN2, "3", "0.2")
    assert code == 0
    T = numbers_after(out, "T =").reshape(4, 4)
    np.testing.assert_allclose(T, chain.fk([3.0, 0.2]), atol=1e-11)
    lo, hi = chain.hard_limits()[0]
    assert err.count("\n") == 1 and "joint 1 " in err and "joint 2" not in err, err
    assert f"{lo:.6g}" in err and f"{hi:.6g}" in err and "outside" in err


def test_fk_outside_the_limits_in_degrees_says_degrees(capsys):
    chain = apair.load(CHAIN2)
    code, _, err = run(capsys, "fk", CHAIN2, "0", "150", "--deg")
    assert code == 0 and "joint 2 " in err and "joint 1" not in err
    assert f"{np.degrees(chain.hard_limits()[1, 1]):.6g} deg" in err


def test_fk_inside_the_limits_has_no_note(capsys):
    code, _, err = run(capsys, "fk", CHAIN2, "2", "-2")  # the limits are ±2.0944 rad
    assert code == 0 and err == ""


def test_export_outside_the_limits_is_refused_naming_the_option(capsys, tmp_path):
    out = tmp_path / "m.xml"
    err = one_line_error(capsys, "export", "mjcf", CHAIN2, "--out", out, "--q", "3,0")
    assert "joint 1" in err and "--outside-limits" in err and "outside_limits=True" not in err
    assert not out.exists()


def test_export_outside_limits_writes_it_anyway(capsys, tmp_path):
    out = tmp_path / "m.xml"
    code, _, err = run(capsys, "export", "mjcf", CHAIN2, "--out", out, "--q", "3,0", "--outside-limits")
    assert code == 0 and err == ""
    chain = apair.load(CHAIN2)
    assert out.read_text() == mjcf.to_mjcf(chain, [3.0, 0.0], name=chain.name, outside_limits=True)


def test_export_no_limits_drops_the_hinge_ranges(capsys, tmp_path):
    out = tmp_path / "m.xml"
    assert run(capsys, "export", "mjcf", CHAIN2, "--out", out, "--no-limits")[0] == 0
    chain = apair.load(CHAIN2)
    xml = out.read_text()
    assert xml == mjcf.to_mjcf(chain, None, name=chain.name, limits=False)
    assert xml != mjcf.to_mjcf(chain, None, name=chain.name)


def test_export_negative_first_angle(capsys, tmp_path):
    out = tmp_path / "m.xml"
    code, _, err = run(capsys, "export", "mjcf", CHAIN2, "--out", out, "--q", "-0.1,0.2")
    assert code == 0 and err == ""
    chain = apair.load(CHAIN2)
    assert out.read_text() == mjcf.to_mjcf(chain, [-0.1, 0.2], name=chain.name)


def test_export_wrong_count_names_the_option(capsys, tmp_path):
    err = one_line_error(capsys, "export", "mjcf", CHAIN2, "--out", tmp_path / "m.xml", "--q", "1,0,4")
    assert err.startswith("apair export: error: --q: "), err


# ----------------------------------------------------------------------------- --out


def test_export_out_option(capsys, tmp_path):
    out = tmp_path / "m.xml"
    code, stdout, err = run(capsys, "export", "mjcf", CHAIN2, "--out", out)
    assert code == 0 and err == "" and str(out) in stdout and out.is_file()


def test_export_positional_out_still_works_with_a_deprecation_note(capsys, tmp_path):
    out = tmp_path / "m.xml"
    code, stdout, err = run(capsys, "export", "mjcf", CHAIN2, out)
    assert code == 0 and out.is_file() and str(out) in stdout
    assert err == "apair export: OUT as a positional argument is deprecated; use --out\n"


def test_export_out_given_twice_is_refused(capsys, tmp_path):
    err = one_line_error(capsys, "export", "mjcf", CHAIN2, tmp_path / "a.xml", "--out", tmp_path / "b.xml")
    assert "--out" in err and "OUT" in err


def test_export_without_out_is_refused(capsys):
    err = one_line_error(capsys, "export", "mjcf", CHAIN2)
    assert "--out" in err


# ----------------------------------------------------------------------------- wording


def test_existing_file_says_force_on_the_command_line(capsys, tmp_path):
    out = tmp_path / "m.xml"
    out.write_text("mine")
    err = one_line_error(capsys, "export", "mjcf", CHAIN2, "--out", out)
    assert "use --force" in err and "overwrite=True" not in err
    assert out.read_text() == "mine"


def test_existing_file_says_overwrite_in_the_api(tmp_path):
    out = tmp_path / "m.xml"
    out.write_text("mine")
    with pytest.raises(ValueError, match=r"exists; pass overwrite=True to replace it$"):
        files.target(out, False, ".xml")


def test_non_finite_angle_names_q(capsys):
    err = one_line_error(capsys, "fk", CHAIN2, "0.1", "nan")
    assert err.startswith("apair fk: error: Q: 'nan'"), err


def test_angle_past_a_pairs_range_names_the_joint_from_1(capsys, general):
    limit = apair.load(general).pairs[0].theta_limit
    err = one_line_error(capsys, "fk", general, "3", "0")
    assert err.startswith("apair fk: error: Q: joint 1 ") and f"{limit:.6g}" in err, err
    assert "q[" not in err and "np.float64" not in err


def test_ik_of_a_general_pair_names_the_file_and_the_joint_from_1(capsys, general):
    err = one_line_error(capsys, "ik", general, *"1 0 0 0 0 1 0 0 0 0 1 0".split())
    assert err.startswith(f"apair ik: error: {general}: joint 1: a general A-pair"), err
    assert "pairs[" not in err


def test_forward_dynamics_of_massless_links_names_the_file(capsys, tmp_path):
    path = tmp_path / "massless.toml"
    path.write_text('[[joint]]\npair = "revolute"\na = 0.1\nalpha = 0\n' * 2)
    err = one_line_error(capsys, "dynamics", path, "--q", "0,0", "--tau", "1,0")
    assert err.startswith(f"apair dynamics: error: {path}: the mass matrix is not positive definite"), err


def test_ik_pose_errors_name_pose(capsys):
    err = one_line_error(capsys, "ik", CHAIN4, *"1 0 0 0 0 1 0 0 0 0 2 0".split())
    assert err.startswith("apair ik: error: POSE: the rotation part is not a proper rotation"), err


# ----------------------------------------------------------------------------- apair kernels


def test_kernels_counts_per_item_with_the_callees(capsys):
    code, out, _ = run(capsys, "kernels")
    assert code == 0
    header, *rows = out.splitlines()
    assert "after CSE" in header and "per item" in header
    kernels = manifest()["kernels"]
    assert [r.split()[0] for r in rows] == sorted(kernels)
    for row in rows:
        name, count = row.split()[:2]
        assert int(count) == kernels[name]["ops_per_item"], row
        # a slide's law values are copies; the third derivative of a linear law is zero; one R-pair's
        # mass matrix is its design's constant
        constant = {"law_prismatic", "law_prismatic_d3", "law_helical_d3", "law_revolute_d3", "mass_matrix_revolute1"}
        assert int(count) > 0 or name in constant, row
    bias6 = next(r for r in rows if r.startswith("bias6 "))
    assert "composite" in bias6
    assert "composite" not in next(r for r in rows if r.startswith("fk6 "))
