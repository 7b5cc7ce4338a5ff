"""The CasADi backend's expression printer: Python arithmetic on casadi.SX with casadi.* functions."""

from __future__ import annotations

from sympy.printing.numpy import NumPyPrinter

from ..numpy.printer import NumpyPrinter


class CasadiPrinter(NumpyPrinter):
    """The NumPy printer with casadi's functions (same names as sympy's: cos, sin, sqrt, ...)."""

    _module = "casadi"
    _sqrt_name = "casadi.sqrt"
    _kf = {name: f"casadi.{name}" for name in NumPyPrinter._kf}
    _kc = {name: f"casadi.{name}" for name in NumPyPrinter._kc}
