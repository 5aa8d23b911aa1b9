"""Transient simulation of an isolated converter: models, drives, one-line and batch runs.

The engine is the Rust core's (:mod:`tcsim._core`): its own variable-order BDF (NDF) solver on the models in
mass-matrix form, with root finding for the stator one-way clutch and for flow reversal.
See ``docs/transient.md`` for the equations, events and conventions.

API tiers (after FMPy):

* one line: :func:`simulate` (a converter, a model name and a drive → :class:`TransientResult`);
* reusable objects: :func:`dynamic_model` → :class:`DynamicModel` (with
  :meth:`DynamicModel.with_shape_effects` for sweeps), drives :class:`PumpTorqueTurbineSpeed`,
  :class:`Speeds`, :class:`PumpTorqueLoad`;
* batch: :func:`simulate_batch`, N models × one drive, one model × N drives, or N pairs, with the
  GIL released and one worker per core;
* columnar batch: :func:`simulate_columns` → :class:`BatchColumns`, one array per chosen column for
  all runs, per-run status and errors, no Python object per run (what scales with cores);
* raw: ``tcsim._core.transient_batch`` with the dicts of :meth:`DynamicModel.spec` and ``Drive.spec``.

Every tier takes ``columns`` (names of :data:`COLUMNS`; default all): only those are computed and
stored by the core.
"""

from __future__ import annotations

import operator
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .. import _core
from ..errors import ARGUMENT, InputError, TcsimWarning, core_input_error, from_core
from ..models.arguments import worker_count
from ..models.converter import Converter
from ..models.drives import Drive
from ..models.dynamic import DynamicModel, dynamic_model

COLUMNS: tuple[str, ...] = tuple(_core.transient_columns())
#: The names of ``initial``'s values (a run's coordinates).
INITIAL_KEYS: tuple[str, ...] = ("pump_speed_rad_s", "turbine_speed_rad_s", "stator_speed_rad_s", "flow_m3_s")


class SolverError(RuntimeError):
    """The solver failed (not the user's fault): the message gives the time and the state."""


# ---------------------------------------------------------------------------------------------
# Runs


@dataclass(frozen=True)
class Event:
    time_s: float
    kind: str  # stator-release, stator-lock, flow-zero, flow-start
    stator_locked: bool
    flow_direction: float  # after the event: +1, −1, 0 (held at zero)


@dataclass
class TransientResult:
    """Columns of a run (SI, names per conventions.md; see :data:`COLUMNS`) and its events."""

    model: str
    columns: dict[str, np.ndarray]
    events: list[Event] = field(default_factory=list)
    #: Whether the caller chose the columns (``simulate(..., columns=[...])``): :meth:`frame` then
    #: keeps each of them.
    chosen_columns: bool = False

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def frame(self) -> pd.DataFrame:
        """The columns as a DataFrame, without the all-NaN columns of coordinates the model lacks
        (the columns the caller chose are all kept: a table model's ``flow_m3_s`` asked for is a
        column of NaN, not an empty frame)."""
        df = pd.DataFrame(self.columns)
        if self.chosen_columns:
            return df
        return df.loc[:, df.notna().any() | (df.columns == "time_s")]


def _options(rtol: float | None, **extra) -> dict[str, Any]:
    o = dict(extra)
    if rtol is not None:
        o["rtol"] = rtol
    return o


_INFINITE_ALLOWED, _NAN_NOT_EXPECTED = _core.output_value_rules()
#: Columns that may hold ±inf or NaN by definition: the K-factor is infinite where the capacity is
#: zero and undefined (NaN) where it is negative (overrun rows of a table, ``conventions.md``). The
#: rule is the core's (``tcsim._core.output_value_rules``), which checks every run with it.
INFINITE_ALLOWED: frozenset[str] = frozenset(_INFINITE_ALLOWED)
#: Unit suffixes of physical quantities (speeds, torques, flows, powers, energies): a run that has
#: such a quantity never leaves it NaN at some samples; ratios, times not reached and metrics may be
#: NaN where undefined. The core's rule, as :data:`INFINITE_ALLOWED`.
NAN_NOT_EXPECTED: tuple[str, ...] = tuple(_NAN_NOT_EXPECTED)
#: Event kinds in the order of the codes of :attr:`BatchColumns.events` ``["kind"]``.
EVENT_KINDS: tuple[str, ...] = tuple(_core.transient_event_kinds())
#: Run status codes of :attr:`BatchColumns.status`: finished; input refused; solver failed;
#: finished, but a column overflowed (±inf, or NaN in a physical quantity).
RUN_OK, RUN_INPUT_ERROR, RUN_SOLVER_ERROR, RUN_OVERFLOW = 0, 1, 2, 3
#: The event arrays of :attr:`BatchColumns.events` and their keys in ``transient_batch``'s result.
_EVENT_KEYS = tuple((k, f"event_{k}") for k in ("run", "time_s", "kind", "stator_locked", "flow_direction"))
#: The models of characteristic tables: their runs are looked at for warnings.
_TABLE_MODELS = ("table", "quasi-dynamic")
#: Columns the table models' extension warning reads (:meth:`DynamicModel.warn_if_extended`).
_WARNING_COLUMNS = ("pump_speed_rad_s", "turbine_speed_rad_s")


