"""What a design search returns (`DesignResult`): the best design as an ordinary chain file with
the objective reached in its comments, and with several objectives the Pareto front as CSV and as
a picture. Every file is written by apair.files' rules: an existing one only with overwrite=True.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..chain import AChain
from ..figures import figure
from ..files import target, write, write_text
from . import chainfile
from .spec import Spec

UNITS = {"coverage": "", "volume": "m^3", "gravity_torque_max": "N m"}


@dataclass(frozen=True)
class FrontPoint:
    """One design of the Pareto front: its varied values and its objectives."""

    values: dict[str, float | str]
    objectives: dict[str, float]


@dataclass
class DesignResult:
    """The best design found: `chain`, its chain file's `document` and `text` (what `write`
    writes), the varied `values`, the `objectives` reached, `reached` of `targets` (None without
    targets), the candidates `evaluated`, the seconds taken and, with several objectives, the
    Pareto `front` (best first by the first objective)."""

    spec: Spec
    chain: AChain
    document: dict[str, Any]
    values: dict[str, float | str]
    objectives: dict[str, float]
    reached: int | None
    targets: int | None
    evaluated: int
    seconds: float
    front: list[FrontPoint] = field(default_factory=list)

    @property
    def summary(self) -> str:
        """One line: every objective reached (coverage with its count of targets)."""
        parts = []
        for name, v in self.objectives.items():
            if name == "coverage" and self.targets:
                parts.append(f"coverage {v:.4g} ({self.reached} of {self.targets} targets)")
            else:
                parts.append(f"{name} {v:.6g}{' ' + UNITS[name] if UNITS[name] else ''}")
        return ", ".join(parts)

    @property
    def text(self) -> str:
        """The best design's chain file, commented with what it reached."""
        s = self.spec
        comments = [
            f"Written by apair design from {s.where} (start {s.start_name}, seed {s.seed}, "
            f"{self.evaluated} candidates evaluated of a budget of {s.budget}).",
            f"Reached: {self.summary}.",
        ]
        if s.targets is not None:
            tol = f"{s.targets.tolerance:g} m" + (
                f" and {s.targets.tolerance_deg:g} deg" if s.targets.tolerance_deg is not None else ""
            )
            comments.append(f"Targets: {len(s.targets)} {s.targets.kind} from {s.targets.source}, within {tol}.")
        comments.append("Varied:")
        comments += [f"  {k} = {_shown(v)}" for k, v in self.values.items()]
        if s.constraints.min_clearance > 0:
            comments.append(
                f"The A-pairs' limits keep a clearance of {s.constraints.min_clearance:g} m between legs and plates."
            )
        return chainfile.dumps(self.document, comments)

    def write(self, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
        """The best design's chain file (a .toml suffix added where the name has none)."""
        return write_text(path, self.text, overwrite, ".toml")

    def front_csv(self) -> str:
        """The Pareto front as CSV: a header of the varied keys and the objectives, a row per design."""
        if not self.front:
            raise ValueError("front: a search with one objective has no Pareto front")
        names = list(self.front[0].values) + list(self.front[0].objectives)
        rows = [",".join(names)]
        for p in self.front:
            rows.append(",".join([_shown(v) for v in p.values.values()] + [repr(v) for v in p.objectives.values()]))
        return "\n".join(rows) + "\n"

    def write_front(self, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
        """The Pareto front's CSV file."""
        return write_text(path, self.front_csv(), overwrite, ".csv")

    def plot_front(self, path: str | os.PathLike[str], overwrite: bool = False) -> Path:
        """The Pareto front against every pair of objectives (PNG), the best design marked."""
        if not self.front:
            raise ValueError("front: a search with one objective has no Pareto front")
        p = target(path, overwrite)
        names = list(self.objectives)
        pairs = [(i, j) for i in range(len(names)) for j in range(i + 1, len(names))]
        plt = figure()
        fig, axes = plt.subplots(1, len(pairs), figsize=(5 * len(pairs), 4.2), squeeze=False)
        F = np.array([[pt.objectives[n] for n in names] for pt in self.front])
        for ax, (i, j) in zip(axes[0], pairs):
            order = np.argsort(F[:, i], kind="stable")
            ax.plot(F[order, i], F[order, j], "o-", ms=4, lw=1, label=f"Pareto front ({len(F)} designs)")
            ax.plot(self.objectives[names[i]], self.objectives[names[j]], "*", ms=14, c="C3", label="best (written)")
            ax.set_xlabel(_label(names[i]))
            ax.set_ylabel(_label(names[j]))
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        fig.suptitle(f"{self.spec.where}: {self.evaluated} candidates", fontsize=9)
        fig.tight_layout()
        write(p, overwrite, lambda f: fig.savefig(f, dpi=110, format="png"))
        plt.close(fig)
        return p


def _label(name: str) -> str:
    return f"{name} [{UNITS[name]}]" if UNITS[name] else name


def _shown(v: float | str) -> str:
    return v if isinstance(v, str) else repr(v)
