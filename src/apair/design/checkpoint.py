"""The candidates a search has evaluated (x → Record), kept in a JSON file every SAVE_SECONDS and
when the search stops, finished or not.

Resuming replays the search from its start: the optimiser is deterministic for its seed, so it
proposes the same candidates again, and those already evaluated are answered from the file (no
work), until the search goes past where it stopped. A resumed run thus ends exactly where an
uninterrupted one does. The file holds the spec's fingerprint (`Spec.fingerprint`): another spec
cannot resume it. Numbers are written in Python's shortest round-trip form, read back bit for bit.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._validate import shorten
from ..files import Refusal, write
from .evaluate import Record

SAVE_SECONDS = 5.0
FORMAT_KEY = "apair design checkpoint"
FORMAT = 1


class Checkpoint:
    """The evaluated candidates, in memory and (with a path) on disk."""

    def __init__(self, path: Path | None, fingerprint: str, clock: Callable[[], float] = time.monotonic) -> None:
        self.path, self.fingerprint, self._clock = path, fingerprint, clock
        self._records: dict[bytes, tuple[NDArray[np.float64], Record]] = {}
        self._saved_at = clock()
        self._dirty = False

    @classmethod
    def open(cls, path: str | os.PathLike[str] | None, fingerprint: str, resume: bool, overwrite: bool) -> Checkpoint:
        """The checkpoint at path: read back with `resume` (afresh if there is none yet); an
        existing file is otherwise refused unless `overwrite` (it holds an earlier run)."""
        if path is None:
            if resume:
                raise ValueError("resume: there is no checkpoint to resume (pass checkpoint=, the file of the run)")
            return cls(None, fingerprint)
        if not isinstance(path, (str, os.PathLike)) or not str(os.fspath(path)).strip():
            raise ValueError(f"checkpoint: expected a file name, got {shorten(repr(path))}")
        p = Path(path)
        if p.is_dir():
            raise ValueError(f"checkpoint: {str(p)!r} is a folder")
        if not p.parent.is_dir():
            raise ValueError(f"checkpoint: folder {str(p.parent)!r} does not exist")
        out = cls(p, fingerprint)
        if p.exists() and resume:
            out._read()
        elif p.exists() and not overwrite:
            raise Refusal(
                f"checkpoint: {str(p)!r} holds an earlier run (resume=True continues it)",
                "overwrite",
                "to start afresh",
            )
        return out

    def _read(self) -> None:
        p = self.path
        assert p is not None
        try:
            doc = json.loads(p.read_text(encoding="utf-8"))
            if doc.get(FORMAT_KEY) != FORMAT:
                raise ValueError("not a checkpoint of apair design")
            entries = [(np.array(e["x"], dtype=float), Record.from_json(e["record"])) for e in doc["evaluated"]]
            fingerprint = doc["spec"]
        except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, AttributeError) as exc:
            raise ValueError(f"checkpoint: {str(p)!r} cannot be resumed: {shorten(str(exc), 120)}") from None
        if fingerprint != self.fingerprint:
            raise ValueError(
                f"checkpoint: {str(p)!r} was written for another spec (or apair version); "
                "start afresh instead of resuming it"
            )
        for x, record in entries:
            self._records[x.tobytes()] = (x, record)

    def __len__(self) -> int:
        return len(self._records)

    def get(self, x: NDArray[np.float64]) -> Record | None:
        hit = self._records.get(np.asarray(x, dtype=float).tobytes())
        return None if hit is None else hit[1]

    def put(self, x: NDArray[np.float64], record: Record) -> None:
        x = np.array(x, dtype=float)
        self._records[x.tobytes()] = (x, record)
        self._dirty = True
        if self._clock() - self._saved_at >= SAVE_SECONDS:
            self.save()

    def items(self) -> Iterator[tuple[NDArray[np.float64], Record]]:
        return iter(self._records.values())

    def save(self) -> None:
        """Write the file now (if there is one and something new to write)."""
        self._saved_at = self._clock()
        if self.path is None or not self._dirty:
            return
        doc: dict[str, Any] = {
            FORMAT_KEY: FORMAT,
            "spec": self.fingerprint,
            "evaluated": [{"x": x.tolist(), "record": r.to_json()} for x, r in self._records.values()],
        }
        text = json.dumps(doc, allow_nan=False)

        def put(tmp: str) -> None:
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(text)

        write(self.path, True, put)
        self._dirty = False
