"""Every ValueError path of the runtime: bad input is rejected with a message naming the argument
(docs/conventions.md §5), and the matching valid input is accepted."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import apair
from apair import AChain, APair
from apair.study import normalise

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
NAN, INF = float("nan"), float("inf")


@pytest.fixture
def chain2():
    return apair.load(EXAMPLES / "2a_chain.toml")


@pytest.fixture
def limited():
    """A general pair with a < b: |theta| <= theta_limit (a = 1.2**2 - 1.25 = 0.19, b = 1)."""
    p = APair(1.0, 1.0, leg_length=1.2)
    assert p.kind == "general" and p.theta_limit is not None
    return p


def sin_pairs(n):
    return [APair(0.05, 0.04)] * n


# ---------------------------------------------------------------- APair construction
@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"base_radius": 0.0}, "base_radius"),
        ({"base_radius": -1.0}, "base_radius"),
        ({"base_radius": NAN}, "base_radius"),
        ({"base_radius": INF}, "base_radius"),
        ({"base_radius": True}, "base_radius"),
        ({"base_radius": [1.0, 1.0]}, "base_radius"),
        ({"base_radius": "one"}, "base_radius"),
        ({"platform_radius": 0.0}, "platform_radius"),
        ({"platform_radius": -0.5}, "platform_radius"),
        ({"platform_radius": NAN}, "platform_radius"),
        ({"platform_radius": -INF}, "platform_radius"),
        ({"platform_radius": np.bool_(True)}, "platform_radius"),
        ({"leg_length": 0.0}, "leg_length"),
        ({"leg_length": -1.2}, "leg_length"),
        ({"leg_length": NAN}, "leg_length"),
        ({"leg_length": INF}, "leg_length"),
        ({"leg_length": True}, "leg_length"),
        ({"leg_length": 0.1}, "leg_length"),  # admits no real pose (a + b <= 0)
        ({"leg_length": 0.5}, "leg_length"),  # the boundary a + b = 0 itself
        ({"leg_mass": -1.0}, "leg_mass"),
        ({"leg_mass": NAN}, "leg_mass"),
        ({"leg_mass": False}, "leg_mass"),
        ({"leg_radius": -0.01}, "leg_radius"),
        ({"leg_radius": INF}, "leg_radius"),
        ({"leg_radius": True}, "leg_radius"),
    ],
)
def test_apair_rejects(kwargs, name):
    args = {"base_radius": 1.0, "platform_radius": 1.0} | kwargs
    with pytest.raises(ValueError, match=rf"^{name}:"):
        APair(**args)


def test_apair_valid():
    p = APair(0.05, 0.03, leg_mass=0.0, leg_radius=0.0)
    assert p.kind == "sinusoidal"
    assert p.amplitude == pytest.approx(math.sqrt(2 * 0.05 * 0.03), rel=1e-14)
    assert p.translation(0.0) == pytest.approx(p.amplitude, rel=1e-14)
    assert p.leg_lengths.shape == (6,)
    ends = p.leg_endpoints(0.4)
    assert ends.shape == (6, 2, 3)
    np.testing.assert_allclose(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=-1), p.leg_lengths, rtol=1e-13)
    assert p.leg_endpoints([0.1, 0.2, 0.3]).shape == (3, 6, 2, 3)
    assert APair(1.0, 1.0, leg_length=0.5000001).kind == "general"  # just past the boundary


@pytest.mark.parametrize("r", [0.01, 0.05, 1.0, 3.0])
def test_congruent_sinusoidal_leg_lengths(r):
    p = APair(r, r)
    np.testing.assert_allclose(p.leg_lengths, np.full(6, 1.5 * r), rtol=1e-14)
    assert p.amplitude == pytest.approx(math.sqrt(2) * r, rel=1e-14)


def test_revolute_pair():
    p = APair.revolute()
    assert p.kind == "revolute" and p.amplitude == 0.0
    assert p.leg_lengths.shape == (0,)
    assert p.leg_endpoints(0.3).shape == (0, 2, 3)
    assert p.translation(0.7) == 0.0
    with pytest.raises(ValueError, match="^theta:"):
        p.translation(NAN)


# ---------------------------------------------------------------- theta of a pair
@pytest.mark.parametrize("theta", [NAN, INF, -INF, [0.1, NAN], [[0.0], [INF]]])
@pytest.mark.parametrize("method", ["translation", "leg_endpoints", "law"])
def test_theta_not_finite(theta, method):
    with pytest.raises(ValueError, match="^theta:"):
        getattr(APair(0.05, 0.04), method)(theta)


@pytest.mark.parametrize("theta", [3.0, -2.0, [0.0, 3.0], np.pi])
@pytest.mark.parametrize("method", ["translation", "leg_endpoints", "law"])
def test_theta_outside_general_range(limited, theta, method):
    with pytest.raises(ValueError, match=r"^theta: outside this pair's range"):
        getattr(limited, method)(theta)


def test_theta_inside_general_range(limited):
    lim = limited.theta_limit
    assert lim == pytest.approx(math.acos(-0.19), rel=1e-12)
    th = np.array([-0.99 * lim, 0.0, 0.99 * lim, 2 * np.pi])  # 2 pi: the range is taken mod 2 pi
    d = limited.translation(th)
    np.testing.assert_allclose(d, np.sqrt(0.19 + np.cos(th)), rtol=1e-13)
    # a > b: unbounded
    assert APair(1.0, 1.0, leg_length=2.0).theta_limit is None
    assert np.isfinite(APair(1.0, 1.0, leg_length=2.0).translation(np.pi))


# ---------------------------------------------------------------- AChain construction
@pytest.mark.parametrize("n", [0, 8])
def test_chain_number_of_pairs(n):
    with pytest.raises(ValueError, match=r"^pairs: a chain has 1 to 7"):
        AChain(sin_pairs(n), [0.1] * n, [0.0] * n)


@pytest.mark.parametrize(
    "pairs, match",
    [
        (None, r"^pairs:"),
        (5, r"^pairs:"),
        ([APair(0.05, 0.04), "R"], r"^pairs\[1\]: expected an APair"),
        ([0.05, APair(0.05, 0.04)], r"^pairs\[0\]: expected an APair"),
    ],
)
def test_chain_non_apair(pairs, match):
    with pytest.raises(ValueError, match=match):
        AChain(pairs, [0.1, 0.1], [0.0, 0.0])


@pytest.mark.parametrize("name", ["a", "alpha", "offset", "theta_offset"])
@pytest.mark.parametrize("value", [[0.1], [0.1, 0.2, 0.3], 0.1, [[0.1, 0.2]], [0.1, NAN], [INF, 0.0], ["x", 0.0]])
def test_chain_dh_rejects(name, value):
    kw = {"a": [0.3, 0.25], "alpha": [math.pi / 2, 0.0], name: value}
    with pytest.raises(ValueError, match=rf"^{name}:"):
        AChain(sin_pairs(2), **kw)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_chain_valid_sizes(n):
    c = AChain(sin_pairs(n - 1) + [APair.revolute()], np.full(n, 0.1), np.zeros(n), np.zeros(n), np.zeros(n))
    assert c.n == n
    assert c.fk(np.zeros(n)).shape == (4, 4)
    assert c.fk(np.zeros((5, n))).shape == (5, 4, 4)
    assert c.jacobian(np.zeros((3, n))).shape == (3, 6, n)


# ---------------------------------------------------------------- q of a chain
@pytest.mark.parametrize(
    "q",
    [
        [0.1, 0.2, 0.3],  # (n+1,)
        [0.1],  # (n-1,)
        np.zeros((5, 3)),  # (N, n+1)
        0.1,  # scalar for n = 2
        np.zeros((2, 1)),
    ],
)
@pytest.mark.parametrize("method", ["fk", "fk_study", "jacobian", "law"])
def test_q_shape(chain2, q, method):
    with pytest.raises(ValueError, match=r"^q: expected shape \(\.\.\., 2\)"):
        getattr(chain2, method)(q)


@pytest.mark.parametrize("method", ["fk", "fk_study", "jacobian", "law"])
def test_q_none(chain2, method):
    with pytest.raises(ValueError, match=r"^q: expected real numbers"):
        getattr(chain2, method)(None)


@pytest.mark.parametrize("q", [[NAN, 0.0], [0.0, INF], [[0.0, 0.0], [-INF, 0.0]], ["x", 0.0]])
@pytest.mark.parametrize("method", ["fk", "fk_study", "jacobian"])
def test_q_not_finite(chain2, q, method):
    with pytest.raises(ValueError, match=r"^q:"):
        getattr(chain2, method)(q)


def test_q_valid(chain2):
    assert chain2.fk(np.zeros((5, 2))).shape == (5, 4, 4)
    assert chain2.fk(np.zeros((2, 3, 2))).shape == (2, 3, 4, 4)
    assert chain2.fk_study([0.1, 0.2]).shape == (8,)
    assert chain2.jacobian(np.zeros((5, 2))).shape == (5, 6, 2)
    T = chain2.fk(np.array([[0.1, 0.2], [0.3, -0.4]]))
    np.testing.assert_allclose(T[1], chain2.fk([0.3, -0.4]), atol=1e-15)


def test_q_outside_general_range(limited):
    c = AChain([APair(0.05, 0.04), limited], [0.1, 0.1], [0.0, 0.0])
    with pytest.raises(ValueError, match=r"^q\[\.\.\., 1\] \(joint 2\): outside this pair's range"):
        c.fk([0.0, 3.0])
    with pytest.raises(ValueError, match=r"^q\[\.\.\., 1\] \(joint 2\): outside"):
        c.jacobian([[0.0, 0.0], [0.0, -2.5]])
    assert c.fk([3.0, 0.5 * limited.theta_limit]).shape == (4, 4)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_jacobian_at_pair_limit():
    p = APair(1.0, 1.0, leg_length=1.0)  # a = -0.25 exactly: d(theta_limit) = 0, d' unbounded
    c = AChain([p], [0.1], [0.0])
    # d = √(a + b cos θ) at the last double of the range: zero up to the rounding of cos θ, √(b ε)
    assert c.fk([p.theta_limit])[2, 3] == pytest.approx(0.0, abs=3 * np.sqrt(np.finfo(float).eps))
    with pytest.raises(ValueError, match=r"^q: a joint is at its pair's limit"):
        c.jacobian([p.theta_limit])
    assert np.all(np.isfinite(c.jacobian([0.5 * p.theta_limit])))


# ---------------------------------------------------------------- bool and complex arrays
@pytest.mark.parametrize(
    "call, name",
    [
        (lambda c: c.fk([True, False]), "q"),
        (lambda c: AChain(sin_pairs(2), [True, False], [0.0, 0.0]), "a"),
        (lambda c: APair(0.05, 0.04).translation(True), "theta"),
        (lambda c: APair(np.array(True), 1.0), "base_radius"),
    ],
    ids=["q", "a", "theta", "base_radius"],
)
def test_bool_arrays_rejected(chain2, call, name):
    with pytest.raises(ValueError, match=rf"^{name}:"):
        call(chain2)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda c: c.fk(np.array([0.1 + 1j, 0.2])), "q"),
        (lambda c: APair(np.complex128(1 + 1j), 1.0), "base_radius"),
    ],
    ids=["q", "base_radius"],
)
def test_complex_arrays_rejected(chain2, call, name):
    with pytest.raises(ValueError, match=rf"^{name}:"):
        call(chain2)


# ---------------------------------------------------------------- backends, polynomials, study
def test_set_backend_unknown():
    before = apair.backend()
    with pytest.raises(ValueError, match=r"^backend: expected one of"):
        apair.set_backend("fortran")
    assert apair.backend() == before


def test_set_backend_c_missing(monkeypatch):
    monkeypatch.setattr(apair.kernels, "c_available", lambda: False)
    with pytest.raises(ValueError, match=r"^backend: 'c' requested"):
        apair.set_backend("c")


def test_env_backend_unknown(monkeypatch):
    monkeypatch.setenv("APAIR_BACKEND", "fortran")
    apair.set_backend(None)
    with pytest.raises(ValueError, match=r"^APAIR_BACKEND:"):
        apair.backend()


def test_backends_agree(chain2):
    q = np.array([[0.1, 0.2], [-0.7, 1.3]])
    try:
        apair.set_backend("numpy")
        assert apair.backend() == "numpy"
        T_np = chain2.fk(q)
    finally:
        apair.set_backend(None)
    if apair.c_available():
        apair.set_backend("c")
        try:
            np.testing.assert_allclose(chain2.fk(q), T_np, atol=1e-14)
        finally:
            apair.set_backend(None)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: apair.polynomials.load("nope"), "name"),
        (lambda: apair.polynomials.raw("nope"), "name"),
        (lambda: apair.polynomials.text("nope"), "name"),
        (lambda: apair.polynomials.text("apair_motion", "pdf"), "fmt"),
    ],
)
def test_polynomials_rejects(call, name):
    with pytest.raises(ValueError, match=rf"^{name}:"):
        call()


def test_polynomials_valid():
    assert "apair_motion" in apair.polynomials.names()
    assert apair.polynomials.text("apair_motion", "tex").lstrip().startswith("%")
    assert "law" in apair.polynomials.load("apair_motion")


def test_study_normalise_zero():
    with pytest.raises(ValueError, match=r"^study:"):
        normalise(np.zeros(8))
    s = normalise(np.array([2.0, 0, 0, 0, 1.0, 0, 0, 0]))
    np.testing.assert_allclose(s, [1, 0, 0, 0, 0.5, 0, 0, 0])


# ---------------------------------------------------------------- apair.load
SIN = 'pair = "sinusoidal"\nbase_radius = 0.05\nplatform_radius = 0.04\n'
GEN = 'pair = "general"\nbase_radius = 0.05\nplatform_radius = 0.04\nleg_length = 0.09\n'


def joints(*bodies):
    return "".join(f"[[joint]]\n{b}\n" for b in bodies)


GOOD = joints(SIN + "a = 0.3\nalpha_deg = 90\noffset = 0.1\n", GEN + "a = 0.25\nalpha = 0.0\ntheta_offset_deg = 30\n")


@pytest.mark.parametrize(
    "text, match",
    [
        ("[[joint]\n", r": not valid TOML: .* \(line 1, column 8\)$"),
        ('name = "x"\nfoo = 1\n' + GOOD, r": unknown key foo$"),
        (joints('pair = "spiral"\na = 0.1\nalpha = 0\n'), r"joint 1\.pair: .*'spiral'"),
        (joints("a = 0.1\nalpha = 0\n"), r"joint 1\.pair: .*None"),
        (
            joints('pair = "revolute"\nbase_radius = 0.05\na = 0.1\nalpha = 0\n'),
            r"joint 1: base_radius is not a key of a revolute pair",
        ),
        (joints('pair = "sinusoidal"\nbase_radius = 0.05\na = 0.1\nalpha = 0\n'), r"joint 1: missing platform_radius"),
        (
            joints('pair = "general"\nbase_radius = 0.05\nplatform_radius = 0.04\na = 0.1\nalpha = 0\n'),
            r"joint 1: missing leg_length",
        ),
        (
            joints(SIN + "leg_length = 0.09\na = 0.1\nalpha = 0\n"),
            r"joint 1: leg_length is not a key of a sinusoidal pair \(only of a general pair\)",
        ),
        (joints(SIN + "a = 0.1\nalpha = 0\nalpha_deg = 0\n"), r"joint 1: give alpha or alpha_deg, not both"),
        (
            joints(SIN + "a = 0.1\nalpha = 0\ntheta_offset = 0\ntheta_offset_deg = 0\n"),
            r"give theta_offset or theta_offset_deg",
        ),
        (joints(SIN + 'a = "x"\nalpha = 0\n'), r"joint 1\.a: expected a number, got 'x'"),
        (joints(SIN + "a = true\nalpha = 0\n"), r"joint 1\.a: expected a number"),
        (joints(SIN + 'a = 0.1\nalpha_deg = "90"\n'), r"joint 1\.alpha_deg: expected a number"),
        (joints(SIN + "a = 0.1\nalpha = 0\noffset = [1]\n"), r"joint 1\.offset: expected a number"),
        (
            joints('pair = "sinusoidal"\nbase_radius = "big"\nplatform_radius = 0.04\na = 0.1\nalpha = 0\n'),
            r"joint 1\.base_radius: expected a number",
        ),
        (joints(SIN + "alpha = 0\n"), r"joint 1: missing a$"),
        (joints(SIN + "a = 0.1\n"), r"joint 1: missing alpha"),
        (joints(SIN.replace("0.05", "-0.05") + "a = 0.1\nalpha = 0\n"), r"joint 1\.base_radius: must be > 0"),
        (joints(GEN.replace("0.09", "0.001") + "a = 0.1\nalpha = 0\n"), r"joint 1\.leg_length: .*no real pose"),
        (joints(SIN + "a = nan\nalpha = 0\n"), r"joint 1\.a: expected a finite number, got nan"),
        (joints(SIN + "a = 0.1\nalpha = inf\n"), r"joint 1\.alpha: expected a finite number, got inf"),
        ('name = "empty"\n', r"needs at least one \[\[joint\]\]"),
        ("joint = []\n", r"needs at least one \[\[joint\]\]"),
        (joints(*[SIN + "a = 0.1\nalpha = 0\n"] * 8), r"pairs: a chain has 1 to 7 pairs, got 8"),
    ],
)
def test_load_rejects(tmp_path, text, match):
    path = tmp_path / "chain.toml"
    path.write_text(text)
    with pytest.raises(ValueError, match=match) as info:
        apair.load(path)
    assert str(path) in str(info.value)  # every message says which file


def test_load_missing_file(tmp_path):
    with pytest.raises(ValueError, match=r"^path: no such file"):
        apair.load(tmp_path / "nope.toml")
    with pytest.raises(ValueError, match=r"^path: .* is a folder"):
        apair.load(tmp_path)


@pytest.mark.parametrize("text", ["joint = [1]\n", "joint = [[1, 2]]\n"])
def test_load_joint_not_a_table(tmp_path, text):
    path = tmp_path / "chain.toml"
    path.write_text(text)
    with pytest.raises(ValueError, match=r"joint 1"):
        apair.load(path)


def test_load_not_utf8(tmp_path):
    path = tmp_path / "chain.toml"
    path.write_bytes(b"\xff\xfe[[joint]]\n")
    with pytest.raises(ValueError, match=r"chain\.toml: not UTF-8 text \(invalid start byte at byte 0\)$"):
        apair.load(path)


def test_load_valid(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(GOOD)
    c = apair.load(path)
    assert c.n == 2 and c.name == "good"
    np.testing.assert_allclose(c.alpha, [math.pi / 2, 0.0], atol=1e-15)
    np.testing.assert_allclose(c.theta_offset, [0.0, math.radians(30)], atol=1e-15)
    np.testing.assert_allclose(c.offset, [0.1, 0.0])
    assert [p.kind for p in c.pairs] == ["sinusoidal", "general"]
    path.write_text(joints(*[SIN + "a = 0.1\nalpha = 0\n"] * 5, 'pair = "revolute"\na = 1\nalpha = 0\n'))
    c = apair.load(path)
    assert c.n == 6 and c.pairs[-1].kind == "revolute" and c.a[-1] == 1.0
    for name, n in (("2a_chain.toml", 2), ("4a_chain.toml", 4)):
        assert apair.load(EXAMPLES / name).n == n
