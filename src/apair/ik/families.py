"""The kinematic family of a chain: which consecutive joint axes are parallel, which meet, which
three meet in one point, and so which subproblem decomposition its inverse kinematics admits.

The families of six-joint arms are those of EAIK (Ostermeier, Külz and Althoff, RA-L 2025), whose
classifier this follows test for test, in its order, so that an arm gets the family EAIK names
(tests/ik/test_ik_families.py checks that against EAIK itself): three parallel axes (2∥3∥4, as in
the UR arms; 1∥2∥3 with 5 and 6 meeting) and a spherical wrist (axes 4, 5, 6 through one point,
as in PUMA, KUKA and ABB arms) with what the first three axes add; a family at the base end of the
chain is the reversed chain's. The facts are read from the DH constants, in the chain's own units
with tolerances scaled to its size (`length_scale`):

- axes k and k+1 are parallel where sin α_k = 0, and meet where a_k = 0 and they are not parallel;
- axes k and k+1 are one line where both hold (two R-pairs about one line: a self-motion, family
  "coaxial"; with a sliding pair they act as one cylindrical pair);
- axes k, k+1, k+2 meet in one point where k, k+1 and k+1, k+2 meet and the offset between the two
  meeting points along axis k+1, c_{k+1} + d_{k+1}, is 0 for every joint value.

An A-, P- or H-pair slides along its axis with its joint variable (d_k is not constant). A slide
keeps parallel axes parallel and meeting axes meeting (it moves the later axes along its own), but
it moves the point where the next two axes meet: a sliding middle joint breaks a spherical triple.
`classify` reports the family of the chain as it is and that of its R twin (every pair turned into
an R-pair at its constant offset c), and which sliding joints break the twin's family. Where the
family survives, the slides still turn constant offsets of its subproblems into functions of the
sliding joints' angles (the modified subproblems of issue 42); `Classification.describe` says
which joints do.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

from .poses import length_scale

TOLERANCE = 1e-9  # |sin α| below it: parallel; |a|, |c| below it times the chain's length scale: zero
SLIDING = ("sinusoidal", "general", "prismatic", "helical")


@dataclass(frozen=True)
class Facts:
    """The axes' relations of an n-joint chain (index k - 1 for joint k, from 1)."""

    parallel: tuple[bool, ...]  # axes k and k+1 parallel (n - 1)
    meeting: tuple[bool, ...]  # axes k and k+1 meet in one point, not parallel (n - 1)
    spherical: tuple[bool, ...]  # axes k, k+1, k+2 meet in one point for every joint value (n - 2)
    sliding: tuple[bool, ...]  # joint k slides along its axis with its variable (n)
    coaxial: tuple[bool, ...]  # axes k and k+1 are one line (parallel at a_k = 0) (n - 1)

    def reversed(self) -> Facts:
        """The facts of the chain run from its last joint to its first."""
        return Facts(
            self.parallel[::-1], self.meeting[::-1], self.spherical[::-1], self.sliding[::-1], self.coaxial[::-1]
        )


@dataclass(frozen=True)
class Family:
    """One family: its key, what defines it (`conditions`, joints from 1 in the chain's order),
    EAIK's name for it, and the decomposition it admits."""

    key: str
    conditions: str
    eaik: str
    decomposition: str
    reversed: bool = False  # the family of the reversed chain (at the base end)


_WRIST_SUB = {  # what joints 1-3 add to a spherical wrist at 4, 5, 6, in EAIK's order
    "first-two-parallel": ((1, "∥", 2), "SPHERICAL_FIRST_TWO_PARALLEL"),
    "second-two-parallel": ((2, "∥", 3), "SPHERICAL_SECOND_TWO_PARALLEL"),
    "first-two-intersecting": ((1, "∩", 2), "SPHERICAL_FIRST_TWO_INTERSECTING"),
    "second-two-intersecting": ((2, "∩", 3), "SPHERICAL_SECOND_TWO_INTERSECTING"),
    "no-parallel-no-intersecting": (None, "SPHERICAL_NO_PARALLEL_NO_INTERSECTING"),
}
GENERAL = Family("general", "", "6R-Unknown Kinematic Class", "none known: the general polynomial system")


def _joint(k: int, reversed_: bool) -> int:
    return 7 - k if reversed_ else k


def _forward(facts: Facts, reversed_: bool) -> Family | None:
    """EAIK's families of a chain as it runs (those not found by reversing it); `reversed_`: the
    facts are the reversed chain's, and the conditions are written in the original's joints."""
    j = lambda k: _joint(k, reversed_)
    par, meet, sph = facts.parallel, facts.meeting, facts.spherical
    if par[0] and par[1] and meet[4]:
        return Family(
            "three-parallel-two-intersecting",
            f"{j(1)}∥{j(2)}∥{j(3)}, {j(5)}∩{j(6)}",
            "6R-THREE_PARALLEL_TWO_INTERSECTING",
            "subproblems 4, 3 and 1 around the three parallel axes",
            reversed_,
        )
    if par[1] and par[2]:
        return Family(
            "three-inner-parallel",
            f"{j(2)}∥{j(3)}∥{j(4)}",
            "6R-THREE_INNER_PARALLEL",
            "the parallel axes leave a planar 3R problem; the outer joints by subproblems 4 and 1",
            reversed_,
        )
    if sph[3]:
        sub = _wrist_sub(facts)
        extra, eaik = _WRIST_SUB[sub]
        cond = f"{j(4)}, {j(5)}, {j(6)} meet"
        if extra is not None:
            cond += f", {j(extra[0])}{extra[1]}{j(extra[2])}"
        position, orientation = ("1-3", "4-6") if not reversed_ else ("4-6", "1-3")
        return Family(
            f"spherical-{sub}",
            cond,
            f"6R-{eaik}",
            f"the wrist centre's position fixes joints {position}; joints {orientation} then set the orientation",
            reversed_,
        )
    return None


