"""Quaternions, dual quaternions and Study parameters over sympy (docs/conventions.md §1).

Only the algebra the derivations need: the Hamilton product, conjugation, and the dual-quaternion
form of the elementary motions (rotation about an axis through the origin, translation), so that
every Study point in the derivations is *computed* from a displacement, never typed in.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class Quaternion:
    """q = w + x i + y j + z k with sympy entries; `w` is the scalar part."""

    w: sp.Expr
    x: sp.Expr
    y: sp.Expr
    z: sp.Expr

    @staticmethod
    def pure(v) -> Quaternion:
        """The pure quaternion (0, v) of a 3-vector."""
        return Quaternion(sp.S(0), sp.S(v[0]), sp.S(v[1]), sp.S(v[2]))

    def __mul__(self, o: Quaternion) -> Quaternion:
        a, b = self, o
        return Quaternion(
            a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
            a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
        )

    def __add__(self, o: Quaternion) -> Quaternion:
        return Quaternion(self.w + o.w, self.x + o.x, self.y + o.y, self.z + o.z)

    def __sub__(self, o: Quaternion) -> Quaternion:
        return Quaternion(self.w - o.w, self.x - o.x, self.y - o.y, self.z - o.z)

    def scale(self, s) -> Quaternion:
        return Quaternion(s * self.w, s * self.x, s * self.y, s * self.z)

    def conj(self) -> Quaternion:
        return Quaternion(self.w, -self.x, -self.y, -self.z)

    def norm2(self) -> sp.Expr:
        return self.w**2 + self.x**2 + self.y**2 + self.z**2

    def dot(self, o: Quaternion) -> sp.Expr:
        return self.w * o.w + self.x * o.x + self.y * o.y + self.z * o.z

    def vec(self) -> list[sp.Expr]:
        return [self.x, self.y, self.z]

    def as_list(self) -> list[sp.Expr]:
        return [self.w, self.x, self.y, self.z]

    def expand(self) -> Quaternion:
        return Quaternion(*(sp.expand(c) for c in self.as_list()))


@dataclass(frozen=True)
class StudyPoint:
    """A displacement as the dual quaternion x + ε y, y = ½ t x (docs/conventions.md §1)."""

    x: Quaternion
    y: Quaternion

    def __mul__(self, o: StudyPoint) -> StudyPoint:
        # (x1 + ε y1)(x2 + ε y2) = x1 x2 + ε (x1 y2 + y1 x2): composition T1·T2.
        return StudyPoint(self.x * o.x, self.x * o.y + self.y * o.x)

    def as_list(self) -> list[sp.Expr]:
        return self.x.as_list() + self.y.as_list()

    def study_quadric(self) -> sp.Expr:
        return self.x.dot(self.y)


def rotation(axis, cos_half, sin_half) -> StudyPoint:
    """Rotation about a unit `axis` through the origin, given cos and sin of half the angle."""
    x = Quaternion(sp.S(cos_half), *(sin_half * sp.S(a) for a in axis))
    return StudyPoint(x, Quaternion(sp.S(0), sp.S(0), sp.S(0), sp.S(0)))


def translation(t) -> StudyPoint:
    """Translation by the 3-vector t: x = 1, y = ½ t · 1."""
    one = Quaternion(sp.S(1), sp.S(0), sp.S(0), sp.S(0))
    return StudyPoint(one, Quaternion.pure(t).scale(sp.Rational(1, 2)))


def study_symbols() -> tuple[Quaternion, Quaternion, list[sp.Symbol]]:
    """Homogeneous Study parameters x0..x3, y0..y3 as symbols."""
    xs = sp.symbols("x0:4", real=True)
    ys = sp.symbols("y0:4", real=True)
    return Quaternion(*xs), Quaternion(*ys), list(xs) + list(ys)


def transform_point_homogeneous(x: Quaternion, y: Quaternion, p) -> list[sp.Expr]:
    """|x|²·(R p + t) for a Study point (x, y), as polynomials in x, y.

    From R p = x p x̃ / |x|² and t = 2 y x̃ / |x|² (y = ½ t x): the vector part of x p x̃ + 2 y x̃.
    Its scalar part is 2 x·y, which vanishes exactly on the Study quadric.
    """
    q = x * Quaternion.pure(p) * x.conj() + (y * x.conj()).scale(2)
    return [sp.expand(c) for c in q.vec()]
