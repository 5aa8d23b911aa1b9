"""Worked example (c): the launch comparison (Li & Sundén 2016, §3.2.2, §3.5.2.2, §4.1).

The bundled mid-size sedan stands braked in first gear, then the brake comes off and the pedal goes
to the floor ("flip-flop"); the three converter models run on the same vehicle. The script prints
the comparison (times to 50 and 100 km/h, the dip of the effective torque ratio against the table
model) and draws vehicle speed and effective torque ratio after the brake release, like thesis
figures 3.5 and 3.6.

Run it::

    python docs/examples/launch_comparison.py [--out DIR] [--fast]

``--fast`` (what CI runs) holds the brake 1 s instead of 5 s and stops the run 4 s later (the
vehicle passes 50 km/h but not 100 km/h); the figure and the 0–50 km/h times are those of the full
run up to that point.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402

from tcsim.analysis.launch import run_comparison  # noqa: E402
from tcsim.models.vehicle import load_vehicle  # noqa: E402
from tcsim.simulation.scenarios import flip_flop  # noqa: E402

KM_H_PER_M_S = 3.6


def main() -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("launch_comparison"), help="folder of the figure")
    parser.add_argument("--fast", action="store_true", help="a short run (CI)")
    args = parser.parse_args()

    # 1. The vehicle (a bundled name or your vehicle .toml) and the scenario.
    vehicle = load_vehicle("midsize-awd-8at")
    hold_s, end_s = (1.0, 5.0) if args.fast else (5.0, 30.0)
    scenario = flip_flop(hold_s=hold_s, end_time_s=end_s)

    # 2. Every model the vehicle's converter supports, in one core call.
    launch = run_comparison(vehicle, scenario)
    release_s = scenario.brake_release_time_s

    # 3. The comparison: one row per model (docs/launch_summary.md defines every column).
    columns = ["model", "time_0_50_km_h_s", "time_0_100_km_h_s", "effective_torque_ratio_dip_first_0_5_s"]
    print(launch.summary[columns].to_string(index=False))

    # 4. The figure: speed and effective torque ratio after the brake release, one line style per model.
    fig, (ax_speed, ax_etr) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    for (name, frame), style in zip(launch.frames.items(), ("-", "--", ":")):
        t = frame["time_s"] - release_s
        ax_speed.plot(t, frame["vehicle_speed_m_s"] * KM_H_PER_M_S, style, label=name)
        ax_etr.plot(t, frame["effective_torque_ratio"], style, label=name)
    ax_speed.set_ylabel("vehicle speed [km/h]")
    ax_etr.set_ylabel("effective torque ratio [-]")
    ax_etr.set_xlabel("time after brake release [s]")
    ax_etr.set_xlim(-0.5, 3.0)
    ax_speed.legend()
    for ax in (ax_speed, ax_etr):
        ax.grid(True, alpha=0.3)
    args.out.mkdir(parents=True, exist_ok=True)
    figure = args.out / "launch_comparison.png"
    fig.savefig(figure, dpi=120, bbox_inches="tight")
    print(f"figure: {figure}")
    return figure


if __name__ == "__main__":
    main()
