"""The README's Python example runs as written (from the repository root)."""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def test_readme_python_example_runs(monkeypatch):
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "README has no python example"
    monkeypatch.chdir(ROOT)
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "README.md", "exec"), namespace)  # the user's view of the API
    assert namespace["g"].kind == "general" and namespace["g"].theta_limit is not None
    assert namespace["chain"].n == 4
    assert np.isfinite(namespace["chain"].fk(np.zeros(4))).all()


def test_conventions_document_ships_and_every_reference_resolves():
    """The project carries its own conventions (docs/conventions.md); every '§N' reference to it in
    the sources, the generated header and the README names a section it has."""
    doc = (ROOT / "docs" / "conventions.md").read_text()
    sections = set(re.findall(r"^## §(\d+)", doc, flags=re.M))
    assert {"1", "2", "3", "4", "5"} <= sections
    files = [ROOT / "README.md", ROOT / "generated" / "c" / "apair.h"]
    for folder in ("src", "derivations", "codegen", "tests"):
        files += [p for p in (ROOT / folder).rglob("*") if p.suffix in (".py", ".j2", ".c", ".h")]
    seen = 0
    for path in files:
        text = path.read_text()
        if path != Path(__file__).resolve():
            assert "CONVENTIONS" + ".md" not in text, path  # a file users never receive
        for ref in re.findall(r"conventions\.md §(\d+)(?:-§(\d+))?", text):
            assert set(r for r in ref if r) <= sections, (path, ref)
            seen += 1
    assert seen >= 5