def _failure(
    f: Mapping[str, Any], model: DynamicModel, where: str, files: Mapping[str, str] | None
) -> InputError | SolverError:
    """The exception of a failed run from the core's report ``f`` (``transient_batch``'s
    ``failures``), shown against ``files[source]`` for the input the core blamed (the model's
    converter file by default). ``where`` names the run in a batch (`` (run 3)``)."""
    if f["kind"] == "overflow":  # never a non-finite result without saying so: the drive is beyond the model
        return InputError(
            (files or {}).get("drive") or "drive",
            f"output {f['column']}{where}",
            f["value"],
            "a drive whose run stays finite "
            f"(it overflows at t = {f['time_s']:.6g} s: check the drive's values and units)",
            core_source="drive",
        )
    if f["kind"] == "input":
        sources = {"converter": model.source, **(files or {})}
        return core_input_error(f["source"], f["field"] + where, f["value"], f["expected"], sources)
    return SolverError(f"{model.name}{where}: {f['message']}")


@dataclass
class BatchColumns:
    """Results of N transient runs as columns (:func:`simulate_columns`): one array per chosen column
    for all runs, no Python object per run.

    Attributes
    ----------
    models : sequence of DynamicModel
        The models as given (one for all runs, or one per run).
    columns : dict of str to ndarray
        Name (:data:`COLUMNS`, SI units in the name) → float64 array of shape (N, S) when every run
        has S samples, else of shape (offsets[-1],), run ``i`` at rows ``offsets[i]:offsets[i + 1]``.
        A run that failed with an error has NaN rows; an overflowing run (status
        :data:`RUN_OVERFLOW`) has its values.
    offsets : ndarray of int64, shape (N + 1,)
        Row offsets of the runs in the flat layout (also given for the (N, S) layout).
    time_s : ndarray or None
        The sample times, s, shape (S,), when every run has the same ones; else None.
    status : ndarray of uint8, shape (N,)
        :data:`RUN_OK`, :data:`RUN_INPUT_ERROR`, :data:`RUN_SOLVER_ERROR` or :data:`RUN_OVERFLOW`.
    events : dict of str to ndarray
        All runs' events as flat arrays in run order: ``run`` (int64), ``time_s`` (s), ``kind``
        (uint8 codes of :data:`EVENT_KINDS`), ``stator_locked`` (bool) and ``flow_direction`` (+1,
        −1, 0 held at zero, after the event).
    errors : dict of int to Exception
        The :class:`~tcsim.errors.InputError` or :class:`SolverError` of each failed run, by index.
    """

    models: Sequence[DynamicModel]
    columns: dict[str, np.ndarray]
    offsets: np.ndarray
    time_s: np.ndarray | None
    status: np.ndarray
    events: dict[str, np.ndarray]
    errors: dict[int, Exception] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.status)

    def _model(self, i: int) -> DynamicModel:
        return self.models[i if len(self.models) > 1 else 0]

    def _index(self, i: int) -> int:
        """Run ``i`` as an index from 0: ``-1`` is the last run, as in a sequence; an index out of
        range, or not an integer, is an :class:`~tcsim.errors.InputError` about ``i``."""
        n = len(self)
        try:
            k = operator.index(i)
        except TypeError:
            k = None
        if k is None or isinstance(i, bool) or not -n <= k < n:
            raise InputError.argument("i", i, f"an integer run index from {-n} to {n - 1} (the batch has {n} runs)")
        return k + n if k < 0 else k

    def rows(self, name: str, i: int) -> np.ndarray:
        """Column ``name`` of run ``i`` (a view, no copy); ``i = -1`` is the last run."""
        col = self.columns.get(name) if isinstance(name, str) else None
        if col is None:
            raise InputError.argument("name", name, f"one of the batch's columns: {', '.join(self.columns)}")
        return self._run_rows(col, self._index(i))

    def _run_rows(self, col: np.ndarray, i: int) -> np.ndarray:
        """Run ``i``'s rows (an index from 0) of the column ``col``, in either layout."""
        return col[i] if col.ndim == 2 else col[self.offsets[i] : self.offsets[i + 1]]

    def run_events(self, i: int) -> list[Event]:
        """The events of run ``i`` (``-1``: the last run)."""
        i = self._index(i)
        a, b = np.searchsorted(self.events["run"], [i, i + 1])
        return _event_list(self.events, slice(a, b))

    def check(self) -> None:
        """Raise the error of the first run that failed with an error (input or solver), else of the
        first run that overflowed; nothing when every run finished."""
        if not self.errors:
            return
        failed = np.flatnonzero((self.status == RUN_INPUT_ERROR) | (self.status == RUN_SOLVER_ERROR))
        if not failed.size:
            failed = np.flatnonzero(self.status == RUN_OVERFLOW)
        if failed.size:
            raise self.errors[int(failed[0])]

    def run(self, i: int) -> TransientResult:
        """Run ``i`` as a :class:`TransientResult` (its columns are views of :attr:`columns`); raises
        the run's error if it failed. ``i = -1`` is the last run."""
        i = self._index(i)
        if self.status[i] != RUN_OK:
            raise self.errors[i]
        cols = {name: self._run_rows(col, i) for name, col in self.columns.items()}
        return TransientResult(self._model(i).name, cols, self.run_events(i))

    def frame(self, i: int) -> pd.DataFrame:
        """Run ``i`` as a DataFrame (:meth:`TransientResult.frame`)."""
        return self.run(i).frame()

    def runs(self) -> list[TransientResult]:
        """Every run as a :class:`TransientResult` (its columns views of :attr:`columns`), after
        :meth:`check` (which raises the first failed run's error)."""
        self.check()
        n = len(self)
        ev = self.events
        events = _event_list(ev)
        if n == 1:  # a single run: the whole of a flat column, the one row of an (1, S) one
            cols = {name: c if c.ndim == 1 else c[0] for name, c in self.columns.items()}
            return [TransientResult(self._model(0).name, cols, events)]
        names = list(self.columns)
        rows = [list(c) if c.ndim == 2 else np.split(c, self.offsets[1:-1]) for c in self.columns.values()]
        bounds = np.searchsorted(ev["run"], np.arange(n + 1)).tolist()
        return [
            TransientResult(self._model(i).name, dict(zip(names, values)), events[bounds[i] : bounds[i + 1]])
            for i, values in enumerate(zip(*rows) if names else iter([()] * n))
        ]


