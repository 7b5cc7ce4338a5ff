"""URDF robots as A-chains: `load_urdf` (an AChain) and `to_toml` (a chain file's text).

The serial path from a base link (default: the URDF's root) to a tip link becomes one R-pair per
revolute or continuous joint, with DH constants computed exactly from the joint axes (`dh`),
fixed joints folded into the constants and the base and tool frames, and each apair link's mass,
centre of mass and full inertia tensor merged from the URDF links it moves (`inertia`). Prismatic,
floating, planar and mimic joints on the path are refused, as are paths of more than 6 joints.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..chain import AChain
from ..io import chain_from_dict
from .dh import Converted, ConvertedJoint
from .dh import convert as _convert
from .parse import parse
from .write import frame_table, is_identity, joint_tables, text

__all__ = ["Converted", "ConvertedJoint", "convert", "frameless_chain", "load_urdf", "to_toml"]

Pairs = Mapping[int, Mapping[str, Any]]


def convert(path: str | os.PathLike[str], tip: str, base: str | None = None) -> Converted:
    """The URDF file's path from link `base` (default: the root) to link `tip` as DH constants,
    links and base and tool frames (4×4: `Converted.base`, `.tool`)."""
    for name, value in (("tip", tip), ("base", base)):
        if value is not None and not isinstance(value, str):
            raise ValueError(f"{name}: expected a link name (a str), got {type(value).__name__}")
    return _convert(parse(path), tip, base)


def _data(conv: Converted, pairs: Pairs | None, gravity: ArrayLike | None = None) -> dict[str, Any]:
    data: dict[str, Any] = {"name": conv.robot, "joint": joint_tables(conv, pairs)}
    if gravity is not None:
        data["gravity"] = np.asarray(gravity, float).tolist()
    return data


def _build(conv: Converted, data: dict[str, Any], pairs: Pairs | None) -> AChain:
    """The chain of `data`; a refusal of a joint that `pairs` replaced names pairs[k]."""
    try:
        return chain_from_dict(data, conv.source)
    except ValueError as exc:
        m = re.fullmatch(rf"{re.escape(conv.source)}: joint (\d+)(?:\.|: )(.*)", str(exc), re.DOTALL)
        if pairs and m and int(m[1]) in pairs:
            raise ValueError(f"pairs[{m[1]}]: {m[2]}") from None
        raise


def frameless_chain(conv: Converted, pairs: Pairs | None = None) -> AChain:
    """The chain of DH frames 0 … n alone, gravity (−z of the base link) expressed in DH frame 0:
    the pose of the tip link in the base link is conv.base @ chain.fk(q) @ conv.tool."""
    return _build(conv, _data(conv, pairs, conv.gravity_dh()), pairs)


def load_urdf(path: str | os.PathLike[str], tip: str, base: str | None = None, pairs: Pairs | None = None) -> AChain:
    """The A-chain of a URDF's serial path from link `base` (default: the root) to link `tip`: an
    R-pair per revolute or continuous joint (the joint variable is the URDF angle), the link
    inertias merged, and its base and tool frames: chain.fk(q) is the tip link's pose in the base
    link's frame, gravity −z of the base link. `pairs` replaces joints by A-pairs:
    {2: {"pair": "sinusoidal", "base_radius": 0.06, "platform_radius": 0.05}} (optionally
    "limits" or "limits_deg"; else the URDF's range). The same chain as `apair.load` of the file
    `to_toml` writes."""
    conv = convert(path, tip, base)
    data = _data(conv, pairs)
    for key, T in (("base", conv.base), ("tool", conv.tool)):
        if not is_identity(T):
            data[key] = frame_table(T)
    return _build(conv, data, pairs)


def to_toml(path: str | os.PathLike[str], tip: str, base: str | None = None, pairs: Pairs | None = None) -> str:
    """The chain file of `load_urdf(path, tip, base, pairs)`, each value commented with where it
    came from; checked by building the chain (its frames aside) before it is returned."""
    conv = convert(path, tip, base)
    _build(conv, _data(conv, pairs), pairs)
    return text(conv, pairs)
