"""Transient simulation of an isolated converter: models, drives, one-line and batch runs.

The engine is the Rust core's (:mod:`tcsim._core`): diffsol's BDF solver on the models in
mass-matrix form, with root finding for the stator one-way clutch and for flow reversal.
See ``docs/transient.md`` for the equations, events and conventions.

API tiers (after FMPy):

* one line: :func:`simulate` (a converter, a model name and a drive → :class:`TransientResult`);
* reusable objects: :func:`dynamic_model` → :class:`DynamicModel` (with
  :meth:`DynamicModel.with_shape_effects` for sweeps), drives :class:`PumpTorqueTurbineSpeed`,
  :class:`Speeds`, :class:`PumpTorqueLoad`;
* batch: :func:`simulate_batch`, N models × one drive, one model × N drives, or N pairs, with the
  GIL released and one worker per core;
* raw: ``tcsim._core.transient_runs`` with the dicts of :meth:`DynamicModel.spec` and ``Drive.spec``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .. import _core
from ..errors import InputError, core_input_error, from_core
from ..models.converter import Converter
from ..models.drives import Drive
from ..models.dynamic import DynamicModel, dynamic_model

COLUMNS: tuple[str, ...] = tuple(_core.transient_columns())


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

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def frame(self) -> pd.DataFrame:
        """The columns as a DataFrame, without the all-NaN columns of coordinates the model lacks."""
        df = pd.DataFrame(self.columns)
        return df.loc[:, df.notna().any() | (df.columns == "time_s")]


def _options(rtol: float | None, **extra) -> dict[str, Any]:
    o = dict(extra)
    if rtol is not None:
        o["rtol"] = rtol
    return o


#: Columns that may hold ±inf or NaN by definition: the K-factor is infinite where the capacity is
#: zero and undefined (NaN) where it is negative (overrun rows of a table, ``conventions.md``).
INFINITE_ALLOWED: frozenset[str] = frozenset({"k_factor_rpm_per_sqrt_nm"})
#: Unit suffixes of physical quantities (speeds, torques, flows, powers, energies): a run that has
#: such a quantity never leaves it NaN at some samples; ratios, times not reached and metrics may be
#: NaN where undefined.
NAN_NOT_EXPECTED: tuple[str, ...] = ("_rad_s", "_nm", "_m3_s", "_w", "_j")


def _overflow(columns: Mapping[str, np.ndarray]) -> tuple[str, float, float] | None:
    """The first column of a run that overflowed (±inf, or NaN in a physical quantity the run has at
    other samples): its name, the value and the time, s."""
    time = np.asarray(columns.get("time_s", []), dtype=float)
    for name, values in columns.items():
        v = np.asarray(values, dtype=float)
        bad = np.isinf(v) if name not in INFINITE_ALLOWED else np.zeros(v.shape, dtype=bool)
        if name.endswith(NAN_NOT_EXPECTED) and not np.isnan(v).all():
            bad |= np.isnan(v)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            return name, float(v[i]), float(time[i]) if i < len(time) else float("nan")
    return None


def _unpack(
    run: _core.TransientRun, model: DynamicModel, index: int | None, files: Mapping[str, str] | None = None
) -> TransientResult:
    """The one reading of the core's result of a transient run (raises its error, shown against
    ``files[source]`` for the input the core blamed, the model's converter file by default)."""
    where = "" if index is None else f" (run {index})"
    err = run.error
    if err is None:
        events = [Event(e.time_s, e.kind, e.stator_locked, e.flow_direction) for e in run.events]
        overflow = _overflow(run.columns)
        if overflow is not None:  # never a non-finite result without saying so: the drive is beyond the model
            name, value, t = overflow
            raise InputError(
                (files or {}).get("drive") or "drive",
                f"output {name}{where}",
                value,
                f"a drive whose run stays finite (it overflows at t = {t:.6g} s: check the drive's values and units)",
                core_source="drive",
            )
        model.warn_about_run(run.columns, "the run" + where)
        return TransientResult(model.name, dict(run.columns), events)
    if err.kind == "input":
        assert err.source is not None and err.field is not None and err.expected is not None
        sources = {"converter": model.source, **(files or {})}
        raise core_input_error(err.source, err.field + where, err.value, err.expected, sources)
    raise SolverError(f"{model.name}{where}: {err.message}")


def _initial(initial: dict[str, float] | None) -> dict[str, float] | None:
    allowed = {"pump_speed_rad_s", "turbine_speed_rad_s", "stator_speed_rad_s", "flow_m3_s"}
    if initial:
        bad = set(initial) - allowed
        if bad:
            raise InputError(
                "initial state", sorted(bad)[0], initial[sorted(bad)[0]], f"one of {', '.join(sorted(allowed))}"
            )
    return initial


