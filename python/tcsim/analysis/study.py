"""The parameter study of Li & Sundén (2016), Appendix D, for any converter with a [geometry].

One Hrovat & Tobler parameter at a time is moved over its range of Table D.1 while the others
stay at the converter's own values; for each value TR, CF and the volume flow are computed
against SR at a fixed pump speed (thesis: 2000 rpm, SR 0 to 0.9 in steps of 0.05, figures
D.1–D.15). The thesis ran its Simulink model to steady state; tcsim uses the closed-form steady
state of the core (eqs 2.12–2.25 with zero left-hand sides), all points of all parameters in one
batched call.

The steady state includes the one-way stator clutch as the core returns it: the stator is locked
below the coupling point and free-wheels above it (TR = 1 exactly there); where the
free-wheeling balance has no positive flow the state is "no-flow" (Q = 0, TR = 1 by continuity).
Points without a steady state, and parameter values outside the model's domain (an angle at
±90°, a negative loss, a radius ≤ 0), are NaN with the reason in ``stator_mode``.

Layers: :func:`default_definition` (the study as data), :func:`run_study` (pure, returns the
tidy table); the figures are :func:`tcsim.plots.study.plot_study`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import _core
from ..errors import InputError
from ..models.converter import STEADY_KEYS, STEADY_SCALE, Converter
from ..models.steady import STATOR_MODES, hrovat_tobler_steady_state, steady_torque_ratio
from ..units import DEFAULT_PUMP_SPEED_RPM, RAD_S_PER_RPM

#: Status of a parameter value the model does not accept (CSV column ``stator_mode``).
INVALID_PARAMETER = "invalid-parameter"

COLUMNS = [
    "parameter",
    "parameter_value",
    "speed_ratio",
    "torque_ratio",
    "capacity_factor_nm_s2",
    "flow_m3_s",
    "pump_torque_nm",
    "turbine_torque_nm",
    "stator_torque_nm",
    "stator_speed_rad_s",
    "stator_mode",
]


@dataclass(frozen=True)
class ParameterRange:
    """One row of Table D.1: a geometry key, its range and how to label it.

    With ``relative`` the range is a fraction of the converter's own value (``-0.25, 0.25`` is
    "reference ±25 %"); otherwise ``low`` and ``high`` are absolute, in the file's units
    (degrees for angles).
    """

    key: str
    label: str
    unit: str
    low: float
    high: float
    relative: bool = False

    def values(self, reference: float, n: int) -> np.ndarray:
        """``n`` evenly spaced values over the range, plus ``reference`` if it is not one of them."""
        if self.relative:
            values = reference * (1.0 + np.linspace(self.low, self.high, n))
        else:
            values = np.linspace(self.low, self.high, n)
        values = np.where(np.isclose(values, reference, rtol=1e-12, atol=0.0), reference, values)
        return np.unique(np.append(values, reference))


@dataclass(frozen=True)
class StudyDefinition:
    """What the study sweeps: the parameters and ranges, values per parameter, the SR grid."""

    parameters: tuple[ParameterRange, ...]
    values_per_parameter: int = 5
    pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM
    speed_ratio: tuple[float, ...] = tuple(np.round(np.arange(19) * 0.05, 12))

    def replace(self, **changes) -> StudyDefinition:
        return dataclasses.replace(self, **changes)

    def parameter(self, key: str) -> ParameterRange:
        return next(p for p in self.parameters if p.key == key)


#: Table D.1 of Li & Sundén (2016): parameter, thesis label, unit, range.
TABLE_D1 = (
    ParameterRange("flow_area_m2", "Fluid area", "m²", -0.25, 0.25, relative=True),
    ParameterRange("fluid_density_kg_m3", "Fluid density", "kg/m³", 800.0, 900.0),
    ParameterRange("pump_exit_radius_m", "Impeller exit radius", "m", -0.25, 0.25, relative=True),
    ParameterRange("turbine_exit_radius_m", "Turbine exit radius", "m", -0.25, 0.25, relative=True),
    ParameterRange("stator_exit_radius_m", "Stator exit radius", "m", -0.25, 0.25, relative=True),
    ParameterRange("pump_exit_angle_deg", "Impeller exit angle", "°", -60.0, 60.0),
    ParameterRange("turbine_exit_angle_deg", "Turbine exit angle", "°", -60.0, 60.0),
    ParameterRange("stator_exit_angle_deg", "Stator exit angle", "°", -60.0, 60.0),
    ParameterRange("pump_inlet_angle_deg", "Impeller inlet angle", "°", -60.0, 60.0),
    ParameterRange("turbine_inlet_angle_deg", "Turbine inlet angle", "°", -60.0, 60.0),
    ParameterRange("stator_inlet_angle_deg", "Stator inlet angle", "°", -60.0, 60.0),
    ParameterRange("pump_shock_loss", "Impeller shock-loss coefficient", "-", -0.5, 0.5, relative=True),
    ParameterRange("turbine_shock_loss", "Turbine shock-loss coefficient", "-", -0.5, 0.5, relative=True),
    ParameterRange("stator_shock_loss", "Stator shock-loss coefficient", "-", -0.5, 0.5, relative=True),
    ParameterRange("friction_loss", "Fluid friction factor", "-", 0.2, 0.8),
)


def default_definition() -> StudyDefinition:
    """The study of Li & Sundén (2016), Appendix D: Table D.1, 2000 rpm, SR 0–0.9 step 0.05.

    Each parameter gets 5 evenly spaced values over its range plus the converter's own value
    when it is not one of them (5 or 6 curves per figure). Change it with
    ``default_definition().replace(values_per_parameter=9)`` and the like.
    """
    return StudyDefinition(parameters=TABLE_D1)


# --------------------------------------------------------------------------------------------
# the computation


def _check_definition(definition: StudyDefinition) -> np.ndarray:
    for p in definition.parameters:
        if p.key not in STEADY_KEYS:
            raise InputError("study definition", "parameter", p.key, f"one of {', '.join(STEADY_KEYS)}")
    if definition.values_per_parameter < 1:
        raise InputError("study definition", "values_per_parameter", definition.values_per_parameter, "at least 1")
    if not (np.isfinite(definition.pump_speed_rpm) and definition.pump_speed_rpm > 0):
        raise InputError("study definition", "pump_speed_rpm", definition.pump_speed_rpm, "a finite, positive speed")
    sr = np.asarray(definition.speed_ratio, dtype=float)
    if sr.size == 0 or not np.all((sr >= 0) & (sr <= 1)):
        raise InputError("study definition", "speed_ratio", list(sr), "speed ratios from 0 to 1")
    return sr


def _valid_row(row: np.ndarray) -> bool:
    try:
        _core.ht_check_geometry(row)
    except _core.CoreInputError:
        return False
    return True


def _parameter_values(definition: StudyDefinition, references: tuple[float, ...]) -> list[np.ndarray]:
    """The values of each parameter of ``definition`` (file units), given the converter's own values."""
    return [p.values(r, definition.values_per_parameter) for p, r in zip(definition.parameters, references)]


