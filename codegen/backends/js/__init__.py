"""The JavaScript backend (backend.py: the viewer's kernels; printer.py: ES5 expressions; templates/)."""

from .backend import WEB_KERNELS, render

__all__ = ["WEB_KERNELS", "render"]
