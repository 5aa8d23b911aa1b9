"""``tcsim design``'s computation (docs/design.md, "tcsim design"): a design's derived converter,
its Hrovat & Tobler closed-form characteristic, and its isolated take-off and vehicle launch against
a reference converter's.

The take-off is :func:`tcsim.models.drives.isolated_takeoff` (pump torque 40 N·m, ramped to
250 N·m over 0.1–0.3 s, the turbine driving 1.2 kg·m² against 10 N·m and 0.002 N·m/(rad/s)²),
sampled every :data:`TAKEOFF_STEP_S` over 0–10 s with the ``hrovat-tobler`` model for both
converters. The summary gives, per converter (:data:`SUMMARY_COLUMNS`):

* the steady state at :data:`~tcsim.units.DEFAULT_PUMP_SPEED_RPM`: stall torque ratio, K-factor at
  stall (rpm/√(N·m)), peak efficiency in converter mode (SR below the coupling point), coupling
  point (SR where the stator clutch releases; NaN when it does not below SR 1);
* the take-off's **effective-TR dip**: the largest amount by which the effective torque ratio
  (effective turbine over effective pump torque, docs/transient.md) falls below the converter's
  own steady-state torque ratio at the same speed ratio, from the start of the torque ramp (0.1 s)
  on, and its time; its **recovery time**, from the start of the ramp until that gap stays within
  :data:`TAKEOFF_RECOVERY_BAND` to the end of the take-off; the turbine speed 1 s after the start
  of the ramp;
* the **launch** (:func:`launch_scenario`: the bundled vehicle, or the one given, in first gear,
  full pedal at the brake release, run to 50 km/h, every model ``hrovat-tobler`` with the
  converter swapped in): the time from the release to 50 km/h and the mean of the same gap over
  the first 0.5 s after the release (the thesis's fig. 3.5 window, §3.2.2);
* the three shape effects of ``[geometry]``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ..errors import InputError
from ..models.converter import Converter, load_converter
from ..models.design_file import DerivedConverter, DesignFile, derive_converter
from ..models.drives import isolated_takeoff
from ..models.dynamic import DynamicModel, dynamic_model
from ..models.steady import characterise, coupling_point
from ..models.vehicle import Vehicle, load_vehicle
from ..simulation.launch import LAUNCH_COLUMNS as RUN_LAUNCH_COLUMNS
from ..simulation.launch import LaunchRun, launch_columns, run_launch
from ..simulation.scenarios import SPEED_50_KM_H_M_S, Scenario, flip_flop
from ..simulation.transient import simulate
from ..units import DEFAULT_PUMP_SPEED_RPM
from .launch import FIRST_WINDOW_S, time_to_speed, window_mean
from .launch_metrics import time_back_in_band

#: The reference converter by default.
DEFAULT_REFERENCE = "li-sunden-2016"
#: The take-off's sample step and end, s; the start of its torque ramp, s.
TAKEOFF_STEP_S, TAKEOFF_END_S, RAMP_START_S = 0.01, 10.0, 0.1
#: The take-off columns the figures read.
TAKEOFF_COLUMNS = ("time_s", "speed_ratio", "effective_torque_ratio", "turbine_speed_rad_s")
#: The take-off has recovered once its effective-TR gap stays within this band, - .
TAKEOFF_RECOVERY_BAND = 0.01
#: The launch: brake held this long, s; the run's longest span after the release, s; output step, s.
LAUNCH_HOLD_S, LAUNCH_SPAN_S, LAUNCH_STEP_S = 1.0, 10.0, 0.01
#: The launch columns the figures read and ``launch.csv`` keeps: every launch run's columns.
LAUNCH_COLUMNS = RUN_LAUNCH_COLUMNS
#: The columns of the summary, one row per converter.
SUMMARY_COLUMNS = (
    "converter",
    "role",
    "stall_torque_ratio",
    "stall_k_factor_rpm_per_sqrt_nm",
    "peak_converter_efficiency",
    "coupling_point_speed_ratio",
    "takeoff_effective_tr_dip",
    "takeoff_effective_tr_dip_time_s",
    "takeoff_turbine_speed_1s_rad_s",
    "takeoff_effective_tr_recovery_time_s",
    "launch_time_0_50_km_h_s",
    "launch_effective_tr_deficit_first_0_5_s",
    "pump_shape_effect_m2",
    "turbine_shape_effect_m2",
    "stator_shape_effect_m2",
)


@dataclass(frozen=True)
class DesignReport:
    """What ``tcsim design`` writes: the derived converter, the reference converter, the
    characteristic, take-off and launch of each (by converter name) and the summary."""

    derived: DerivedConverter
    reference: Converter
    characteristics: dict[str, pd.DataFrame]
    takeoffs: dict[str, pd.DataFrame]
    launches: dict[str, pd.DataFrame]
    summary: pd.DataFrame


def takeoff_frame(conv: Converter) -> pd.DataFrame:
    """The isolated take-off of ``conv`` with the ``hrovat-tobler`` model, 0–10 s every 0.01 s."""
    times = np.round(np.arange(0.0, TAKEOFF_END_S + TAKEOFF_STEP_S / 2, TAKEOFF_STEP_S), 10).tolist()
    return simulate(conv, isolated_takeoff(), model="hrovat-tobler", times_s=times).frame()


def _gap(run: Mapping[str, np.ndarray], steady_sr: np.ndarray, steady_tr: np.ndarray) -> np.ndarray:
    """The converter's steady-state TR at the run's speed ratio less the run's effective TR."""
    sr = np.asarray(run["speed_ratio"], dtype=float)
    return np.interp(sr, steady_sr, steady_tr) - np.asarray(run["effective_torque_ratio"], dtype=float)


