"""The launch comparison (Li & Sundén 2016, §3.2.2, §3.5.2.2, §4.1): the runs of every model and of
the optional shape-effect sweep, and their summary metrics (times to 50 and 100 km/h measured from
the brake release, peak acceleration, and over the first 0.5 s after it the mean acceleration and
the smallest effective torque ratio; NaN where a speed is not reached; then the launch peak apart
from the shift transients and the effective-TR dip and recovery against the table model,
:mod:`tcsim.analysis.launch_metrics`, docs/launch_summary.md)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import InputError
from ..models.vehicle import Vehicle
from ..simulation.launch import (
    DYNAMIC_MODELS,
    LaunchRun,
    SweepCase,
    run_launch,
    select_models,
    sweep_cases,
    sweep_scenario,
)
from ..simulation.scenarios import SPEED_50_KM_H_M_S, SPEED_100_KM_H_M_S, Scenario
from .launch_metrics import dip_metrics, phase_metrics, recovery_time, shift_windows

#: Width of the window after the brake release of the "first 0.5 s" metrics, s.
FIRST_WINDOW_S = 0.5
SUMMARY_COLUMNS: tuple[str, ...] = (
    "model",
    "time_0_100_km_h_s",
    "time_0_50_km_h_s",
    "peak_accel_m_s2",
    "mean_accel_first_0_5_s_m_s2",
    "min_effective_torque_ratio_first_0_5_s",
    "launch_peak_accel_m_s2",
    "launch_peak_accel_time_s",
    "shift_count",
    "shift_peak_accel_m_s2",
    "max_shift_accel_ratio",
    "effective_torque_ratio_dip_first_0_5_s",
    "effective_torque_ratio_dip_time_s",
    "mean_effective_torque_ratio_deficit_first_0_5_s",
    "effective_torque_ratio_recovery_time_s",
)
#: An axis label with its unit for each summary metric (docs/launch_summary.md; times from the brake
#: release ``t_r``): the histograms of a Monte Carlo study.
SUMMARY_LABELS: dict[str, str] = {
    "time_0_100_km_h_s": "Time 0–100 km/h [s]",
    "time_0_50_km_h_s": "Time 0–50 km/h [s]",
    "peak_accel_m_s2": "Peak acceleration, whole run [m/s²]",
    "mean_accel_first_0_5_s_m_s2": "Mean acceleration, first 0.5 s [m/s²]",
    "min_effective_torque_ratio_first_0_5_s": "Min. effective TR, first 0.5 s [-]",
    "launch_peak_accel_m_s2": "Peak acceleration before the first shift [m/s²]",
    "launch_peak_accel_time_s": "Time of the launch peak acceleration [s after release]",
    "shift_count": "Shifts [-]",
    "shift_peak_accel_m_s2": "Peak acceleration in a shift [m/s²]",
    "max_shift_accel_ratio": "Shift peak ÷ acceleration before the shift [-]",
    "effective_torque_ratio_dip_first_0_5_s": "Effective TR dip vs the table model, first 0.5 s [-]",
    "effective_torque_ratio_dip_time_s": "Time of the effective TR dip [s after release]",
    "mean_effective_torque_ratio_deficit_first_0_5_s": "Mean effective TR deficit vs the table model, first 0.5 s [-]",
    "effective_torque_ratio_recovery_time_s": "Effective TR recovery (±0.05) [s after release]",
}
#: The model whose effective TR the dip and recovery columns compare with.
REFERENCE_MODEL = "table"
EVENT_COLUMNS: tuple[str, ...] = ("model", "time_s", "kind", "detail")


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


def _column(frame: pd.DataFrame, name: str) -> np.ndarray | None:
    return frame[name].to_numpy(dtype=float) if name in frame.columns else None


def _shifts(frame: pd.DataFrame):
    return shift_windows(frame["time_s"].to_numpy(dtype=float), _column(frame, "shifting"), _column(frame, "gear"))


def _first_shift_s(frame: pd.DataFrame, release_s: float) -> float:
    """Start of the run's first shift at or after the release; infinity without one."""
    t = frame["time_s"].to_numpy(dtype=float)
    starts = [t[s.first] for s in _shifts(frame) if t[s.first] >= release_s]
    return float(starts[0]) if starts else math.inf


