"""The MuJoCo export's joint limits, keyframe checks and text fields (apair.mjcf.to_mjcf).

The hinges carry the chain's hard limits as ranges, digit for digit, so a MuJoCo simulation stops
where chain.simulate stops; a keyframe outside the limits is refused; a model name that XML cannot
hold is refused, and any other is escaped so that the document parses and the name round-trips.
"""

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import apair
from apair import io, mjcf
from apair.cli import main

mujoco = pytest.importorskip("mujoco")


def free_joint_chain(limits=None):
    """An R-pair (free unless limited), a sinusoidal pair with legs of finite radius, and a general
    pair with a < b (its motion ends at ±theta_limit)."""
    r_b, r_p = 0.05, 0.04
    general = apair.APair(r_b, r_p, leg_length=math.sqrt(r_b**2 + r_p**2 / 4 + 0.5 * r_b * r_p))
    pairs = [apair.APair.revolute(), apair.APair(0.06, 0.05, leg_mass=0.08, leg_radius=0.004), general]
    links = [apair.Link(1.5, [0.0, 0.02, 0.1], np.diag([0.02, 0.03, 0.01])) for _ in pairs]
    return apair.AChain(pairs, a=[0.0, 0.3, 0.0], alpha=[np.pi / 2, 0.0, -np.pi / 2], links=links, limits=limits)


def explicit_limits_chain():
    """The same with explicit limits on the R-pair and the sinusoidal pair (odd digits, to see
    that none is lost) and the general pair's own."""
    return free_joint_chain(limits=[(-2.5, 1 / 3), (-math.pi / 7, 1.2345678901234567), None])


CHAINS = {
    "2a": lambda: io.load("examples/2a_chain.toml"),
    "4a": lambda: io.load("examples/4a_chain.toml"),
    "explicit": explicit_limits_chain,
    "free": free_joint_chain,
}


def hinges(xml):
    """{pair number: the hinge element} of the MJCF text."""
    root = ET.fromstring(xml)
    return {int(j.get("name")[4:-6]): j for j in root.iter("joint") if j.get("type") == "hinge"}


def joint_id(m, name):
    return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_hinge_ranges_are_the_limits(name):
    """Every hinge with finite hard limits has limited="true" and a range equal to chain.limits bit
    for bit, in the XML and in the compiled model; a free hinge has none."""
    chain = CHAINS[name]()
    xml = mjcf.to_mjcf(chain)
    joints = hinges(xml)
    assert sorted(joints) == list(range(1, chain.n + 1))
    m = mujoco.MjModel.from_xml_string(xml)
    hard = chain.hard_limits()
    for i in range(chain.n):
        j, jid = joints[i + 1], joint_id(m, f"pair{i + 1}_theta")
        if np.isfinite(hard[i]).all():
            assert j.get("limited") == "true"
            got = [float(v) for v in j.get("range").split()]
            assert [v.hex() for v in got] == [float(v).hex() for v in chain.limits[i]]
            assert m.jnt_limited[jid] and list(m.jnt_range[jid]) == got
        else:
            assert j.get("range") is None and j.get("limited") in (None, "false")
            assert not m.jnt_limited[jid]
    if name == "free":
        assert not np.isfinite(hard[0]).all()  # the case of a free hinge is met


@pytest.mark.parametrize("name", ["2a", "explicit"])
def test_limits_false_leaves_the_ranges_out(name):
    """limits=False: no hinge has a range; the slides keep theirs."""
    chain = CHAINS[name]()
    xml = mjcf.to_mjcf(chain, limits=False)
    assert all(j.get("range") is None and j.get("limited") in (None, "false") for j in hinges(xml).values())
    slides = [j for j in ET.fromstring(xml).iter("joint") if j.get("type") == "slide"]
    assert slides and all(j.get("range") is not None for j in slides)
    m = mujoco.MjModel.from_xml_string(xml)
    assert not any(m.jnt_limited[joint_id(m, f"pair{i + 1}_theta")] for i in range(chain.n))
    with pytest.raises(ValueError, match="^limits: "):
        mjcf.to_mjcf(chain, limits="no")


