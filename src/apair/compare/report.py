"""The comparison as pictures (matplotlib, Agg) and as one self-contained HTML page: the tables and
the pictures (PNG, base64) in the page itself, no script, no style sheet or font fetched."""

from __future__ import annotations

import base64
import html
import io
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .. import figures
from ..files import target, write, write_text
from . import text
from .result import Findings, Measures

COLOURS = {"chain": "tab:blue", "twin": "tab:orange", "both": "0.75"}
CODES = ("white", COLOURS["chain"], COLOURS["twin"], COLOURS["both"])  # section image: 0 .. 3


def plain(words: str) -> str:
    """Text for matplotlib as it is: a `$` in a chain's name starts no formula."""
    return words.replace("$", r"\$")


def _sections(fig: Any, f: Findings, where: list[int]) -> None:
    """The three cross-sections through the middle of both workspaces, overlaid."""
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    s, names = f.shared, "xyz"
    for axis, (layer, corner, image) in enumerate(s.sections):
        ax = fig.add_subplot(*where, axis + 1)
        a, b = [k for k in range(3) if k != axis]
        extent = (corner[0], corner[0] + image.shape[0] * s.voxel, corner[1], corner[1] + image.shape[1] * s.voxel)
        ax.imshow(
            image.T, origin="lower", extent=extent, cmap=ListedColormap(CODES), vmin=0, vmax=3, interpolation="nearest"
        )
        if s.path_points is not None:
            ax.plot(s.path_points[:, a], s.path_points[:, b], "k--", lw=1.2, label="common path (projected)")
        ax.set_aspect("equal")
        ax.set_xlabel(f"{names[a]} [m]")
        ax.set_ylabel(f"{names[b]} [m]")
        ax.set_title(f"section {names[axis]} = {layer:.3g} m", fontsize=9)
    handles: list[Any] = [
        Patch(color=COLOURS["chain"], label=plain(f"{f.chain.name} only")),
        Patch(color=COLOURS["twin"], label=f"{f.settings['twin']} twin only"),
        Patch(color=COLOURS["both"], label="both"),
    ]
    if s.path_points is not None:
        handles.append(Line2D([], [], color="k", ls="--", label="common path (projected)"))
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8)


def _histogram(ax: Any, f: Findings, what: str, log: bool = False) -> None:
    """The distribution of `what` ("manipulability" or "condition") over the joint samples."""
    values = [np.asarray(getattr(m, what)) for m in (f.chain, f.twin)]
    every = np.concatenate(values)
    shown = every[np.isfinite(every) & (every > 0)]
    if len(shown) == 0:  # every sample singular
        ax.text(0.5, 0.5, f"no finite positive {what}", ha="center", transform=ax.transAxes)
        return
    if log:  # the central 99 % (a condition number is unbounded near a singularity)
        lo, hi = np.percentile(shown, [0.5, 99.5])
        bins = np.geomspace(lo, max(hi, lo * 1.01), 60)
    else:
        bins = np.linspace(0.0, shown.max(), 60)
    for m, v, who in zip((f.chain, f.twin), values, ("chain", "twin")):
        _, p50, _ = m.percentiles(what)
        ax.hist(
            v,
            bins=bins,
            histtype="step",
            lw=1.5,
            color=COLOURS[who],
            weights=np.full(len(v), 100.0 / len(v)),
            label=f"{who}: median {p50:.3g}",
        )
        ax.axvline(p50, color=COLOURS[who], ls=":", lw=1)
    if log:
        ax.set_xscale("log")
    label = "condition number (central 99 %)" if log else what
    ax.set_xlabel(f"{label}, scale-free")
    ax.set_ylabel("% of the joint samples")
    ax.legend(fontsize=7)


def main_picture(fig: Any, f: Findings) -> None:
    """The sections overlaid and the manipulability distributions (2 x 2)."""
    _sections(fig, f, [2, 2])
    _histogram(fig.add_subplot(2, 2, 4), f, "manipulability")
    ws = [m.workspace for m in (f.chain, f.twin)]
    said = [
        f"{text.num(w.volume)} m³" if w.dimension == 3 else f"{text.num(w.measure)} m{'²' if w.dimension == 2 else ''}"
        for w in ws
    ]
    fig.suptitle(
        plain(
            f"{f.chain.name}: workspace {said[0]} beside its {f.settings['twin']} twin's {said[1]}; "
            f"{100 * f.shared.only_chain:.0f} % / {100 * f.shared.only_twin:.0f} % reached by one alone"
        ),
        fontsize=10,
    )


def dexterity(fig: Any, f: Findings) -> None:
    """The distributions of the manipulability and of the condition number."""
    _histogram(fig.add_subplot(1, 2, 1), f, "manipulability")
    _histogram(fig.add_subplot(1, 2, 2), f, "condition", log=True)


