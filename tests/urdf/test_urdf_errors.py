"""What a URDF import refuses: one line each, naming the file, the joint, link or argument."""

from __future__ import annotations

import pytest
from robots import Inertial, J, check, compare, urdf, write

from apair.urdf import convert, load_urdf


def _arm(tmp_path, middle: J, extra: str = "") -> str:
    joints = [
        J("j1", "revolute", "b", "l1", (0.0, 0.0, 0.1)),
        middle,
        J("j3", "revolute", "l2", "l3", (0.0, 0.0, 0.1), axis=(0.0, 1.0, 0.0)),
    ]
    return str(write(tmp_path, urdf("arm", "b", joints, {})))


def _refused(match: str, *args, **kwargs) -> None:
    with pytest.raises(ValueError, match=match) as exc:
        convert(*args, **kwargs)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize(
    ("kind", "extra", "message"),
    [
        ("floating", "", r"joint 'j2' is floating: a floating joint has more than one degree of freedom"),
        ("planar", "", r"joint 'j2' is planar: a planar joint has more than one degree of freedom"),
        ("revolute", '<mimic joint="j1" multiplier="2"/>', r"joint 'j2' mimics joint 'j1': mimic joints on the path"),
    ],
)
def test_joint_kinds_refused_on_the_path(tmp_path, kind: str, extra: str, message: str) -> None:
    path = _arm(tmp_path, J("j2", kind, "l1", "l2", (0.0, 0.0, 0.2), axis=(1.0, 0.0, 0.0), extra=extra))
    _refused(message, path, "l3")
    assert convert(path, "l1").n == 1  # the path up to before it converts


def test_off_path_prismatic_is_locked(tmp_path) -> None:
    joints = [
        J("j1", "revolute", "b", "l1", (0.0, 0.0, 0.1)),
        J("finger", "prismatic", "l1", "f", (0.1, 0.0, 0.0), axis=(0.0, 1.0, 0.0)),
        J("j2", "revolute", "l1", "l2", (0.0, 0.0, 0.2), axis=(1.0, 0.0, 0.0)),
    ]
    path = write(tmp_path, urdf("arm", "b", joints, {"f": Inertial(0.5, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))}))
    conv = convert(path, "l2")
    assert conv.joints[0].body.mass == 0.5 and "f" in conv.joints[0].body.links