def _references(converter: Converter, definition: StudyDefinition) -> tuple[float, ...]:
    geometry = converter.geometry
    assert geometry is not None  # run_study's converter.require checked it
    return tuple(float(getattr(geometry, p.key)) for p in definition.parameters)


def case_count(definition: StudyDefinition, references: tuple[float, ...]) -> int:
    """How many (parameter, value) cases the study has: its number of geometries."""
    return sum(len(v) for v in _parameter_values(definition, references))


def _cases(
    base: np.ndarray,
    definition: StudyDefinition,
    references: tuple[float, ...],
    start: int = 0,
    stop: int | None = None,
) -> tuple[pd.DataFrame, np.ndarray]:
    """The cases ``start`` to ``stop`` (exclusive; all by default) in the study's order: one
    (parameter, value) per case with its geometry row (``base``, the converter's row, with that
    parameter changed) in core order and units. Only the rows of the slice are built."""
    names: list[str] = []
    values: list[float] = []
    rows: list[np.ndarray] = []
    first = 0
    for p, parameter_values in zip(definition.parameters, _parameter_values(definition, references)):
        last = first + len(parameter_values)
        lo, hi = max(start, first), last if stop is None else min(stop, last)
        j = STEADY_KEYS.index(p.key)
        for v in parameter_values[lo - first : hi - first] if lo < hi else ():
            row = base.copy()
            row[j] = v * STEADY_SCALE[j]
            names.append(p.key)
            values.append(float(v))
            rows.append(row)
        first = last
    cases = pd.DataFrame({"parameter": names, "parameter_value": values})
    return cases, np.array(rows, dtype=float).reshape(-1, len(STEADY_KEYS))


