"""P- and H-pairs in chain files and in APair: the kinds, their keys and ranges, and the refusals."""

from __future__ import annotations

import numpy as np
import pytest

import apair
from apair import APair

SCARA = """
name = "scara"
[[joint]]
pair = "revolute"
a = 0.35
alpha = 0.0
offset = 0.4
[[joint]]
pair = "revolute"
a = 0.3
alpha_deg = 180
[[joint]]
pair = "prismatic"
limits = [0.0, 0.2]
a = 0.0
alpha = 0.0
theta_offset_deg = 30
[[joint]]
pair = "helical"
pitch = 0.002
a = 0.0
alpha = 0.0
offset = 0.05
"""


def test_scara_file_equals_the_chain_made_in_code():
    chain = apair.io.loads(SCARA)
    assert [repr(p) for p in chain.pairs] == ["APair.revolute()"] * 2 + ["APair.prismatic()", "APair.helical(0.002)"]
    same = apair.AChain(
        [APair.revolute(), APair.revolute(), APair.prismatic(), APair.helical(0.002)],
        a=[0.35, 0.3, 0, 0],
        alpha=[0, np.pi, 0, 0],
        offset=[0.4, 0, 0, 0.05],
        theta_offset=[0, 0, np.pi / 6, 0],
        limits=[None, None, (0.0, 0.2), None],
    )
    q = np.array([0.3, -0.4, 0.15, 2.0])
    np.testing.assert_allclose(chain.fk(q), same.fk(q), atol=1e-15)
    np.testing.assert_array_equal(chain.limits, [[-np.pi, np.pi], [-np.pi, np.pi], [0.0, 0.2], [-np.pi, np.pi]])
    # the slide moves the tool straight down its axis (alpha = 180°: -z); the helix turns and rises
    T0, T1 = chain.fk(q), chain.fk(q + [0, 0, 0.05, 0])
    np.testing.assert_allclose(T1[:3, 3] - T0[:3, 3], [0, 0, -0.05], atol=1e-15)
    np.testing.assert_allclose(chain.law(q)[3], [0.004, 0.002, 0.0])
    np.testing.assert_allclose(chain.law(q)[2], [0.15, 1.0, 0.0])


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("limits = [0.0, 0.2]\n", ""), r"joint 3: missing limits \(a prismatic joint's range \[lo, hi\] in metres\)$"),
        (
            ("limits = [0.0, 0.2]", "limits_deg = [0, 20]"),
            r"joint 3\.limits_deg: a prismatic joint's range is in metres",
        ),
        (("limits = [0.0, 0.2]", "limits = [0.2, 0.0]"), r"joint 3\.limits: expected lo < hi, got \(0\.2, 0\) m$"),
        (("limits = [0.0, 0.2]", "limits = [0.0, 1e45]"), r"joint 3\.limits\[1\]: 1e\+45 m is outside the range"),
        (("pitch = 0.002\n", ""), r"joint 4: missing pitch \(d = pitch \* theta, m/rad\)$"),
        (("pitch = 0.002", 'pitch = "fine"'), r"joint 4\.pitch: expected a number, got 'fine'$"),
        (("pitch = 0.002", "pitch = 1e45"), r"joint 4\.pitch: 1e\+45 m/rad is outside the range"),
        (
            ('pair = "revolute"\na = 0.3', 'pair = "revolute"\npitch = 0.1\na = 0.3'),
            r"joint 1: pitch is not a key of a revolute pair \(only of a helical pair\)$",
        ),
    ],
)
def test_file_refusals(change, message):
    text = SCARA.replace(*change, 1)
    assert text != SCARA
    with pytest.raises(ValueError, match=message) as exc:
        apair.io.loads(text, "scara.toml")
    assert "\n" not in str(exc.value)


def test_chain_needs_a_slide_range():
    with pytest.raises(ValueError, match=r"^limits\[1\]: joint 2 is prismatic: give its range \(lo, hi\) in metres$"):
        apair.AChain([APair.revolute(), APair.prismatic()], [0.1, 0.0], [0.0, 0.0])
    with pytest.raises(ValueError, match=r"^pitch: contains NaN or infinite values$"):
        APair.helical(float("nan"))


def test_lower_pairs_have_no_legs_and_refuse_what_needs_them():
    for p in (APair.prismatic(), APair.helical(0.01)):
        assert not p.is_apair and p.leg_endpoints(0.3).shape == (0, 2, 3)
        assert p.collision_limits()[:2] == (-np.inf, np.inf)
        with pytest.raises(ValueError, match=r"^amplitude: a (prismatic|helical) pair's translation is unbounded$"):
            _ = p.amplitude
    with pytest.raises(ValueError, match=r"^dynamics: a prismatic pair does not turn"):
        APair.prismatic().dynamics(0.1)
    assert APair.prismatic().turning == 0.0 and APair.helical(0.01).turning == 1.0


def test_all_solutions_ik_refuses_the_helical_pair_and_ik_local_solves():
    """The SCARA of the file: all-solutions ik refuses its helical pair (one line naming it); with a
    revolute last joint it finds the pose's joint values (the slide in m) among its certified
    solutions; ik_local solves the helical one from a nearby seed."""
    chain = apair.io.loads(SCARA)
    q = np.array([0.5, -0.7, 0.12, 1.3])
    with pytest.raises(ValueError, match=r"^pairs\[3\]: a helical pair's d = pitch\*theta is not algebraic"):
        chain.ik(chain.fk(q))
    revolute = apair.io.loads(SCARA.replace('pair = "helical"\npitch = 0.002', 'pair = "revolute"'))
    sol = revolute.ik(revolute.fk(q), full=True)
    assert sol.certified and len(sol.q) == 2 and np.abs(sol.q - q).max(axis=1).min() < 1e-9
    sol = chain.ik_local(chain.fk(q), q + [0.05, -0.05, 0.02, 0.05])
    assert sol.converged and np.abs(sol.q - q).max() < 1e-9


def test_cli_states_a_slide_in_its_units(tmp_path, capsys):
    from apair.cli import main

    path = tmp_path / "scara.toml"
    path.write_text(SCARA)
    assert main(["limits", str(path)]) == 0
    out = capsys.readouterr().out
    assert "joint 3:    +0.0000 ..  +200.0000   explicit" in out and "[deg; mm for slides]" in out
    assert main(["fk", str(path), "0.1", "0.2", "0.1", "0.3"]) == 0
    assert "q = [0.1 0.2 0.1 0.3] rad; m for slides" in capsys.readouterr().out


def test_compare_leaves_out_the_counts_it_cannot_make():
    from apair.compare import metrics

    chain = apair.io.loads(SCARA)
    assert not metrics.ik_counted(chain)
    assert metrics.ik_counts(chain, chain.limits.mean(axis=1)[None]) == (None, [], [])
