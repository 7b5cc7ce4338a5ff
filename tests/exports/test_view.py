"""apair view: the page in a real headless browser (a Chromium driven by Playwright: $CHROMIUM, the
system's or Playwright's own, as tests/sysdeps.py finds it; `make browser` installs one)."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sysdeps  # tests/sysdeps.py

import apair
from apair import io, view
from apair.cli import main

EXAMPLE = "examples/4a_chain.toml"
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
    """A headless Chromium: the test fails, never skips, without Playwright or a browser."""
    try:
        from playwright import sync_api
    except ImportError:
        pytest.fail("Playwright is missing: it is in the test extra (pip install -e '.[test]')")
    try:
        found = sysdeps.find_browser()
    except sysdeps.BrowserError as e:
        pytest.fail(str(e))
    if found is None:
        pytest.fail(sysdeps.missing_browser_message() + "\n(`make browser` does this where it can)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=found.path, args=ARGS)
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


def test_page_with_a_slide_and_a_helix(browser, tmp_path):
    """A P-pair's slider is in metres (shown in mm, a thousandth of its range per step), an H-pair's
    in radians; the page's kinematics of both equal chain.fk."""
    chain = apair.AChain(
        [apair.APair.revolute(), apair.APair.prismatic(), apair.APair.helical(0.02)],
        a=[0.3, 0.0, 0.1],
        alpha=[0.0, np.pi / 2, 0.0],
        offset=[0.2, 0.0, 0.05],
        theta_offset=[0.0, 0.4, 0.0],
        limits=[None, (0.05, 0.25), None],
    )
    page, errors, _ = open_page(browser, view.write(chain, tmp_path / "slides.html"))
    assert page.get_attribute("#q2", "step") == repr((0.25 - 0.05) / 1000)
    page.focus("#q2")
    page.keyboard.press("End")
    q = np.array(page.evaluate("apairView.q()"))
    assert q[1] == 0.25 and page.text_content("#q2-value") == "250.0 mm"
    assert np.abs(shown_pose(page) - chain.fk(q)).max() < 1e-12
    rng = np.random.default_rng(6)
    for qs in rng.uniform(chain.limits[:, 0], chain.limits[:, 1], (20, 3)):
        js = np.array(page.evaluate("qs => apairView.fk(qs)", qs.tolist())).reshape(4, 4)
        assert np.abs(js - chain.fk(qs)).max() < 1e-12
    assert errors == []
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


# ------------------------------------------------------------------ finding the browser (tests/sysdeps.py)
def fake_browser(folder, name):
    """An executable that answers --version like a browser, as `name` in folder."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text("#!/bin/sh\necho 'Chromium 1.0 (fake)'\n")
    path.chmod(0o755)
    return str(path)


@pytest.fixture
def no_browsers(tmp_path, monkeypatch):
    """No $CHROMIUM, a PATH with no browser on it, and an empty folder for Playwright's browsers."""
    monkeypatch.delenv("CHROMIUM", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "bin"))
    monkeypatch.setenv("PLAYWRIGHT_BROWSERS_PATH", str(tmp_path / "pw"))
    return tmp_path


def test_browser_is_found_in_order(no_browsers, monkeypatch):
    """$CHROMIUM first, then a system browser on PATH, then Playwright's own; none: a message that
    names the commands that install one, with and without root."""
    tmp = no_browsers
    assert sysdeps.find_browser() is None
    message = sysdeps.missing_browser_message()
    assert "apt-get install -y --no-install-recommends chromium" in message
    assert f"{sys.executable} -m playwright install chromium" in message and "CHROMIUM=" in message
    # Playwright's own, where `python -m playwright install chromium` puts it
    own = sysdeps.playwright_executable()
    assert own is not None and own.startswith(str(tmp / "pw"))
    fake_browser(Path(own).parent, Path(own).name)
    assert sysdeps.find_browser() == sysdeps.Browser(own, "playwright")
    # a system browser comes before it, under any of the usual names
    system = fake_browser(tmp / "bin", "chromium-browser")
    assert sysdeps.find_browser() == sysdeps.Browser(system, "system")
    # and $CHROMIUM before both, by path or by name on PATH
    chosen = fake_browser(tmp / "mine", "chrome-canary")
    monkeypatch.setenv("CHROMIUM", chosen)
    assert sysdeps.find_browser() == sysdeps.Browser(chosen, "$CHROMIUM")
    monkeypatch.setenv("CHROMIUM", "chromium-browser")
    assert sysdeps.find_browser() == sysdeps.Browser(system, "$CHROMIUM")
    # a $CHROMIUM that names nothing that runs is an error, not passed over
    for bad in (str(tmp / "missing"), "no-such-browser"):
        monkeypatch.setenv("CHROMIUM", bad)
        with pytest.raises(sysdeps.BrowserError, match="CHROMIUM="):
            sysdeps.find_browser()
    broken = tmp / "bin" / "chromium"
    broken.write_text("#!/bin/sh\nexit 1\n")  # e.g. a stub that names a missing snap
    broken.chmod(0o755)
    monkeypatch.delenv("CHROMIUM")
    assert sysdeps.find_browser() == sysdeps.Browser(system, "system")


def test_make_browser_installs_or_stops_with_the_commands(no_browsers, monkeypatch, capsys):
    """`make browser` without a browser: Debian's package where root or sudo allows, else
    Playwright's download; when neither brings one it exits 1 naming the commands."""
    tried = []
    monkeypatch.setattr(sysdeps, "apt_install", lambda packages: tried.append(("apt", packages)) or False)
    monkeypatch.setattr(sysdeps, "playwright_install", lambda: tried.append(("playwright",)) or False)
    assert sysdeps.main(["browser"]) == 1
    assert tried == [("apt", ("chromium",)), ("playwright",)]
    err = capsys.readouterr().err
    assert "no Chromium for the browser test" in err and "playwright install chromium" in err

    # the first way that brings a browser ends the search
    def apt(packages):
        fake_browser(no_browsers / "bin", "chromium")
        return True

    monkeypatch.setattr(sysdeps, "apt_install", apt)
    assert sysdeps.main(["browser"]) == 0
    assert "(system)" in capsys.readouterr().out


def test_make_browser_as_a_user_without_root_or_sudo(no_browsers, monkeypatch):
    """Without root or a password-less sudo apt-get is not tried (no password prompt either)."""
    monkeypatch.setattr(sysdeps.os, "geteuid", lambda: 1000)
    fake_browser(no_browsers / "bin", "apt-get")
    sudo = no_browsers / "bin" / "sudo"
    sudo.write_text("#!/bin/sh\nexit 1\n")  # sudo -n: a password would be needed
    sudo.chmod(0o755)
    assert sysdeps.root_prefix() is None and sysdeps.apt_install(("chromium",)) is False
    sudo.write_text("#!/bin/sh\nexit 0\n")
    assert sysdeps.root_prefix() == [str(sudo), "-n"]


def test_sysdeps_script_runs_from_the_makefile():
    """The Makefile's browser target runs the script with the venv's python from the root."""
    root = Path(__file__).resolve().parents[2]
    assert "\t@$(PY) tests/sysdeps.py browser" in (root / "Makefile").read_text()
    res = subprocess.run([sys.executable, "tests/sysdeps.py", "nothing"], capture_output=True, text=True, cwd=root)
    assert res.returncode == 2 and "usage" in res.stderr
