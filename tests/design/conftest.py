"""Small design problems whose answer exists: targets made by a design inside the bounds, a start
from another design. Each builder writes a folder (start.toml, true.toml, targets.csv, spec.toml)
and returns the spec's path."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import apair

ROOT = Path(__file__).resolve().parents[2]


def three_joint_chain(c1: float, a2: float, a3: float, r2: float = 0.05, name: str = "arm") -> str:
    """A revolute base (offset c1, twist 90°) and two sinusoidal A-pairs on parallel axes."""
    return f'''name = "{name}"

[[joint]]
pair = "revolute"
a = 0.0
alpha_deg = 90
offset = {c1!r}
mass = 1.0
com = [0.0, 0.0, 0.05]

[[joint]]
pair = "sinusoidal"
base_radius = {r2!r}
platform_radius = 0.05
a = {a2!r}
alpha_deg = 0
mass = 1.5
com = [-0.1, 0.0, 0.0]

[[joint]]
pair = "sinusoidal"
base_radius = 0.04
platform_radius = 0.04
a = {a3!r}
alpha_deg = 0
mass = 1.0
com = [-0.1, 0.0, 0.0]
'''


def points_of(chain_file: Path, count: int, seed: int) -> np.ndarray:
    """End-effector positions of the chain at joint vectors drawn uniformly inside its limits."""
    chain = apair.load(chain_file)
    lim = chain.limits
    q = np.random.default_rng(seed).uniform(lim[:, 0], lim[:, 1], (count, chain.n))
    return chain.fk(q)[:, :3, 3]


def write_points(path: Path, points: np.ndarray) -> None:
    path.write_text("x,y,z\n" + "".join(",".join(repr(float(v)) for v in p) + "\n" for p in points))


SPEC = """start = "start.toml"
seed = {seed}
budget = {budget}

[vary]
{vary}

[targets]
points = "targets.csv"
tolerance = 0.002

[objective]
{objective}
{extra}"""

VARY3 = """"joint.1.offset" = [0.0, 0.3]
"joint.2.a" = [0.1, 0.5]
"joint.3.a" = [0.1, 0.5]"""


def make_problem(
    folder: Path,
    *,
    vary: str = VARY3,
    objective: str = 'maximise = "coverage"',
    budget: int = 200,
    seed: int = 1,
    targets: int = 30,
    extra: str = "",
    true: tuple[float, float, float, float] = (0.15, 0.30, 0.22, 0.06),
    start: tuple[float, float, float, float] = (0.05, 0.15, 0.40, 0.04),
) -> Path:
    """A three-joint problem in `folder`: targets made by `true` (c1, a2, a3, r2), the search
    from `start`; returns the spec's path."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "true.toml").write_text(three_joint_chain(*true, name="true"))
    (folder / "start.toml").write_text(three_joint_chain(*start, name="start"))
    write_points(folder / "targets.csv", points_of(folder / "true.toml", targets, seed=7))
    spec = folder / "spec.toml"
    spec.write_text(SPEC.format(seed=seed, budget=budget, vary=vary, objective=objective, extra=extra))
    return spec


@pytest.fixture
def problem(tmp_path):
    """make_problem in a fresh folder: problem(**options) -> the spec's path."""
    count = iter(range(100))
    return lambda **kw: make_problem(tmp_path / f"p{next(count)}", **kw)
