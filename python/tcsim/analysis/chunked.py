"""Studies computed in chunks: the compute side of sharded, resumable studies (docs/study.md,
"Large studies"; the shard files are :mod:`tcsim.io.shards`).

A study is an ordered list of ``n_cases`` cases. With a chunk size N, chunk ``i`` is the cases
``i·N`` to ``min((i+1)·N, n_cases)``, and its rows are a pure function of the study (plain data:
numbers, text, tuples) and ``i``: :func:`chunk_rows`. So any process that imports tcsim computes
the same chunk bit for bit, and the rows of all chunks in order are those of the unchunked study.

Where the chunks are computed (:func:`iter_chunks`):

* without a scheduler: one after the other in this process, each by one batched core call (the core
  uses its own threads where it has them);
* ``scheduler="local"``: a ``dask.distributed.LocalCluster`` of ``workers`` processes with one
  thread each;
* ``scheduler="tcp://HOST:PORT"`` (any address ``dask.distributed.Client`` accepts): that cluster.
  Its workers need the same tcsim installed.

dask.distributed is an optional dependency (``pip install 'tcsim[dask]'``). At most
:data:`IN_FLIGHT_PER_WORKER` chunks per worker are submitted at a time, more as results arrive, so
that neither the workers nor the client hold more than a few chunks whatever the number of chunks.
A worker that dies loses only its chunks in flight, which the scheduler gives to another worker.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import itertools
import math
import os
from collections.abc import Generator, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Protocol

import numpy as np
import pandas as pd

from ..errors import InputError
from ..models.converter import Converter
from ..models.design_file import DesignFile
from .design_study import check_sweep, design_rows, row_columns, study_base
from .study import (
    COLUMNS,
    StudyDefinition,
    _check_definition,
    _references,
    case_count,
    default_definition,
    study_rows,
)

#: The largest chunk size, cases.
MAX_CHUNK_SIZE = 1_000_000
#: Chunks submitted to a dask cluster at a time, per worker.
IN_FLIGHT_PER_WORKER = 2
#: What ``--scheduler`` names the local cluster by.
LOCAL = "local"


class ChunkedStudy(Protocol):
    """What :func:`chunk_rows` needs of a study: plain, picklable data."""

    @property
    def kind(self) -> str:
        """The kind of study, recorded in its manifest (``appendix-d``)."""
        ...

    @property
    def columns(self) -> tuple[str, ...]:
        """The columns of its rows, in order."""
        ...

    @property
    def n_cases(self) -> int: ...

    def definition(self) -> dict[str, Any]:
        """Everything the rows depend on, as JSON data (hashed into the manifest)."""
        ...

    def rows(self, start: int, stop: int) -> pd.DataFrame:
        """The rows of the cases ``start`` to ``stop`` (exclusive)."""
        ...


@dataclass(frozen=True)
class AppendixDStudy:
    """The Appendix D study (:mod:`tcsim.analysis.study`) as plain data: a case is one (parameter,
    value), with one row per speed ratio of the definition."""

    converter: str
    base_row: tuple[float, ...]
    references: tuple[float, ...]
    study: StudyDefinition
    kind: str = "appendix-d"
    columns: tuple[str, ...] = tuple(COLUMNS)

    @functools.cached_property
    def n_cases(self) -> int:
        return case_count(self.study, self.references)

    def definition(self) -> dict[str, Any]:
        d = self.study
        return {
            "converter": self.converter,
            "geometry": list(self.base_row),
            "parameters": [
                {"key": p.key, "low": p.low, "high": p.high, "relative": p.relative, "reference": r}
                for p, r in zip(d.parameters, self.references)
            ],
            "values_per_parameter": d.values_per_parameter,
            "pump_speed_rpm": d.pump_speed_rpm,
            "speed_ratio": list(d.speed_ratio),
        }

    def rows(self, start: int, stop: int) -> pd.DataFrame:
        return study_rows(np.asarray(self.base_row), self.study, self.references, start, stop)


def appendix_d_study(converter: Converter, definition: StudyDefinition | None = None) -> AppendixDStudy:
    """The Appendix D study of ``converter`` (which needs a [geometry]) for chunked runs."""
    converter.require("hrovat-tobler")
    definition = definition or default_definition()
    _check_definition(definition)
    assert converter.geometry is not None
    return AppendixDStudy(
        converter=converter.name,
        base_row=tuple(float(v) for v in converter.geometry.core_row()),
        references=_references(converter, definition),
        study=definition,
    )


@dataclass(frozen=True)
class DesignSweepStudy:
    """A design study (:func:`tcsim.analysis.design_study.design_study`) as plain data: a case is one
    design of the full grid of ``values`` (one tuple per swept parameter of ``names``, the first
    varying slowest); its row is :func:`~tcsim.analysis.design_study.design_rows`'s, without
    ``pareto_front`` (which compares all designs: compute it from the shards read back with
    :func:`~tcsim.analysis.design_study.pareto_front`). ``threads``: core workers of each chunk (0:
    all cores); it does not change the rows."""

    design: DesignFile
    names: tuple[str, ...]
    values: tuple[tuple[float, ...], ...]
    threads: int = 0
    kind: str = "design-study"

    @property
    def n_cases(self) -> int:
        return math.prod(len(v) for v in self.values)

    @property
    def columns(self) -> tuple[str, ...]:
        return row_columns(self.names)

    def definition(self) -> dict[str, Any]:
        d = self.design
        return {
            "design": {
                "file": d.path,
                "name": d.name,
                "design": dataclasses.asdict(d.design),
                "metal_inertia": d.metal_inertia.model_dump(),
                "losses": dict(d.losses),
            },
            "sweep": {n: list(v) for n, v in zip(self.names, self.values)},
        }

    def rows(self, start: int, stop: int) -> pd.DataFrame:
        grid = list(itertools.islice(itertools.product(*self.values), start, stop))
        return design_rows(self.design, self.names, grid, self.threads)


def design_sweep_study(
    design: DesignFile, sweep: Mapping[str, Sequence[float] | np.ndarray], threads: int = 0
) -> DesignSweepStudy:
    """The design study of ``sweep`` (one or two parameters → their values) around ``design`` for
    chunked runs; the sweep checked as :func:`~tcsim.analysis.design_study.design_study` checks it,
    without its cap on the designs held in memory."""
    check_sweep(sweep, chunked=True)
    names = tuple(sweep)
    values = tuple(tuple(np.asarray(sweep[n], dtype=float).tolist()) for n in names)
    return DesignSweepStudy(study_base(design, names), names, values, threads)


def check_chunk_size(chunk_size: Any, source: str = "command line", field: str = "--chunk-size") -> int:
    """``chunk_size`` as an int from 1 to :data:`MAX_CHUNK_SIZE`, else :class:`InputError`."""
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, int | np.integer) or not 1 <= chunk_size:
        raise InputError(source, field, chunk_size, f"an integer from 1 to {MAX_CHUNK_SIZE} (cases per chunk)")
    if chunk_size > MAX_CHUNK_SIZE:
        raise InputError(source, field, chunk_size, f"an integer from 1 to {MAX_CHUNK_SIZE} (cases per chunk)")
    return int(chunk_size)


def chunk_count(n_cases: int, chunk_size: int) -> int:
    """How many chunks ``n_cases`` cases make (the last may be short)."""
    return math.ceil(n_cases / chunk_size)


def chunk_rows(study: ChunkedStudy, chunk_size: int, index: int) -> pd.DataFrame:
    """The rows of chunk ``index``: a pure function of its arguments (what a worker runs)."""
    start = index * chunk_size
    return study.rows(start, min(start + chunk_size, study.n_cases))


def _distributed() -> ModuleType:
    """``dask.distributed``, or :class:`InputError` of ``--scheduler`` when it is not installed."""
    try:
        return importlib.import_module("distributed")
    except ImportError:
        raise InputError(
            "command line",
            "--scheduler",
            "given",
            "no --scheduler, or dask.distributed installed (pip install 'tcsim[dask]')",
        ) from None


def check_scheduler(scheduler: str | None, workers: int | None) -> None:
    """Refuse a scheduler that cannot be used (dask missing, a bad worker count) before anything runs."""
    if workers is not None and (scheduler != LOCAL or not 1 <= workers <= 1024):
        raise InputError("command line", "--workers", workers, "1 to 1024 workers, with --scheduler local")
    if scheduler is not None:
        if not scheduler.strip():
            raise InputError("command line", "--scheduler", scheduler, f"{LOCAL!r} or a dask scheduler's address")
        _distributed()


def iter_chunks(
    study: ChunkedStudy,
    chunk_size: int,
    indices: Iterable[int],
    scheduler: str | None = None,
    workers: int | None = None,
) -> Generator[tuple[int, pd.DataFrame], None, None]:
    """``(index, rows)`` of each chunk of ``indices``, in the order the results arrive (see the
    module's docstring for ``scheduler`` and ``workers``). Closing the generator cancels the chunks
    still in flight and closes the client (and the local cluster it started)."""
    if scheduler is None:
        for i in indices:
            yield i, chunk_rows(study, chunk_size, i)
        return
    todo = list(indices)
    if todo:  # no cluster is started or reached for nothing
        yield from _iter_dask(_distributed(), study, chunk_size, todo, scheduler, workers)


def _iter_dask(
    distributed: ModuleType,
    study: ChunkedStudy,
    chunk_size: int,
    indices: list[int],
    scheduler: str,
    workers: int | None,
) -> Generator[tuple[int, pd.DataFrame], None, None]:
    cluster = None
    if scheduler == LOCAL:
        n = workers or max(1, min(len(indices), os.cpu_count() or 1))
        cluster = distributed.LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=50
        )
    client = distributed.Client(cluster if cluster is not None else scheduler, set_as_default=False)
    futures: dict[Any, int] = {}
    try:
        window = IN_FLIGHT_PER_WORKER * max(1, len(client.scheduler_info().get("workers", {})))
        todo = iter(indices)
        pending = distributed.as_completed(loop=client.loop)
        for i in _take(todo, window):
            f = client.submit(chunk_rows, study, chunk_size, i, pure=False)
            futures[f] = i
            pending.add(f)
        for f in pending:
            i = futures.pop(f)
            rows = f.result()
            f.release()
            for j in _take(todo, 1):
                g = client.submit(chunk_rows, study, chunk_size, j, pure=False)
                futures[g] = j
                pending.add(g)
            yield i, rows
    finally:
        client.cancel(list(futures))
        client.close()
        if cluster is not None:
            cluster.close()


def _take(items: Iterator[int], n: int) -> list[int]:
    out = []
    for _ in range(n):
        nxt = next(items, None)
        if nxt is None:
            break
        out.append(nxt)
    return out
