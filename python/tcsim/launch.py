"""``tcsim launch``: whole-vehicle take-off with every converter model on the same vehicle.

The thesis's central comparison (Li & Sundén 2016, §3.2.2, §3.5.2.2, §4.1): a vehicle held on
the brake in first gear, then brake off and pedal on; the steady-state (table) model against the
dynamic models, whose effective torque ratio dips in the first tenths of a second.

::

    tcsim launch [VEHICLE] [--out DIR] [--scenario flip-flop|part-pedal|FILE] [--model M ...]
                 [--sweep-shape-effects]

Scenarios
---------
A :class:`Scenario` is accelerator and brake pedal positions (0–1, linearly interpolated) against
time, an end time, an optional stop speed (the run ends when the vehicle reaches it) and the brake
release time from which the summary's times are measured.

* :func:`flip_flop` (``--scenario flip-flop``, the default; thesis §3.2.2 and §3.5.1): first
  gear, brake 1 and pedal 0 for ``hold_s`` = 5 s, then within 0.05 s brake 0 and pedal 1; to
  100 km/h or 30 s.
* :func:`part_pedal` (``--scenario part-pedal``): the same with pedal 0.3; to 50 km/h or 40 s.
* :func:`read_scenario` (``--scenario FILE``): a CSV, Parquet, ``.mat`` or MDF4 file with
  ``time_s`` (or ``time_ms``), ``accelerator_pedal`` and ``brake_pedal`` (0–1; or
  ``accelerator_pedal_percent``/``brake_pedal_percent``, 0–100). Runs to the last time stamp.
  The brake release time is where the brake pedal's last fall to zero begins. The file's times
  are shifted so that its first sample is time 0.

Time 0 is the start of the scenario: the vehicle at rest (held by the brake if it is applied).

Runs
----
:func:`run_launch` is the only call into the core (``tcsim._core.launch_runs``): all models in
one call, the GIL released, one worker per core. Each run gives a time series with at least
:data:`LAUNCH_COLUMNS` and events (gear shifts, lock-up, converter events) as
``(time_s, kind, ...)``.

Outputs (in DIR, default ``launch``; written all at once, nothing on error)
---------------------------------------------------------------------------
* ``summary.csv``: one row per model, :data:`SUMMARY_COLUMNS`. Times are measured from the brake
  release; "first 0.5 s" is the 0.5 s after it; NaN where a speed is not reached.
* ``<model>.csv``: each model's time series; ``timeseries.csv``: all of them with a ``model`` column.
* ``events.csv``: ``model, time_s, kind, detail``; ``scenario.csv``: the pedal inputs.
* Plots like thesis figures 3.5, 3.6 and 3.20 (:mod:`tcsim.launch_plots`).
* With ``--sweep-shape-effects``: ``shape_sweep.csv``, ``shape_sweep_summary.csv`` and, per dynamic
  model, plots like figures 4.3–4.6: S_p = S_t over the thesis's values (quasi-dynamic, with the
  thesis's pair S_p = 0.4, S_t = 0.3) or over admissible values (Hrovat & Tobler,
  :func:`tcsim.shape_fit.sweep_values`), all runs in one batched core call, each to
  :data:`SWEEP_SPAN_S` after the brake release. A sweep run that fails is left out with a warning.

Errors: a bad vehicle file, scenario file or option is an :class:`~tcsim.errors.InputError`
(exit 2, nothing written); a solver failure is a :class:`~tcsim.transient.SolverError` (exit 1).
"""

from __future__ import annotations

import contextlib
import math
import time
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from . import _core
from .errors import InputError, TcsimWarning, core_value
from .transient import DynamicModel, SolverError
from .vehicle import SECTIONS, Vehicle, load_vehicle

KM_H = 1.0 / 3.6
SPEED_50_KM_H_M_S = 50.0 * KM_H
SPEED_100_KM_H_M_S = 100.0 * KM_H
#: Width of the window after the brake release of the "first 0.5 s" metrics, s.
FIRST_WINDOW_S = 0.5
#: Time the flip-flop takes to swap the pedals, s.
PEDAL_SWAP_S = 0.05
#: The shape-effect sweep runs to this long after the brake release (figures 4.3–4.6 show the first
#: 1.5 s; the later shifts and lock-up add nothing to them), s.
SWEEP_SPAN_S = 2.0
#: Brake pedal position at or below which the brake counts as released (scenario files).
BRAKE_RELEASED = 1e-3

