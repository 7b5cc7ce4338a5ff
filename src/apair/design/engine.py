"""Where candidates are evaluated: in this process, on a LocalCluster of worker processes, or on a
Dask cluster by its scheduler's address; batches in, Records out in the batch's order, whatever
order the workers finish in (so the optimiser sees the same numbers everywhere). Every candidate
goes through the checkpoint: one evaluated before is not evaluated again.
"""

from __future__ import annotations

import logging
import math
import os
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._validate import integer, shorten
from .checkpoint import Checkpoint
from .evaluate import Record, evaluate, evaluate_many
from .spec import Spec

MAX_WORKERS = 1024
CONNECT_TIMEOUT = "10s"  # to reach a scheduler address
Progress = Callable[[int, int, dict[str, float]], object]  # progress(done, budget, best so far)


@contextmanager
def client_for(workers: object, scheduler: object) -> Iterator[Any]:
    """A dask.distributed Client, or None for this process: `scheduler` (an address or a Client),
    else `workers` worker processes on this machine (None: one per core; 0: none, this process)."""
    if scheduler is not None and workers is not None:
        raise ValueError("workers, scheduler: give one of them, not both")
    if scheduler is not None:
        yield from _remote(scheduler)
        return
    if workers is None:
        n = os.cpu_count() or 1
    else:
        n = integer("workers", workers, minimum=0, maximum=MAX_WORKERS)
    if n == 0:
        yield None
        return
    from dask.distributed import Client, LocalCluster

    with warnings.catch_warnings():  # the scheduler's HTTP port taken by another cluster: it takes another
        warnings.filterwarnings("ignore", message="Port .* is already in use")
        cluster = LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.CRITICAL
        )
    with cluster, Client(cluster) as client:
        yield client


def _remote(scheduler: object) -> Iterator[Any]:
    from dask.distributed import Client

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if not isinstance(scheduler, str) or ":" not in scheduler:
        raise ValueError(
            f"scheduler: expected a Dask scheduler's address (tcp://host:8786) or a Client, got {shorten(repr(scheduler))}"
        )
    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ValueError(
            f"scheduler: cannot reach a Dask scheduler at {scheduler!r} within {CONNECT_TIMEOUT} ({type(exc).__name__})"
        ) from None
    with client:
        yield client


def chunks(count: int, slots: int) -> list[tuple[int, int]]:
    """(start, end) of the tasks a batch of `count` candidates is cut into for `slots` parallel
    workers: guided self-scheduling, each chunk 1/(2 slots) of what remains (at least one
    candidate). Few tasks (Dask's overhead per task is milliseconds of the client's time), and
    small ones last, so that no worker waits long for another at the end of a generation."""
    out, start = [], 0
    while start < count:
        size = max(1, math.ceil((count - start) / (2 * slots)))
        out.append((start, min(count, start + size)))
        start += size
    return out


class Engine:
    """Evaluates batches of candidates of `spec` (serially without a client), through the
    checkpoint, telling `progress` after each candidate how many of `budget` are done and the
    best value of each objective so far."""

    def __init__(self, spec: Spec, checkpoint: Checkpoint, client: Any, progress: Progress | None, budget: int) -> None:
        self.spec, self.checkpoint, self.client = spec, checkpoint, client
        self.progress, self.budget = progress, budget
        self.done = 0
        self.best: dict[str, float] = {}
        self._spec_future: Any = None

    def __call__(self, xs: Sequence[NDArray[np.float64]]) -> list[Record]:
        """The Records of the candidates xs, in order."""
        xs = [np.asarray(x, dtype=float) for x in xs]
        out: list[Record | None] = [self.checkpoint.get(x) for x in xs]
        todo = [k for k, r in enumerate(out) if r is None]
        for r in out:
            if r is not None:
                self._tick(r)
        for k, record in self._evaluate([xs[k] for k in todo], todo):
            out[k] = record
            self.checkpoint.put(xs[k], record)
            self._tick(record)
        return [r for r in out if r is not None]

    def _evaluate(self, xs: list[NDArray[np.float64]], keys: list[int]) -> Iterator[tuple[int, Record]]:
        """(key, Record) of each candidate as it is done: on Dask in chunks of decreasing size
        (`chunks`), each chunk one task."""
        if self.client is None:
            for k, x in zip(keys, xs):
                yield k, evaluate(self.spec, x)
            return
        if not xs:
            return
        from dask.distributed import as_completed

        if self._spec_future is None:
            self._spec_future = self.client.scatter(self.spec, broadcast=True, hash=False)
        slots = max(1, sum(self.client.nthreads().values()))
        spans = chunks(len(xs), slots)
        futures = [self.client.submit(evaluate_many, self._spec_future, xs[a:b], pure=False) for a, b in spans]
        span_of = {f.key: span for f, span in zip(futures, spans)}
        try:
            for future in as_completed(futures):
                a, b = span_of[future.key]
                yield from zip(keys[a:b], future.result())
        finally:
            self.client.cancel(futures)

    def _tick(self, record: Record) -> None:
        self.done += 1
        if record.objectives is not None:
            for o, v in zip(self.spec.objectives, record.objectives):
                better = max if o.sense == "maximise" else min
                self.best[o.name] = better(self.best.get(o.name, v), v)
        if self.progress is not None:
            self.progress(self.done, self.budget, dict(self.best))
