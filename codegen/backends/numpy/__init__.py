"""The NumPy backend (backend.py: the modules; printer.py: NumPy expressions; templates/)."""

from .backend import module, render

__all__ = ["module", "render"]
