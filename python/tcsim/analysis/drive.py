"""Drive cycles: every converter model in one vehicle follows a speed trace (``tcsim drive``).

The driver, the plant and the energies are the core's (``tcsim._core.drive_runs``,
``crates/tcsim-core/src/vehicle/cycle.rs``; equations in ``docs/drive.md``). This module runs
them and summarises each run: speed tracking, the energies of the cycle and the energy balance.

Summary columns (:data:`SUMMARY_COLUMNS`, one row per model):

* ``rms_speed_error_km_h``, ``max_speed_error_km_h``: trace minus vehicle speed over every output
  sample (every control step), km/h;
* ``engine_work_kj``: the engine's indicated work; ``converter_loss_kj``,
  ``lockup_loss_kj`` (slipping lock-up clutch), ``event_loss_kj`` (kinetic energy removed where a
  clutch closes: lock-up, shifts), ``brake_energy_kj`` (friction brakes);
* ``heat_to_fluid_kj``: converter plus lock-up clutch losses, the heat into the transmission fluid
  over the cycle; ``engine_braking_kj``: the work the engine absorbed, ∫ max(0, −T_e ω_e) dt;
* ``energy_residual``: (engine work − change of stored energy − losses − event losses) / engine work;
* ``lockup_time_fraction``: the share of the cycle's time with the lock-up clutch locked.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .. import _core
from ..errors import InputError, TcsimWarning, core_input_error, from_core
from ..models.dynamic import DynamicModel, select_models, warn_about_runs
from ..models.plausibility import warn_implausible
from ..models.vehicle import Vehicle
from ..simulation.transient import SolverError
from ..units import KM_H

#: The bundled cycles: ``tcsim drive --cycle NAME`` → file in ``tcsim/data/cycles`` (sources in
#: each file's header).
BUNDLED_CYCLES: dict[str, str] = {
    "us06": "us06.csv",
    "udds": "udds.csv",
    "hwfet": "hwfet.csv",
    "wltc-3b": "wltc-3b.csv",
}

#: Columns of ``summary.csv``.
SUMMARY_COLUMNS: tuple[str, ...] = (
    "model",
    "cycle",
    "duration_s",
    "distance_km",
    "rms_speed_error_km_h",
    "max_speed_error_km_h",
    "engine_work_kj",
    "converter_loss_kj",
    "lockup_loss_kj",
    "event_loss_kj",
    "brake_energy_kj",
    "heat_to_fluid_kj",
    "engine_braking_kj",
    "energy_residual",
    "lockup_time_fraction",
)


@dataclass(frozen=True)
class Cycle:
    """A speed trace: ``time_s`` from 0, ``vehicle_speed_m_s`` (m/s), ``grade_percent`` (%, None for a
    level road), its ``name``, ``source`` (the file it came from) and ``start_time_s`` (s, the file's
    first time stamp)."""

    name: str
    source: str
    time_s: np.ndarray
    vehicle_speed_m_s: np.ndarray
    grade_percent: np.ndarray | None = None
    #: The file's first time stamp, s (``time_s`` starts at 0): errors name the file's own times.
    start_time_s: float = 0.0
    #: The file's speed column: ``vehicle_speed_m_s``, or ``vehicle_speed_km_h`` (read ÷ 3.6), which
    #: errors about the speed name with the file's value.
    speed_column: str = "vehicle_speed_m_s"

    def core_spec(self) -> dict[str, Any]:
        """The trace as ``tcsim._core.drive_runs`` takes it."""
        spec: dict[str, Any] = {
            "time_s": np.asarray(self.time_s, float).tolist(),
            "vehicle_speed_m_s": np.asarray(self.vehicle_speed_m_s, float).tolist(),
        }
        if self.grade_percent is not None:
            spec["grade_percent"] = np.asarray(self.grade_percent, float).tolist()
        return spec


@dataclass(frozen=True)
class DriveRun:
    """One model's drive: its time series (columns ``tcsim._core.drive_columns()``, the all-NaN
    columns of coordinates the model lacks left out) and its events ``(time_s, kind, gear)``."""

    frame: pd.DataFrame
    events: list[tuple[Any, ...]] = field(default_factory=list)


@dataclass(frozen=True)
class Drive:
    """A drive cycle run with every model: the vehicle, the cycle, ``{model: run}`` and the summary."""

    vehicle: Vehicle
    cycle: Cycle
    runs: dict[str, DriveRun]
    summary: pd.DataFrame

    def events(self) -> pd.DataFrame:
        """``model, time_s, kind, gear`` of every run."""
        rows = [(name, *e) for name, run in self.runs.items() for e in run.events]
        return pd.DataFrame(rows, columns=["model", "time_s", "kind", "gear"])


def _unpack(run: _core.LaunchRun, name: str, files: dict[str, str]) -> DriveRun | Exception:
    err = run.error
    if err is None:
        df = pd.DataFrame({k: np.asarray(v) for k, v in run.columns.items()})
        keep = df.notna().any() | (df.columns == "time_s")
        return DriveRun(df.loc[:, keep], [(e.time_s, e.kind, e.gear) for e in run.events])
    if err.kind == "input":
        assert err.source is not None and err.field is not None and err.expected is not None
        return core_input_error(err.source, err.field, err.value, err.expected, files)
    return SolverError(f"{name}: {err.message}")


#: A field the core names by a trace sample: ``column[i]`` (0-based).
_SAMPLE_FIELD = re.compile(r"^(\w+)\[(\d+)\]$")


def located(error: InputError, cycle: Cycle) -> InputError:
    """An error the core raised about sample ``i`` of a trace column (field ``column[i]``) in the
    terms of the trace file's other errors: the column, and the value at its 1-based data row with
    the file's time stamp there (``-1 at row 3 (time_s 102)``); any other error unchanged."""
    match = _SAMPLE_FIELD.match(error.field)
    if error.core_source != "scenario" or match is None or int(match[2]) >= len(cycle.time_s):
        return error
    i = int(match[2])
    column, value, expected = match[1], error.value, error.expected
    if column == "vehicle_speed_m_s" and cycle.speed_column != column:  # the file's km/h
        column, expected = cycle.speed_column, f"{expected} (in m/s: the file's km/h ÷ 3.6)"
        value = value * 3.6 if isinstance(value, float) else value
    shown = f"{value:g}" if isinstance(value, float) else value
    where = f"{shown} at row {i + 1} (time_s {cycle.time_s[i] + cycle.start_time_s:g})"
    return InputError(error.source, column, where, expected, core_source=error.core_source)