def takeoff_figures(
    takeoff: Mapping[str, np.ndarray], steady_sr: np.ndarray, steady_tr: np.ndarray
) -> dict[str, float]:
    """The take-off's effective-TR dip (-), its time (s), its recovery time (s) and the turbine speed
    1 s after the start of the ramp (rad/s), from the take-off's columns (``time_s``,
    ``speed_ratio``, ``effective_torque_ratio``, ``turbine_speed_rad_s``) and the characteristic's
    SR (ascending from 0) and TR."""
    t = np.asarray(takeoff["time_s"], dtype=float)
    after = t >= RAMP_START_S
    gap = _gap(takeoff, steady_sr, steady_tr)[after]
    k = int(np.argmax(gap))
    return {
        "takeoff_effective_tr_dip": float(gap[k]),
        "takeoff_effective_tr_dip_time_s": float(t[after][k]),
        "takeoff_turbine_speed_1s_rad_s": float(np.interp(RAMP_START_S + 1.0, t, takeoff["turbine_speed_rad_s"])),
        "takeoff_effective_tr_recovery_time_s": time_back_in_band(t[after], gap, TAKEOFF_RECOVERY_BAND, RAMP_START_S),
    }


def launch_scenario() -> Scenario:
    """The design launch: the thesis's flip-flop (§3.2.2) with the brake held :data:`LAUNCH_HOLD_S`,
    run to 50 km/h or :data:`LAUNCH_SPAN_S` after the release."""
    base = flip_flop(hold_s=LAUNCH_HOLD_S, end_time_s=LAUNCH_HOLD_S + LAUNCH_SPAN_S)
    return replace(base, stop_speed_m_s=SPEED_50_KM_H_M_S)


def _launch_models(converters: Sequence[Converter], vehicle: Vehicle | None) -> tuple[Vehicle, list[DynamicModel]]:
    """The launch's vehicle (default: the bundled one) and the ``hrovat-tobler`` model of each converter."""
    return (load_vehicle(None) if vehicle is None else vehicle), [dynamic_model(c, "hrovat-tobler") for c in converters]


def launch_runs(
    converters: Sequence[Converter], labels: Sequence[str], vehicle: Vehicle | None = None
) -> dict[str, LaunchRun]:
    """The launch (:func:`launch_scenario`) of each converter with the ``hrovat-tobler`` model on
    ``vehicle`` (default: the bundled vehicle), in one core call; by label
    (:func:`tcsim.simulation.launch.run_launch`: the first failure raises)."""
    veh, models = _launch_models(converters, vehicle)
    return run_launch(veh, launch_scenario(), models, {"output_step_s": LAUNCH_STEP_S}, labels=labels)


def launch_column_runs(
    converters: Sequence[Converter], vehicle: Vehicle | None = None, threads: int = 0
) -> list[dict[str, np.ndarray] | Exception]:
    """:func:`launch_runs` as :data:`LAUNCH_COLUMNS` arrays only, each run or its error in its place
    (:func:`tcsim.simulation.launch.launch_columns`; for studies of thousands of designs)."""
    veh, models = _launch_models(converters, vehicle)
    options = {"output_step_s": LAUNCH_STEP_S}
    return launch_columns(veh, launch_scenario(), models, LAUNCH_COLUMNS, options, threads)


def launch_figures(launch: Mapping[str, np.ndarray], steady_sr: np.ndarray, steady_tr: np.ndarray) -> dict[str, float]:
    """The launch's time from the release to 50 km/h (s; NaN if not reached) and its mean
    effective-TR gap to the converter's steady state over the first 0.5 s after the release (-),
    from the launch's columns (:data:`LAUNCH_COLUMNS`) and the characteristic's SR and TR."""
    t = np.asarray(launch["time_s"], dtype=float)
    v = np.asarray(launch["vehicle_speed_m_s"], dtype=float)
    return {
        "launch_time_0_50_km_h_s": time_to_speed(t, v, SPEED_50_KM_H_M_S, LAUNCH_HOLD_S),
        "launch_effective_tr_deficit_first_0_5_s": window_mean(
            t, _gap(launch, steady_sr, steady_tr), LAUNCH_HOLD_S, FIRST_WINDOW_S
        ),
    }


