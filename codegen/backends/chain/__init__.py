"""The specialised-chain backend of `apair codegen` (backend.py; templates/, with the C backend's
c_macros.j2 and the NumPy backend's kernels.py.j2)."""

from .backend import render, render_registry

__all__ = ["render", "render_registry"]
