"""`Comparison`: the findings of `compare` with the ways to show them (text table, HTML report,
the main picture)."""

from __future__ import annotations

import os
from pathlib import Path

from . import report, text
from .result import Findings


class Comparison(Findings):
    """A chain beside its twin: .chain and .twin (`Measures`), .shared (`Shared`), .settings."""

    def table(self) -> str:
        """The comparison as a text table (what `apair compare` prints)."""
        return text.table(self)

    def report(self, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
        """One self-contained HTML page (tables, pictures embedded, nothing fetched) written to
        `path` (an existing file only with overwrite=True)."""
        return report.write_html(self, path, overwrite)

    def picture(self, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
        """The report's main picture as a PNG: the workspaces' cross-sections overlaid and the
        manipulability distributions."""
        return report.write_picture(self, path, overwrite)