def _event_list(events: dict[str, np.ndarray], rows: slice | None = None) -> list[Event]:
    """The :class:`Event` of each of the ``rows`` (default all) of a batch's ``events`` arrays, in
    order. Each is made as ``Event(...)`` would make it, its fields set at once (a frozen
    dataclass's ``__init__`` sets them one by one through ``object.__setattr__``)."""
    times = events["time_s"]
    if not times.size:
        return []
    names = ("time_s", "kind", "stator_locked", "flow_direction")
    fields = [events[k].tolist() if rows is None else events[k][rows].tolist() for k in names]
    made = []
    for t, k, locked, flow in zip(*fields):
        e = object.__new__(Event)
        e.__dict__.update(time_s=t, kind=EVENT_KINDS[k], stator_locked=locked, flow_direction=flow)
        made.append(e)
    return made


#: The model :func:`simulate` runs of a converter when none is named.
DEFAULT_MODEL = "hrovat-tobler"


def simulate(
    converter: Converter | str | DynamicModel,
    drive: Drive,
    model: str | None = None,
    times_s: Sequence[float] | None = None,
    initial: dict[str, float] | None = None,
    rtol: float | None = None,
    files: Mapping[str, str] | None = None,
    columns: Sequence[str] | None = None,
    **solver_options,
) -> TransientResult:
    """Run one model under one drive; samples at ``times_s`` (default: the drive's time stamps).

    ``converter`` is a converter (a :class:`~tcsim.Converter`, bundled name or file) whose model
    ``model`` runs (default :data:`DEFAULT_MODEL`), or a :class:`DynamicModel`, which runs as it is
    (``model`` then none or its own name).

    The run always integrates from the drive's first time stamp; ``times_s`` (s, increasing, within
    the drive's span) only chooses the samples, so a later first sample gives the same values as a
    full run at the same times (:func:`output_times`). Events before the first sample are kept.
    ``columns`` chooses the output columns (names of :data:`COLUMNS`, default all); the others are
    neither computed nor stored.

    The initial state is the steady state consistent with the first input sample (drive c: with
    the turbine at rest) unless ``initial`` gives ``pump_speed_rad_s``, ``turbine_speed_rad_s``,
    ``stator_speed_rad_s`` or ``flow_m3_s``. ``files`` names the file of an input the core may
    blame in an :class:`InputError` (``{"drive": "log.csv"}``; see :func:`simulate_batch`).
    """
    if isinstance(converter, DynamicModel):
        m = converter
        if model is not None and model != m.name:  # it was ignored: a table model's run for "hrovat-tobler"
            raise InputError.argument("model", model, f"none, or the DynamicModel's own ({m.name!r})")
    else:
        m = dynamic_model(converter, DEFAULT_MODEL if model is None else model)
    return _single_run(m, drive, times_s, initial, rtol, files, columns, solver_options)


