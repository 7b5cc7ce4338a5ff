"""The CasADi backend (backend.py: casadi/<derivation>.py; printer.py: casadi.* calls)."""

from .backend import SOURCES, render

__all__ = ["SOURCES", "render"]