def summary_row(
    conv: Converter, role: str, steady: pd.DataFrame, takeoff: pd.DataFrame, launch: pd.DataFrame
) -> dict[str, object]:
    """One row of the summary (:data:`SUMMARY_COLUMNS`) from a converter's characteristic ``steady``
    (SR ascending from 0), take-off ``takeoff`` and launch ``launch``."""
    assert conv.geometry is not None  # the hrovat-tobler model ran
    ssr, steady_tr = steady["speed_ratio"].to_numpy(dtype=float), steady["torque_ratio"].to_numpy(dtype=float)
    figures = takeoff_figures({c: takeoff[c].to_numpy(dtype=float) for c in TAKEOFF_COLUMNS}, ssr, steady_tr)
    figures |= launch_figures({c: launch[c].to_numpy(dtype=float) for c in LAUNCH_COLUMNS}, ssr, steady_tr)
    cp = coupling_point(conv)
    below = steady["speed_ratio"] < (cp if cp is not None else np.inf)
    return {
        "converter": conv.name,
        "role": role,
        "stall_torque_ratio": float(steady["torque_ratio"].iloc[0]),
        "stall_k_factor_rpm_per_sqrt_nm": float(steady["k_factor_rpm_per_sqrt_nm"].iloc[0]),
        "peak_converter_efficiency": float(steady["efficiency"][below].max()),
        "coupling_point_speed_ratio": float("nan") if cp is None else float(cp),
        **figures,
        "pump_shape_effect_m2": conv.geometry.pump_shape_effect_m2,
        "turbine_shape_effect_m2": conv.geometry.turbine_shape_effect_m2,
        "stator_shape_effect_m2": conv.geometry.stator_shape_effect_m2,
    }


def _design_launches(
    file: DesignFile, converters: Sequence[Converter], labels: Sequence[str], vehicle: Vehicle | None
) -> dict[str, LaunchRun]:
    """:func:`launch_runs`; a refusal by the vehicle's checks (its engine cannot hold the stalled
    converter) is the design's: the vehicle holds the reference, so the derived converter is what
    changed (a radius typed in mm blamed the bundled vehicle's idle speed, in a file the user never
    touched: a fresh-eyes trial)."""
    try:
        return launch_runs(converters, labels, vehicle)
    except InputError as e:
        if e.core_source != "vehicle":
            raise
        expected = (
            f"a design whose converter the launch vehicle can drive; {e.source} refused it: "
            f"{e.field} = {e.value:g}: expected {e.expected} (check the design's radii and their units)"
            if isinstance(e.value, float)
            else f"a design whose converter the launch vehicle can drive; {e}"
        )
        raise InputError(file.path, "[design]", "the derived converter", expected) from None


def design_report(
    file: DesignFile,
    reference: str = DEFAULT_REFERENCE,
    pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM,
    vehicle: Vehicle | None = None,
) -> DesignReport:
    """Derive the design's converter, then the characteristic, the take-off and the launch (on
    ``vehicle``, default the bundled one) of it and of the ``reference`` converter (a bundled name or
    a converter file with ``[geometry]``)."""
    derived = derive_converter(file)
    ref = load_converter(reference)
    ref.require("hrovat-tobler")
    pairs = ((derived.converter, "design"), (ref, "reference"))
    names = [derived.converter.name]
    names.append(ref.name if ref.name != names[0] else f"{ref.name} (reference)")
    runs = _design_launches(file, [c for c, _ in pairs], names, vehicle)
    characteristics, takeoffs, launches, rows = {}, {}, {}, []
    for (conv, role), name in zip(pairs, names):
        characteristics[name] = characterise(conv, "hrovat-tobler", pump_speed_rpm)
        takeoffs[name] = takeoff_frame(conv)
        launches[name] = runs[name].frame.loc[:, list(LAUNCH_COLUMNS)]
        row = summary_row(conv, role, characteristics[name], takeoffs[name], launches[name])
        rows.append(row | {"converter": name})
    summary = pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))
    return DesignReport(derived, ref, characteristics, takeoffs, launches, summary)


__all__ = [
    "DEFAULT_REFERENCE",
    "LAUNCH_COLUMNS",
    "launch_column_runs",
    "launch_figures",
    "launch_runs",
    "launch_scenario",
    "SUMMARY_COLUMNS",
    "DesignReport",
    "design_report",
    "summary_row",
    "takeoff_figures",
    "takeoff_frame",
]
