"""Launch scenarios: accelerator and brake pedal positions against time (Li & Sundén 2016 §3.2.2,
§3.5.1). :func:`flip_flop` and :func:`part_pedal` are the built-in ones; scenario files are read by
:func:`tcsim.io.scenario.read_scenario`. Time 0 is the start of the scenario: the vehicle at rest
(held by the brake if it is applied)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from ..errors import InputError
from ..units import KM_H

SPEED_50_KM_H_M_S = 50.0 * KM_H
SPEED_100_KM_H_M_S = 100.0 * KM_H
#: Time the flip-flop takes to swap the pedals, s.
PEDAL_SWAP_S = 0.05
#: Brake pedal position at or below which the brake counts as released (scenario files).
BRAKE_RELEASED = 1e-3


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
