"""What a hostile user met (issue 41): values outside the range apair computes in, masked arrays,
flags that are not bools, unbounded counts, seeds, output paths that are folders or devices,
codegen prefixes that shadow a module or header, negative numbers in exponent form, errors that
span lines."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import apair
from apair import _validate as V
from apair.cli import main
from apair.io import load
from apair.specialise import check_prefix, prefix_from

ROOT = Path(__file__).resolve().parents[2]
CHAIN4 = str(ROOT / "examples" / "4a_chain.toml")
CHAIN2 = str(ROOT / "examples" / "2a_chain.toml")


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, *argv) -> str:
    code, _, err = run(capsys, *argv)
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


# ----------------------------------------------------------------------------- item 7: ranges
def chain_with(**kw):
    base = load(CHAIN2)
    args = dict(pairs=base.pairs, a=base.a, alpha=base.alpha, offset=base.offset, links=base.links)
    args.update(kw)
    return apair.AChain(**args)


@pytest.mark.parametrize(
    "field, value",
    [("a", [1.5e308, 0.2]), ("a", [0.3, 1e41]), ("offset", [-1.7e308, 0.0]), ("offset", [1e-45, 0.0])],
)
def test_lengths_outside_the_range_are_refused(field, value):
    with pytest.raises(ValueError, match=rf"^{field}\[\d\]: .* outside the range apair computes in"):
        chain_with(**{field: value})


def test_lengths_at_the_ends_of_the_range_give_finite_answers():
    for s in (1e-40, 1e40):
        c = chain_with(a=[s, -s], offset=[s, 0.0])
        q = np.array([0.3, -0.2])
        assert np.isfinite(c.fk(q)).all()
        assert np.isfinite(c.jacobian(q)).all()


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(mass=1e308), "mass"),
        (dict(mass=1e-300), "mass"),
        (dict(mass=1.0, com=(0, 0, 1e300)), r"com\[2\]"),
        (dict(mass=1.0, inertia=np.eye(3) * 1e200), r"inertia\[0, 0\]"),
    ],
)
def test_masses_outside_the_range_are_refused(kw, field):
    with pytest.raises(ValueError, match=rf"^{field}: .* outside the range"):
        apair.Link(**kw)


def test_heavy_links_give_a_finite_mass_matrix():
    heavy = [apair.Link(1e40, (0.1, 0, 0), np.eye(3) * 1e39) for _ in range(2)]
    c = chain_with(links=heavy)
    M = c.mass_matrix(np.array([0.3, -0.2]))
    assert np.isfinite(M).all() and M[0, 0] > 0


def test_chain_file_with_a_huge_length_names_file_joint_and_key(tmp_path, capsys):
    text = Path(CHAIN2).read_text().replace("a = 0.30", "a = 1.5e308", 1)
    assert text != Path(CHAIN2).read_text()
    f = tmp_path / "huge.toml"
    f.write_text(text)
    err = one_line_error(capsys, "fk", f, 0, 0)
    assert "huge.toml" in err and "outside the range" in err


# ----------------------------------------------------------------------------- item 10: masked
@pytest.mark.parametrize("method", ["fk", "jacobian", "mass_matrix"])
def test_masked_arrays_are_refused(method):
    c = load(CHAIN2)
    q = np.ma.masked_array([0.1, np.nan], mask=[False, True])
    with pytest.raises(ValueError, match="^q: masked arrays are not accepted"):
        getattr(c, method)(q)
    getattr(c, method)(np.zeros(2))  # the native single-pose path is set up now: it refuses them too
    for values in ([0.1, np.nan], [0.1, 0.2]):
        with pytest.raises(ValueError, match="^q: masked arrays are not accepted"):
            getattr(c, method)(np.ma.masked_array(values, mask=[False, True]))


def test_masked_pose_is_refused_by_ik():
    c = load(CHAIN2)
    T = np.ma.masked_array(c.fk([0.1, 0.2]), mask=np.zeros((4, 4), bool))
    with pytest.raises(ValueError, match="masked arrays are not accepted"):
        c.ik(T)


# ----------------------------------------------------------------------------- items 13, 17
def test_view_workspace_count_is_bounded(capsys, tmp_path):
    from apair.view import MAX_WORKSPACE_POINTS

    err = one_line_error(capsys, "view", CHAIN2, "--out", tmp_path / "v.html", "--workspace", 10**7)
    assert "--workspace" in err and str(MAX_WORKSPACE_POINTS) in err
    with pytest.raises(ValueError, match="^workspace: must be <= "):
        load(CHAIN2).to_html(workspace=MAX_WORKSPACE_POINTS + 1)
    assert not (tmp_path / "v.html").exists()


@pytest.mark.parametrize("value", [10**12, 2**70])
def test_ik_local_max_iter_is_bounded(value):
    c = load(CHAIN2)
    with pytest.raises(ValueError, match="^max_iter: must be <= "):
        c.ik_local(c.fk([0.1, 0.2]), [0.0, 0.0], max_iter=value)


@pytest.mark.parametrize(
    "value, message", [(None, "expected"), (-1, "must be >= 0"), (2**64, "must be <="), (1.5, "integer")]
)
def test_seeds_must_be_integers_in_range(value, message):
    c = load(CHAIN2)
    with pytest.raises(ValueError, match=f"^seed: .*{message}"):
        c.constraint_variety(max_degree=2, seed=value)
    with pytest.raises(ValueError, match=f"^seed: .*{message}"):
        c.workspace(samples=1000, seed=value)


@pytest.mark.parametrize("flag", ["full", "within_limits"])
@pytest.mark.parametrize("value", ["no", 0, 1, None])
def test_ik_flags_are_bools(flag, value):
    c = load(CHAIN2)
    with pytest.raises(ValueError, match=f"^{flag}: expected True or False"):
        c.ik(c.fk([0.1, 0.2]), **{flag: value})


def test_overwrite_is_a_bool(tmp_path):
    with pytest.raises(ValueError, match="^overwrite: expected True or False"):
        load(CHAIN2).to_html(tmp_path / "x.html", overwrite="no")
    assert not (tmp_path / "x.html").exists()


# ----------------------------------------------------------------------------- items 17, 19: paths
@pytest.mark.parametrize("path", [".", "..", "sub", "sub/", "/dev/null", ""])
def test_plot_paths_that_are_no_file_names_are_refused(capsys, tmp_path, monkeypatch, path):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    before = sorted(p.name for p in tmp_path.rglob("*"))
    err = one_line_error(capsys, "limits", CHAIN4, "--plot", path)
    assert "path: " in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # nothing written beside it
    assert not Path("/dev/null.png").exists()


def test_plot_into_an_unwritable_folder_names_the_folder_not_a_temporary_file(capsys):
    err = one_line_error(capsys, "limits", CHAIN4, "--plot", "/proc/x")
    assert "'/proc'" in err and "/proc/.x" not in err


@pytest.mark.parametrize(
    "argv, folder",
    [
        (["export", "mjcf", CHAIN2, "--out", "{d}"], "d"),
        (["view", CHAIN2, "--out", "{d}"], "d"),
        (["workspace", CHAIN2, "--samples", "1000", "--quiet", "--plot", "{d}"], "d"),
    ],
)
def test_every_command_refuses_a_folder_as_output(capsys, tmp_path, argv, folder):
    d = tmp_path / folder
    d.mkdir()
    err = one_line_error(capsys, *[a.format(d=d) for a in argv])
    assert "is a folder" in err
    assert sorted(tmp_path.iterdir()) == [d] and not any(d.iterdir())


@pytest.mark.parametrize(
    "argv, kind",
    [
        (["export", "mjcf", CHAIN2, "--out", "{d}/m.png"], "XML model"),
        (["view", CHAIN2, "--out", "{d}/x.htm"], "HTML page"),
    ],
)
def test_wrong_suffix_names_the_kind_of_output(capsys, tmp_path, argv, kind):
    err = one_line_error(capsys, *[a.format(d=tmp_path) for a in argv])
    assert kind in err and "picture" not in err


# ----------------------------------------------------------------------------- item 18: one line
def test_errors_quoting_a_large_value_stay_short():
    big = np.arange(10_000.0).reshape(100, 100).astype(complex)
    with pytest.raises(ValueError) as info:
        V.real_array("q", big)
    assert "\n" not in str(info.value) and len(str(info.value)) < 200
    with pytest.raises(ValueError) as info:
        apair.AChain(list(range(1000)), [0.0], [0.0])  # type: ignore[arg-type]
    assert "\n" not in str(info.value) and len(str(info.value)) < 200


# ----------------------------------------------------------------------------- item 21: prefixes
@pytest.mark.parametrize("name", ["numpy", "math", "os", "sys", "stddef", "stdio", "string", "time", "ctypes"])
def test_prefixes_that_shadow_a_module_or_header_are_refused(name):
    with pytest.raises(ValueError, match="^prefix: .*shadow"):
        check_prefix(name)


def test_codegen_cli_refuses_a_shadowing_prefix_and_writes_nothing(capsys, tmp_path):
    err = one_line_error(capsys, "codegen", CHAIN2, "--prefix", "math", "--out", tmp_path / "out")
    assert "prefix" in err and not (tmp_path / "out").exists()


def test_a_chain_file_named_like_a_module_gets_a_safe_default_prefix():
    assert prefix_from("math.toml") == "chain_math"
    assert prefix_from("stdio.toml") == "chain_stdio"
    assert prefix_from("arm.toml") == "arm"


# ----------------------------------------------------------------------------- item 24: -1e-3
@pytest.mark.parametrize("word", ["-1e-3", "-1E-3", "-2.5e+0", "-.5e1", "-1."])
def test_negative_numbers_in_exponent_form_are_values(capsys, word):
    code, out, err = run(capsys, "fk", CHAIN2, word, "0.2")
    assert code == 0, err
    q = float(word)
    assert f"q = [{q:.1f}" in out or "q = [" in out
    T = load(CHAIN2).fk([q, 0.2])
    assert f"{T[0, 3]:.6f}"[:6] in out


def test_negative_exponent_pose_for_ik(capsys):
    c = load(CHAIN2)
    T = c.fk([-1e-3, 0.2])
    words = [f"{x:.17e}" for x in T.ravel()]
    assert any(w.startswith("-") and "e-" in w for w in words)
    code, out, err = run(capsys, "ik", CHAIN2, *words)
    assert code == 0, err
    assert "real solution" in out


def test_unknown_options_are_still_refused(capsys):
    with pytest.raises(SystemExit):
        main(["fk", CHAIN2, "-x", "0.2"])
