"""The Panda (example-robot-data) as a 7-joint apair chain and as Pinocchio's reduced model (the
fingers locked): the independent oracle of the tests in tests/chain7."""

from __future__ import annotations

import glob
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import apair

pin = pytest.importorskip("pinocchio")


def panda_path() -> Path:
    cmeel = pytest.importorskip("cmeel")
    root = os.path.join(cmeel.__path__[0], "..", "cmeel.prefix", "share", "example-robot-data", "robots")
    found = glob.glob(os.path.join(root, "panda_description", "urdf", "panda.urdf"))
    if not found:
        pytest.skip("example-robot-data (the Panda URDF) is not installed")
    return Path(found[0])


@dataclass
class Panda:
    chain: apair.AChain
    model: Any  # pinocchio.Model of the seven arm joints
    data: Any
    frame: int  # the tip's frame id in the model
    names: list[str]

    def pin_q(self, q: np.ndarray) -> np.ndarray:
        out = np.zeros(self.model.nq)
        for name, x in zip(self.names, q):
            self.model.joints[self.model.getJointId(name)]  # the arm's joints are revolute (nq = 1)
            out[self.model.joints[self.model.getJointId(name)].idx_q] = x
        return out

    def order(self) -> list[int]:
        return [self.model.joints[self.model.getJointId(n)].idx_v for n in self.names]


def panda(tip: str = "panda_link8") -> Panda:
    path = panda_path()
    chain = apair.load_urdf(path, tip)
    full = pin.buildModelFromUrdf(str(path))
    names = [f"panda_joint{i}" for i in range(1, 8)]
    lock = [full.getJointId(n) for n in full.names[1:] if n not in names]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    assert model.nv == 7
    return Panda(chain, model, model.createData(), model.getFrameId(tip), names)


def relative(a: np.ndarray, ref: np.ndarray) -> float:
    """The largest entry of |a − ref| relative to the largest entry of |ref| (at least 1)."""
    return float(np.abs(np.asarray(a) - ref).max()) / max(1.0, float(np.abs(ref).max()))
