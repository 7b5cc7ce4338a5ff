"""Base and tool frames (issue 38) in the viewer: the page, in a real headless browser (as in
tests/exports/test_view.py), shows and draws the tool's pose in the world, chain.fk."""

from __future__ import annotations

import numpy as np
import pytest
import sysdeps  # tests/sysdeps.py
from test_frames_kinematics import pair_of_chains

from apair import view


@pytest.fixture(scope="module")
def browser():
    try:
        from playwright import sync_api
    except ImportError:
        pytest.fail("Playwright is missing: it is in the test extra (pip install -e '.[test]')")
    found = sysdeps.find_browser()
    if found is None:
        pytest.fail(sysdeps.missing_browser_message())
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=found.path, args=["--no-sandbox", "--disable-gpu"])
        yield b
        b.close()


def test_page_shows_the_tool_in_the_world(browser, tmp_path):
    chain, *_ = pair_of_chains(np.random.default_rng(12), 3, ("sinusoidal", "revolute"))
    out = view.write(chain, tmp_path / "view.html", workspace=200)
    page = browser.new_page(viewport={"width": 900, "height": 600})
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("console", lambda m: errors.append(m.text) if m.type in ("error", "warning") else None)
    page.goto(out.as_uri())
    page.wait_for_selector("body[data-ready='1']", timeout=20000)
    q0 = np.array(page.evaluate("apairView.q()"))
    shown = np.array(page.evaluate("JSON.parse(document.getElementById('pose').dataset.matrix)")).reshape(4, 4)
    assert np.abs(shown - chain.fk(q0)).max() < 1e-12
    assert np.abs(np.array(page.evaluate("apairView.drawnPose()")).reshape(4, 4) - chain.fk(q0)).max() < 1e-12
    lim = np.clip(chain.limits, -np.pi, np.pi)
    for qs in np.random.default_rng(3).uniform(lim[:, 0], lim[:, 1], (10, chain.n)):
        js = np.array(page.evaluate("qs => apairView.fk(qs)", qs.tolist())).reshape(4, 4)
        assert np.abs(js - chain.fk(qs)).max() < 1e-12
    page.check("#show-ws")
    assert errors == []
    page.close()