def comparison_row(frame: pd.DataFrame, reference: pd.DataFrame | None, release_s: float) -> dict[str, float]:
    """The launch-phase, shift and effective-TR comparison metrics of one run against the
    ``reference`` (table) run (docs/launch_summary.md); the comparison NaN without a reference."""
    t = frame["time_s"].to_numpy(dtype=float)
    a = frame["vehicle_accel_m_s2"].to_numpy(dtype=float)
    row = phase_metrics(t, a, _shifts(frame), release_s)
    names = (
        "effective_torque_ratio_dip_first_0_5_s",
        "effective_torque_ratio_dip_time_s",
        "mean_effective_torque_ratio_deficit_first_0_5_s",
    )
    row.update(dict.fromkeys(names, math.nan), effective_torque_ratio_recovery_time_s=math.nan)
    if reference is None:
        return row
    e, rt, re = (x.to_numpy(dtype=float) for x in (frame["effective_torque_ratio"], *_ref(reference)))
    dip = dip_metrics(t, e, rt, re, release_s, FIRST_WINDOW_S)
    row.update(zip(names, (dip["dip"], dip["dip_time_s"], dip["mean_deficit"])))
    phase_end = min(_first_shift_s(frame, release_s), _first_shift_s(reference, release_s))
    row["effective_torque_ratio_recovery_time_s"] = recovery_time(t, e, rt, re, release_s, phase_end)
    return row


def _ref(reference: pd.DataFrame) -> tuple[pd.Series, pd.Series]:
    return reference["time_s"], reference["effective_torque_ratio"]


def launch_summary(frames: Mapping[str, pd.DataFrame], release_s: float) -> pd.DataFrame:
    """One row per run: ``model``, the metrics of :func:`summary_row`, then those of
    :func:`comparison_row` against the :data:`REFERENCE_MODEL` run (when it was run)."""
    reference = frames.get(REFERENCE_MODEL)
    rows = [
        {"model": name, **summary_row(f, release_s), **comparison_row(f, reference, release_s)}
        for name, f in frames.items()
    ]
    df = pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))
    return df.astype({"shift_count": int})


def events_table(runs: Mapping[str, LaunchRun]) -> pd.DataFrame:
    """All runs' events: ``model, time_s, kind, detail`` (the event's further fields as text)."""
    rows = []
    for name, run in runs.items():
        for e in run.events:
            rest = " ".join(str(x) for x in e[2:])
            rows.append({"model": name, "time_s": float(e[0]), "kind": str(e[1]), "detail": rest})
    return pd.DataFrame(rows, columns=list(EVENT_COLUMNS))


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
    runs: dict[str, LaunchRun]
    summary: pd.DataFrame
    sweep: pd.DataFrame | None = None
    sweep_summary: pd.DataFrame | None = None
    compute_s: float = 0.0
    sweep_compute_s: float = 0.0
    notes: list[str] = field(default_factory=list)

    @property
    def frames(self) -> dict[str, pd.DataFrame]:
        """Each model's time series."""
        return {name: run.frame for name, run in self.runs.items()}

    @property
    def events(self) -> pd.DataFrame:
        return events_table(self.runs)

    def timeseries(self) -> pd.DataFrame:
        """All runs in one long frame with a leading ``model`` column."""
        parts = [f.assign(model=name) for name, f in self.frames.items()]
        df = pd.concat(parts, ignore_index=True)
        return df[["model", *[c for c in df.columns if c != "model"]]]


def run_comparison(
    vehicle: Vehicle,
    scenario: Scenario,
    models: Sequence[str] = (),
    sweep: bool = False,
    threads: int = 0,
    options: dict | None = None,
    on_step: Callable[[str], None] | None = None,
) -> Launch:
    """Run the launch (no files written): every model, then the optional shape-effect sweep.
    ``on_step`` is told what runs next (for a progress display)."""
    step = on_step or (lambda _: None)
    dyn = select_models(vehicle, models)
    cases = sweep_cases(dyn) if sweep else []
    if sweep and not cases:
        raise InputError(
            "command line",
            "--sweep-shape-effects",
            "set",
            f"at least one of {', '.join(DYNAMIC_MODELS)} among the models run",
        )
    step(f"{vehicle.name}, {scenario.name}: {len(dyn)} models")
    t0 = time.perf_counter()
    runs = run_launch(vehicle, scenario, dyn, options, threads)
    compute = time.perf_counter() - t0
    frames = {name: run.frame for name, run in runs.items()}
    result = Launch(vehicle, scenario, runs, launch_summary(frames, scenario.brake_release_time_s), compute_s=compute)
    if cases:
        step(f"shape-effect sweep: {len(cases)} runs")
        t0 = time.perf_counter()
        sweep_runs = run_launch(
            vehicle,
            sweep_scenario(scenario),
            [c.dynamic for c in cases],
            options,
            threads,
            labels=[f"{c.model} {c.label}" for c in cases],
            on_error="warn",
        )
        sweep_frames = {name: run.frame for name, run in sweep_runs.items()}
        result.sweep_compute_s = time.perf_counter() - t0
        result.sweep = sweep_frame(cases, sweep_frames)
        result.sweep_summary = sweep_summary(cases, sweep_frames, scenario.brake_release_time_s)
    return result