#: The span a trace's acceleration is taken over, s: a second, as drive cycles are published.
ACCELERATION_SPAN_S = 1.0


def trace_acceleration(time_s: np.ndarray, speed_m_s: np.ndarray) -> np.ndarray:
    """The speed change per second from each sample to the first one at least
    :data:`ACCELERATION_SPAN_S` later, m/s², for every sample that has one (a prefix of the samples:
    value ``i`` is sample ``i``'s); a trace shorter than the span gives its first-to-last change. Over
    the span a measured trace's noise averages out (its last second, over ever shorter spans, would
    not: 0.03 m/s of noise at 100 Hz read as 9 m/s²)."""
    later = np.searchsorted(time_s, time_s[:-1] + ACCELERATION_SPAN_S)
    later = later[later < len(time_s)]
    if later.size == 0:
        later = np.array([len(time_s) - 1])
    start = np.arange(later.size)
    return (speed_m_s[later] - speed_m_s[start]) / (time_s[later] - time_s[start])


def warn_of_acceleration(cycle: Cycle) -> None:
    """Warn of a trace whose speed changes faster than a road vehicle's (``trace_acceleration_m_s2``),
    most often one in km/h under the m/s name, naming the file's column, data row and time stamp;
    the drive runs on (the driver follows what it can, and the speed error says how well)."""
    time_s = np.asarray(cycle.time_s, float)

    # the value is in m/s²: a km/h column says so (as :func:`located` does for its speeds)
    unit = ", in m/s²: the file's km/h ÷ 3.6" if cycle.speed_column != "vehicle_speed_m_s" else ""

    def where(i: int) -> str:
        start = time_s[i] + cycle.start_time_s
        return f"{cycle.speed_column}'s change per second from row {i + 1} (time_s {start:g}{unit})"

    accel = trace_acceleration(time_s, np.asarray(cycle.vehicle_speed_m_s, float))
    warn_implausible("trace_acceleration_m_s2", accel, cycle.source, where)