def simulate_batch(
    models: Sequence[DynamicModel],
    drives: Sequence[Drive],
    times_s: Sequence[float] | None = None,
    initial: dict[str, float] | None = None,
    rtol: float | None = None,
    threads: int = 0,
    files: Mapping[str, str] | None = None,
    columns: Sequence[str] | None = None,
    **solver_options,
) -> list[TransientResult]:
    """Run ``models[i]`` under ``drives[i]``; a sequence of length one is broadcast. The runs go to
    the core in one call, which releases the GIL and uses ``threads`` workers (0: all cores).
    Raises :class:`InputError` or :class:`SolverError` for the first run that fails (an error
    before an overflow). ``columns`` as in :func:`simulate`; each result's columns are views of the
    batch's arrays (:func:`simulate_columns`, which this reads).

    An :class:`InputError` names the input the core blamed (``core_source``: ``converter``,
    ``drive``, ``initial``, ``options``), shown as ``files[source]`` when given, else as the models'
    converter file or the input's name. ``solver_options`` are the core's: ``rtol``,
    ``speed_atol_rad_s``, ``flow_atol_m3_s``, ``first_step_s``, ``max_events`` and
    ``max_output_bytes`` (default 2e9: the estimated size of all runs' outputs, counting only the
    chosen columns, is refused above it before anything runs)."""
    batch = _run_batch(
        models, drives, times_s, columns, initial, rtol, threads, files, solver_options, shaped=False, every_time=False
    )
    try:
        batch.check()
    except InputError as e:
        _blame_times(e, drives, times_s)
        raise
    batch.columns = _warned_columns(batch, columns)
    runs = batch.runs()
    for r in runs:
        r.chosen_columns = columns is not None
    return runs


def _single_run(
    m: DynamicModel,
    drive: Drive,
    times_s: Sequence[float] | None,
    initial: dict[str, float] | None,
    rtol: float | None,
    files: Mapping[str, str] | None,
    columns: Sequence[str] | None,
    solver_options: dict[str, Any],
) -> TransientResult:
    """``simulate_batch([m], [drive], ...)[0]`` without a batch's bookkeeping: the same call of the
    core, errors, warnings and result, about 2 µs sooner (tests/integration/test_single_run.py). The
    arguments are :func:`simulate`'s own, which :func:`_check_batch` would look at again."""
    spec = _drive_spec(drive)
    if spec is None:
        raise InputError.argument("drive", type(drive).__name__, _NOT_A_DRIVE)
    if times_s is not None:
        spec["output_time_s"], spec["output_skip"] = _output_times(spec["time_s"], times_s, False)
    raw = _call_core([m], [spec], initial, rtol, 1, files, columns, solver_options)
    if raw["failures"]:  # (one run: its one failure)
        error = _failure(raw["failures"][0], m, "", files)
        if isinstance(error, InputError):
            _blame_times(error, [drive], times_s)
        raise error
    if m.name in _TABLE_MODELS:  # only their runs have warnings, which read the run's rows as a batch's
        cols = _warned_columns(_batch_columns(raw, [m], None, files, shaped=False), columns)
    else:
        cols = _chosen(raw["columns"], columns)
    return TransientResult(m.name, cols, _event_list(_raw_events(raw)), columns is not None)


def _blame_times(e: InputError, drives: Sequence[Drive], times_s: Sequence[float] | None) -> None:
    """Raise an :class:`InputError` about the argument ``times_s`` when the core's error ``e`` about
    a drive came from them: the core names the output times the drive's (a time outside its span,
    times not increasing or closer than the time resolution)."""
    if times_s is None or e.core_source != "drive":
        return
    for spec in map(_drive_spec, drives):
        if spec is not None:  # (each is: the run got this far) a time outside its span
            _output_times(spec["time_s"], times_s)
    _check_times_argument(_floats_1d(times_s))