#: Columns every launch run has (more may follow).
LAUNCH_COLUMNS: tuple[str, ...] = (
    "time_s",
    "vehicle_speed_m_s",
    "vehicle_accel_m_s2",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "speed_ratio",
    "torque_ratio",
    "effective_torque_ratio",
    "gear",
    "lockup_state",
    "engine_torque_nm",
    "pump_torque_nm",
    "turbine_torque_nm",
)
SUMMARY_COLUMNS: tuple[str, ...] = (
    "model",
    "time_0_100_km_h_s",
    "time_0_50_km_h_s",
    "peak_accel_m_s2",
    "mean_accel_first_0_5_s_m_s2",
    "min_effective_torque_ratio_first_0_5_s",
)
EVENT_COLUMNS: tuple[str, ...] = ("model", "time_s", "kind", "detail")
SCENARIOS: tuple[str, ...] = ("flip-flop", "part-pedal")
DYNAMIC_MODELS: tuple[str, ...] = ("hrovat-tobler", "quasi-dynamic")
_SCENARIO_KEYS = ("time_s", "accelerator_pedal", "brake_pedal", "end_time_s", "stop_speed_m_s")


# ---------------------------------------------------------------------------------------------
# scenarios


@dataclass(frozen=True, eq=False)
class Scenario:
    """Pedal and brake against time (linear interpolation), validated on construction.

    ``source`` names the scenario in messages (a file, or ``scenario <name>``)."""

    name: str
    time_s: np.ndarray
    accelerator_pedal: np.ndarray
    brake_pedal: np.ndarray
    end_time_s: float
    stop_speed_m_s: float | None = None
    brake_release_time_s: float = 0.0
    source: str = ""
    #: A logged engine (crank) torque replayed instead of the engine model (thesis §3.5.2.2), N·m,
    #: one value per time stamp; the pedal then drives only the shift and lock-up schedules.
    engine_torque_nm: np.ndarray | None = None

    def __post_init__(self) -> None:
        src = self.source or f"scenario {self.name}"
        object.__setattr__(self, "source", src)
        arrays = {}
        for key in ("time_s", "accelerator_pedal", "brake_pedal"):
            a = np.array(getattr(self, key), dtype=float, ndmin=1)
            if a.ndim != 1:
                raise InputError(src, key, f"shape {a.shape}", "a one-dimensional array")
            bad = np.flatnonzero(~np.isfinite(a))
            if bad.size:
                raise InputError(src, f"{key}[{bad[0]}]", float(a[bad[0]]), "a finite number")
            arrays[key] = a
            object.__setattr__(self, key, a)
        t = arrays["time_s"]
        if len(t) < 2:
            raise InputError(src, "time_s", f"{len(t)} points", "at least 2 points")
        if t[0] != 0.0:
            raise InputError(src, "time_s[0]", float(t[0]), "0: a scenario starts at time 0 (the braked standstill)")
        for key in ("accelerator_pedal", "brake_pedal"):
            if len(arrays[key]) != len(t):
                raise InputError(src, key, f"{len(arrays[key])} values", f"one per time_s ({len(t)})")
            a = arrays[key]
            bad = np.flatnonzero((a < 0) | (a > 1))
            if bad.size:
                raise InputError(src, f"{key}[{bad[0]}]", float(a[bad[0]]), "a pedal position from 0 to 1")
        steps = np.flatnonzero(np.diff(t) <= 0)
        if steps.size:
            i = int(steps[0]) + 1
            raise InputError(src, f"time_s[{i}]", float(t[i]), f"time strictly increasing (previous {t[i - 1]:g} s)")
        if not (math.isfinite(self.end_time_s) and self.end_time_s > t[0]):
            raise InputError(
                src, "end_time_s", self.end_time_s, f"a finite time after the first time stamp ({t[0]:g} s)"
            )
        if self.stop_speed_m_s is not None and not (math.isfinite(self.stop_speed_m_s) and self.stop_speed_m_s > 0):
            raise InputError(src, "stop_speed_m_s", self.stop_speed_m_s, "a positive speed or none")
        if not (math.isfinite(self.brake_release_time_s) and t[0] <= self.brake_release_time_s <= self.end_time_s):
            raise InputError(
                src,
                "brake_release_time_s",
                self.brake_release_time_s,
                f"a time within the scenario [{t[0]:g}, {self.end_time_s:g}] s",
            )
        object.__setattr__(self, "end_time_s", float(self.end_time_s))
        object.__setattr__(self, "brake_release_time_s", float(self.brake_release_time_s))
        if self.stop_speed_m_s is not None:
            object.__setattr__(self, "stop_speed_m_s", float(self.stop_speed_m_s))
        if self.engine_torque_nm is not None:
            e = np.array(self.engine_torque_nm, dtype=float, ndmin=1)
            if e.shape != t.shape:
                raise InputError(src, "engine_torque_nm", f"{e.size} values", f"one per time_s ({len(t)})")
            bad = np.flatnonzero(~np.isfinite(e) | (np.abs(e) > 20_000))
            if bad.size:
                raise InputError(src, f"engine_torque_nm[{bad[0]}]", float(e[bad[0]]), "a finite crank torque in N·m")
            object.__setattr__(self, "engine_torque_nm", e)

    def pedals_at(self, time_s) -> tuple[np.ndarray, np.ndarray]:
        """Accelerator and brake pedal at ``time_s`` (linear interpolation, end values held)."""
        t = np.asarray(time_s, dtype=float)
        return np.interp(t, self.time_s, self.accelerator_pedal), np.interp(t, self.time_s, self.brake_pedal)

    def core_spec(self) -> dict[str, Any]:
        """The dict the core takes."""
        spec = {
            "time_s": self.time_s.tolist(),
            "accelerator_pedal": self.accelerator_pedal.tolist(),
            "brake_pedal": self.brake_pedal.tolist(),
            "end_time_s": self.end_time_s,
            "stop_speed_m_s": self.stop_speed_m_s,
        }
        if self.engine_torque_nm is not None:
            spec["engine_torque_nm"] = self.engine_torque_nm.tolist()
        return spec

    def frame(self) -> pd.DataFrame:
        return pd.DataFrame(
            {"time_s": self.time_s, "accelerator_pedal": self.accelerator_pedal, "brake_pedal": self.brake_pedal}
        )


