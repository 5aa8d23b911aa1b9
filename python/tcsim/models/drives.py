"""Drives of the isolated converter (what the transient engine is given against time): pump torque
and turbine speed (a), both speeds (b), pump torque against a load (c).

Every drive may command the converter's lock-up clutch (docs/lockup.md): ``lockup_capacity_nm``, a
constant or one value per time stamp (N·m, zero or more; None: no clutch, the same run as a command
of zero), and ``lockup_static_to_kinetic`` (the static-to-kinetic friction ratio, 1 or more; None:
the core's default, 1.2)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

#: Default width of the smoothing window of measured-speed derivatives, s (see docs/transient.md).
DERIVATIVE_WINDOW_S = 0.04


# ---------------------------------------------------------------------------------------------
# Drives


def _arr(x: Any) -> list[float] | float:
    try:
        if np.isscalar(x):
            return float(x)  # type: ignore[arg-type]  # a real scalar; complex inputs are not drives
        return np.asarray(x, dtype=float).tolist()
    except (TypeError, ValueError):
        return x  # not numbers: the core's input error names the drive's series


def _series(x: Any) -> np.ndarray | list[float] | float:
    """:func:`_arr` for the core (``Drive._core_spec``): a one-dimensional series as a float64 array,
    which the binding copies in one go instead of a list's floats one by one; a number, a 0-d array
    or an array of another shape as :func:`_arr` gives it (so the same constant, or the same error)."""
    try:
        if not isinstance(x, np.ndarray) and np.isscalar(x):  # (an array is never a scalar here)
            return float(x)  # type: ignore[arg-type]  # a real scalar; complex inputs are not drives
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        return x  # not numbers (text): the core's input error names the drive's series
    return a if a.ndim == 1 else a.tolist()


#: How a drive's series go into its spec: :func:`_arr` (lists, ``spec()``) or :func:`_series`.
_Series = Callable[[Any], Any]


def _lockup(capacity_nm: ArrayLike | None, static_to_kinetic: float | None, series: _Series = _arr) -> dict[str, Any]:
    """The lock-up keys of a drive's spec (none without a capacity command)."""
    spec: dict[str, Any] = {}
    if capacity_nm is not None:
        spec["lockup_capacity_nm"] = series(capacity_nm)
        if static_to_kinetic is not None:
            spec["lockup_static_to_kinetic"] = float(static_to_kinetic)
    return spec


@dataclass(frozen=True)
class PumpTorqueTurbineSpeed:
    """Drive (a), the thesis/VSIM causality: pump torque and turbine speed given (time series);
    pump speed and turbine torque come out. The turbine speed's derivative is smoothed over
    ``derivative_window_s`` (local least-squares slope). A locked lock-up clutch makes the pump
    follow the turbine speed."""

    time_s: ArrayLike
    pump_torque_nm: ArrayLike
    turbine_speed_rad_s: ArrayLike
    derivative_window_s: float = DERIVATIVE_WINDOW_S
    lockup_capacity_nm: ArrayLike | None = None
    lockup_static_to_kinetic: float | None = None

    def spec(self) -> dict[str, Any]:
        """The drive as the core's dict (``tcsim._core.transient_batch``), its series as lists."""
        return self._spec(_arr)

    def _core_spec(self) -> dict[str, Any]:
        """:meth:`spec` with its one-dimensional series as float64 arrays (what the runs pass)."""
        return self._spec(_series)

    def _spec(self, series: _Series) -> dict[str, Any]:
        return {
            "kind": "pump-torque-turbine-speed",
            "time_s": series(self.time_s),
            "pump_torque_nm": series(self.pump_torque_nm),
            "turbine_speed_rad_s": series(self.turbine_speed_rad_s),
            "derivative_window_s": self.derivative_window_s,
            **_lockup(self.lockup_capacity_nm, self.lockup_static_to_kinetic, series),
        }


@dataclass(frozen=True)
class Speeds:
    """Drive (b): pump and turbine speeds given; the torques come out. A lock-up clutch can only
    slip (both speeds are given)."""

    time_s: ArrayLike
    pump_speed_rad_s: ArrayLike
    turbine_speed_rad_s: ArrayLike
    derivative_window_s: float = DERIVATIVE_WINDOW_S
    lockup_capacity_nm: ArrayLike | None = None
    lockup_static_to_kinetic: float | None = None

    def spec(self) -> dict[str, Any]:
        """The drive as the core's dict (``tcsim._core.transient_batch``), its series as lists."""
        return self._spec(_arr)

    def _core_spec(self) -> dict[str, Any]:
        """:meth:`spec` with its one-dimensional series as float64 arrays (what the runs pass)."""
        return self._spec(_series)

    def _spec(self, series: _Series) -> dict[str, Any]:
        return {
            "kind": "speeds",
            "time_s": series(self.time_s),
            "pump_speed_rad_s": series(self.pump_speed_rad_s),
            "turbine_speed_rad_s": series(self.turbine_speed_rad_s),
            "derivative_window_s": self.derivative_window_s,
            **_lockup(self.lockup_capacity_nm, self.lockup_static_to_kinetic, series),
        }


@dataclass(frozen=True)
class PumpTorqueLoad:
    """Drive (c): pump torque given; the turbine drives a load inertia against
    ``load_torque_nm + load_drag_nm_s2·ω_t|ω_t|``. Both speeds come out. A locked lock-up clutch
    makes pump and turbine turn as one."""

    time_s: ArrayLike
    pump_torque_nm: ArrayLike
    load_inertia_kg_m2: float
    load_torque_nm: ArrayLike = 0.0
    load_drag_nm_s2: float = 0.0
    lockup_capacity_nm: ArrayLike | None = None
    lockup_static_to_kinetic: float | None = None

    def spec(self) -> dict[str, Any]:
        """The drive as the core's dict (``tcsim._core.transient_batch``), its series as lists."""
        return self._spec(_arr)

    def _core_spec(self) -> dict[str, Any]:
        """:meth:`spec` with its one-dimensional series as float64 arrays (what the runs pass)."""
        return self._spec(_series)

    def _spec(self, series: _Series) -> dict[str, Any]:
        return {
            "kind": "pump-torque-load",
            "time_s": series(self.time_s),
            "pump_torque_nm": series(self.pump_torque_nm),
            "load_torque_nm": series(self.load_torque_nm),
            "load_inertia_kg_m2": float(self.load_inertia_kg_m2),
            "load_drag_nm_s2": float(self.load_drag_nm_s2),
            **_lockup(self.lockup_capacity_nm, self.lockup_static_to_kinetic, series),
        }


Drive = PumpTorqueTurbineSpeed | Speeds | PumpTorqueLoad


def isolated_takeoff(tip_out: bool = False) -> PumpTorqueLoad:
    """The isolated take-off of the tests and benchmarks (drive c), 0–10 s: pump torque 40 N·m,
    ramped to 250 N·m over 0.1–0.3 s (with ``tip_out``, down to −30 N·m over 5.0–5.1 s); the
    turbine drives 1.2 kg·m² against 10 N·m and 0.002 N·m/(rad/s)²."""
    t = [0.0, 0.1, 0.3] + ([5.0, 5.1] if tip_out else []) + [10.0]
    tp = [40.0, 40.0, 250.0] + ([250.0, -30.0, -30.0] if tip_out else [250.0])
    return PumpTorqueLoad(np.array(t), np.array(tp), load_inertia_kg_m2=1.2, load_torque_nm=10.0, load_drag_nm_s2=0.002)
