"""Shared by the lock-up tests: the energy identity with the clutch booked, and output times dense
around a run's events (so that trapezoidal integrals see the jumps of the power columns)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from tcsim import transient


def energy_residual(f: pd.DataFrame) -> tuple[float, float]:
    """``∫P_in + W − (ΔE + ∫(fluid + clutch loss) + D)`` and the energy through the pump, J
    (docs/lockup.md, "Energy identity"), by the trapezoidal rule over the frame's samples."""
    t = f["time_s"].to_numpy()
    trap = lambda c: float(np.trapezoid(f[c].to_numpy(), t))  # noqa: E731
    lhs = trap("converter_input_power_w") + f["lockup_lock_work_j"].iloc[-1]
    rhs = (
        f["stored_energy_j"].iloc[-1]
        - f["stored_energy_j"].iloc[0]
        + trap("fluid_loss_power_w")
        + trap("lockup_loss_power_w")
        + f["lockup_lock_loss_j"].iloc[-1]
    )
    return lhs - rhs, float(np.trapezoid(np.abs(f["pump_torque_nm"] * f["pump_speed_rad_s"]), t))


def dense_run(converter, make: Callable, model: str, grid: np.ndarray) -> transient.TransientResult:
    """The run of drive ``make()`` sampled on ``grid`` plus each event's time and every 5 µs over the
    10 ms after it (the drive is the same; the solution does not depend on the output times, and
    the events must not move: asserted)."""
    first = transient.simulate(converter, make(), model, times_s=grid)
    after = np.arange(0, 2001) * 5e-6
    extra = np.unique(np.concatenate([e.time_s + after for e in first.events] or [[]]))
    extra = extra[(extra < grid[-1]) & np.concatenate([[True], np.diff(extra) >= 2e-6])]
    near = np.abs(grid[:, None] - extra[None, :]).min(axis=1) < 2e-6 if len(extra) else np.zeros(len(grid), bool)
    times = np.sort(np.concatenate([grid[~near], extra]))
    run = transient.simulate(converter, make(), model, times_s=times)
    assert [(e.time_s, e.kind) for e in run.events] == [(e.time_s, e.kind) for e in first.events]
    return run