def _warned_columns(batch: BatchColumns, columns: Sequence[str] | None) -> dict[str, np.ndarray]:
    """The warnings about the batch's finished runs (:func:`_warn_about_runs`), then the columns the
    caller chose (:func:`_chosen`). Every entry point's warnings come from here, one place, so that
    Python's filter shows a warning that ``simulate`` and ``simulate_batch`` both give once."""
    _warn_about_runs(batch)
    return _chosen(batch.columns, columns)


def _chosen(cols: dict[str, np.ndarray], columns: Sequence[str] | None) -> dict[str, np.ndarray]:
    """The ``columns`` the caller chose of the core's ``cols``, which has more for a table model
    (what its warnings read, :func:`_core_columns`)."""
    if columns is None or len(cols) == len(columns):
        return cols
    return {name: cols[name] for name in columns}


def _where(i: int, n: int) -> str:
    """How an error or a warning names run ``i`` of ``n``: nothing for a single run."""
    return "" if n == 1 else f" (run {i})"


def _warning_rows(batch: BatchColumns, i: int) -> dict[str, np.ndarray]:
    return {name: batch.rows(name, i) for name in _WARNING_COLUMNS}


def _drive_specs(
    drives: Sequence[Drive], times_s: Sequence[float] | None, every_time: bool = True
) -> tuple[list[dict], np.ndarray | None]:
    """The drives' dicts for the core (with ``output_time_s`` and ``output_skip`` for ``times_s``) and
    the sample times every run shares, s (None when the drives' time stamps differ). ``every_time``
    as in :func:`_output_times`; with it, ``times_s`` are also checked to increase no closer than
    the time resolution (:func:`_check_times_argument`; without it, :func:`_blame_times` does that
    once the core has refused them)."""
    if not _is_list(drives):
        raise InputError.argument("drives", drives, "a list of one or more drives")
    specs = []
    for i, d in enumerate(drives):
        s = _drive_spec(d)
        if s is None:
            raise InputError.argument("drive" if len(drives) == 1 else f"drives[{i}]", type(d).__name__, _NOT_A_DRIVE)
        if times_s is not None:
            s["output_time_s"], s["output_skip"] = _output_times(s["time_s"], times_s, every_time)
        specs.append(s)
    if times_s is not None:
        t = _floats_1d(times_s)
        if every_time:  # (the times every run shares: checked once, not blamed on each run's drive)
            _check_times_argument(t)
        return specs, t
    stamps = [_time_stamps(s["time_s"]) for s in specs]  # (None where they are no time stamps: the core refuses them)
    first = stamps[0]
    same = first is not None and all(s is not None and np.array_equal(first, s) for s in stamps[1:])
    return specs, first if same else None


#: What an argument that is no drive is expected to be.
_NOT_A_DRIVE = "a drive: tcsim.transient.PumpTorqueTurbineSpeed, Speeds or PumpTorqueLoad"


def _drive_spec(d: Drive) -> dict[str, Any] | None:
    """A drive's dict for the core: its series as arrays (a stand-in drive's ``spec()``); None for
    an object that is no drive."""
    spec = getattr(d, "_core_spec", None)
    if spec is None or not callable(spec):
        spec = getattr(d, "spec", None)
        if spec is None or not callable(spec):
            return None
    return spec()


def _is_sequence(x: Any) -> bool:
    """``isinstance(x, Sequence)``, a list or a tuple tested first (the abstract class's test costs
    more than the rest of a batch's checks of its arguments)."""
    return type(x) is list or type(x) is tuple or isinstance(x, Sequence)


def _is_list(x: Any) -> bool:
    """``x`` is a non-empty sequence other than a string."""
    return _is_sequence(x) and not isinstance(x, str) and len(x) > 0