def drive(xml, joint, torque, seconds):
    """Under a constant motor torque on one hinge from keyframe 0: its largest angle, its last angle
    (both signed by the torque) and its largest rate."""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    d.ctrl[joint] = torque
    jid = joint_id(m, f"pair{joint + 1}_theta")
    sign, peak, rate = math.copysign(1.0, torque), -np.inf, 0.0
    for _ in range(int(round(seconds / m.opt.timestep))):
        mujoco.mj_step(m, d)
        peak, rate = max(peak, sign * d.qpos[m.jnt_qposadr[jid]]), max(rate, abs(d.qvel[m.jnt_dofadr[jid]]))
    return peak, sign * d.qpos[m.jnt_qposadr[jid]], rate


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_simulation_stops_at_the_hinge_range(sign):
    """A constant torque (with gravity) drives pair 2 of the 2A example into its collision limit:
    chain.simulate stops there, and so does MuJoCo. The limit is as stiff as the loops: the hinge
    hits it at several rad/s and overshoots by its rate times about one solref time constant
    (MuJoCo's default limit would give 0.1 rad), then rests on it to 1e-6 rad. Without limits
    MuJoCo passes through."""
    chain = io.load("examples/2a_chain.toml")
    run = chain.simulate(np.zeros(2), np.zeros(2), np.linspace(0, 0.5, 6), tau=[0.0, 2.0 * sign])
    assert run.stop is not None and run.stop.joint == 2 and run.stop.side == ("upper" if sign > 0 else "lower")
    stop = abs(run.stop.value)
    assert stop == abs(chain.limits[1, 1 if sign > 0 else 0])
    peak, last, rate = drive(mjcf.to_mjcf(chain), 1, 2.0 * sign, run.stop.t + 0.2)
    assert rate > 3.0  # it hits the limit hard
    assert stop < peak < stop + 2 * mjcf.SOLREF[0] * rate
    assert abs(last - stop) < 1e-6
    assert drive(mjcf.to_mjcf(chain, limits=False), 1, 2.0 * sign, run.stop.t + 0.1)[0] > stop + 0.05


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_keyframe_outside_the_limits_is_refused(name):
    """q beyond a joint's limit is refused (one line naming q, the joint from 1 and its range)
    unless outside_limits=True; q on the limit is accepted; a free joint takes any angle."""
    chain = CHAINS[name]()
    hard = chain.hard_limits()
    for i in range(chain.n):
        for end in (0, 1):
            q = np.zeros(chain.n)
            q[i] = chain.limits[i, end]
            if not np.isfinite(hard[i]).all():
                q[i] = 7.0 * (1 if end else -1)  # beyond one turn
                mjcf.to_mjcf(chain, q)
                continue
            mjcf.to_mjcf(chain, q)  # on the limit
            q[i] = np.nextafter(q[i], 10.0 if end else -10.0)
            with pytest.raises(ValueError, match=rf"^q: joint {i + 1} .*outside.*\(") as exc:
                mjcf.to_mjcf(chain, q)
            assert "\n" not in str(exc.value)
            xml = mjcf.to_mjcf(chain, q, outside_limits=True)
            m = mujoco.MjModel.from_xml_string(xml)
            assert m.key_qpos[0, m.jnt_qposadr[joint_id(m, f"pair{i + 1}_theta")]] == q[i]
    with pytest.raises(ValueError, match="^outside_limits: "):
        mjcf.to_mjcf(chain, outside_limits=1)


def test_default_keyframe_outside_explicit_limits_is_refused():
    """A range that leaves out θ = 0 makes the default keyframe (q = 0) one outside the limits."""
    chain = free_joint_chain(limits=[(0.5, 1.0), None, None])
    with pytest.raises(ValueError, match=r"^q: joint 1 .*outside"):
        mjcf.to_mjcf(chain)
    assert "<key" in mjcf.to_mjcf(chain, [0.75, 0.0, 0.0])