def _bars(ax: Any, f: Findings, get: Callable[[Measures], Any], label: str) -> None:
    n = len(f.chain.pairs)
    x = np.arange(1, n + 1)
    for k, (m, who) in enumerate(((f.chain, "chain"), (f.twin, "twin"))):
        ax.bar(x + (k - 0.5) * 0.38, get(m), width=0.38, color=COLOURS[who], label=who)
    ax.set_xticks(x)
    ax.set_xlabel("joint")
    ax.set_ylabel(label)
    ax.legend(fontsize=7)


def statics(fig: Any, f: Findings) -> None:
    """Gravity torques (max and RMS) per joint, and the torques along the common path."""
    _bars(fig.add_subplot(1, 3, 1), f, lambda m: m.gravity_torque_max, "max |gravity torque| [N m]")
    _bars(fig.add_subplot(1, 3, 2), f, lambda m: m.gravity_torque_rms, "RMS gravity torque [N m]")
    ax = fig.add_subplot(1, 3, 3)
    for m, who, style in ((f.chain, "chain", "-"), (f.twin, "twin", "--")):
        run = m.path
        if run.followed and run.t is not None and run.tau is not None:
            for i in range(run.tau.shape[1]):
                ax.plot(run.t, run.tau[:, i], style, color=f"C{i}", lw=1.2, label=f"{who}, joint {i + 1}")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("torque on the common path [N m]")
    if ax.lines:
        ax.legend(fontsize=6, ncol=2)
    else:
        ax.text(0.5, 0.5, "the path is not followed", ha="center", transform=ax.transAxes)


def _render(draw: Callable[[Any, Findings], None], f: Findings, size: tuple[float, float]) -> bytes:
    """A picture as PNG bytes."""
    plt = figures.figure()
    fig = plt.figure(figsize=size)
    try:
        draw(fig, f)
        fig.tight_layout(rect=(0, 0.03, 1, 1))
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=100)
    finally:
        plt.close(fig)
    return buf.getvalue()


def write_picture(f: Findings, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
    """The main picture (`main_picture`) as a PNG file."""
    p = target(path, overwrite)
    data = _render(main_picture, f, (11, 9))

    def save(tmp: str) -> None:
        Path(tmp).write_bytes(data)

    return write(p, overwrite, save)


def _image(data: bytes, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{base64.b64encode(data).decode("ascii")}">'


def _table(f: Findings) -> str:
    head = "<tr><th></th><th>chain</th><th>twin</th></tr>"
    body = "".join(
        f"<tr><th>{html.escape(a)}</th><td>{html.escape(b)}</td><td>{html.escape(c)}</td></tr>"
        for a, b, c in text.rows(f)
    )
    return f"<table>{head}{body}</table>"


STYLE = (
    "body{font-family:sans-serif;max-width:72rem;margin:1rem auto;padding:0 1rem;color:#222}"
    "table{border-collapse:collapse;margin:1rem 0}th,td{border:1px solid #ccc;padding:.25rem .6rem;text-align:left;"
    "vertical-align:top}td{font-family:monospace}img{max-width:100%}"
)

HOW = (
    "Workspaces: the volume and its standard uncertainty by apair's estimator (chain.workspace, the same "
    "samples and seed for both); the shares reached by one alone on one voxel grid of the coarser volume "
    "voxel. Joint ranges: the A-pairs' collision limits (or explicit ones); the twin's R-pairs turn fully. "
    "Dexterity over uniform joint samples inside the limits: the Jacobian's translation rows divided by the "
    "chain's length scale, manipulability the product of its singular values (√det(J Jᵀ), for fewer than six "
    "joints √det(Jᵀ J)), the condition number their ratio; near a singularity where the smallest over the "
    "largest is below the threshold. Gravity torques over the same samples. Mass: links and legs (the plates "
    "are part of the links). The common path: the end-effector origin along straight lines with quintic "
    "timing, solved step by step from the previous solution (damped least squares; a step that fails, leaves "
    "the limits or jumps ends the run), velocities and accelerations by finite differences, torques by the "
    "inverse dynamics; energy ∫|τ·θ'| dt."
)


def html_page(f: Findings) -> str:
    """The report: title, settings, main picture, table, notes, dexterity, statics and dynamics."""
    title = f"{f.chain.name} beside its {f.settings['twin']} twin"
    settings = ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}" for k, v in f.settings.items())
    notes = "".join(f"<li>{html.escape(n)}</li>" for n in text.notes(f))
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{html.escape(settings)}</p>",
        _image(_render(main_picture, f, (11, 9)), "cross-sections of both workspaces, manipulability"),
        _table(f),
        f"<ul>{notes}</ul>",
        "<h2>Dexterity</h2>",
        _image(_render(dexterity, f, (11, 4)), "manipulability and condition number"),
        "<h2>Statics and dynamics</h2>",
        _image(_render(statics, f, (14, 4.5)), "gravity torques and torques along the common path"),
        "<h2>How the numbers are taken</h2>",
        f"<p>{html.escape(HOW)}</p>",
        "</body></html>",
    ]
    return "\n".join(parts)


def write_html(f: Findings, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
    """The report (`html_page`) as an HTML file."""
    target(path, overwrite, ".html")  # refused before the pictures are drawn
    return write_text(path, html_page(f), overwrite, ".html")
