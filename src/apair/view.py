"""`apair view`: one self-contained HTML page (works offline) that draws the chain in 3D with a
slider per joint.

The page's kinematics are the generated JavaScript kernels (generated/js/apair_kernels.js, from
the derivations like the C and NumPy kernels): each joint's law, its transform fk1 (multiplied
into every frame, from the chain's base on; the tool frame after frame n), and pair_legs for the
legs. The page shows the tool's pose in the world (chain.fk). Nothing in the page retypes a formula. The legs'
clearance (collisions.clearances: segment distances) is a table in θ, 0.25° apart, read by linear
interpolation. The drawing is a small canvas renderer (no library, nothing fetched).
"""

from __future__ import annotations

import json
import os
import re
from html import escape
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _validate as V
from . import collisions
from .files import write_text

if TYPE_CHECKING:
    from ._typing import ChainLike, PairLike

CLEARANCE_STEP = np.radians(0.25)  # the clearance table's spacing in θ
MAX_WORKSPACE_POINTS = 1_000_000  # sampled end points in the page: about 25 MB of it


def _kernels_js() -> str:
    return resources.files("apair.generated").joinpath("js/apair_kernels.js").read_text(encoding="utf-8")


def _page_template() -> str:
    return resources.files("apair").joinpath("data/view.html").read_text(encoding="utf-8")


def _clearance_table(pair: PairLike, lo: float, hi: float) -> dict[str, Any]:
    th = np.arange(lo, hi + CLEARANCE_STEP / 2, CLEARANCE_STEP)
    th = th[th <= hi]
    legs, plates = collisions.clearances(pair, th)
    return {
        "theta0": float(th[0]),
        "step": float(CLEARANCE_STEP),
        "legs": np.min(legs, axis=-1).tolist(),
        "plates": np.asarray(plates).tolist(),
    }


def _name(chain: ChainLike) -> str:
    """The chain's name for the page, checked as a text field (docs/conventions.md)."""
    name = getattr(chain, "name", None)
    if name is None:
        return "apair chain"
    return V.text("chain.name", name) or "apair chain"


def chain_data(chain: ChainLike, workspace: int = 0, seed: int = 0) -> dict[str, Any]:
    """What the page needs of the chain: its joints (law kernel and parameters, DH row, range),
    the A-pairs' radii and clearance tables, its base and tool frames, and optionally `workspace`
    sampled tool origins (in the world)."""
    lim = np.array(chain.limits, float)
    joints: list[dict[str, Any]] = []
    for i, p in enumerate(chain.pairs):
        kernel, params = p.law_kernel
        lo, hi = lim[i]
        if p.kind in ("revolute", "sinusoidal", "general"):  # one period of the pose (a slide's range as it is)
            period = 2 * np.pi if p.kind == "revolute" else 4 * np.pi
            lo, hi = (max(lo, -period / 2), min(hi, period / 2))
        j: dict[str, Any] = {
            "kind": p.kind,
            "law": kernel,
            "params": [float(x) for x in params],
            "dh": [float(chain.a[i]), float(chain.alpha[i]), float(chain.offset[i]), float(chain.theta_offset[i])],
            "lower": float(lo),
            "upper": float(hi),
        }
        if p.is_apair:
            j["radii"] = [float(p.base_radius), float(p.platform_radius)]
            j["leg_radius"] = float(p.leg_radius)
            j["clearance"] = _clearance_table(p, lo, hi)
        joints.append(j)
    base, tool = (getattr(chain, key, None) for key in ("base", "tool"))
    data: dict[str, Any] = {
        "name": _name(chain),
        "n": chain.n,
        "joints": joints,
        # frame 0 in the world and the tool in frame n, 4x4 row-major (docs/conventions.md)
        "base": np.eye(4).ravel().tolist() if base is None else np.asarray(base, float).ravel().tolist(),
        "tool": np.eye(4).ravel().tolist() if tool is None else np.asarray(tool, float).ravel().tolist(),
    }
    if workspace:
        rng = np.random.default_rng(seed)
        q = rng.uniform([j["lower"] for j in joints], [j["upper"] for j in joints], (workspace, chain.n))
        # 7 significant digits each (a page of a reasonable size at any scale: rounding to a fixed
        # number of decimals would put a micrometre chain's points all at 0)
        data["workspace"] = np.char.mod("%.7g", chain.fk(q)[:, :3, 3].ravel()).astype(float).tolist()
    return data


def _script_json(data: dict[str, Any]) -> str:
    """data as JSON that a <script> element holds intact: ASCII only (so U+2028 and U+2029 too are
    escapes), and no <, > or & (a "</script>" or "<!--" in a name would end or change the
    script's data); in JSON they can occur only inside strings, where the escapes mean the same."""
    text = json.dumps(data, separators=(",", ":"), ensure_ascii=True)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def to_html(chain: ChainLike, workspace: int = 0) -> str:
    """The viewer page of the chain (see the module's docstring)."""
    workspace = V.integer("workspace", workspace, minimum=0, maximum=MAX_WORKSPACE_POINTS)
    title = _name(chain)
    data = _script_json(chain_data(chain, workspace))
    parts = {"/*APAIR_KERNELS*/": _kernels_js(), "/*APAIR_CHAIN*/null": data, "APAIR_TITLE": escape(title)}
    # one pass over the template: what goes in (a name holding "APAIR_TITLE") is never replaced again
    return re.sub("|".join(map(re.escape, parts)), lambda m: parts[m.group()], _page_template())


def write(chain: ChainLike, path: str | os.PathLike[str], overwrite: bool = False, workspace: int = 0) -> Path:
    """Writes the page to path (.html added if it has no suffix); an existing file only with
    overwrite=True. Returns the path."""
    return write_text(path, to_html(chain, workspace), overwrite, ".html")
