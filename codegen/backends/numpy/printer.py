"""The NumPy backend's expression printer: fully qualified numpy calls, vectorised over a batch."""

from __future__ import annotations

from sympy.printing.numpy import NumPyPrinter as _SympyNumPyPrinter

from ..printing import float_literal, small_power


class NumpyPrinter(_SympyNumPyPrinter):
    _sqrt_name = "numpy.sqrt"

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "inline": True})

    def _print_Float(self, expr):
        return float_literal(expr)

    def _print_Pow(self, expr, rational=False):
        return small_power(self, expr) or super()._print_Pow(expr, rational=rational)