def _release(name: str, pedal: float, hold_s: float, end_time_s: float, stop_speed_m_s: float) -> Scenario:
    src = f"scenario {name}"
    if not (math.isfinite(pedal) and 0 < pedal <= 1):
        raise InputError(src, "pedal", pedal, "an accelerator pedal position in (0, 1]")
    if not (math.isfinite(hold_s) and hold_s > 0):
        raise InputError(src, "hold_s", hold_s, "a positive time on the brake, s")
    if not (math.isfinite(end_time_s) and end_time_s > hold_s + PEDAL_SWAP_S):
        raise InputError(src, "end_time_s", end_time_s, f"a time after the pedal swap ({hold_s + PEDAL_SWAP_S:g} s)")
    t = [0.0, hold_s, hold_s + PEDAL_SWAP_S, end_time_s]
    return Scenario(
        name,
        np.array(t),
        np.array([0.0, 0.0, pedal, pedal]),
        np.array([1.0, 1.0, 0.0, 0.0]),
        end_time_s,
        stop_speed_m_s,
        hold_s,
        src,
    )


def flip_flop(hold_s: float = 5.0, end_time_s: float = 30.0) -> Scenario:
    """The thesis's flip-flop launch (§3.2.2, §3.5.1): first gear, brake 1 and pedal 0 from 0 to
    ``hold_s``, then within 0.05 s brake 0 and pedal 1; run to 100 km/h or ``end_time_s``."""
    return _release("flip-flop", 1.0, hold_s, end_time_s, SPEED_100_KM_H_M_S)


def part_pedal(pedal: float = 0.3, hold_s: float = 5.0, end_time_s: float = 40.0) -> Scenario:
    """A part-pedal launch: as :func:`flip_flop` with accelerator ``pedal``; run to 50 km/h or
    ``end_time_s``."""
    return _release("part-pedal", pedal, hold_s, end_time_s, SPEED_50_KM_H_M_S)


def brake_release_time(time_s, brake_pedal, released: float = BRAKE_RELEASED) -> float:
    """Where the brake pedal's last fall to (at most) ``released`` begins, before it first gets
    there after having been applied: the first time stamp if the brake is never applied, the last
    one if it is never released."""
    t = np.asarray(time_s, dtype=float)
    b = np.asarray(brake_pedal, dtype=float)
    applied = b > released
    if not applied.any():
        return float(t[0])
    first_applied = int(np.argmax(applied))
    off = np.flatnonzero(~applied[first_applied:])
    if not off.size:
        return float(t[-1])
    j = first_applied + int(off[0])
    while j > 0 and b[j - 1] > b[j]:
        j -= 1
    return float(t[j])


# --------------------------------------------------------------------------------------------
# scenario files

_PEDALS = ("accelerator_pedal", "brake_pedal")
_TIME_COLUMNS = {"time_s": 1.0, "time_ms": 1e-3}


def _pedal_columns(name: str) -> dict[str, float]:
    return {name: 1.0, f"{name}_percent": 0.01}


def _unit_scale(path: Path, column: str, unit: str, is_time: bool) -> float | None:
    """Factor to SI from a file's unit metadata (MDF4); None when there is no unit."""
    u = unit.strip().lower()
    if not u or u in ("-", "1"):
        return None
    table = {"s": 1.0, "ms": 1e-3} if is_time else {"%": 0.01, "percent": 0.01}
    if u not in table:
        accepted = ", ".join(table) + ("" if is_time else ", or none (0..1)")
        raise InputError(str(path), f"{column} (unit)", unit, f"one of {accepted}")
    return table[u]


