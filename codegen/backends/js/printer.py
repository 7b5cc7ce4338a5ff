"""The JavaScript backend's expression printer: ES5 Math, with the C printer's literals."""

from __future__ import annotations

from sympy.printing.jscode import JavascriptCodePrinter

from ..printing import Literals


class JSPrinter(Literals, JavascriptCodePrinter):
    """JavaScript (ES5 Math), with the C printer's literals; rationals as quotients of doubles."""

    _sqrt_name = "Math.sqrt"

    def _print_Rational(self, expr):
        return f"({int(expr.p)}.0/{int(expr.q)}.0)"
