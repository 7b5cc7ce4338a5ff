"""The `apair` command line: inspect derived polynomials, evaluate chains, run the demonstration.

`main(argv)` runs one command (apair.cli.app); the commands live by group: info (list, show,
variety, kernels, demo), motion (fk, jacobian, dynamics, limits), reach (ik, ik-prepare,
workspace), exports (export, view, codegen), over the arguments' parsing (args) and what is
printed (output: text, `--json` documents, notes, error lines).
"""

from __future__ import annotations

from .app import build_parser, main

__all__ = ["build_parser", "main"]