class _ScenarioPicker:
    """Picks the time and the two pedal columns from a file's column names (see measurement.py)."""

    def __init__(self, path: Path):
        self.path = path
        self.picks: dict[str, tuple[str, float]] = {}

    def _one(self, canonical: str, options: Mapping[str, float], names: Sequence[str]) -> None:
        for column, factor in options.items():
            if column in names:
                self.picks[canonical] = (column, factor)
                return
        shown = ", ".join(list(names)[:12]) + (" ..." if len(names) > 12 else "")
        raise InputError(
            str(self.path),
            canonical,
            "missing",
            f"a column named {' or '.join(options)}; columns found: {shown or '(none)'}",
        )

    def __call__(self, names: Sequence[str]) -> list[str]:
        self._one("time_s", _TIME_COLUMNS, names)
        for pedal in _PEDALS:
            self._one(pedal, _pedal_columns(pedal), names)
        if "engine_torque_nm" in names:  # optional: a logged engine torque to replay
            self.picks["engine_torque_nm"] = ("engine_torque_nm", 1.0)
        return list(dict.fromkeys(c for c, _ in self.picks.values()))


def read_scenario(path, stop_speed_m_s: float | None = None, end_time_s: float | None = None) -> Scenario:
    """A user scenario from a CSV, Parquet, ``.mat`` or MDF4 file (the formats of
    :func:`tcsim.measurement.read_measurement`): ``time_s`` (or ``time_ms``), ``accelerator_pedal``
    and ``brake_pedal`` from 0 to 1 (or ``*_percent`` from 0 to 100; MDF4 ``%`` units are read),
    and optionally ``engine_torque_nm``, a logged crank torque replayed instead of the engine model.

    Time strictly increasing, no NaN, pedals within range; each problem an InputError naming the
    file, the column, the row and the value. Runs to ``end_time_s`` (default the last time stamp)
    or ``stop_speed_m_s``; the brake release time is :func:`brake_release_time`. Times are
    shifted so that the first sample is time 0 (runs start at time 0, braked and at rest)."""
    from . import measurement as meas

    path = Path(path)
    reader = meas._READERS.get(path.suffix.lower())
    if reader is None:
        raise InputError(
            str(path),
            "(extension)",
            path.suffix or "(none)",
            f"a scenario file ending in one of {', '.join(meas._READERS)}",
        )
    if not path.is_file():
        raise InputError(str(path), "(file)", "not found", "an existing scenario file")
    picker = _ScenarioPicker(path)
    raw, units = reader(path, picker)
    time_column, time_factor = picker.picks["time_s"]
    n = len(raw[time_column])
    if n < 2:
        raise InputError(str(path), time_column, f"{n} rows", "at least 2 data rows")
    out: dict[str, np.ndarray] = {}
    time_s = None
    for canonical in ("time_s", *_PEDALS, *(["engine_torque_nm"] if "engine_torque_nm" in picker.picks else [])):
        column, factor = picker.picks[canonical]
        values = np.asarray(raw[column])
        if len(values) != n:
            raise InputError(str(path), column, f"{len(values)} samples", f"as many as {time_column} ({n})")
        values = meas._numeric(path, column, values, time_s)
        meas._finite(path, column, values, time_s)
        if canonical == "time_s":
            meas._increasing(path, column, values)
        unit_factor = _unit_scale(path, column, units.get(column, ""), canonical == "time_s")
        scale = unit_factor if unit_factor is not None else factor
        if canonical == "engine_torque_nm":
            out[canonical] = values
            continue
        if canonical != "time_s":
            limit = 1.0 / scale
            bad = np.flatnonzero((values < 0) | (values > limit * (1 + 1e-12)))
            if bad.size:
                row = int(bad[0])
                raise InputError(
                    str(path),
                    column,
                    f"{values[row]:g} at row {row + 1} (time_s {time_s[row]:g})",
                    f"a pedal position from 0 to {limit:g}",
                )
        values = np.clip(values * scale, 0.0, 1.0) if canonical != "time_s" else values * scale
        out[canonical] = values
        if canonical == "time_s":
            time_s = values
    t = out["time_s"] - out["time_s"][0]
    end = float(t[-1]) if end_time_s is None else end_time_s
    release = brake_release_time(t, out["brake_pedal"])
    return Scenario(
        path.stem,
        t,
        out["accelerator_pedal"],
        out["brake_pedal"],
        end,
        stop_speed_m_s,
        min(release, end),
        str(path),
        out.get("engine_torque_nm"),
    )


