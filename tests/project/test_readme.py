"""The README is a front page: short, the set-up first, its tour runs as written, its links resolve;
and the conventions it and the sources refer to exist."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
MAX_LINES = 300


def test_readme_is_a_front_page():
    text = README.read_text()
    assert len(text.splitlines()) <= MAX_LINES
    # the two set-up commands, exactly, before anything else the reader could run
    first = re.search(r"^(?: {4}.*\n)+", text, re.M).group(0)
    assert [line.split("#")[0].strip() for line in first.splitlines()] == ["make", "make test"]
    assert text.index(first) < text.index("```")
    # two pictures (the viewer, the comparison with the R twin), which exist
    pictures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert len(pictures) <= 2 and all((ROOT / p).is_file() for p in pictures)
    assert "docs/images/compare.png" in pictures


def test_readme_links_resolve():
    text = README.read_text()
    links = [t for t in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text) if "://" not in t]
    assert len(links) >= 15
    for target in links:
        assert (ROOT / target).exists(), target
    assert "docs/tutorial.md" in links and "docs/benchmarks.md" in links


def test_readme_tour_runs(monkeypatch, tmp_path):
    """The tour's Python, in order, as a user types it at the repository root (here a copy of
    examples/ in a scratch folder, so that nothing is written into the repository)."""
    shutil.copytree(ROOT / "examples", tmp_path / "examples", ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.chdir(tmp_path)
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert blocks, "README has no python example"
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "README.md", "exec"), namespace)  # the user's view of the API
    chain, q = namespace["chain"], namespace["q"]
    assert chain.n == 4 and namespace["Ts"].shape == (100_000, 4, 4)
    assert np.allclose(namespace["T"], chain.fk(q))
    assert any(np.allclose(s, q) for s in chain.ik(namespace["T"]))
    assert namespace["sol"].certified
    assert namespace["pair"].kind == "sinusoidal" and namespace["pair"].amplitude > 0


def test_conventions_document_ships_and_every_reference_resolves():
    """The project carries its own conventions (docs/conventions.md, a page of the site); every
    '§N' reference to it in the sources, the generated header, the README and the site names a
    section it has."""
    doc = (ROOT / "docs" / "conventions.md").read_text()
    sections = set(re.findall(r"^## §(\d+)", doc, flags=re.M))
    assert {"1", "2", "3", "4", "5", "6", "7", "8"} <= sections
    files = [README, ROOT / "generated" / "c" / "apair.h", *(ROOT / "docs").rglob("*.md")]
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
        for ref in re.findall(r"conventions\.md#(\d+)-", text):  # the site's links to a section
            assert ref in sections, (path, ref)
    assert seen >= 5
