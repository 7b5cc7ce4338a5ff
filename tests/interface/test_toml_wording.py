"""How loading a chain words its errors (issue 36 item 13, the load side), and the pair's ranges.

A file that is not TOML names the file, tomllib's reason and the line and column; a key that is
not valid at its place gets the nearest valid key as a hint (or the pair kind it belongs to); an
angle in radians of more than a turn is refused with the degrees key as a hint; a pair's angle
past its range is printed as a plain number; and every length and mass of a pair lies in the
range apair computes in (docs/conventions.md).
"""

from __future__ import annotations

import difflib
import math
import re
from pathlib import Path

import numpy as np
import pytest

import apair
from apair import _validate as V
from apair import io
from apair.cli import main

ROOT = Path(__file__).resolve().parents[2]
R = 'pair = "revolute"\na = 0.1\nalpha = 0.0\n'
SIN = 'pair = "sinusoidal"\nbase_radius = 0.05\nplatform_radius = 0.04\na = 0.1\nalpha = 0.0\n'
GEN = 'pair = "general"\nbase_radius = 0.05\nplatform_radius = 0.04\nleg_length = 0.06\na = 0.1\nalpha = 0.0\n'


def joints(*bodies):
    return "".join(f"[[joint]]\n{b}" for b in bodies)


def error(text, where="f.toml"):
    """The one-line message of loading text."""
    with pytest.raises(ValueError) as exc:
        io.loads(text, where=where)
    msg = str(exc.value)
    assert "\n" not in msg and len(msg) < 300, msg
    return msg


# ----------------------------------------------------------------------------- (b) not TOML
@pytest.mark.parametrize(
    "text, line, column",
    [("[[joint]\n", 1, 8), ('name = "x"\n\n[[joint]]\npair = "revolute\n', 4, 17), ("a = 1\na = 2\n", 2, 6)],
)
def test_invalid_toml_names_file_reason_line_and_column(tmp_path, text, line, column):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    for load in (lambda: io.load(path), lambda: io.loads(text, where=str(path))):
        with pytest.raises(ValueError) as exc:
            load()
        msg = str(exc.value)
        assert re.fullmatch(rf"{re.escape(str(path))}: not valid TOML: \S.* \(line {line}, column {column}\)", msg), msg
        assert "at line" not in msg and not msg.startswith("path:")


def test_invalid_toml_at_the_end_of_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "x')
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: not valid TOML: .*\(at the end of the file\)$"):
        io.load(path)