def scenario_from_option(value: str) -> Scenario:
    """``--scenario``: ``flip-flop``, ``part-pedal`` or a scenario file."""
    if value == "flip-flop":
        return flip_flop()
    if value == "part-pedal":
        return part_pedal()
    if not Path(value).is_file():
        raise InputError(
            "command line",
            "--scenario",
            value,
            "flip-flop, part-pedal, or an existing scenario file (.csv, .parquet, .mat, .mf4/.mdf)",
        )
    return read_scenario(value)


# ---------------------------------------------------------------------------------------------
# summary metrics (pure)


def _arrays(time_s, values) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(time_s, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.shape != v.shape or t.ndim != 1:
        raise ValueError(f"time and values need the same one-dimensional shape ({t.shape}, {v.shape})")
    return t, v


def time_to_speed(time_s, speed_m_s, target_m_s: float, start_s: float = 0.0) -> float:
    """Time from ``start_s`` until the speed first reaches ``target_m_s`` at or after ``start_s``
    (linear interpolation between samples); NaN if it never does."""
    t, v = _arrays(time_s, speed_m_s)
    idx = np.flatnonzero((t >= start_s) & (v >= target_m_s))
    if not idx.size:
        return math.nan
    k = int(idx[0])
    if k == 0:
        return float(t[0] - start_s)
    v0, v1, t0, t1 = v[k - 1], v[k], t[k - 1], t[k]
    if v0 >= target_m_s:  # already there before start_s (else sample k - 1 would be the first)
        return 0.0
    crossing = t0 + (target_m_s - v0) / (v1 - v0) * (t1 - t0)
    return float(max(crossing, start_s) - start_s)


def peak_value(time_s, values, start_s: float = -math.inf) -> float:
    """Largest value at or after ``start_s`` (NaN samples ignored); NaN if there is none."""
    t, v = _arrays(time_s, values)
    w = v[(t >= start_s) & np.isfinite(v)]
    return float(w.max()) if w.size else math.nan


def _window(t: np.ndarray, v: np.ndarray, start_s: float, width_s: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Samples within [start, start + width] with values interpolated at both edges; None if the
    series does not cover the window."""
    end = start_s + width_s
    tol = 1e-9 * max(1.0, abs(end))
    if len(t) == 0 or t[0] > start_s + tol or t[-1] < end - tol:
        return None
    inside = (t > start_s) & (t < end)
    tw = np.concatenate([[start_s], t[inside], [end]])
    vw = np.concatenate([[np.interp(start_s, t, v)], v[inside], [np.interp(end, t, v)]])
    return tw, vw


def window_mean(time_s, values, start_s: float, width_s: float = FIRST_WINDOW_S) -> float:
    """Time average (trapezoidal) over [start_s, start_s + width_s]; NaN if not covered."""
    t, v = _arrays(time_s, values)
    w = _window(t, v, start_s, width_s)
    if w is None or width_s <= 0:
        return math.nan
    tw, vw = w
    return float(np.sum(0.5 * (vw[1:] + vw[:-1]) * np.diff(tw)) / width_s)


def window_min(time_s, values, start_s: float, width_s: float = FIRST_WINDOW_S) -> float:
    """Smallest value over [start_s, start_s + width_s] (samples and the interpolated edges, NaN
    samples ignored); NaN if not covered."""
    t, v = _arrays(time_s, values)
    w = _window(t, v, start_s, width_s)
    if w is None:
        return math.nan
    finite = w[1][np.isfinite(w[1])]
    return float(finite.min()) if finite.size else math.nan


def summary_row(frame: pd.DataFrame, release_s: float) -> dict[str, float]:
    """The summary metrics of one run (see :data:`SUMMARY_COLUMNS`), times from ``release_s``."""
    t = frame["time_s"].to_numpy(dtype=float)
    v = frame["vehicle_speed_m_s"].to_numpy(dtype=float)
    a = frame["vehicle_accel_m_s2"].to_numpy(dtype=float)
    etr = frame["effective_torque_ratio"].to_numpy(dtype=float)
    return {
        "time_0_100_km_h_s": time_to_speed(t, v, SPEED_100_KM_H_M_S, release_s),
        "time_0_50_km_h_s": time_to_speed(t, v, SPEED_50_KM_H_M_S, release_s),
        "peak_accel_m_s2": peak_value(t, a, release_s),
        "mean_accel_first_0_5_s_m_s2": window_mean(t, a, release_s, FIRST_WINDOW_S),
        "min_effective_torque_ratio_first_0_5_s": window_min(t, etr, release_s, FIRST_WINDOW_S),
    }


def launch_summary(frames: Mapping[str, pd.DataFrame], release_s: float) -> pd.DataFrame:
    """One row per run: ``model`` and the metrics of :func:`summary_row`."""
    rows = [{"model": name, **summary_row(f, release_s)} for name, f in frames.items()]
    return pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))


def events_table(frames: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """All runs' events: ``model, time_s, kind, detail`` (the event's further fields as text)."""
    rows = []
    for name, f in frames.items():
        for e in f.attrs.get("events", []):
            rest = " ".join(str(x) for x in e[2:])
            rows.append({"model": name, "time_s": float(e[0]), "kind": str(e[1]), "detail": rest})
    return pd.DataFrame(rows, columns=list(EVENT_COLUMNS))


# ---------------------------------------------------------------------------------------------
# the core call


def core_has_vehicle() -> bool:
    """Whether this build of the core has the vehicle plant (``_core.launch_runs``)."""
    return hasattr(_core, "launch_runs")


def _source_of(fld: str, vehicle: Vehicle, scenario: Scenario, model: DynamicModel | None) -> str:
    head = fld.lstrip("[").split("]")[0].split(".")[0].split("[")[0]
    if head in SECTIONS or head == "vehicle":
        return vehicle.path
    if head in ("scenario", *_SCENARIO_KEYS):
        return scenario.source
    return model.source if model is not None else "model"


def _frame(columns: Mapping[str, Any], events: Sequence[Sequence[Any]]) -> pd.DataFrame:
    df = pd.DataFrame({k: np.asarray(v) for k, v in columns.items()})
    keep = df.notna().any() | (df.columns == "time_s")
    df = df.loc[:, keep]
    df.attrs["events"] = [tuple(e) for e in events]
    return df


def run_launch(
    vehicle: Vehicle,
    scenario: Scenario,
    models: Sequence[DynamicModel],
    options: dict | None = None,
    threads: int = 0,
    labels: Sequence[str] | None = None,
    on_error: str = "raise",
) -> dict[str, pd.DataFrame]:
    """Every model on the vehicle under the scenario, in one core call (GIL released, ``threads``
    workers, 0 for all cores). Returns ``{label: time series}`` (labels default to the model names
    and must be unique); each frame's ``attrs["events"]`` holds its events ``(time_s, kind, ...)``.

    ``on_error="raise"``: the first failed run raises :class:`InputError` (the file its field
    belongs to) or :class:`SolverError`. ``on_error="warn"``: a failed run is left out with a
    :class:`TcsimWarning`."""
    if not models:
        return {}
    names = list(labels) if labels is not None else [m.name for m in models]
    if len(names) != len(models) or len(set(names)) != len(names):
        raise ValueError(f"one unique label per model needed: {names}")
    if not core_has_vehicle():
        raise RuntimeError(
            "this build of tcsim._core has no vehicle plant (launch_runs); reinstall tcsim "
            "(python3 -m pip install .) from a source tree that has it"
        )
    try:
        raw = _core.launch_runs([m.spec for m in models], vehicle.core, scenario.core_spec(), options, threads)
    except _core.CoreInputError as e:
        _msg, fld, value, expected = e.args
        only = models[0] if len(models) == 1 else None
        raise InputError(_source_of(fld, vehicle, scenario, only), fld, core_value(value), expected) from None
    out: dict[str, pd.DataFrame] = {}
    for name, model, entry in zip(names, models, raw):
        status = entry[0]
        if status == "ok":
            out[name] = _frame(entry[1], entry[2])
            continue
        if status == "input":
            _, _msg, fld, value, expected = entry
            err: Exception = InputError(_source_of(fld, vehicle, scenario, model), fld, core_value(value), expected)
            text = str(err)
        else:
            err, text = SolverError(f"{name}: {entry[1]}"), f"solver: {entry[1]}"
        if on_error == "raise":
            raise err
        warnings.warn(f"{name} left out ({text})", TcsimWarning, stacklevel=2)
    return out


# ---------------------------------------------------------------------------------------------
# models and the shape-effect sweep


def select_models(vehicle: Vehicle, requested: Sequence[str]) -> list[DynamicModel]:
    """``--model``: the models requested, or every model the vehicle's converter supports."""
    from .replay import select_models as select

    return select(vehicle.converter, requested)


@dataclass(frozen=True)
class SweepCase:
    """One run of the shape-effect sweep."""

    model: str
    pump_shape_effect_m2: float
    turbine_shape_effect_m2: float
    label: str
    dynamic: DynamicModel


def sweep_cases(models: Sequence[DynamicModel]) -> list[SweepCase]:
    """S_p = S_t over :func:`tcsim.shape_fit.sweep_values` for each dynamic model (the thesis's
    values for quasi-dynamic, plus its pair S_p = 0.4, S_t = 0.3; admissible fractions of the
    mass-matrix bound for Hrovat & Tobler)."""
    from .shape_fit import THESIS_PAIR_M2, mass_matrix_bound, sweep_values

    cases = []
    for m in models:
        if m.name not in DYNAMIC_MODELS:
            continue
        pairs = [(v, v) for v in sweep_values(m)]
        bound = mass_matrix_bound(m)
        if bound is None:
            pairs.append(THESIS_PAIR_M2)
        for sp, st in pairs:
            if bound is not None and not bound.admissible(sp, st):
                continue
            label = f"S_p = S_t = {sp:g} m²" if sp == st else f"S_p = {sp:g}, S_t = {st:g} m²"
            cases.append(SweepCase(m.name, float(sp), float(st), label, m.with_shape_effects(sp, st)))
    return cases


_SWEEP_KEEP = (
    "time_s",
    "speed_ratio",
    "torque_ratio",
    "effective_torque_ratio",
    "vehicle_speed_m_s",
    "vehicle_accel_m_s2",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
)


def sweep_scenario(scenario: Scenario) -> Scenario:
    """The scenario of the sweep: the same pedals, ending :data:`SWEEP_SPAN_S` after the release."""
    end = min(scenario.end_time_s, scenario.brake_release_time_s + SWEEP_SPAN_S)
    return Scenario(
        scenario.name,
        scenario.time_s,
        scenario.accelerator_pedal,
        scenario.brake_pedal,
        end,
        scenario.stop_speed_m_s,
        scenario.brake_release_time_s,
        scenario.source,
    )


def sweep_frame(cases: Sequence[SweepCase], frames: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """Tidy frame of the sweep: ``model, pump_shape_effect_m2, turbine_shape_effect_m2, label``,
    then the main columns of each run that finished."""
    parts = []
    for c in cases:
        f = frames.get(f"{c.model} {c.label}")
        if f is None:
            continue
        cols = f[[k for k in _SWEEP_KEEP if k in f.columns]]
        parts.append(
            cols.assign(
                model=c.model,
                pump_shape_effect_m2=c.pump_shape_effect_m2,
                turbine_shape_effect_m2=c.turbine_shape_effect_m2,
                label=c.label,
            )
        )
    if not parts:
        return pd.DataFrame(columns=["model", "pump_shape_effect_m2", "turbine_shape_effect_m2", "label", *_SWEEP_KEEP])
    df = pd.concat(parts, ignore_index=True)
    head = ["model", "pump_shape_effect_m2", "turbine_shape_effect_m2", "label"]
    return df[head + [c for c in df.columns if c not in head]]


#: Metrics of the sweep summary (the sweep's runs end before the speeds of the time metrics).
SWEEP_METRICS = ("peak_accel_m_s2", "mean_accel_first_0_5_s_m_s2", "min_effective_torque_ratio_first_0_5_s")


def sweep_summary(cases: Sequence[SweepCase], frames: Mapping[str, pd.DataFrame], release_s: float) -> pd.DataFrame:
    """Per sweep run: ``model, pump_shape_effect_m2, turbine_shape_effect_m2, label, finished`` and
    :data:`SWEEP_METRICS` (NaN for a run that failed)."""
    rows = []
    for c in cases:
        f = frames.get(f"{c.model} {c.label}")
        metrics = summary_row(f, release_s) if f is not None else {}
        rows.append(
            {
                "model": c.model,
                "pump_shape_effect_m2": c.pump_shape_effect_m2,
                "turbine_shape_effect_m2": c.turbine_shape_effect_m2,
                "label": c.label,
                "finished": f is not None,
                **{k: metrics.get(k, math.nan) for k in SWEEP_METRICS},
            }
        )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------------------
# the whole launch


@dataclass
class Launch:
    """Everything a launch produced (see the module docstring for the files)."""

    vehicle: Vehicle
    scenario: Scenario
    frames: dict[str, pd.DataFrame]
    summary: pd.DataFrame
    sweep: pd.DataFrame | None = None
    sweep_summary: pd.DataFrame | None = None
    compute_s: float = 0.0
    sweep_compute_s: float = 0.0
    notes: list[str] = field(default_factory=list)

    @property
    def events(self) -> pd.DataFrame:
        return events_table(self.frames)

    def timeseries(self) -> pd.DataFrame:
        """All runs in one long frame with a leading ``model`` column."""
        parts = [f.assign(model=name) for name, f in self.frames.items()]
        df = pd.concat(parts, ignore_index=True)
        return df[["model", *[c for c in df.columns if c != "model"]]]


@contextlib.contextmanager
def _progress(enabled: bool) -> Iterator[Any]:
    """A rich progress display on stderr; silent when stderr is not a terminal."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    console = Console(stderr=True)
    with Progress(
        SpinnerColumn(),
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        transient=True,
        disable=not (enabled and console.is_terminal),
    ) as progress:
        yield progress


def launch(
    vehicle: Vehicle | str | None = None,
    scenario: Scenario | str = "flip-flop",
    models: Sequence[str] = (),
    sweep: bool = False,
    threads: int = 0,
    options: dict | None = None,
    progress: bool = False,
) -> Launch:
    """Run the launch (no files written): every model, then the optional shape-effect sweep."""
    veh = vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)
    scen = scenario if isinstance(scenario, Scenario) else scenario_from_option(scenario)
    dyn = select_models(veh, models)
    cases = sweep_cases(dyn) if sweep else []
    if sweep and not cases:
        raise InputError(
            "command line",
            "--sweep-shape-effects",
            "set",
            f"at least one of {', '.join(DYNAMIC_MODELS)} among the models run",
        )
    with _progress(progress) as p:
        task = p.add_task(f"{veh.name}, {scen.name}: {len(dyn)} models", total=2 if cases else 1)
        t0 = time.perf_counter()
        frames = run_launch(veh, scen, dyn, options, threads)
        compute = time.perf_counter() - t0
        p.advance(task)
        result = Launch(veh, scen, frames, launch_summary(frames, scen.brake_release_time_s), compute_s=compute)
        if cases:
            p.update(task, description=f"shape-effect sweep: {len(cases)} runs")
            t0 = time.perf_counter()
            sweep_frames = run_launch(
                veh,
                sweep_scenario(scen),
                [c.dynamic for c in cases],
                options,
                threads,
                labels=[f"{c.model} {c.label}" for c in cases],
                on_error="warn",
            )
            result.sweep_compute_s = time.perf_counter() - t0
            result.sweep = sweep_frame(cases, sweep_frames)
            result.sweep_summary = sweep_summary(cases, sweep_frames, scen.brake_release_time_s)
            p.advance(task)
    return result


def write_launch(result: Launch, out_dir: Path) -> list[Path]:
    """The CSV files and plots of a launch into ``out_dir`` (a staging directory)."""
    from .launch_plots import plot_launch, plot_sweep

    out_dir = Path(out_dir)
    files: dict[str, pd.DataFrame] = {f"{name}.csv": f for name, f in result.frames.items()}
    files.update(
        {
            "summary.csv": result.summary,
            "timeseries.csv": result.timeseries(),
            "events.csv": result.events,
            "scenario.csv": result.scenario.frame(),
        }
    )
    if result.sweep is not None:
        files["shape_sweep.csv"] = result.sweep
        files["shape_sweep_summary.csv"] = result.sweep_summary
    paths = []
    for filename, df in files.items():
        paths.append(out_dir / filename)
        df.to_csv(paths[-1], index=False)
    paths += plot_launch(result, out_dir)
    if result.sweep is not None:
        paths += plot_sweep(result, out_dir)
    return paths


def _fmt(x: float, digits: int = 3) -> str:
    return "not reached" if not math.isfinite(x) else f"{x:.{digits}f}"


def summary(result: Launch, out: Path):
    """A rich table of the summary and where the files are."""
    from rich.console import Group
    from rich.table import Table

    s = result.scenario
    table = Table(
        title=f"launch of {result.vehicle.name} ({result.vehicle.converter.name}), scenario {s.name}, "
        f"brake release at {s.brake_release_time_s:g} s"
    )
    for col in (
        "model",
        "0–50 km/h [s]",
        "0–100 km/h [s]",
        "peak accel [m/s²]",
        "mean accel first 0.5 s [m/s²]",
        "min eff. TR first 0.5 s",
    ):
        table.add_column(col)
    for _, r in result.summary.iterrows():
        table.add_row(
            r["model"],
            _fmt(r["time_0_50_km_h_s"], 2),
            _fmt(r["time_0_100_km_h_s"], 2),
            _fmt(r["peak_accel_m_s2"], 2),
            _fmt(r["mean_accel_first_0_5_s_m_s2"], 2),
            _fmt(r["min_effective_torque_ratio_first_0_5_s"], 3),
        )
    lines = [
        f"compute {result.compute_s * 1e3:.0f} ms for {len(result.frames)} models"
        + (f", sweep {result.sweep_compute_s * 1e3:.0f} ms" if result.sweep is not None else ""),
        f"written to {out}/: summary.csv, {', '.join(f'{m}.csv' for m in result.frames)}, timeseries.csv, "
        f"events.csv, scenario.csv{', shape_sweep*.csv' if result.sweep is not None else ''} and plots",
    ]
    return Group(table, *lines)


def launch_command(vehicle: str | None, out: str | Path, scenario: str, models: Sequence[str], sweep: bool):
    """``tcsim launch``: runs, writes DIR all at once, returns the summary to print."""
    from .outputs import output_dir

    result = launch(vehicle, scenario, models, sweep, progress=True)
    with output_dir(out) as stage, _progress(True) as p:
        p.add_task(f"writing {out}/ (files and plots)", total=None)
        write_launch(result, stage)
    return summary(result, Path(out))