def test_cli_keyframe_outside_the_limits(tmp_path, capsys):
    """apair export mjcf --q past a collision limit: a one-line error, exit 2, no file."""
    out = tmp_path / "m.xml"
    assert main(["export", "mjcf", "examples/2a_chain.toml", "--out", str(out), "--q", "130,0", "--deg"]) == 2
    err = capsys.readouterr().err
    assert "joint 1" in err and "outside" in err and "Traceback" not in err
    assert not out.exists()


HOSTILE = [
    'double "quoted"',
    "single 'quoted'",
    "both \"and' quotes",
    "<mujoco> & </mujoco>",
    "&amp; &#0; &lt;",
    "]]> --> <!-- -- -->",
    "<![CDATA[ x ]]>",
    "ünïcødé ☃ 中文 𝄞 ﷺ",
    "  leading and trailing  ",
    "",
]


@pytest.mark.parametrize("name", HOSTILE)
def test_hostile_names_are_escaped(name):
    """Any name XML can hold is written so that the document parses, MuJoCo loads it, and the
    model's name round-trips, through mjcf.to_mjcf and chain.to_mjcf (chain.name)."""
    chain = io.load("examples/2a_chain.toml")
    xml = mjcf.to_mjcf(chain, name=name)
    assert ET.fromstring(xml).get("model") == name
    m = mujoco.MjModel.from_xml_string(xml)
    assert bytes(m.names).split(b"\0")[0].decode() == name
    chain.name = name or "x"
    assert ET.fromstring(chain.to_mjcf()).get("model") == chain.name


REFUSED = ["\x00", "bell\x07", "tab\t", "line\nfeed", "cr\r", "esc\x1b[0m", "del\x7f", "nel\x85", "c1\x9f"]
REFUSED += ["lone \ud800 surrogate", "\udfff", "non\ufffe", "char\uffff"]


@pytest.mark.parametrize("name", REFUSED)
def test_names_xml_cannot_hold_are_refused(name):
    """Control characters (C0, DEL, C1), lone surrogates and U+FFFE/U+FFFF: a one-line ValueError
    naming `name` and the character's code point (chain.name refuses them when set)."""
    chain = io.load("examples/2a_chain.toml")
    bad = next(c for c in name if not c.isprintable() or c in "\ufffe\uffff")
    with pytest.raises(ValueError, match=rf"^name: .*U\+{ord(bad):04X}") as exc:
        mjcf.to_mjcf(chain, name=name)
    assert "\n" not in str(exc.value) and not any(c in str(exc.value) for c in name if not c.isprintable())
    with pytest.raises(ValueError, match="^name: "):  # chain.name refuses it when it is set
        chain.name = name
    with pytest.raises(ValueError, match="^name: expected a string"):
        mjcf.to_mjcf(chain, name=b"bytes")


def test_cli_name_with_a_control_character(tmp_path, capsys):
    """A chain file whose name holds U+0007: apair export mjcf ends with a one-line error naming
    `name`, not a file that is not XML."""
    text = open("examples/2a_chain.toml").read().replace('name = "2A example"', 'name = "2A \\u0007 example"')
    src, out = tmp_path / "bell.toml", tmp_path / "bell.xml"
    src.write_text(text)
    assert main(["export", "mjcf", str(src), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "name" in err and "Traceback" not in err and "\x07" not in err
    assert not out.exists()


def test_chain_to_mjcf_passes_limits_and_outside_limits():
    """chain.to_mjcf takes limits and outside_limits as mjcf.to_mjcf does (issue 36 item 2, 12)."""
    chain = io.load("examples/2a_chain.toml")
    assert chain.to_mjcf() == mjcf.to_mjcf(chain, name=chain.name)
    assert all(j.get("range") is None for j in hinges(chain.to_mjcf(limits=False)).values())
    q = np.array([np.nextafter(chain.limits[0, 1], 10.0), 0.0])
    with pytest.raises(ValueError, match=r"^q: joint 1 .*outside"):
        chain.to_mjcf(q)
    assert "<key" in chain.to_mjcf(q, outside_limits=True)
