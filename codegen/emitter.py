"""The code generator's front door: `lower`, `Emitter` and the output helpers under their old names.

The work is done by the shared passes (lowering/: symbol check, CSE, ordering, hoisting, printing)
and one backend per target (backends/: c, numpy, js, polynomials, chain); render.py asks the
backends for the files of generated/, output.py writes them. `Emitter` renders through templates
looked up in every backend's folder (its `_template` is the one place they are found, so a test can
substitute one).
"""

from __future__ import annotations

import json  # noqa: F401 (tests/interface/test_robustness.py reads codegen.emitter.json)
from pathlib import Path

from .backends import chain
from .backends.c import PREFIX
from .backends.js import WEB_KERNELS
from .backends.polynomials import render as render_polynomials
from .hashing import content_hash, sources_hash
from .ir import Arg, Code, Hoisted, KernelSpec, Lowered, LoweredCall, PolynomialSet, Signature
from .lowering import lower
from .output import OutputError, owned_files, write
from .render import render_all
from .templating import VERSION, Templates

__all__ = [
    "Arg",
    "Code",
    "Emitter",
    "Hoisted",
    "KernelSpec",
    "Lowered",
    "LoweredCall",
    "OutputError",
    "PREFIX",
    "PolynomialSet",
    "Signature",
    "VERSION",
    "WEB_KERNELS",
    "content_hash",
    "lower",
    "owned_files",
    "render_polynomials",
    "sources_hash",
    "write",
]

BACKENDS = Path(__file__).parent / "backends"
FOLDERS = tuple(BACKENDS / name / "templates" for name in ("c", "numpy", "js", "polynomials", "chain"))


class Emitter:
    """Renders lowered kernels: generated/ (`render`), one chain's code (`render_chain`) and its
    registry for the runtime (`render_chain_registry`)."""

    def __init__(self):
        self.templates = Templates(*FOLDERS)
        self.env = self.templates.env

    def _template(self, name: str):
        """The template and its text (with the text of the templates it imports), for hashes."""
        return self.templates(name)

    def render(self, lowered: dict[str, list[Lowered]], poly_files: dict[str, str]) -> dict[str, str]:
        """lowered: {derivation module stem: its lowered kernels}; poly_files: the rendered
        polynomial sets (`render_polynomials`) -> {path under generated/: text}."""
        return render_all(lowered, poly_files, template=self._template)

    def render_chain(
        self, kernels: list[Lowered], parts: dict[str, Lowered], name: str, meta: dict, tests: list[dict]
    ) -> dict[str, str]:
        """The code of one chain with its design built in (see backends/chain)."""
        return chain.render(kernels, parts, name, meta, tests, template=self._template)

    def render_chain_registry(self, kernels: list[Lowered], name: str, hash: str) -> str:
        """The registry of a specialised chain's kernels in apair.h's form (for the runtime)."""
        return chain.render_registry(kernels, name, hash, template=self._template)
