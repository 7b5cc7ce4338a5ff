"""What the backends' expression printers share: small powers as products, floats as their
shortest exact literal, and (C and JavaScript) π and e as 25-digit decimals."""

from __future__ import annotations

import sympy as sp


def small_power(printer, expr) -> str | None:
    """x**k for |k| ≤ 4 and half-integers as products and sqrt: exact, and faster than pow()."""
    base, exp = expr.as_base_exp()
    if not exp.is_Rational:
        return None
    b = printer.parenthesize(base, sp.printing.precedence.PRECEDENCE["Mul"] + 1)
    num, den = int(exp.p), int(exp.q)
    if den == 1 and 2 <= abs(num) <= 4:
        prod = "*".join([b] * abs(num))
        return f"({prod})" if num > 0 else f"(1.0/({prod}))"
    if den == 2 and abs(num) <= 5 and num != 1 and num != -1:
        k = (abs(num) - 1) // 2
        root = f"{printer._sqrt_name}({printer._print(base)})"
        prod = "*".join([root] + [b] * k)
        return f"({prod})" if num > 0 else f"(1.0/({prod}))"
    return None


def float_literal(expr) -> str:
    """A Float (a design constant folded at generation time) as the shortest literal that reads
    back as its nearest double."""
    return repr(float(expr))


class Literals:
    """What the C and JavaScript printers share: π and e as 25-digit decimals, floats as their
    shortest exact literal, small powers as products."""

    def _print_NumberSymbol(self, expr):
        return sp.Float(expr.evalf(25), 25).__str__()

    _print_Pi = _print_NumberSymbol
    _print_Exp1 = _print_NumberSymbol

    def _print_Float(self, expr):
        return float_literal(expr)

    def _print_Pow(self, expr):
        return small_power(self, expr) or super()._print_Pow(expr)
