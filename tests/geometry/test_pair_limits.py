"""`APair.theta_limit` near the minimum leg length (issue 41, item 11) and the collision limits of
extreme designs (items 14, 15): bounded time, cached, right value, errors in the user's terms."""

from __future__ import annotations

import math
import time

import mpmath
import numpy as np
import pytest

import apair
from apair import collisions

EPS = np.finfo(float).eps


def min_leg_length(r_b: float, r_p: float) -> float:
    """L1 where a + b = L1² − (r_b − r_p/2)² vanishes (docs/conventions.md §2)."""
    return abs(r_b - r_p / 2)


def gap_as_the_law_forms_it(a: float, b: float, theta: float) -> float:
    """a + b cos θ with cos θ = cos²(θ/2) − sin²(θ/2), as the generated law kernel forms it."""
    c, s = math.cos(theta / 2), math.sin(theta / 2)
    return a + b * (c * c - s * s)


def check_theta_limit(pair: apair.APair, monkeypatch: pytest.MonkeyPatch) -> float:
    """theta_limit: computed quickly, with few evaluations, cached, and the limit it claims to be."""
    calls = []
    gap = apair.APair._gap
    monkeypatch.setattr(apair.APair, "_gap", lambda self, th: calls.append(th) or gap(self, th))
    start = time.perf_counter()
    lim = pair.theta_limit
    elapsed = time.perf_counter() - start
    assert elapsed < 0.5, f"theta_limit took {elapsed:.3f} s for {pair!r}"
    assert 0 < len(calls) <= 70  # a bisection over the doubles of [0, pi]: at most 64 steps
    n = len(calls)
    assert pair.theta_limit == lim and len(calls) == n  # cached: the second access does no work
    assert lim is not None and 0 < lim < math.pi
    a, b = pair.a, pair.b
    # the defining condition: a + b cos θ >= 0 holds at the limit and fails one double beyond it
    assert gap_as_the_law_forms_it(a, b, lim) >= 0
    assert gap_as_the_law_forms_it(a, b, math.nextafter(lim, math.pi)) < 0
    # and independently of rounding: exact a + b cos θ vanishes there to within rounding of a, b
    with mpmath.workdps(60):
        exact = mpmath.mpf(a) + mpmath.mpf(b) * mpmath.cos(mpmath.mpf(lim))
    assert abs(float(exact)) <= 8 * EPS * (abs(a) + b)
    d = pair.translation(lim)  # the law is defined there, d ≈ 0
    assert 0 <= d <= math.sqrt(8 * EPS * (abs(a) + b))
    return lim


@pytest.mark.parametrize("excess", [1e-12, 3e-12, 1e-9])
@pytest.mark.parametrize("radii", [(0.05, 0.04), (1.0, 0.3), (0.02, 0.09)])
def test_theta_limit_just_above_the_minimum_leg_length(radii, excess, monkeypatch):
    """One ulp step at a time these took from 0.6 ms to over 60 s (arccos(−a/b) is off by up to
    1e11 doubles when a + b is tiny); a bisection is bounded whatever the design."""
    r_b, r_p = radii
    pair = apair.APair(r_b, r_p, leg_length=min_leg_length(r_b, r_p) * (1 + excess))
    assert pair.kind == "general" and pair.a < pair.b
    lim = check_theta_limit(pair, monkeypatch)
    assert lim < 1e-3  # just above the minimum the pair barely moves (a + b ≈ 0)


