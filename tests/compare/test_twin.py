"""The twin: the same DH constants and links, every A-pair an R-pair that turns fully, an R-pair's
explicit limits kept; only the kinds in TWINS, refused in one line otherwise."""

from __future__ import annotations

import numpy as np
import pytest
from compare_designs import arm3a, mixed

import apair
from apair.compare import TWINS, twin


def test_the_twin_has_the_design_without_the_legs():
    chain = mixed()
    other = twin.build(chain)
    assert [p.kind for p in other.pairs] == ["revolute"] * 3
    for key in ("a", "alpha", "offset", "theta_offset", "gravity"):
        assert np.array_equal(getattr(other, key), getattr(chain, key)), key
    assert [link.as_row().tolist() for link in other.links] == [link.as_row().tolist() for link in chain.links]
    assert np.all(other._legs[:, 0] == 0)  # no leg mass left


def test_with_parallel_vertical_axes_the_twin_is_lower_by_the_rise():
    """All axes vertical (α = 0): the twin's end effector is lower by Σ d_i(θ_i), whatever q."""
    pairs = [apair.APair(0.05, 0.04), apair.APair.revolute(), apair.APair(0.04, 0.04, leg_length=0.07)]
    chain = apair.AChain(pairs, [0.3, 0.2, 0.1], [0.0, 0.0, 0.0], [0.1, 0.0, 0.05])
    other = twin.build(chain)
    q = np.random.default_rng(3).uniform(chain.limits[:, 0], chain.limits[:, 1], (50, 3))
    rise = sum(p.translation(q[:, i]) for i, p in enumerate(pairs))
    gap = chain.fk(q)[:, :3, 3] - other.fk(q)[:, :3, 3]
    assert np.allclose(gap[:, :2], 0, atol=1e-12) and np.allclose(gap[:, 2], rise, atol=1e-12)


def test_the_twin_turns_fully_and_keeps_explicit_r_limits():
    chain = mixed()
    hard = twin.build(chain).hard_limits()
    assert hard[0].tolist() == [-2.5, 2.0]  # the R-pair's own explicit limit
    assert np.all(np.isinf(hard[1:]))  # the former A-pairs: full turns
    assert np.all(np.isfinite(chain.hard_limits()[1:]))  # where the chain's legs collide


def test_the_twin_is_named_after_the_chain():
    chain = arm3a()
    assert twin.build(chain).name == "chain (revolute twin)"
    chain.name = "arm"
    assert twin.build(chain).name == "arm (revolute twin)"


@pytest.mark.parametrize("bad", ["helical", "Revolute", 3, ""])
def test_other_twin_kinds_are_refused_in_one_line(bad):
    with pytest.raises(ValueError) as exc:
        twin.kind(bad)
    text = str(exc.value)
    assert text.startswith("twin: expected one of revolute") and "\n" not in text
    assert TWINS == ("revolute",)


def test_none_is_the_revolute_twin():
    assert twin.kind(None) == "revolute"


class OnItsOwnKernels(apair.AChain):
    """A subclass built from another chain, as AChain.specialise's SpecialisedChain is."""

    def __init__(self, chain: apair.AChain) -> None:
        self.__dict__.update(chain.__dict__)


def test_a_subclass_chain_gets_a_plain_twin():
    chain = OnItsOwnKernels(mixed())
    other = twin.build(chain)
    assert type(other) is apair.AChain and [p.kind for p in other.pairs] == ["revolute"] * 3


def test_the_twin_keeps_the_base_and_tool_frames():
    """A chain with base and tool frames: its twin has the same frames, so both are measured in
    one world frame (gravity there too): the twin's poses are those of the frameless twin with
    the frames around them."""
    plain = arm3a()
    base = apair.frame([0.1, -0.2, 0.3], [0.2, -0.4, 1.1])
    tool = apair.frame([0.0, 0.05, 0.12], [0.0, np.pi / 2, 0.0])
    framed = apair.AChain(
        plain.pairs, plain.a, plain.alpha, plain.offset, plain.theta_offset, links=plain.links, base=base, tool=tool
    )
    tw = twin.build(framed)
    assert np.array_equal(tw.base, base) and np.array_equal(tw.tool, tool)
    q = np.random.default_rng(3).uniform(-1, 1, (5, plain.n))
    expected = base @ twin.build(plain).fk(q) @ tool
    assert np.allclose(tw.fk(q), expected, atol=1e-12)
