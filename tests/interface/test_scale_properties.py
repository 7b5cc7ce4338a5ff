"""Property test of whole designs at every scale (issue 41): chain files of random designs, the
designs users build among them (twists of 0 and ±90°, zero link lengths and offsets, R-pairs mixed
with sinusoidal and general A-pairs with a < b), every length times s in 1e-6 … 1e6 (masses times
s³, inertias times s⁵), go through load, fk, ik, the workspace and the exports.

Each step either returns finite numbers (fk(ik(T)) = T with translations to the tolerance in units
of the chain's size, the sampled q among the solutions where the answer is certified, a workspace
volume in [0, the reach ball's]) or raises a one-line ValueError that names an argument; nothing
else escapes, no RuntimeWarning is raised.
"""

from __future__ import annotations

import json
import math
import re
import tempfile
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, event, given, settings
from hypothesis import strategies as st

import apair
from apair import view
from apair.ik import poses

SETTINGS = settings(
    max_examples=40,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
TOL = 1e-9
NUMBER = re.compile(r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|nan|inf", re.IGNORECASE)


def uniform(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Floats on a grid of 1000 steps in [lo, hi] (hypothesis' floats would bring subnormals)."""
    return st.integers(0, 1000).map(lambda k: lo + (hi - lo) * k / 1000)


@st.composite
def joints(draw, s: float) -> dict[str, object]:
    """One [[joint]] table at scale s: a pair (R, sinusoidal, or general with a < b) and its link."""
    kind = draw(st.sampled_from(["revolute", "sinusoidal", "sinusoidal", "general"]))
    j: dict[str, object] = {"pair": kind}
    if kind != "revolute":
        r_b = draw(uniform(0.03, 0.08)) * s
        r_p = r_b * draw(uniform(0.6, 1.0))
        j |= {"base_radius": r_b, "platform_radius": r_p}
        if kind == "general":  # legs longer than the sinusoidal pair's: motion ends at ±theta_limit
            j["leg_length"] = math.sqrt(r_b**2 + r_p**2 / 4 + 0.5 * r_b * r_p)
    j["a"] = draw(st.sampled_from([0.0]) | uniform(0.05, 0.5)) * s
    j["alpha_deg"] = draw(st.sampled_from([0.0, 90.0, -90.0, 180.0]) | uniform(-180.0, 180.0))
    j["offset"] = draw(st.sampled_from([0.0]) | uniform(-0.3, 0.3)) * s
    j["theta_offset_deg"] = draw(st.sampled_from([0.0, 180.0]) | uniform(-180.0, 180.0))
    j["mass"] = draw(uniform(0.2, 3.0)) * s**3
    j["com"] = [draw(uniform(-0.1, 0.1)) * s for _ in range(3)]
    moment = draw(uniform(1e-3, 3e-2)) * s**5  # principal moments within [0.6, 1] of it: a body
    j["inertia"] = [moment * draw(uniform(0.6, 1.0)) for _ in range(3)]
    return j


@st.composite
def designs(draw) -> tuple[float, list[dict[str, object]]]:
    s = 10.0 ** draw(st.sampled_from([-6.0, 0.0, 6.0]) | uniform(-6.0, 6.0))
    n = draw(st.integers(1, 4))
    return s, [draw(joints(s)) for _ in range(n)]


def toml(rows: list[dict[str, object]]) -> str:
    """The chain file of the joints (floats by repr, so the design is read back exactly)."""

    def value(v: object) -> str:
        return f'"{v}"' if isinstance(v, str) else repr(v) if isinstance(v, float) else repr(list(v))  # type: ignore[call-overload]

    lines = ['name = "property"']
    for j in rows:
        lines += ["", "[[joint]]"] + [f"{k} = {value(v)}" for k, v in j.items()]
    return "\n".join(lines) + "\n"


def one_line_naming_an_argument(exc: ValueError) -> None:
    msg = str(exc)
    assert msg and "\n" not in msg and len(msg) < 400, msg
    assert re.match(r"^[\w./\\ -]*?(\w+)(\[[^\]]*\])?[\w. ]*:", msg), msg


def same_angles(q: np.ndarray, Q: np.ndarray, chain: apair.AChain, tol: float = 1e-6) -> bool:
    """Whether q is among the rows of Q, angles compared modulo each pair's period."""
    per = np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])
    d = np.abs((Q - q + per / 2) % per - per / 2)
    return bool(np.any(np.all(d < tol, axis=-1)))


def sample_q(chain: apair.AChain, u: np.ndarray) -> np.ndarray:
    """A joint vector inside the limits (their finite part) at fractions u of each range."""
    lim = np.clip(chain.limits, -np.pi, np.pi)
    return lim[:, 0] + u * (lim[:, 1] - lim[:, 0])


@SETTINGS
@given(design=designs(), u=st.lists(st.sampled_from([0.0, 0.5, 1.0]) | uniform(0.0, 1.0), min_size=4, max_size=4))
@pytest.mark.slow
def test_designs_at_every_scale(design, u):
    s, rows = design
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("error")  # overflow, invalid values: a RuntimeWarning fails the test
        path = Path(tmp) / "chain.toml"
        path.write_text(toml(rows))
        try:
            chain = apair.load(path)
        except ValueError as exc:  # a design the checks refuse (plates or legs overlapping)
            one_line_naming_an_argument(exc)
            event("refused at load")
            return
        event(f"{chain.n} joints, scale 1e{round(math.log10(s)):+d}")
        n = chain.n
        L = poses.length_scale(chain)
        assert math.isfinite(L) and L > 0
        q = sample_q(chain, np.asarray(u[:n]))
        T = chain.fk(q)
        assert T.shape == (4, 4) and np.isfinite(T).all()
        assert np.abs(T[:3, :3] @ T[:3, :3].T - np.eye(3)).max() < 1e-12
        check_ik(chain, q, T, L)
        check_workspace(chain, L)
        check_exports(chain, q, Path(tmp))


def check_ik(chain: apair.AChain, q: np.ndarray, T: np.ndarray, L: float) -> None:
    """fk(ik(T)) = T; the sampled q is among the solutions where the answer is certified."""
    try:
        sol = chain.ik(T, full=True)
    except ValueError as exc:
        one_line_naming_an_argument(exc)
        if "not isolated" in str(exc):  # a curve of solutions through q: the Jacobian is singular there
            assert rank_at(chain, q, L) < min(chain.n, 6), exc
        else:  # general pairs have no elimination: refused, by name
            assert any(p.kind == "general" for p in chain.pairs), exc
        return
    assert sol.q.ndim == 2 and sol.q.shape[1] == chain.n and np.isfinite(sol.q).all()
    assert len(sol.q) > 0, "T = fk(q) is reachable"
    F = chain.fk(sol.q)
    assert np.abs(F[:, :3, :3] - T[:3, :3]).max() <= 10 * TOL
    assert np.abs(F[:, :3, 3] - T[:3, 3]).max() <= 10 * TOL * L
    if generic_rank(chain, L) < min(chain.n, 6):  # a self-motion: every solution lies on a curve
        assert not sol.certified, "a finite answer for a chain with a self-motion is not certified"
    elif sol.certified:
        assert same_angles(q, sol.q, chain), (q, sol.q, sol.method)


def generic_rank(chain: apair.AChain, L: float) -> int:
    """The Jacobian's rank at random joint values (translations in units of the chain's size):
    below min(n, 6), the chain moves with its end fixed (e.g. two A-pairs on one axis and an R-pair
    about the same axis), at every pose."""
    return max(rank_at(chain, q, L) for q in np.random.default_rng(7).uniform(-np.pi, np.pi, (3, chain.n)))


def rank_at(chain: apair.AChain, q: np.ndarray, L: float) -> int:
    """The Jacobian's rank at q, translations in units of the chain's size L."""
    J = chain.jacobian(q) * np.array([1 / L] * 3 + [1.0] * 3)[:, None]
    return int(np.linalg.matrix_rank(J, tol=1e-9 * np.abs(J).max()))


def check_workspace(chain: apair.AChain, L: float) -> None:
    """A small workspace: finite points within the reach, a volume in [0, the reach ball's] (or
    a curve's length, a surface's area)."""
    try:
        ws = chain.workspace(samples=3000, resolution=8, rounds=1)
    except ValueError as exc:  # e.g. one R-pair about its own origin: a point, no volume
        one_line_naming_an_argument(exc)
        assert str(exc).startswith("chain: ") and "no volume" in str(exc), exc
        return
    assert np.isfinite(ws.points).all() and len(ws.points) > 0
    reach = poses.reach_of(chain)
    assert np.linalg.norm(ws.points, axis=-1).max() <= reach * (1 + 1e-9)
    if ws.dimension < 3:  # a curve or a surface: a length or an area instead of a volume
        assert ws.volume is None and ws.measure is not None and math.isfinite(ws.measure) and ws.measure > 0
        return
    assert ws.volume is not None and ws.volume_error is not None
    assert math.isfinite(ws.volume) and 0.0 <= ws.volume <= 4 / 3 * math.pi * reach**3 * (1 + 1e-9)
    assert math.isfinite(ws.volume_error) and ws.volume_error >= 0.0


def check_exports(chain: apair.AChain, q: np.ndarray, tmp: Path) -> None:
    """MJCF that parses with only finite numbers (keyframe q inside the limits); the viewer's data
    finite and at the chain's scale; a file written once and never replaced without overwrite."""
    try:
        xml = chain.to_mjcf(q, path=tmp / "m.xml")
    except ValueError as exc:  # q on a collision limit where the legs lie flat: no loop closure
        one_line_naming_an_argument(exc)
        assert str(exc).startswith("q: ") and "legs flat" in str(exc) and "np." not in str(exc), exc
        assert np.any(np.isclose(q, chain.limits[:, 0]) | np.isclose(q, chain.limits[:, 1])), exc
        q = sample_q(chain, np.full(chain.n, 0.5))
        xml = chain.to_mjcf(q, path=tmp / "m.xml")
    root = ET.fromstring(xml)
    for el in root.iter():
        for key in ("pos", "quat", "size", "mass", "diaginertia", "range", "fromto", "qpos", "solref"):
            text = el.get(key)
            if text is not None:
                values = [float(v) for v in text.split()]
                assert all(math.isfinite(v) for v in values), (el.tag, key, text)
    with pytest.raises(ValueError, match="^path: "):
        chain.to_mjcf(q, path=tmp / "m.xml")
    data = view.chain_data(chain, 64)
    json.dumps(data, allow_nan=False)  # ValueError on a non-finite number
    points = np.reshape(data["workspace"], (-1, 3))
    reach = poses.reach_of(chain)
    assert np.abs(np.linalg.norm(points, axis=-1)).max() <= reach * (1 + 1e-6)
    spread = np.ptp(chain.fk(sample_q(chain, np.random.default_rng(0).random((64, chain.n))))[:, :3, 3], axis=0)
    if spread.max() > 1e-2 * reach:
        assert np.ptp(points, axis=0).max() > 1e-3 * reach, "the viewer's points keep the chain's scale"
    assert "<title>" in chain.to_html()


def test_a_chain_with_a_self_motion_is_refused_not_certified():
    """Found by the property test: joints 1 and 2 on one axis (a = 0, twist 180°) ahead of an
    R-pair, so the Jacobian has rank 3 of 4 everywhere and every pose's solutions form curves. The
    elimination used to return 8 of their points as a certified complete set."""
    P = apair.APair
    s = 0.0008472274141405964
    pairs = [P(0.034 * s, 0.0252 * s), P(0.03 * s, 0.018 * s), P.revolute(), P(0.0334 * s, 0.0205 * s)]
    chain = apair.AChain(
        pairs, [0.0, 0.0, 0.0, 0.4996 * s], np.radians([180.0, 0.0, 90.0, 25.2]), [-0.13 * s, -0.18 * s, 0.0, 0.0]
    )
    L = poses.length_scale(chain)
    assert generic_rank(chain, L) == 3
    q = np.full(4, -2 * np.pi / 3)
    q[2] = 0.0
    with pytest.raises(ValueError, match=r"^T: the solutions at this pose are not isolated"):
        chain.ik(chain.fk(q))
