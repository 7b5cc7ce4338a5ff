"""Chain files (apair.io): sizes are checked before any work on the contents, and a pair's design
is checked on loading, in the file's terms (issue 41, items 12, 15, 20)."""

from __future__ import annotations

import time

import pytest

import apair
from apair.cli import main

JOINT = 'pair = "sinusoidal"\nbase_radius = 0.05\nplatform_radius = 0.04\na = 0.2\nalpha = 0.5\n'


def write(tmp_path, text, name="chain.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def load_error(path, *parts):
    """The one-line ValueError of loading path; it names each of parts."""
    with pytest.raises(ValueError) as info:
        apair.load(path)
    msg = str(info.value)
    assert "\n" not in msg and len(msg) < 400, msg
    for part in parts:
        assert part in msg, msg
    return msg


@pytest.fixture
def no_collision_work(monkeypatch):
    """Counts collision-limit computations (the slow part of loading a joint with a range)."""
    calls = []
    limits = apair.APair.collision_limits
    monkeypatch.setattr(apair.APair, "collision_limits", lambda self: calls.append(self) or limits(self))
    return calls


@pytest.mark.parametrize("key", ["limits = [-0.5, 0.5]", "limits_deg = [-30, 30]"])
def test_thousands_of_joints_are_refused_before_any_work(tmp_path, key, no_collision_work):
    """3000 joints with ranges took 45-72 s (a collision-limit computation each) before the
    1-to-6-joints check refused them."""
    path = write(tmp_path, f"[[joint]]\n{JOINT}{key}\n" * 3000)
    start = time.perf_counter()
    load_error(path, str(path), "[[joint]]", "1 to 7", "3000")
    assert time.perf_counter() - start < 2
    assert no_collision_work == []


def test_list_sizes_come_before_the_joints_ranges(tmp_path, no_collision_work):
    """A gravity of the wrong size is reported before any joint's range is checked."""
    path = write(tmp_path, "gravity = [0.0, 0.0, -9.81, 1.0]\n" + f"[[joint]]\n{JOINT}limits = [-0.5, 0.5]\n" * 6)
    load_error(path, "gravity", "(3,)")
    assert no_collision_work == []


def test_huge_lists_give_short_messages(tmp_path):
    """Every list is checked by its size first, and quoted shortened (reprlib), as are unknown keys."""
    path = write(tmp_path, "gravity = [" + "1.0, " * 100_000 + "]\n" + f"[[joint]]\n{JOINT}")
    start = time.perf_counter()
    load_error(path, "gravity", "100000 entries")
    keys = "".join(f"k{i} = 1\n" for i in range(20_000))
    load_error(write(tmp_path, f"[[joint]]\n{JOINT}{keys}", "keys.toml"), "joint 1", "unknown keys", "more")
    assert time.perf_counter() - start < 2


@pytest.mark.parametrize(
    ("line", "key", "value"),
    [("leg_radius = 1.0", "leg_radius", "1.0"), ("thickness = 0.5", "thickness", "0.5")],
)
def test_legs_or_plates_that_overlap_are_refused_on_loading(tmp_path, line, key, value):
    """leg_radius = 1.0 loaded, and later commands failed naming neither the file nor the joint."""
    path = write(tmp_path, f"[[joint]]\n{JOINT}\n[[joint]]\n{JOINT}{line}\n")
    msg = load_error(path, str(path), "joint 2", key, value, "cannot move")
    assert msg.startswith(f"{path}: joint 2.{key}:")


def test_design_errors_quote_the_files_values(tmp_path):
    """A base radius of 1e-40 with a platform of 2 m was refused at `apair limits` for a
    base_radius of 5e-41 (the pair in units of its size), which the file does not have."""
    path = write(
        tmp_path, '[[joint]]\npair = "sinusoidal"\nbase_radius = 1e-40\nplatform_radius = 2.0\na = 0.2\nalpha = 0.5\n'
    )
    msg = load_error(path, str(path), "joint 1.base_radius", "1e-40", "platform_radius = 2.0")
    assert "5e-41" not in msg


def test_cli_refuses_an_unresolvable_design_without_internal_error(tmp_path, capsys):
    """`apair limits` on a pair like APair(1, 1e15) ended in "internal error" (exit 3)."""
    path = write(
        tmp_path, '[[joint]]\npair = "sinusoidal"\nbase_radius = 1.0\nplatform_radius = 1e15\na = 0.2\nalpha = 0.5\n'
    )
    code = main(["limits", str(path)])
    err = capsys.readouterr().err
    assert code not in (0, 3) and "internal error" not in err
    assert "base_radius" in err and str(path) in err