def simulate_columns(
    models: Sequence[DynamicModel],
    drives: Sequence[Drive],
    times_s: Sequence[float] | None = None,
    columns: Sequence[str] | None = None,
    initial: dict[str, float] | None = None,
    rtol: float | None = None,
    threads: int = 0,
    files: Mapping[str, str] | None = None,
    **solver_options,
) -> BatchColumns:
    """Run ``models[i]`` under ``drives[i]`` (a sequence of length one is broadcast) and return the
    results as columns: one float64 array per chosen column for all runs, built by the core with the
    GIL released on ``threads`` workers (0: all cores) and handed to NumPy without a copy.

    Parameters
    ----------
    models, drives : sequence of DynamicModel, sequence of Drive
        As in :func:`simulate_batch`.
    times_s : sequence of float, optional
        Sample times, s, for every run (:func:`output_times`); default each drive's time stamps.
    columns : sequence of str, optional
        Names of :data:`COLUMNS` (SI units in the name), each once; default all. Only these are
        computed and stored; an empty list gives the status and events only. An unknown or repeated
        name is an :class:`InputError` about ``columns[i]`` listing the valid names.
    initial, rtol, files, **solver_options
        As in :func:`simulate_batch`; ``max_output_bytes`` counts only the chosen columns.

    Returns
    -------
    BatchColumns
        Columns of shape (N, S) (or flat with ``offsets`` when the runs' sample counts differ), the
        per-run ``status``, the events as flat arrays, and ``errors`` for the failed runs only. A
        failed run does not raise here: :meth:`BatchColumns.check` or :meth:`BatchColumns.run` do.
    """
    batch = _run_batch(models, drives, times_s, columns, initial, rtol, threads, files, solver_options)
    batch.columns = _warned_columns(batch, columns)
    return batch


def _run_batch(
    models: Sequence[DynamicModel],
    drives: Sequence[Drive],
    times_s: Sequence[float] | None,
    columns: Sequence[str] | None,
    initial: dict[str, float] | None,
    rtol: float | None,
    threads: int,
    files: Mapping[str, str] | None,
    solver_options: dict[str, Any],
    shaped: bool = True,
    every_time: bool = True,
) -> BatchColumns:
    """The one call of the core's ``transient_batch`` (:func:`simulate_columns`) after the checks of
    its arguments; ``shaped`` as in :func:`_batch_columns`, ``every_time`` as in :func:`_output_times`."""
    _check_batch(models, drives, threads)
    specs, shared_time = _drive_specs(drives, times_s, every_time)
    raw = _call_core(models, specs, initial, rtol, threads, files, columns, solver_options)
    return _batch_columns(raw, models, shared_time, files, shaped)


def _call_core(
    models: Sequence[DynamicModel],
    specs: list[dict],
    initial: dict[str, float] | None,
    rtol: float | None,
    threads: int,
    files: Mapping[str, str] | None,
    columns: Sequence[str] | None,
    solver_options: dict[str, Any],
) -> dict[str, Any]:
    """The core's ``transient_batch`` of the drives' ``specs``, with the columns the warnings read
    added for table models (:func:`_core_columns`); its refusal of an input as an
    :class:`InputError` naming the file or argument."""
    if initial is not None:
        _warn_ignored_initial(models, specs, initial)
    try:
        return _core.transient_batch(
            [m.spec for m in models],
            specs,
            initial,
            _options(rtol, **solver_options),
            threads,
            _core_columns(models, columns),
        )
    except _core.CoreInputError as e:
        if str(e.args[1]).startswith("columns["):
            raise from_core(e, ARGUMENT) from None
        converters = {m.source for m in models}
        sources = {"converter": converters.pop() if len(converters) == 1 else "model", **(files or {})}
        raise from_core(e, sources) from None


def _warn_ignored_initial(models: Sequence[DynamicModel], specs: list[dict], initial: Any) -> None:
    """A :class:`TcsimWarning` for each value of ``initial`` that a run does not use (the core's
    ``InitialState::ignored``): a speed its drive gives, or a state its model lacks. ``initial``
    that is not a dict is an :class:`InputError`; its other faults (a misspelt name, a value not a
    number), and a drive's, are the run's to report."""
    if not isinstance(initial, Mapping):
        expected = f"a dict of initial values by name: {', '.join(INITIAL_KEYS)}"
        raise InputError("initial state", "initial", type(initial).__name__, expected)
    shown: set[str] = set()
    asked: set[tuple[int, str]] = set()  # what is ignored depends on the model and the drive's kind only
    for i, spec in enumerate(specs):
        m = models[i if len(models) > 1 else 0]
        if (id(m), spec["kind"]) in asked:
            continue
        asked.add((id(m), spec["kind"]))
        try:
            ignored = _core.ignored_initial(m.spec, spec, dict(initial))
        except (_core.CoreInputError, TypeError, ValueError):
            continue  # an error of the drive or the model: the core call below reports it
        for key, why in ignored:
            why_not = f": the drive prescribes it ({spec['kind']})"
            if why == "model":
                why_not = f" by the {m.name} model: it has no such state"
            message = f"initial {key} is ignored{why_not}"
            if message not in shown:
                shown.add(message)
                warnings.warn(message, TcsimWarning, stacklevel=4)


