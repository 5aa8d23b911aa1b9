"""``tcsim design``'s computation (docs/design.md, "tcsim design"): a design's derived converter,
its Hrovat & Tobler closed-form characteristic, and its isolated take-off against a reference
converter's.

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
  on, and its time; the turbine speed 1 s after the start of the ramp;
* the three shape effects of ``[geometry]``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..models.converter import Converter, load_converter
from ..models.design_file import DerivedConverter, DesignFile, derive_converter
from ..models.drives import isolated_takeoff
from ..models.steady import characterise, coupling_point
from ..simulation.transient import simulate
from ..units import DEFAULT_PUMP_SPEED_RPM

#: The reference converter by default.
DEFAULT_REFERENCE = "li-sunden-2016"
#: The take-off's sample step and end, s; the start of its torque ramp, s.
TAKEOFF_STEP_S, TAKEOFF_END_S, RAMP_START_S = 0.01, 10.0, 0.1
#: The take-off columns the figures read.
TAKEOFF_COLUMNS = ("time_s", "speed_ratio", "effective_torque_ratio", "turbine_speed_rad_s")
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
    "pump_shape_effect_m2",
    "turbine_shape_effect_m2",
    "stator_shape_effect_m2",
)


@dataclass(frozen=True)
class DesignReport:
    """What ``tcsim design`` writes: the derived converter, the reference converter, the
    characteristic and take-off of each (by converter name) and the summary."""

    derived: DerivedConverter
    reference: Converter
    characteristics: dict[str, pd.DataFrame]
    takeoffs: dict[str, pd.DataFrame]
    summary: pd.DataFrame


def takeoff_frame(conv: Converter) -> pd.DataFrame:
    """The isolated take-off of ``conv`` with the ``hrovat-tobler`` model, 0–10 s every 0.01 s."""
    times = np.round(np.arange(0.0, TAKEOFF_END_S + TAKEOFF_STEP_S / 2, TAKEOFF_STEP_S), 10).tolist()
    return simulate(conv, isolated_takeoff(), model="hrovat-tobler", times_s=times).frame()


def takeoff_figures(
    takeoff: Mapping[str, np.ndarray], steady_sr: np.ndarray, steady_tr: np.ndarray
) -> dict[str, float]:
    """The take-off's effective-TR dip (-), its time (s) and the turbine speed 1 s after the start of
    the ramp (rad/s), from the take-off's columns (``time_s``, ``speed_ratio``,
    ``effective_torque_ratio``, ``turbine_speed_rad_s``) and the characteristic's SR (ascending from
    0) and TR."""
    t = np.asarray(takeoff["time_s"], dtype=float)
    after = t >= RAMP_START_S
    sr = np.asarray(takeoff["speed_ratio"], dtype=float)[after]
    gap = np.interp(sr, steady_sr, steady_tr) - np.asarray(takeoff["effective_torque_ratio"], dtype=float)[after]
    k = int(np.argmax(gap))
    return {
        "takeoff_effective_tr_dip": float(gap[k]),
        "takeoff_effective_tr_dip_time_s": float(t[after][k]),
        "takeoff_turbine_speed_1s_rad_s": float(np.interp(RAMP_START_S + 1.0, t, takeoff["turbine_speed_rad_s"])),
    }


def summary_row(conv: Converter, role: str, steady: pd.DataFrame, takeoff: pd.DataFrame) -> dict[str, object]:
    """One row of the summary (:data:`SUMMARY_COLUMNS`) from a converter's characteristic ``steady``
    (SR ascending from 0) and take-off ``takeoff``."""
    assert conv.geometry is not None  # the hrovat-tobler model ran
    ssr, steady_tr = steady["speed_ratio"].to_numpy(dtype=float), steady["torque_ratio"].to_numpy(dtype=float)
    figures = takeoff_figures({c: takeoff[c].to_numpy(dtype=float) for c in TAKEOFF_COLUMNS}, ssr, steady_tr)
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


def design_report(
    file: DesignFile, reference: str = DEFAULT_REFERENCE, pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM
) -> DesignReport:
    """Derive the design's converter, then the characteristic and the take-off of it and of the
    ``reference`` converter (a bundled name or a converter file with ``[geometry]``)."""
    derived = derive_converter(file)
    ref = load_converter(reference)
    ref.require("hrovat-tobler")
    characteristics, takeoffs, rows = {}, {}, []
    for conv, role in ((derived.converter, "design"), (ref, "reference")):
        name = conv.name if conv.name not in characteristics else f"{conv.name} ({role})"
        characteristics[name] = characterise(conv, "hrovat-tobler", pump_speed_rpm)
        takeoffs[name] = takeoff_frame(conv)
        rows.append(summary_row(conv, role, characteristics[name], takeoffs[name]) | {"converter": name})
    summary = pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))
    return DesignReport(derived, ref, characteristics, takeoffs, summary)


__all__ = [
    "DEFAULT_REFERENCE",
    "SUMMARY_COLUMNS",
    "DesignReport",
    "design_report",
    "summary_row",
    "takeoff_figures",
    "takeoff_frame",
]