def simulate(
    converter: Converter | str | DynamicModel,
    drive: Drive,
    model: str = "hrovat-tobler",
    times_s: Sequence[float] | None = None,
    initial: dict[str, float] | None = None,
    rtol: float | None = None,
    files: Mapping[str, str] | None = None,
    **solver_options,
) -> TransientResult:
    """Run one model under one drive; samples at ``times_s`` (default: the drive's time stamps).

    The run always integrates from the drive's first time stamp; ``times_s`` (s, increasing, within
    the drive's span) only chooses the samples, so a later first sample gives the same values as a
    full run at the same times (:func:`output_times`). Events before the first sample are kept.

    The initial state is the steady state consistent with the first input sample (drive c: with
    the turbine at rest) unless ``initial`` gives ``pump_speed_rad_s``, ``turbine_speed_rad_s``,
    ``stator_speed_rad_s`` or ``flow_m3_s``. ``files`` names the file of an input the core may
    blame in an :class:`InputError` (``{"drive": "log.csv"}``; see :func:`simulate_batch`).
    """
    m = converter if isinstance(converter, DynamicModel) else dynamic_model(converter, model)
    return simulate_batch([m], [drive], times_s, initial, rtol, threads=1, files=files, **solver_options)[0]


def simulate_batch(
    models: Sequence[DynamicModel],
    drives: Sequence[Drive],
    times_s: Sequence[float] | None = None,
    initial: dict[str, float] | None = None,
    rtol: float | None = None,
    threads: int = 0,
    files: Mapping[str, str] | None = None,
    **solver_options,
) -> list[TransientResult]:
    """Run ``models[i]`` under ``drives[i]``; a sequence of length one is broadcast. The runs go to
    the core in one call, which releases the GIL and uses ``threads`` workers (0: all cores).
    Raises :class:`InputError` or :class:`SolverError` for the first run that fails.

    An :class:`InputError` names the input the core blamed (``core_source``: ``converter``,
    ``drive``, ``initial``, ``options``), shown as ``files[source]`` when given, else as the models'
    converter file or the input's name. ``solver_options`` are the core's: ``rtol``,
    ``speed_atol_rad_s``, ``flow_atol_m3_s``, ``first_step_s``, ``max_events`` and
    ``max_output_bytes`` (default 2e9: the estimated size of all runs' outputs is refused above it
    before anything runs)."""
    specs, skip = [], []
    for d in drives:
        s = d.spec()
        skip.append(0)
        if times_s is not None:
            s["output_time_s"], skip[-1] = output_times(s["time_s"], times_s)
        specs.append(s)
    try:
        raw = _core.transient_runs(
            [m.spec for m in models], specs, _initial(initial), _options(rtol, **solver_options), threads
        )
    except _core.CoreInputError as e:
        converters = {m.source for m in models}
        sources = {"converter": converters.pop() if len(converters) == 1 else "model", **(files or {})}
        raise from_core(e, sources) from None
    n = len(raw)
    failed = next((i for i, r in enumerate(raw) if r.error is not None), None)
    if failed is not None:  # raised before any run's warning: a failure is one line
        _unpack(raw[failed], models[failed if len(models) > 1 else 0], failed if n > 1 else None, files)
    results = [_unpack(r, models[i if len(models) > 1 else 0], i if n > 1 else None, files) for i, r in enumerate(raw)]
    return [_drop_first(r, skip[i if len(skip) > 1 else 0]) for i, r in enumerate(results)]


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
    t = np.atleast_1d(np.asarray(times_s, dtype=float))
    span = np.atleast_1d(np.asarray(drive_time_s, dtype=float))
    start, end = float(span[0]), float(span[-1])
    if t.ndim != 1 or t.size < 1:
        raise InputError("simulate", "times_s", f"shape {t.shape}", "a one-dimensional sequence of output times")
    outside = np.flatnonzero(~np.isfinite(t) | (t < start) | (t > end))
    if outside.size:
        i = int(outside[0])
        raise InputError(
            "simulate", f"times_s[{i}]", float(t[i]), f"a time within the drive's span, {start:g} to {end:g} s"
        )
    if t[0] == start:
        return t.tolist(), 0
    resolution = _core.time_resolution_s(start)
    if t[0] - start < (1.0 - 1e-3) * resolution:
        raise InputError(
            "simulate",
            "times_s[0]",
            float(t[0]),
            f"the drive's start ({start:g} s) or a time at least {resolution:g} s after it (the time resolution)",
        )
    return [start, *t.tolist()], 1


def _drop_first(result: TransientResult, n: int) -> TransientResult:
    """``result`` without its first ``n`` samples (the drive's start, prepended by :func:`output_times`)."""
    if n == 0:
        return result
    return TransientResult(result.model, {k: np.asarray(v)[n:] for k, v in result.columns.items()}, result.events)
