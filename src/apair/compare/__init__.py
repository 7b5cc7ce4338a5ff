"""A chain beside its twin, every A-pair replaced by an R-pair at the same DH constants and links
(`compare`): workspaces, joint ranges, dexterity, statics and dynamics, mass, inverse-kinematics
counts, measured on the same work; as data, a JSON document, a text table, an HTML report.

How each number is taken: apair.compare.metrics (joint ranges, dexterity, gravity, mass, ik counts),
apair.compare.overlap (the shared workspace), apair.compare.path (the common path's dynamics).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from .. import _validate as V
from ..ik.poses import length_scale
from .comparison import Comparison
from .measure import DEXTERITY_SAMPLES, IK_POSES, measures, shared
from .metrics import SINGULAR
from .path import DURATION, STEPS, points
from .twin import TWINS, Chain, build, kind

__all__ = ["TWINS", "Comparison", "compare"]


def compare(
    chain: Chain,
    twin: str | None = "revolute",
    samples: int = 300_000,
    seed: int = 0,
    path: object = None,
    engine: object = None,
    progress: Callable[[str], object] | None = None,
) -> Comparison:
    """The chain beside its twin (`twin`: the kind of pair that replaces each A-pair; one of
    TWINS, None for "revolute").

    samples and engine: the workspaces' (`AChain.workspace`; the chain's volume is what
    `chain.workspace(samples=samples, seed=seed)` gives). seed: every random choice (the joint
    samples, the default path). path: the common end-effector path, points (k, 3) [m] joined by
    straight lines (default: the longest straight line found inside what both reach). progress:
    called with a few words before each stage. Returns a `Comparison` (.chain, .twin, .shared,
    .as_dict(), .table(), .report(path), .picture(path))."""
    started = time.perf_counter()
    kind_ = kind(twin)
    seed = V.seed(seed)
    corners = None if path is None else points(path)
    say = progress or (lambda _words: None)
    other = build(chain, kind_)
    say("workspace of the chain")
    ws_chain = chain.workspace(samples=samples, seed=seed, engine=engine)
    say("workspace of the twin")
    ws_twin = other.workspace(samples=samples, seed=seed, engine=engine)
    common = shared(ws_chain, ws_twin, corners, seed)
    scale = length_scale(chain)
    mine = measures(chain, ws_chain, common, scale, seed, say)
    first = None if mine.path.q is None else mine.path.q[0]
    theirs = measures(other, ws_twin, common, scale, seed, say, first)
    settings = {
        "twin": kind_,
        "samples": int(samples),
        "seed": seed,
        "dexterity_samples": DEXTERITY_SAMPLES,
        "ik_poses": IK_POSES,
        "length_scale": scale,
        "singular_threshold": SINGULAR,
        "path_steps": STEPS,
        "duration": DURATION,
        "seconds": time.perf_counter() - started,
    }
    return Comparison(mine, theirs, common, settings)
