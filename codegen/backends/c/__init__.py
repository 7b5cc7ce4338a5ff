"""The C backend (backend.py: the library's files; printer.py: C99 expressions; templates/)."""

from .backend import PREFIX, Library, render

__all__ = ["PREFIX", "Library", "render"]