@dataclass(frozen=True)
class Classification:
    """The family of a chain and of its R twin (None for chains of other than six joints)."""

    n: int
    facts: Facts
    twin_facts: Facts
    family: Family | None
    twin: Family | None
    broken_by: tuple[int, ...]  # sliding joints (from 1) whose slide breaks the twin's family

    @property
    def key(self) -> str:
        return self.family.key if self.family is not None else "unclassified"

    def sliding_joints(self) -> list[int]:
        return [k + 1 for k, s in enumerate(self.facts.sliding) if s]

    def describe(self) -> str:
        """One line: the family, its conditions, and what the sliding joints do to it."""
        if self.family is None:
            return f"{self.n} joints: families are for six-joint chains"
        f = self.family
        text = f"{f.key}" + (f" ({f.conditions}{', at the base end' if f.reversed else ''})" if f.conditions else "")
        if self.broken_by:
            assert self.twin is not None
            joints = ", ".join(str(k) for k in self.broken_by)
            text += (
                f"; the R twin is {self.twin.key} ({self.twin.conditions}), which the slide of joint(s) {joints} "
                "breaks (it moves where the axes meet)"
            )
        elif self.sliding_joints() and f is not GENERAL:
            joints = ", ".join(str(k) for k in self.sliding_joints())
            text += f"; the slide of joint(s) {joints} turns constant offsets of its subproblems into functions of their variables"
        return text


def facts_of(chain, *, twin: bool = False) -> Facts:
    """The axes' relations of `chain` (of its R twin with `twin`: no joint slides)."""
    n = chain.n
    scale = length_scale(chain)
    sin_alpha = np.abs(np.sin(np.asarray(chain.alpha, float)))
    a = np.abs(np.asarray(chain.a, float)) / scale
    c = np.abs(np.asarray(chain.offset, float)) / scale
    sliding = tuple(False if twin else p.kind in SLIDING for p in chain.pairs)
    parallel = tuple(bool(sin_alpha[k] < TOLERANCE) for k in range(n - 1))
    meeting = tuple(bool(a[k] < TOLERANCE and not parallel[k]) for k in range(n - 1))
    spherical = tuple(
        bool(meeting[k] and meeting[k + 1] and c[k + 1] < TOLERANCE and not sliding[k + 1]) for k in range(n - 2)
    )
    coaxial = tuple(bool(a[k] < TOLERANCE and parallel[k]) for k in range(n - 1))
    return Facts(parallel, meeting, spherical, sliding, coaxial)


def family_of(facts: Facts) -> Family:
    """The family of a six-joint chain from its facts, by EAIK's tests in EAIK's order: a family
    found only by reversing the chain (3∥4∥5; 4∥5∥6 with 1∩2; axes 1, 2, 3 meeting) is the
    reversed chain's."""
    par, meet, sph = facts.parallel, facts.meeting, facts.spherical
    for k, same in enumerate(facts.coaxial):
        if same and not (facts.sliding[k] or facts.sliding[k + 1]):
            return Family(
                "coaxial",
                f"{k + 1}≡{k + 2}",
                "",
                "two R-pairs turn about one line: a self-motion, no isolated solutions",
            )
    first = par[0] and par[1] and meet[4]
    if first or (par[1] and par[2]):
        return cast(Family, _forward(facts, False))
    reverse = (par[2] and par[3]) or (par[3] and par[4] and meet[0])
    if not reverse and sph[3]:
        return cast(Family, _forward(facts, False))
    if reverse or sph[0]:
        return _forward(facts.reversed(), True) or GENERAL
    return GENERAL


def _wrist_sub(facts: Facts) -> str:
    par, meet = facts.parallel, facts.meeting
    if par[0]:
        return "first-two-parallel"
    if par[1]:
        return "second-two-parallel"
    if meet[0]:
        return "first-two-intersecting"
    if meet[1]:
        return "second-two-intersecting"
    return "no-parallel-no-intersecting"


def classify(chain) -> Classification:
    """The family of `chain` and of its R twin, and the sliding joints that break the twin's."""
    facts, twin_facts = facts_of(chain), facts_of(chain, twin=True)
    if chain.n != 6:
        return Classification(chain.n, facts, twin_facts, None, None, ())
    family, twin = family_of(facts), family_of(twin_facts)
    broken: tuple[int, ...] = ()
    if family != twin:
        # the twin's spherical triples whose middle joint slides
        broken = tuple(
            k + 2 for k, s in enumerate(twin_facts.spherical) if s and not facts.spherical[k] and facts.sliding[k + 1]
        )
    return Classification(6, facts, twin_facts, family, twin, broken)
