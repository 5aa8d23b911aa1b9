"""Worked example (d): a drive cycle with the three converter models.

The bundled mid-size AWD sedan follows the bundled US06 cycle (US EPA, 600 s, up to 129 km/h) with
each converter model; a driver (a PI controller with feed-forward, docs/drive.md) works the pedals.
The script prints, per model, how well the vehicle follows the trace, the engine's work, the
converter's and the lock-up clutch's losses, the brakes' energy, the energy balance's residual and
the share of time locked up, then how much of the highway part (trace above 80 km/h) the lock-up is
locked, and draws the speeds and the cumulative converter loss.

Run it::

    python docs/examples/drive_cycle.py [--out DIR] [--fast]

``--fast`` (what CI runs) cuts the cycle at 128 s: the first trips of US06, from rest to 104 km/h
and back to rest.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from tcsim.analysis.drive import Cycle, drive  # noqa: E402
from tcsim.io.cycle import cycle_from_option  # noqa: E402
from tcsim.models.vehicle import load_vehicle  # noqa: E402

KM_H_PER_M_S = 3.6
#: The trace speed above which the example calls the cycle "highway", km/h.
HIGHWAY_KM_H = 80.0
#: The lock-up state of a locked clutch in the drive's ``lockup_state`` column.
LOCKED = 2


def cut(cycle: Cycle, end_s: float) -> Cycle:
    """The first ``end_s`` seconds of ``cycle``."""
    keep = cycle.time_s <= end_s
    grade = None if cycle.grade_percent is None else cycle.grade_percent[keep]
    return dataclasses.replace(
        cycle, time_s=cycle.time_s[keep], vehicle_speed_m_s=cycle.vehicle_speed_m_s[keep], grade_percent=grade
    )


def number(x: float) -> str:
    """A summary value as printed: kJ to 0.1 kJ, the rest to 4 significant digits."""
    return f"{x:.1f}" if abs(x) >= 100 else f"{x:.4g}"


def main() -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("drive_cycle"), help="folder of the figure")
    parser.add_argument("--fast", action="store_true", help="the first 128 s of the cycle (CI)")
    args = parser.parse_args()

    # 1. The vehicle and the cycle (a bundled name or a trace file: time_s, vehicle_speed_m_s).
    vehicle = load_vehicle("midsize-awd-8at")
    cycle = cycle_from_option("us06")
    if args.fast:
        cycle = cut(cycle, 128.0)

    # 2. Every model the vehicle's converter supports (`tcsim drive --cycle us06`).
    result = drive(vehicle, cycle)

    # 3. The summary (docs/drive.md defines every column): tracking, energies in kJ, balance.
    columns = [
        "model",
        "rms_speed_error_km_h",
        "max_speed_error_km_h",
        "engine_work_kj",
        "converter_loss_kj",
        "lockup_loss_kj",
        "brake_energy_kj",
        "energy_residual",
        "lockup_time_fraction",
    ]
    print(result.summary[columns].to_string(index=False, float_format=number))

    # 4. The lock-up on the highway part: the share of the time above 80 km/h (trace) it is locked.
    print(f"share of the time above {HIGHWAY_KM_H:g} km/h with the lock-up locked:")
    for name, run in result.runs.items():
        frame = run.frame
        highway = frame["target_speed_m_s"] * KM_H_PER_M_S > HIGHWAY_KM_H
        share = float(np.mean(frame.loc[highway, "lockup_state"] == LOCKED)) if highway.any() else float("nan")
        print(f"{name} {share:.3f}")

    # 5. The figure: trace and vehicle speeds; the converter's cumulative loss.
    fig, (ax_speed, ax_loss) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    ax_speed.plot(cycle.time_s, cycle.vehicle_speed_m_s * KM_H_PER_M_S, color="0.6", lw=3, label="trace")
    for (name, run), style in zip(result.runs.items(), ("-", "--", ":")):
        f = run.frame
        ax_speed.plot(f["time_s"], f["vehicle_speed_m_s"] * KM_H_PER_M_S, style, label=name)
        ax_loss.plot(f["time_s"], f["converter_loss_j"] / 1000.0, style, label=name)
    ax_speed.set_ylabel("vehicle speed [km/h]")
    ax_loss.set_ylabel("converter loss, cumulative [kJ]")
    ax_loss.set_xlabel("time [s]")
    for ax in (ax_speed, ax_loss):
        ax.legend(fontsize=8)
        ax.grid(True, alpha=0.3)
    args.out.mkdir(parents=True, exist_ok=True)
    figure = args.out / "drive_cycle.png"
    fig.savefig(figure, dpi=120, bbox_inches="tight")
    print(f"figure: {figure}")
    return figure


if __name__ == "__main__":
    main()