def _check_batch(models: Sequence[DynamicModel], drives: Sequence[Drive], threads: int) -> None:
    r"""The arguments of a batch that the core would refuse as a bare ``ValueError`` or an
    ``OverflowError``, or that fail before it (a converter's name among the models), as
    :class:`InputError` about them."""
    if not _is_list(models):
        raise InputError.argument(
            "models", models, "a list of one or more models (tcsim.dynamic_model(converter, name))"
        )
    for i, m in enumerate(models):
        if not isinstance(m, DynamicModel):
            expected = "a DynamicModel (tcsim.dynamic_model(converter, name); simulate() also takes a name)"
            raise InputError.argument(f"models[{i}]", type(m).__name__, expected)
    if len(models) != 1 and _is_sequence(drives) and len(models) != len(drives) and len(drives) != 1:
        expected = f"as many drives as models ({len(models)}), or one of either"
        raise InputError.argument("drives", f"{len(drives)} drives", expected)
    worker_count(threads)


def _core_columns(models: Sequence[DynamicModel], columns: Sequence[str] | None) -> list[str] | None:
    """The columns asked of the core: ``columns`` and, for table models, what their warning reads."""
    if columns is None:
        return None
    if isinstance(columns, str):
        raise InputError.argument("columns", columns, "a list of output column names (one name: [name])")
    chosen = [str(c) for c in columns]
    for m in models:
        if m.name in _TABLE_MODELS:
            return chosen + [c for c in _WARNING_COLUMNS if c not in chosen]
    return chosen


def _batch_columns(
    raw: dict[str, Any],
    models: Sequence[DynamicModel],
    shared_time: np.ndarray | None,
    files: Mapping[str, str] | None,
    shaped: bool = True,
) -> BatchColumns:
    """The :class:`BatchColumns` of the core's ``transient_batch`` result (reshaped views, no copy).
    Without ``shaped``, a single run keeps the core's flat columns (its rows, offsets ``[0, S]``), for
    :meth:`BatchColumns.runs` (:func:`simulate_batch`), which takes them as they are."""
    offsets, status = raw["offsets"], raw["status"]
    n = len(status)
    if n == 1:
        regular, samples = True, offsets.tolist()[1]  # (offsets[0] is 0)
    else:
        counts = np.diff(offsets)
        regular = n > 0 and bool((counts == counts[0]).all())
        samples = int(counts[0]) if regular else 0
    cols = raw["columns"]
    if regular and (shaped or n > 1):
        cols = {k: v.reshape(n, samples) for k, v in cols.items()}
    if shared_time is not None and not (regular and samples == len(shared_time)):
        shared_time = None
    batch = BatchColumns(models, cols, offsets, shared_time, status, _raw_events(raw))
    for f in raw["failures"]:
        i = int(f["run"])
        batch.errors[i] = _failure(f, batch._model(i), _where(i, n), files)
    return batch


def _raw_events(raw: dict[str, Any]) -> dict[str, np.ndarray]:
    """The event arrays of the core's ``transient_batch`` result, by :attr:`BatchColumns.events` key."""
    return {k: raw[key] for k, key in _EVENT_KEYS}


def _warn_about_runs(batch: BatchColumns) -> None:
    """The warnings about the finished runs (:meth:`DynamicModel.warn_if_fragile_near_coupling` and
    :meth:`DynamicModel.warn_if_extended`): only the table
    models have any about a run's values, so only their runs are looked at."""
    n = len(batch)
    tables = [m for m in batch.models if m.name in _TABLE_MODELS]
    if not tables:
        return
    for m in {id(m): m for m in tables if m.name == "quasi-dynamic"}.values():
        m.warn_if_fragile_near_coupling()
    for i in np.flatnonzero(batch.status == RUN_OK).tolist():
        m = batch._model(i)
        if m.name in _TABLE_MODELS:
            m.warn_if_extended(_warning_rows(batch, i), "the run" + _where(i, n))


def output_times(drive_time_s: Sequence[float] | float, times_s: Sequence[float]) -> tuple[list[float], int]:
    """The output times a run is given for the samples ``times_s`` of a drive with time stamps
    ``drive_time_s``, and how many leading samples to drop.

    A run always starts at the drive's first time stamp (its initial state is the steady state of
    the first input sample), and ``times_s`` only chooses where it is sampled: a first sample after
    the drive's start is reached by integrating from the start, which is then prepended to the
    output times and dropped (returned count 1). ``times_s`` must be finite, increasing and within
    the drive's span, else :class:`InputError` about ``times_s[i]``; a first sample closer to the
    start than the engine's time resolution (1 µs, or 1024 ulp of the time) is refused likewise.
    """
    if _time_stamps(drive_time_s) is None:
        raise InputError.argument("drive_time_s", drive_time_s, _TIME_STAMPS)
    t, skip = _output_times(drive_time_s, times_s)
    _check_times_argument(t[skip:])
    return t.tolist(), skip


