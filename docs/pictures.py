"""`make pictures`: the documentation's pictures of the two exits, from examples/4a_chain.toml.

docs/images/mujoco.png: the exported MuJoCo model after 0.2 s of free motion from keyframe 0,
rendered off-screen by MuJoCo (MUJOCO_GL=egl); docs/images/viewer.png: `apair view`'s page in
headless Chromium; docs/images/optimal_swing.png: examples/optimal_swing.py (CasADi and IPOPT).
Not part of `make`: off-screen OpenGL is not on every machine.
"""

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])

import mujoco

from apair import io, mjcf, view

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images"
Q = [0.3, 0.5, -0.6, 0.8]


def mujoco_frame(chain):
    m = mujoco.MjModel.from_xml_string(chain.to_mjcf(Q))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    d.qpos[:], d.qvel[:] = mjcf.state(chain, Q, [0.5, -0.5, 0.5, -0.5])
    for _ in range(int(0.2 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    cam = mujoco.MjvCamera()
    cam.lookat[:] = d.subtree_com[0]
    cam.distance, cam.azimuth, cam.elevation = 1.3, 135, -25
    with mujoco.Renderer(m, 480, 720) as r:
        r.update_scene(d, cam)
        img = r.render()
    import matplotlib.image

    matplotlib.image.imsave(OUT / "mujoco.png", img)


def viewer_shot(chain):
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        page_file = view.write(chain, Path(tmp) / "view.html", workspace=3000)
        with sync_playwright() as p:
            b = p.chromium.launch(
                executable_path=os.environ.get("CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium",
                args=["--no-sandbox", "--disable-gpu", "--disable-background-networking"],
            )
            page = b.new_page(viewport={"width": 1000, "height": 560})
            page.goto(page_file.as_uri())
            page.wait_for_selector("body[data-ready='1']")
            page.focus("#q2")
            for _ in range(200):
                page.keyboard.press("ArrowRight")
            page.check("#show-ws")
            page.screenshot(path=str(OUT / "viewer.png"))
            b.close()


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    chain = io.load(ROOT / "examples" / "4a_chain.toml")
    mujoco_frame(chain)
    viewer_shot(chain)
    swing = OUT / "optimal_swing.png"
    subprocess.run([sys.executable, str(ROOT / "examples" / "optimal_swing.py"), str(swing), "--force"], check=True)
    print(f"written {OUT / 'mujoco.png'}, {OUT / 'viewer.png'} and {swing}", file=sys.stderr)
