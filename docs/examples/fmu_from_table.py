"""Worked example (a): from a manufacturer's K-factor table to an FMU simulated in FMPy.

The steps a user takes, each a ``tcsim`` command run here as a subprocess (so this script is the
command line, not an internal API):

1. ``tcsim init converter --from TABLE``: the table as a converter file for the ``table`` model;
2. ``tcsim fit li-sunden-2016 --target TABLE``: Hrovat & Tobler parameters fitted to the table,
   starting from the thesis's converter (its inertias are kept and said so: replace them with
   your converter's);
3. ``tcsim export-fmu fit/fitted.toml --model hrovat-tobler``: an FMI 2.0 FMU (Model Exchange and
   Co-Simulation, inputs pump torque and turbine speed);
4. FMPy simulates the FMU's co-simulation on a take-off: the engine torque ramps up while the
   turbine, held by the vehicle, speeds up. The script prints and draws the pump speed and turbine
   torque.

Run it::

    python docs/examples/fmu_from_table.py [--table TABLE.csv] [--out DIR] [--fast]

``TABLE`` defaults to the Project Chrono HMMWV converter (a K-factor table in
``tests/data/converters/chrono_hmmwv.csv``; the columns tcsim reads are in docs/conventions.md).
``--fast`` (what CI runs) fits with one start instead of the default multi-start and simulates 2 s
instead of 5 s.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import fmpy
import matplotlib
import numpy as np

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
TABLE = REPO / "tests" / "data" / "converters" / "chrono_hmmwv.csv"


def tcsim(*args: str | Path) -> None:
    """One ``tcsim`` command, as typed in a shell; stops the example if it fails."""
    print("$ tcsim", *args)
    subprocess.run([sys.executable, "-m", "tcsim", *map(str, args)], check=True)


def takeoff_inputs(end_s: float) -> np.ndarray:
    """The FMU's inputs every 1 ms: pump torque 40 → 250 N·m over 0.1–0.3 s; a turbine that the
    vehicle speeds up from rest (150 rad/s·(t/3 s)², then held), with its rate, which a master should
    give (docs/fmu.md: without it the FMU estimates the rate from the last interval); the lock-up
    clutch open (capacity 0)."""
    t = np.round(np.arange(0.0, end_s + 5e-4, 1e-3), 6)
    names = ("time", "pump_torque_nm", "turbine_speed_rad_s", "turbine_accel_rad_s2", "lockup_capacity_nm")
    inputs = np.zeros(len(t), dtype=[(name, float) for name in names])
    inputs["time"] = t
    inputs["pump_torque_nm"] = np.interp(t, [0.0, 0.1, 0.3, end_s], [40.0, 40.0, 250.0, 250.0])
    ramp = np.clip(t / 3.0, 0.0, 1.0)
    inputs["turbine_speed_rad_s"] = 150.0 * ramp**2
    inputs["turbine_accel_rad_s2"] = np.where(t < 3.0, 100.0 * ramp, 0.0)  # d/dt of 150 (t/3)²
    return inputs


def main() -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=TABLE, help="K-factor or capacity table (.csv, .vtcc)")
    parser.add_argument("--out", type=Path, default=Path("fmu_from_table"), help="folder of every file")
    parser.add_argument("--fast", action="store_true", help="a short run (CI)")
    args = parser.parse_args()
    out = args.out
    out.mkdir(parents=True, exist_ok=True)

    # 1. The table as a converter file: the table model runs on it at once.
    tcsim("init", "converter", "--from", args.table, "--out", out / "table.toml", "--force")
    tcsim("characterise", out / "table.toml", "--model", "table", "--no-plots", "--out", out / "table")

    # 2. Hrovat & Tobler fitted to the table (fit_report.md says what was fitted, derived and kept).
    free = ["--free", "friction_loss,pump_exit_angle_deg,turbine_exit_angle_deg,stator_exit_angle_deg"]
    tcsim("fit", "li-sunden-2016", "--target", args.table, *(free if args.fast else []), "--out", out / "fit")

    # 3. The FMU of the fitted converter.
    fmu = out / "converter.fmu"
    tcsim("export-fmu", out / "fit" / "fitted.toml", "--model", "hrovat-tobler", "-o", fmu)

    # 4. FMPy: co-simulation every 1 ms with the take-off's inputs.
    end_s = 2.0 if args.fast else 5.0
    inputs = takeoff_inputs(end_s)
    result = fmpy.simulate_fmu(str(fmu), fmi_type="CoSimulation", input=inputs, output_interval=1e-3, stop_time=end_s)
    t = result["time"]
    print(f"{'time [s]':>9} {'pump speed [rad/s]':>19} {'turbine torque [N·m]':>21}")
    for k in np.searchsorted(t, [0.0, 0.25, 0.5, 1.0, end_s]).clip(max=len(t) - 1):
        print(f"{t[k]:9.3f} {result['pump_speed_rad_s'][k]:19.2f} {result['turbine_torque_nm'][k]:21.2f}")

    fig, (ax_speed, ax_torque) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    ax_speed.plot(t, result["pump_speed_rad_s"], label="pump")
    ax_speed.plot(inputs["time"], inputs["turbine_speed_rad_s"], "--", label="turbine (input)")
    ax_speed.set_ylabel("Speed [rad/s]")
    ax_speed.legend()
    ax_torque.plot(t, result["turbine_torque_nm"], label="turbine torque")
    ax_torque.plot(inputs["time"], inputs["pump_torque_nm"], "--", label="pump torque (input)")
    ax_torque.set_ylabel("Torque [N·m]")
    ax_torque.set_xlabel("Time [s]")
    ax_torque.legend()
    fig.suptitle(f"{fmu.name} (Hrovat & Tobler fitted to {args.table.name}) in FMPy")
    figure = out / "fmu_takeoff.png"
    fig.savefig(figure, dpi=120)
    return figure


if __name__ == "__main__":
    print("wrote", main())
