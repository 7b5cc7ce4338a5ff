"""The polynomials backend (backend.py: text, LaTeX and JSON of derived polynomial sets; templates/)."""

from .backend import render, render_polynomial_set

__all__ = ["render", "render_polynomial_set"]
