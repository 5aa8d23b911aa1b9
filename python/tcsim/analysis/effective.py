"""Effective torques of a measurement (Li & Sundén 2016 §3.5.2, eqs 3.3 and 3.4) and the smoothed
derivative they use.

The derivative is the transient engine's own (``tcsim-core`` ``signal.rs``): at each sample, the
slope of the least-squares line through the samples within ±window/2, and at least one neighbour
on each side (a first-order Savitzky–Golay filter on non-uniform samples). Measured and simulated
effective torques are therefore filtered alike.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import _core
from ..models.drives import DERIVATIVE_WINDOW_S
from ..models.measurement import Measurement


def smoothed_rate(time_s, values, window_s: float = DERIVATIVE_WINDOW_S) -> np.ndarray:
    """The core's smoothed derivative of ``values`` at the samples (exact on a straight line, and
    on a parabola where the window is symmetric; a window of zero gives the three-point slope)."""
    t, y = np.ascontiguousarray(time_s, dtype=float), np.ascontiguousarray(values, dtype=float)
    if len(t) < 2:
        return np.zeros(len(t))
    return _core.smoothed_rate(t, y, float(window_s))


def _channels(source: Measurement | Mapping[str, Any]) -> dict[str, np.ndarray]:
    if isinstance(source, Measurement):
        return {"time_s": source.time_s, **source.channels}
    return {k: np.asarray(v, dtype=float) for k, v in source.items()}


def measured_effective_torques(
    measurement_or_arrays: Measurement | Mapping[str, Any],
    turbine_inertia_kg_m2: float,
    pump_inertia_kg_m2: float,
    window_s: float = DERIVATIVE_WINDOW_S,
) -> dict[str, np.ndarray]:
    """Effective torques of a measurement (eqs 3.3 and 3.4):

    * effective pump input ``= pump_torque_nm − I_p·ω̇_p`` (needs ``pump_torque_nm`` and ``pump_speed_rad_s``),
    * effective turbine output ``= turbine_torque_nm + I_t·ω̇_t`` (``turbine_torque_nm``, ``turbine_speed_rad_s``),
    * effective TR = output / input (when both are there).

    Takes a :class:`Measurement` or a mapping of arrays with ``time_s``; returns ``time_s``, the
    accelerations (:func:`smoothed_rate` over ``window_s``) and the effective torques the channels allow.
    """
    c = _channels(measurement_or_arrays)
    t = c["time_s"]
    out: dict[str, np.ndarray] = {"time_s": t}
    if "pump_speed_rad_s" in c:
        out["pump_accel_rad_s2"] = smoothed_rate(t, c["pump_speed_rad_s"], window_s)
        if "pump_torque_nm" in c:
            out["effective_pump_torque_nm"] = c["pump_torque_nm"] - pump_inertia_kg_m2 * out["pump_accel_rad_s2"]
    if "turbine_speed_rad_s" in c:
        out["turbine_accel_rad_s2"] = smoothed_rate(t, c["turbine_speed_rad_s"], window_s)
        if "turbine_torque_nm" in c:
            out["effective_turbine_torque_nm"] = (
                c["turbine_torque_nm"] + turbine_inertia_kg_m2 * out["turbine_accel_rad_s2"]
            )
    if "effective_pump_torque_nm" in out and "effective_turbine_torque_nm" in out:
        with np.errstate(divide="ignore", invalid="ignore"):
            out["effective_torque_ratio"] = out["effective_turbine_torque_nm"] / out["effective_pump_torque_nm"]
    return out