def test_links_and_paths_refused(tmp_path) -> None:
    path = _arm(tmp_path, J("j2", "revolute", "l1", "l2", (0.0, 0.0, 0.2), axis=(1.0, 0.0, 0.0)))
    _refused(r"^tip: .*robot\.urdf has no link 'l7'$", path, "l7")
    _refused(r"^tip: .* has no link 'l22'; did you mean 'l2'\?$", path, "l22")
    _refused(r"^base: .* has no link 'x'$", path, "l3", base="x")
    _refused(
        r"^base: no path from link 'l2' down to link 'l1' in .*\('l1' is not below 'l2'; the root is 'b'\)$",
        path,
        "l1",
        base="l2",
    )
    _refused(r"^tip: no revolute, continuous or prismatic joint between links 'l1' and 'l1'$", path, "l1", base="l1")
    with pytest.raises(ValueError, match=r"^tip: expected a link name \(a str\), got int$"):
        convert(path, 3)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<robot name='x'><link name='a'></robot>", r"not well-formed XML: mismatched tag \(line 1, column \d+\)$"),
        ("", r"not well-formed XML: no element found \(line 1, column 1\)$"),
        ("<model/>", r"not a URDF file \(the root element is <model>, not <robot>\)$"),
        ("<robot><link name='a'/><link name='a'/></robot>", r"link 'a' is defined twice$"),
        ("<robot><link name='a'/><link name='b'/></robot>", r"the links form no single tree: 2 roots \(a, b\)$"),
        (
            "<robot><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/><child link='c'/></joint></robot>",
            r"joint 'j': <child> names link 'c', which .* does not define$",
        ),
        (
            "<robot><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/></joint></robot>",
            r"joint 'j': a revolute joint needs <limit lower=\.\.\. upper=\.\.\.> \(use continuous for none\)$",
        ),
        (
            "<robot><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/><child link='b'/><limit lower='1' upper='-1'/></joint></robot>",
            r"joint 'j' <limit>: expected lower < upper, got lower=1, upper=-1 rad$",
        ),
        (
            "<robot><link name='a'/><link name='b'/><joint name='j' type='continuous'><parent link='a'/><child link='b'/><axis xyz='0 0 0'/></joint></robot>",
            r"joint 'j' <axis xyz>: the axis is the zero vector$",
        ),
        (
            "<robot><link name='a'/><link name='b'/><joint name='j' type='continuous'><parent link='a'/><child link='b'/><origin xyz='0 ${l} 0'/></joint></robot>",
            r"joint 'j' <origin xyz>: expected 3 finite numbers, got '0 \$\{l\} 0'$",
        ),
        (
            "<robot><link name='a'/><link name='b'/><joint name='j' type='screw'><parent link='a'/><child link='b'/></joint></robot>",
            r"joint 'j': unknown type 'screw'",
        ),
        (
            "<robot><link name='a'><inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='3' ixy='0' ixz='0' iyz='0'/></inertial></link></robot>",
            r"link 'a' <inertia>: not a physical inertia tensor \(principal moments 1, 1, 3 kg m\^2",
        ),
        (
            "<robot><link name='a'><inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='1' ixy='2' ixz='0' iyz='0'/></inertial></link></robot>",
            r"link 'a' <inertia>: not a physical inertia tensor \(principal moments -1, 1, 3 kg m\^2: it must be positive semi-definite",
        ),
        (
            "<robot><link name='a'><inertial><mass value='-1'/><inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial></link></robot>",
            r"link 'a' <mass value>: a mass is not negative, got -1 kg$",
        ),
    ],
)
def test_malformed_files_refused(tmp_path, text: str, message: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ValueError, match=message) as exc:
        load_urdf(path, "b")
    assert str(exc.value).startswith(str(path)) and "\n" not in str(exc.value)


def test_missing_file_refused(tmp_path) -> None:
    with pytest.raises(ValueError, match=r"^path: no such file '.*nothing\.urdf'$"):
        convert(tmp_path / "nothing.urdf", "b")
    with pytest.raises(ValueError, match=r"^path: '.*' is not a file$"):
        convert(tmp_path, "b")


def test_nearly_parallel_axes(tmp_path) -> None:
    """Axes 1e-9 rad from parallel stay skew (never snapped to parallel): converted exactly where
    their common normal is near; refused where it lies 3e8 m out (the constants would lose digits)."""
    eps = 1e-9
    near = [
        J("j1", "revolute", "b", "l1", (0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0)),
        J("j2", "revolute", "l1", "l2", (0.3, 0.0, 0.0), (eps, 0.0, 0.0), axis=(0.0, 0.0, 1.0)),
    ]
    path = write(tmp_path, urdf("near", "b", near, {}), "near.urdf")
    conv = convert(path, "l2")
    assert conv.joints[0].normal == "skew" and conv.joints[0].alpha == pytest.approx(eps, rel=1e-6)
    assert conv.joints[0].a == pytest.approx(0.3)
    check(compare(path, "l2"))
    far = [near[0], J("j2", "revolute", "l1", "l2", (0.3, 0.0, 0.0), (0.0, eps, 0.0), axis=(0.0, 0.0, 1.0))]
    path = write(tmp_path, urdf("far", "b", far, {}), "far.urdf")
    _refused(
        r"joints 'j1' and 'j2' have axes 1e-09 rad from parallel whose common normal lies 3e\+08 m out", path, "l2"
    )