def test_theta_limit_on_random_admissible_designs(monkeypatch):
    """Sizes over the pair's whole length range, triangles up to 1e3 apart, leg lengths from just
    above the minimum to just below the sinusoidal one, where the range ends."""
    rng = np.random.default_rng(41)
    checked = 0
    for _ in range(300):
        scale = 10 ** rng.uniform(-38, 38)
        r_b, r_p = scale * 10 ** rng.uniform(-1.5, 1.5, size=2)
        lo, hi = min_leg_length(r_b, r_p), r_b + r_p / 2  # a + b > 0 and a < b
        L1 = lo + (hi - lo) * 10 ** rng.uniform(-14, -1e-3)
        try:
            pair = apair.APair(r_b, r_p, leg_length=L1)
        except ValueError as exc:  # a + b rounded to 0: refused, naming the leg length
            assert "leg_length" in str(exc)
            continue
        if pair.kind != "general" or not pair.a < pair.b:
            assert pair.theta_limit is None
            continue
        check_theta_limit(pair, monkeypatch)
        monkeypatch.undo()
        checked += 1
    assert checked > 250


def test_theta_limit_is_none_where_the_pair_turns_freely():
    for pair in (apair.APair.revolute(), apair.APair(0.05, 0.04), apair.APair(0.05, 0.04, leg_length=0.2)):
        assert pair.theta_limit is None


def one_line_error(call, *names):
    with pytest.raises(ValueError) as info:
        call()
    msg = str(info.value)
    assert "\n" not in msg and len(msg) < 300, msg
    for name in names:
        assert name in msg, msg
    return msg


def test_collision_limits_of_very_unequal_triangles_are_refused_by_name():
    """APair(1, 1e15).collision_limits() raised AttributeError (the base triangle rounded to 0 in the
    polynomials); now a ValueError naming the radius with the values the user gave."""
    msg = one_line_error(lambda: apair.APair(1, 1e15).collision_limits(), "base_radius", "1.0", repr(1e15))
    assert msg.startswith("base_radius:")
    msg = one_line_error(lambda: apair.APair(3e8, 0.5).collision_limits(), "platform_radius", "0.5", "300000000.0")
    assert msg.startswith("platform_radius:")


def test_collision_errors_name_the_values_the_user_gave():
    """The unit pair (lengths / (r_b + r_p)) was built with the pair's range checks, so
    APair(1e-40, 2) was refused for a base_radius of 5e-41 that nobody gave, and a leg radius of
    1e-40 (allowed) made 5e-41 (refused)."""
    msg = one_line_error(lambda: apair.APair(1e-40, 2).collision_limits(), "base_radius", "1e-40")
    assert "5e-41" not in msg
    free = apair.APair(1, 1).collision_limits()
    assert apair.APair(1, 1, leg_radius=1e-40).collision_limits() == free
    assert apair.APair(1, 1, thickness=1e-40).collision_limits() == free


def test_too_long_legs_are_refused_and_the_longest_allowed_are_right():
    """Legs of 10^3.75 sizes gave a free turn (the touch tolerance lost in the segment distances);
    at the bound, the legs' axes still cross at ±120° (docs/conventions.md §6)."""
    size = 0.09
    one_line_error(
        lambda: apair.APair(0.05, 0.04, leg_length=1.01 * collisions.LEG_RATIO_MAX * size).collision_limits(),
        "leg_length",
    )
    lim = apair.APair(0.05, 0.04, leg_length=0.99 * collisions.LEG_RATIO_MAX * size).collision_limits()
    assert lim.theta_max == pytest.approx(2 * math.pi / 3, abs=1e-9)
    assert lim.theta_min == pytest.approx(-2 * math.pi / 3, abs=1e-9)


def test_the_largest_leg_radius_in_the_overlap_message_is_right():
    """The largest radius was computed as (clearance + 2ρ)/2, 0 for a huge ρ by cancellation."""
    msg = one_line_error(lambda: apair.APair(0.05, 0.04, leg_radius=1e40).collision_limits(), "leg_radius", "1e+40")
    largest = float(msg.split("largest radius is ")[1].split()[0])
    assert largest > 0
    assert math.isfinite(apair.APair(0.05, 0.04, leg_radius=0.99 * largest).collision_limits().theta_max)
    one_line_error(lambda: apair.APair(0.05, 0.04, leg_radius=1.01 * largest).collision_limits(), "leg_radius")
