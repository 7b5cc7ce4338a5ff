"""apair view: the page in a real headless browser (Debian's Chromium, driven by Playwright)."""

import math
import os
import shutil

import numpy as np
import pytest

import apair
from apair import io, view
from apair.cli import main

EXAMPLE = "examples/4a_chain.toml"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]


def mixed_chain():
    r_b, r_p = 0.05, 0.04
    general = apair.APair(r_b, r_p, leg_length=math.sqrt(r_b**2 + r_p**2 / 4 + 0.5 * r_b * r_p), leg_radius=0.003)
    pairs = [
        apair.APair.revolute(),
        apair.APair(0.06, 0.05, leg_radius=0.004, thickness=0.005),
        general,
        apair.APair.revolute(),
    ]
    return apair.AChain(
        pairs,
        a=[0.0, 0.3, 0.0, 0.1],
        alpha=[np.pi / 2, 0.0, -np.pi / 2, 0.0],
        offset=[0.25, 0.0, 0.0, 0.05],
        theta_offset=[0.0, 0.3, 0.0, -1.0],
    )


@pytest.fixture(scope="module")
def browser():
    sync = pytest.importorskip("playwright.sync_api")
    if not os.path.exists(CHROMIUM):
        pytest.fail("Chromium is not installed: `make test` installs it (Debian: apt install chromium)")
    with sync.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def open_page(browser, path):
    page = browser.new_page(viewport={"width": 1000, "height": 640})
    errors, requests = [], []
    page.on("console", lambda m: errors.append(m.text) if m.type in ("error", "warning") else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("request", lambda r: requests.append(r.url) if not r.url.startswith("file:") else None)
    page.goto(path.as_uri())
    page.wait_for_selector("body[data-ready='1']", timeout=20000)
    return page, errors, requests


def shown_pose(page):
    return np.array(page.evaluate("JSON.parse(document.getElementById('pose').dataset.matrix)")).reshape(4, 4)


@pytest.mark.parametrize("which", ["example", "mixed"])
def test_page_in_browser(browser, tmp_path, which):
    """Loads offline without console errors; the screenshot shows the mechanism; moving a slider
    with the keyboard changes the drawn and shown pose to chain.fk of the sliders' angles; the
    page's kinematics equal chain.fk at random angles."""
    chain = io.load(EXAMPLE) if which == "example" else mixed_chain()
    out = view.write(chain, tmp_path / "view.html", workspace=500)
    page, errors, requests = open_page(browser, out)
    png = tmp_path / "shot.png"
    page.locator("canvas").screenshot(path=str(png))
    import matplotlib.image

    img = matplotlib.image.imread(str(png))[..., :3]
    background = img[2, 2]
    drawn = np.any(np.abs(img - background) > 0.1, axis=-1)
    assert drawn.mean() > 0.005, "the canvas shows next to nothing"
    before = shown_pose(page)
    q0 = np.array(page.evaluate("apairView.q()"))
    assert np.allclose(before, chain.fk(q0), atol=1e-12, rtol=0)
    page.focus("#q2")
    for _ in range(120):  # 12°, as a user does with the arrow keys
        page.keyboard.press("ArrowRight")
    page.focus("#q1")
    page.keyboard.press("End")  # the upper limit
    q = np.array(page.evaluate("apairView.q()"))
    step = math.pi / 1800  # the sliders' step (a range starts at its lower limit)
    assert abs(q[1] - q0[1] - 120 * step) <= step * 1.001 and abs(q[0] - min(chain.limits[0, 1], math.pi)) < step
    after = shown_pose(page)
    assert np.abs(after - before).max() > 1e-3
    T = chain.fk(q)
    assert np.abs(after - T).max() < 1e-12
    assert np.abs(np.array(page.evaluate("apairView.drawnPose()")).reshape(4, 4) - T).max() < 1e-12
    rng = np.random.default_rng(5)
    lo, hi = np.maximum(chain.limits[:, 0], -math.pi), np.minimum(chain.limits[:, 1], math.pi)
    for qs in rng.uniform(lo, hi, (20, chain.n)):
        js = np.array(page.evaluate("qs => apairView.fk(qs)", qs.tolist())).reshape(4, 4)
        assert np.abs(js - chain.fk(qs)).max() < 1e-12
    page.check("#show-ws")
    assert errors == [] and requests == []
    page.close()


def test_page_is_self_contained(tmp_path):
    html = mixed_chain().to_html()
    assert "<script src" not in html and "<link" not in html and "http://" not in html and "https://" not in html
    assert "apairKernels" in html and "/*APAIR_CHAIN*/" not in html


def test_cli_view(tmp_path, capsys):
    out = tmp_path / "v.html"
    assert main(["view", EXAMPLE, "--out", str(out)]) == 0
    assert "viewer written" in capsys.readouterr().out and out.read_text().startswith("<!DOCTYPE html>")
    assert main(["view", EXAMPLE, "--out", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["view", EXAMPLE, "--out", str(tmp_path / "w.html"), "--workspace", "-3"]) == 2
    assert "--workspace" in capsys.readouterr().err
    with pytest.raises(ValueError, match="workspace"):
        view.to_html(io.load(EXAMPLE), workspace=1.5)
