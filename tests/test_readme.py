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