def run_drive(
    vehicle: Vehicle,
    cycle: Cycle,
    models: Sequence[DynamicModel],
    options: dict[str, Any] | None = None,
    threads: int = 0,
) -> dict[str, DriveRun]:
    """Every model follows ``cycle`` in ``vehicle``, in one core call (GIL released, ``threads``
    workers, 0 for all cores). ``options``: the solver options of a launch (``max_output_bytes``, bytes,
    default 2e9: the estimated size of all runs' outputs is refused above it before anything runs,
    an :class:`~tcsim.errors.InputError` naming the cycle file) and the driver's gains
    ``driver_kp_per_s`` (1/s), ``driver_ki_per_s2`` (1/s²), ``driver_control_step_s`` (s),
    ``driver_hold_brake`` (0–1). The first failed run raises :class:`~tcsim.errors.InputError`
    (naming the cycle file for the trace's values) or :class:`SolverError`."""
    converters = {m.source for m in models}
    files = {"vehicle": vehicle.path, "scenario": cycle.source, "converter": converters.pop()}
    try:
        raw = _core.drive_runs([m.spec for m in models], vehicle.core, cycle.core_spec(), options, threads)
    except _core.CoreInputError as e:
        raise located(from_core(e, files), cycle) from None
    warn_of_acceleration(cycle)  # the trace passed the core's checks
    finished: list[tuple[DynamicModel, DriveRun]] = []
    for model, run in zip(models, raw):
        result = _unpack(run, model.name, files)
        if not isinstance(result, DriveRun):
            raise result
        finished.append((model, result))
    warn_about_runs("drive", [(m.name, m, {str(k): v for k, v in r.frame.items()}) for m, r in finished])
    return {m.name: r for m, r in finished}


def _trapezoid(y: np.ndarray, t: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def summary_row(name: str, cycle: Cycle, f: pd.DataFrame) -> dict[str, Any]:
    """The :data:`SUMMARY_COLUMNS` of one run's frame ``f``."""
    t = f.time_s.to_numpy()
    err = f.speed_error_m_s.to_numpy() / KM_H
    last = f.iloc[-1]
    engine = float(last.engine_work_j)
    stored = float(last.vehicle_stored_energy_j - f.vehicle_stored_energy_j.iloc[0])
    residual = engine - stored - float(last.vehicle_loss_j) - float(last.booked_event_loss_j)
    absorbed = np.maximum(0.0, -f.engine_torque_nm.to_numpy() * f.pump_speed_rad_s.to_numpy())
    locked = (f.lockup_state.to_numpy() == 2).astype(float)
    return {
        "model": name,
        "cycle": cycle.name,
        "duration_s": float(t[-1] - t[0]),
        "distance_km": _trapezoid(f.vehicle_speed_m_s.to_numpy(), t) / 1000.0,
        "rms_speed_error_km_h": float(np.sqrt(np.mean(err**2))),
        "max_speed_error_km_h": float(np.max(np.abs(err))),
        "engine_work_kj": engine / 1000.0,
        "converter_loss_kj": float(last.converter_loss_j) / 1000.0,
        "lockup_loss_kj": float(last.lockup_loss_j) / 1000.0,
        "event_loss_kj": float(last.booked_event_loss_j) / 1000.0,
        "brake_energy_kj": float(last.brake_energy_j) / 1000.0,
        "heat_to_fluid_kj": float(last.converter_loss_j + last.lockup_loss_j) / 1000.0,
        "engine_braking_kj": _trapezoid(absorbed, t) / 1000.0,
        "energy_residual": residual / engine if engine > 0 else float("nan"),
        "lockup_time_fraction": _trapezoid(locked, t) / max(float(t[-1] - t[0]), 1e-12),
    }


def summarise(cycle: Cycle, runs: dict[str, DriveRun]) -> pd.DataFrame:
    """One row of :data:`SUMMARY_COLUMNS` per run; a :class:`~tcsim.errors.TcsimWarning` per model
    whose RMS speed error exceeds 2 km/h (the driver could not follow the trace: check the vehicle)."""
    rows = [summary_row(name, cycle, run.frame) for name, run in runs.items()]
    for r in rows:
        if r["rms_speed_error_km_h"] > 2.0:
            warnings.warn(
                f"{r['model']}: RMS speed error {r['rms_speed_error_km_h']:.2f} km/h over {cycle.name}: "
                "the vehicle does not follow the trace",
                TcsimWarning,
                stacklevel=2,
            )
    return pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))


def drive(
    vehicle: Vehicle,
    cycle: Cycle,
    requested: Sequence[str] = (),
    options: dict[str, Any] | None = None,
    threads: int = 0,
) -> Drive:
    """Every requested model (default: all of the vehicle's converter) follows ``cycle``."""
    models = select_models(vehicle.converter, requested)
    runs = run_drive(vehicle, cycle, models, options, threads)
    return Drive(vehicle, cycle, runs, summarise(cycle, runs))
