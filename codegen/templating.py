"""The jinja2 environment of the backends' templates, and the version stamped into their output.

A backend renders its templates through a `template(name)` callable that returns the template and
its text, with the text of the templates it imports (e.g. c_macros.j2): the content hash of a
generated file covers that text. `Templates(folder, ...)` is such a callable over the given
folders; codegen.emitter.Emitter passes its own, over every backend's folder.
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable
from pathlib import Path

import jinja2
from jinja2 import meta

TemplateSource = Callable[[str], tuple[jinja2.Template, str]]


def _version() -> str:
    """The package version: from pyproject.toml in the source tree, else the installed apair's."""
    project = Path(__file__).resolve().parent.parent / "pyproject.toml"
    if project.is_file():
        return tomllib.loads(project.read_text())["project"]["version"]
    from importlib.metadata import version

    return version("apair")


VERSION = _version()  # stamped into the C library (header, CMake, pkg-config) and a chain's code


def shape_doc(a) -> str:
    """An argument's shape for a comment: "4 x 4"."""
    return " x ".join(str(s) for s in a.shape)


def dims(a) -> str:
    """An argument's shape as three C initialisers, unused dimensions 0: "4, 4, 0"."""
    return ", ".join(str(d) for d in (tuple(a.shape) + (0, 0, 0))[:3])


class Templates:
    """The templates in `folders` (searched in order), rendered with StrictUndefined."""

    def __init__(self, *folders: Path):
        self.folders = folders
        self.env = jinja2.Environment(
            loader=jinja2.FileSystemLoader(folders),
            keep_trailing_newline=True,
            trim_blocks=True,
            lstrip_blocks=True,
            undefined=jinja2.StrictUndefined,
        )
        self.env.filters["shape"] = shape_doc
        self.env.filters["dims"] = dims

    def text(self, name: str) -> str:
        """The template's own text."""
        return self.env.loader.get_source(self.env, name)[0]

    def __call__(self, name: str) -> tuple[jinja2.Template, str]:
        """The template and its text followed by the text of the templates it imports (for hashes)."""
        text = self.text(name)
        for other in sorted(meta.find_referenced_templates(self.env.parse(text))):
            text += self.text(other)
        return self.env.get_template(name), text
