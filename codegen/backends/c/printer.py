"""The C backend's expression printer: C99 with libm only."""

from __future__ import annotations

from sympy.printing.c import C99CodePrinter

from ..printing import Literals


class CPrinter(Literals, C99CodePrinter):
    """C99 without M_PI and friends (not in strict C99): constants print as decimal literals."""

    _sqrt_name = "sqrt"

    def __init__(self):
        super().__init__({"math_macros": {}})
