"""Chains for the comparison's tests: a 3A arm whose twin is the 3R arm of an exact spherical
shell, and a mixed chain with masses, legs and an explicit limit."""

from __future__ import annotations

import math

import numpy as np

import apair

R = apair.APair.revolute
SHOULDER, UPPER, FORE = 0.3, 0.4, 0.3  # the arm's shoulder height and link lengths [m]


def link(mass: float, com=(0.0, 0.0, 0.0)) -> apair.Link:
    return apair.Link(mass, com, np.diag([0.01, 0.02, 0.02]) * mass)


def arm3a(leg_mass: float = 0.05) -> apair.AChain:
    """Three sinusoidal A-pairs laid out as an anthropomorphic arm: a vertical axis at the shoulder
    height, then two parallel axes. Its twin (every joint a full turn) reaches the shell
    |UPPER − FORE| ≤ |p − (0, 0, SHOULDER)| ≤ UPPER + FORE."""
    pairs = [
        apair.APair(0.05, 0.04, leg_mass=leg_mass),
        apair.APair(0.05, 0.05, leg_mass=leg_mass),
        apair.APair(0.04, 0.04, leg_mass=leg_mass),
    ]
    links = [link(2.0, (0, -0.05, 0)), link(2.5, (-0.2, 0, 0)), link(1.5, (-0.15, 0, 0))]
    return apair.AChain(pairs, [0.0, UPPER, FORE], [math.pi / 2, 0.0, 0.0], [SHOULDER, 0.0, 0.0], links=links)


def shell() -> float:
    """The volume of the 3R twin's workspace [m³]."""
    return 4 / 3 * math.pi * ((UPPER + FORE) ** 3 - abs(UPPER - FORE) ** 3)


def mixed() -> apair.AChain:
    """A first R-pair with an explicit limit and offset, then two A-pairs (one general) with legs."""
    pairs = [R(), apair.APair(0.05, 0.04, leg_mass=0.07), apair.APair(0.04, 0.04, leg_length=0.07, leg_mass=0.03)]
    links = [link(1.0, (0, 0, 0.02)), link(2.0, (-0.15, 0, 0)), link(0.5, (-0.1, 0, 0))]
    return apair.AChain(
        pairs, [0.0, 0.3, 0.25], [math.pi / 2, 0.0, 0.0], [0.2, 0.0, 0.0], links=links, limits=[(-2.5, 2.0), None, None]
    )