def test_cli_words_invalid_toml_the_same(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text("[[joint]\n")
    assert main(["fk", str(path), "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"error: {path}: not valid TOML: " in err and "(line 1, column 8)" in err, err


# ----------------------------------------------------------------------------- (c) unknown keys
VALID = {
    "sinusoidal": SIN,
    "general": GEN,
    "revolute": R,
}


@pytest.mark.parametrize(
    "kind, typo",
    [
        ("sinusoidal", "alpah_deg"),
        ("general", "leg_lenght"),
        ("revolute", "theta_ofset"),
        ("sinusoidal", "plattform_radius"),
    ],
)
def test_a_misspelt_key_gets_the_nearest_valid_key(kind, typo):
    valid = set(io._PAIR_KEYS[kind] | io._DH_KEYS | io._LINK_KEYS | {"pair"})
    near = difflib.get_close_matches(typo, sorted(valid), n=1)
    assert near, typo  # the test's typos are near some key
    msg = error(joints(R, VALID[kind] + f"{typo} = 1\n"))
    assert msg == f"f.toml: joint 2: unknown key {typo}; did you mean {near[0]}?", msg


@pytest.mark.parametrize(
    "kind, key, others",
    [("revolute", "base_radius", ["sinusoidal", "general"]), ("sinusoidal", "leg_length", ["general"])],
)
def test_a_key_of_another_pair_kind_says_which_kind_it_belongs_to(kind, key, others):
    msg = error(joints(VALID[kind] + f"{key} = 0.09\n"))
    assert msg.startswith(f"f.toml: joint 1: {key} is not a key of a {kind} pair"), msg
    assert all(o in msg for o in others) and not any(k in msg for k in VALID if k not in others + [kind]), msg


def test_a_top_level_typo_gets_the_nearest_top_level_key():
    assert error("gravty = [0, 0, -9.81]\n" + joints(R)) == "f.toml: unknown key gravty; did you mean gravity?"


@pytest.mark.parametrize("key", ["alpha", "base_radius", "mass"])
def test_a_joint_key_at_the_top_says_where_it_belongs(key):
    msg = error(f"{key} = 0.1\n" + joints(R))
    assert msg.startswith(f"f.toml: {key} belongs in a [[joint]] table"), msg


def test_a_top_level_key_in_a_joint_says_where_it_belongs():
    msg = error(joints(R + "gravity = [0, 0, -9.81]\n"))
    assert msg.startswith("f.toml: joint 1: gravity belongs at the top of the file"), msg


def test_a_key_far_from_every_valid_one_is_named_without_a_guess():
    msg = error(joints(R + "zzzzzz = 1\n"))
    assert msg.startswith("f.toml: joint 1: unknown key zzzzzz") and "did you mean" not in msg, msg


def test_several_unknown_keys_are_all_named():
    msg = error(joints(R + "alpah_deg = 1\nzzzzzz = 2\n"))
    assert "alpah_deg" in msg and "zzzzzz" in msg and "did you mean alpha_deg" in msg, msg


@pytest.mark.parametrize("key", ["bell\u0007", "line\nfeed", "", "a" * 500])
def test_an_unknown_key_is_quoted_when_it_cannot_be_printed_plainly(key):
    text = key.replace("\\", "\\\\").replace("\n", "\\n").replace("\u0007", "\\u0007")
    msg = error(joints(R + f'"{text}" = 1\n'))
    assert msg.isprintable() and msg.startswith("f.toml: joint 1: unknown key "), msg


# ----------------------------------------------------------------------------- (d) radians or degrees
@pytest.mark.parametrize(
    "line, key, hint",
    [
        ("alpha = 90", "alpha", "alpha_deg = 90"),
        ("alpha = -45.5", "alpha", "alpha_deg = -45.5"),
        ("theta_offset = 30", "theta_offset", "theta_offset_deg = 30"),
        ("limits = [-90, 90]", "limits", "limits_deg = [-90, 90]"),
        ("limits = [-1.0, 120.0]", "limits", "limits_deg = [-1.0, 120.0]"),
    ],
)
def test_an_angle_of_more_than_a_turn_in_radians_is_refused_with_a_hint(line, key, hint):
    body = R.replace("alpha = 0.0\n", "") + ("" if key == "alpha" else "alpha = 0.0\n") + line + "\n"
    msg = error(joints(body))
    assert msg.startswith(f"f.toml: joint 1.{key}: ") and "2 pi" in msg and msg.endswith(f"did you mean {hint}?"), msg


@pytest.mark.parametrize("x", [2 * math.pi, -2 * math.pi, 6.28, 0.5])
def test_angles_of_up_to_a_turn_are_accepted(x):
    chain = io.loads(joints(f'pair = "revolute"\na = 0.1\nalpha = {x!r}\ntheta_offset = {x!r}\n'))
    assert chain.alpha[0] == x and chain.theta_offset[0] == x
    if x > 0:
        assert tuple(io.loads(joints(R + f"limits = [{-x!r}, {x!r}]\n")).limits[0]) == (-x, x)


def test_degrees_keys_take_more_than_a_turn():
    chain = io.loads(joints(R + "limits_deg = [-540, 540]\n"))
    np.testing.assert_allclose(chain.limits[0], np.radians([-540, 540]))


# ----------------------------------------------------------------------------- (a) a pair's range
def test_an_angle_past_a_pairs_range_is_printed_plainly():
    pair = apair.APair(0.05, 0.04, leg_length=0.06)
    with pytest.raises(ValueError) as exc:
        pair.law(np.array([0.1, 3.0]))
    msg = str(exc.value)
    assert msg.startswith("theta: outside this pair's range") and msg.endswith("e.g. 3"), msg
    assert "np." not in msg and "float64" not in msg
    with pytest.raises(ValueError, match=r"e\.g\. -2\.99999999999$"):
        pair.law(-2.99999999999)


# ----------------------------------------------------------------------------- the pair's sizes
LO, HI = V.LENGTH_RANGE


@pytest.mark.parametrize(
    "kw, field, unit",
    [
        ({"base_radius": LO / 10}, "base_radius", "m"),
        ({"platform_radius": HI * 10}, "platform_radius", "m"),
        ({"leg_length": HI * 10}, "leg_length", "m"),
        ({"leg_radius": LO / 10}, "leg_radius", "m"),
        ({"thickness": HI * 10}, "thickness", "m"),
        ({"leg_mass": LO / 10}, "leg_mass", "kg"),
        ({"leg_mass": HI * 10}, "leg_mass", "kg"),
    ],
)
def test_a_pairs_lengths_and_leg_mass_lie_in_the_range_apair_computes_in(kw, field, unit):
    args = {"base_radius": 0.05, "platform_radius": 0.04, **kw}
    with pytest.raises(
        ValueError, match=rf"^{field}: {re.escape(f'{kw[field]:.6g}')} {unit} is outside the range"
    ) as exc:
        apair.APair(**args)
    assert "\n" not in str(exc.value)


def test_a_pairs_sizes_at_the_range_ends_are_accepted():
    assert apair.APair(LO, LO, leg_mass=HI, leg_radius=LO, thickness=LO).leg_mass == HI
    assert apair.APair(HI, HI, leg_mass=LO).base_radius == HI


def test_a_chain_file_names_the_key_of_a_pair_size_out_of_range():
    msg = error(joints(SIN.replace("base_radius = 0.05", f"base_radius = {LO / 10!r}")))
    assert msg.startswith("f.toml: joint 1.base_radius: ") and "outside the range" in msg, msg


def test_the_conventions_state_the_range_the_code_checks():
    """docs/conventions.md: the pair's lengths (§2) in the one range, not another."""
    doc = (ROOT / "docs" / "conventions.md").read_text(encoding="utf-8")
    section2 = doc[doc.index("## §2") : doc.index("## §3")]
    stated = set(re.findall(r"1e-?\d+", section2))
    assert stated == {f"{LO:g}", f"{HI:g}".replace("+", "")}, stated