def _output_times(
    drive_time_s: Sequence[float] | float, times_s: Sequence[float], every_time: bool = True
) -> tuple[np.ndarray, int]:
    """:func:`output_times` with the times as a float64 array (what the runs pass to the core).
    Without ``every_time``, only the first and the last time are checked against the drive's span: enough
    for times that increase, which the core checks on every run; a caller that passes False looks
    at the whole of ``times_s`` again once the core has refused them (:func:`simulate_batch`; the
    two reductions over the times were 1.7 µs of a 140 µs :func:`simulate`)."""
    try:
        t = _floats_1d(times_s)
    except (TypeError, ValueError):
        raise InputError.argument("times_s", times_s, "output times, s: a list or a 1-D array of numbers") from None
    if t.ndim != 1 or t.size < 1:
        raise InputError.argument("times_s", f"shape {t.shape}", "a one-dimensional sequence of output times")
    span = _time_stamps(drive_time_s)
    if span is None:  # (a drive of constants would run between the output times, its own unread)
        shown = drive_time_s.tolist() if isinstance(drive_time_s, np.ndarray) else drive_time_s
        raise InputError("drive", "time_s", shown, _TIME_STAMPS, core_source="drive")
    start, end = float(span[0]), float(span[-1])
    ends_inside = not every_time and start <= t[0] and t[-1] <= end
    if not ends_inside and not (start <= t.min() and t.max() <= end):  # a time outside the span or NaN
        outside = np.flatnonzero(~np.isfinite(t) | (t < start) | (t > end))
        if outside.size:
            i = int(outside[0])
            raise InputError.argument(
                f"times_s[{i}]", float(t[i]), f"a time within the drive's span, {start:g} to {end:g} s"
            )
    if t[0] == start:
        if t.size == 1:  # (a run needs two output times; a later single time gets the start before it)
            raise InputError.argument("times_s", [start], "two or more output times, or one after the drive's start")
        return t, 0
    resolution = _core.time_resolution_s(start)
    if t[0] - start < (1.0 - 1e-3) * resolution:
        raise InputError.argument(
            "times_s[0]",
            float(t[0]),
            f"the drive's start ({start:g} s) or a time at least {resolution:g} s after it (the time resolution)",
        )
    return np.concatenate(([start], t)), 1


#: What a drive's time stamps are expected to be, before they are checked as the core checks them.
_TIME_STAMPS = "time stamps: a list or a 1-D array of two or more numbers"


def _time_stamps(drive_time_s: Any) -> np.ndarray | None:
    """A drive's time stamps as floats; None unless they are a one-dimensional sequence of two or
    more numbers (the core's first check of a drive's ``time_s``)."""
    try:
        span = np.asarray(drive_time_s, dtype=float)
    except (TypeError, ValueError):
        return None
    return span if span.ndim == 1 and span.size >= 2 else None


def _check_times_argument(t: np.ndarray) -> None:
    """An :class:`InputError` about the argument ``times_s[i]`` unless the output times ``t`` increase
    strictly (:func:`_check_increasing`) and are no closer than the time resolution (the core's rule
    for time stamps, which every run applies to its output times, blaming the drive)."""
    _check_increasing(t)
    try:
        _core.check_time_stamps("times_s", np.ascontiguousarray(t))
    except _core.CoreInputError as e:
        raise from_core(e, ARGUMENT) from None


def _check_increasing(t: np.ndarray) -> None:
    """An :class:`InputError` about the argument ``times_s[i]`` unless ``t`` increases strictly (the
    core checks it on every run and blames the drive's ``time_s[i + 1]``; this names the caller's
    argument once the core has refused)."""
    if t.size > 1 and not (t[1:] > t[:-1]).all():
        i = int(np.flatnonzero(t[1:] <= t[:-1])[0]) + 1
        expected = f"strictly increasing times (times_s[{i - 1}] = {t[i - 1]:g})"
        raise InputError.argument(f"times_s[{i}]", float(t[i]), expected)


def _floats_1d(x: Any) -> np.ndarray:
    """``np.atleast_1d(np.asarray(x, dtype=float))``, without the call's overhead."""
    a = np.asarray(x, dtype=float)
    return a.reshape(1) if a.ndim == 0 else a
