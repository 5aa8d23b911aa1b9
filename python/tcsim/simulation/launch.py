"""Whole-vehicle launch runs (``tcsim._core.launch_runs``): every converter model on the same vehicle
under one scenario, and the runs of the shape-effect sweep (Li & Sundén 2016, §3.2.2, §4.1).

:func:`run_launch` is the only call into the core: all models in one call, the GIL released, one
worker per core. Each run gives a time series with at least :data:`LAUNCH_COLUMNS` and its events
(gear shifts, lock-up, converter events) as ``(time_s, kind, gear)``, a field of :class:`LaunchRun`.
The core's typed results (``tcsim._core.LaunchRun``) are read in one place, :func:`_unpack`.
Errors: a bad vehicle, scenario or model is an :class:`~tcsim.errors.InputError` naming the file
of the input the core blames (its ``source``, data, not text); a solver failure is a
:class:`~tcsim.simulation.transient.SolverError`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .. import _core
from ..errors import TcsimWarning, core_input_error, from_core
from ..models.dynamic import DynamicModel, warn_about_runs
from ..models.dynamic import select_models as select_converter_models
from ..models.shape_effects import THESIS_PAIR_M2, mass_matrix_bound, sweep_values
from ..models.vehicle import Vehicle
from .scenarios import Scenario
from .transient import SolverError

#: The shape-effect sweep runs to this long after the brake release (figures 4.3–4.6 show the first
#: 1.5 s; the later shifts and lock-up add nothing to them), s.
SWEEP_SPAN_S = 2.0
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
DYNAMIC_MODELS: tuple[str, ...] = ("hrovat-tobler", "quasi-dynamic")


# ---------------------------------------------------------------------------------------------
# the core call


def _files(vehicle: Vehicle, scenario: Scenario, models: Sequence[DynamicModel]) -> dict[str, str]:
    """Where each input the core may blame comes from (the models' converter file when they share
    one)."""
    converters = {m.source for m in models}
    files = {"vehicle": vehicle.path, "scenario": scenario.source}
    return {**files, "converter": converters.pop()} if len(converters) == 1 else {**files, "converter": "model"}


@dataclass(frozen=True)
class LaunchRun:
    """One launch run: its time series (the all-NaN columns of coordinates the model lacks left
    out) and its events ``(time_s, kind, ...)``: gear shifts, lock-up, converter events."""

    frame: pd.DataFrame
    events: list[tuple[Any, ...]] = field(default_factory=list)


def _unpack(run: _core.LaunchRun, name: str, files: Mapping[str, str]) -> LaunchRun | Exception:
    """The one reading of the core's result of a launch run: the run, or its error (an
    :class:`InputError` naming the file of the input the core blames, or a :class:`SolverError`)."""
    err = run.error
    if err is None:
        df = pd.DataFrame({k: np.asarray(v) for k, v in run.columns.items()})
        keep = df.notna().any() | (df.columns == "time_s")
        return LaunchRun(df.loc[:, keep], [(e.time_s, e.kind, e.gear) for e in run.events])
    if err.kind == "input":
        assert err.source is not None and err.field is not None and err.expected is not None
        return core_input_error(err.source, err.field, err.value, err.expected, files)
    return SolverError(f"{name}: {err.message}")


def _launch_core(
    vehicle: Vehicle, scenario: Scenario, models: Sequence[DynamicModel], options: dict | None, threads: int
) -> list[_core.LaunchRun]:
    """The one core call of every launch (GIL released); a bad input of the whole call raises."""
    try:
        return _core.launch_runs([m.spec for m in models], vehicle.core, scenario.core_spec(), options, threads)
    except _core.CoreInputError as e:
        raise from_core(e, _files(vehicle, scenario, models)) from None


def launch_columns(
    vehicle: Vehicle,
    scenario: Scenario,
    models: Sequence[DynamicModel],
    columns: Sequence[str],
    options: dict | None = None,
    threads: int = 0,
) -> list[dict[str, np.ndarray] | Exception]:
    """Each model's launch as ``columns`` only (float64 arrays, no DataFrame), or its error (an
    :class:`InputError` naming the file, or a :class:`SolverError`) in its place: the path for
    thousands of runs (design studies). The models' run warnings are not checked here."""
    out: list[dict[str, np.ndarray] | Exception] = []
    for model, run in zip(models, _launch_core(vehicle, scenario, models, options, threads)):
        if run.error is None:
            out.append({c: np.asarray(run.columns[c], dtype=float) for c in columns})
        else:
            failed = _unpack(run, model.name, _files(vehicle, scenario, [model]))
            assert isinstance(failed, Exception)
            out.append(failed)
    return out


def run_launch(
    vehicle: Vehicle,
    scenario: Scenario,
    models: Sequence[DynamicModel],
    options: dict | None = None,
    threads: int = 0,
    labels: Sequence[str] | None = None,
    on_error: str = "raise",
) -> dict[str, LaunchRun]:
    """Every model on the vehicle under the scenario, in one core call (GIL released, ``threads``
    workers, 0 for all cores). Returns ``{label: run}`` (:class:`LaunchRun`; labels default to the model
    names and must be unique).

    ``on_error="raise"``: the first failed run raises :class:`InputError` (the file its field
    belongs to) or :class:`SolverError`. ``on_error="warn"``: a failed run is left out with a
    :class:`TcsimWarning`."""
    if not models:
        return {}
    names = list(labels) if labels is not None else [m.name for m in models]
    if len(names) != len(models) or len(set(names)) != len(names):
        raise ValueError(f"one unique label per model needed: {names}")
    raw = _launch_core(vehicle, scenario, models, options, threads)
    results = [_unpack(run, name, _files(vehicle, scenario, [model])) for name, model, run in zip(names, models, raw)]
    failed = next((r for r in results if not isinstance(r, LaunchRun)), None)
    if on_error == "raise" and failed is not None:
        raise failed  # before any run's warning: a failure is one line
    out: dict[str, LaunchRun] = {}
    finished = []
    for name, model, run, result in zip(names, models, raw, results):
        if isinstance(result, LaunchRun):
            finished.append((name, model, {str(k): v for k, v in result.frame.items()}))
            out[name] = result
            continue
        text = f"solver: {run.error.message}" if isinstance(result, SolverError) and run.error else str(result)
        warnings.warn(f"{name} left out ({text})", TcsimWarning, stacklevel=2)
    warn_about_runs("launch", finished)
    return out


# ---------------------------------------------------------------------------------------------
# models and the shape-effect sweep


def select_models(vehicle: Vehicle, requested: Sequence[str]) -> list[DynamicModel]:
    """``--model``: the models requested, or every model the vehicle's converter supports."""
    return select_converter_models(vehicle.converter, requested)


@dataclass(frozen=True)
class SweepCase:
    """One run of the shape-effect sweep."""

    model: str
    pump_shape_effect_m2: float
    turbine_shape_effect_m2: float
    label: str
    dynamic: DynamicModel


def sweep_cases(models: Sequence[DynamicModel]) -> list[SweepCase]:
    """S_p = S_t over :func:`tcsim.models.shape_effects.sweep_values` for each dynamic model (the
    thesis's values for quasi-dynamic, plus its pair S_p = 0.4, S_t = 0.3; admissible fractions of
    the mass-matrix bound for Hrovat & Tobler)."""
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