def _solve(rows: np.ndarray, speed_ratio: np.ndarray, pump_speed_rad_s: float) -> dict[str, np.ndarray]:
    """All points in one batched core call (one geometry row per point), strict=False."""
    n_sr = len(speed_ratio)
    geometry = np.ascontiguousarray(np.repeat(rows, n_sr, axis=0))
    pump = np.full(len(geometry), pump_speed_rad_s)
    turbine = np.tile(speed_ratio * pump_speed_rad_s, len(rows))
    return hrovat_tobler_steady_state(geometry, pump, turbine, strict=False)


def _columns(out: dict[str, np.ndarray], pump_speed_rad_s: float) -> dict[str, np.ndarray]:
    """TR and CF as in :func:`tcsim.steady.characterise_hrovat_tobler`; NaN without a steady state."""
    cols = {
        k: np.asarray(out[k], dtype=float)
        for k in ("flow_m3_s", "pump_torque_nm", "turbine_torque_nm", "stator_torque_nm", "stator_speed_rad_s")
    }
    cols["torque_ratio"] = steady_torque_ratio(out)
    cols["capacity_factor_nm_s2"] = out["pump_torque_nm"] / pump_speed_rad_s**2
    return cols


def run_study(converter: Converter, definition: StudyDefinition | None = None) -> pd.DataFrame:
    """The Appendix D study of ``converter``: one row per (parameter, value, speed ratio).

    Columns :data:`COLUMNS`; ``stator_mode`` is ``locked``, ``free-wheeling``, ``no-flow``,
    ``no-steady-state`` or ``invalid-parameter`` (the last two with NaN results). Raises
    :class:`InputError` if the converter has no [geometry] (Li & Sundén 2016, Appendix D).
    """
    converter.require("hrovat-tobler")
    definition = definition or default_definition()
    _check_definition(definition)
    assert converter.geometry is not None
    return study_rows(converter.geometry.core_row(), definition, _references(converter, definition))


def study_rows(
    base: np.ndarray,
    definition: StudyDefinition,
    references: tuple[float, ...],
    start: int = 0,
    stop: int | None = None,
) -> pd.DataFrame:
    """The rows of the cases ``start`` to ``stop`` of the study (:func:`run_study`'s table for all of
    them): a pure function of the converter's geometry row ``base`` (core order and units), the
    definition and the converter's own values of its parameters (``references``, file units). Every
    point is computed on its own, so the rows of a slice are those of the whole study, bit for bit."""
    sr = _check_definition(definition)
    wp = definition.pump_speed_rpm * RAD_S_PER_RPM
    cases, rows = _cases(np.asarray(base, dtype=float), definition, references, start, stop)
    valid = np.array([_valid_row(r) for r in rows], dtype=bool)
    n_sr = len(sr)
    n = len(rows) * n_sr
    cols = {c: np.full(n, np.nan) for c in COLUMNS[3:-1]}
    mode = np.full(n, INVALID_PARAMETER, dtype=object)
    ok = np.repeat(valid, n_sr)
    if valid.any():
        out = _solve(rows[valid], sr, wp)
        for k, v in _columns(out, wp).items():
            cols[k][ok] = v
        mode[ok] = [STATOR_MODES[int(m)] for m in out["stator_mode"]]
    df = pd.DataFrame(
        {
            "parameter": np.repeat(cases["parameter"].to_numpy(dtype=object), n_sr),
            "parameter_value": np.repeat(cases["parameter_value"].to_numpy(dtype=float), n_sr),
            "speed_ratio": np.tile(sr, len(rows)),
            **cols,
            "stator_mode": mode,
        }
    )
    return df[COLUMNS]
