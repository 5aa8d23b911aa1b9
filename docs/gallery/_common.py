"""What the gallery scripts share: the command line (``--fast``, ``--out DIR``) and how a figure is
saved (``fig_<number>.png`` at :data:`DPI` with its plotted data beside it as ``fig_<number>.csv``).

Not a part of tcsim: a helper of the scripts in ``docs/gallery/`` (each script's folder is on its
``sys.path`` when it runs, so ``from _common import ...`` finds it).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from tcsim.analysis.launch import run_comparison
from tcsim.models.vehicle import Vehicle, load_vehicle
from tcsim.plots.common import plt
from tcsim.simulation.scenarios import Scenario

#: Resolution of the gallery's PNG files, dots per inch (the committed images stay under ~100 kB).
DPI = 90
#: The bundled vehicle of the launches (converter ``li-sunden-2016-fitted``).
VEHICLE = "midsize-awd-8at"
#: The logged channels of the synthetic measurements (SI, tcsim's canonical names), and their rate, s.
CHANNELS = ["time_s", "pump_torque_nm", "pump_speed_rad_s", "turbine_speed_rad_s", "turbine_torque_nm"]
LOG_STEP_S = 0.01


def parse_args(doc: str | None, default_out: str) -> argparse.Namespace:
    """``--fast`` (a shorter run for CI) and ``--out DIR`` (the folder of the figures, created)."""
    parser = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(default_out), help="folder of the figures and their CSV data")
    parser.add_argument("--fast", action="store_true", help="a shorter run with fewer points (CI)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    return args


def save(fig, out: Path, name: str, data: pd.DataFrame, title: str) -> Path:
    """Title ``fig`` with the thesis figure's caption, save it as ``out/<name>.png`` and its plotted
    ``data`` as ``out/<name>.csv``; close the figure and print the PNG's path."""
    fig.suptitle(title, fontsize="medium")
    png = out / f"{name}.png"
    fig.savefig(png, dpi=DPI)
    plt.close(fig)
    data.to_csv(out / f"{name}.csv", index=False)
    print(f"{name}: {png}")
    return png


def tidy(curves: dict[str, pd.DataFrame], columns: list[str]) -> pd.DataFrame:
    """One long frame of the plotted ``columns`` of each curve, with a leading ``curve`` column."""
    parts = [df[columns].assign(curve=name) for name, df in curves.items()]
    frame = pd.concat(parts, ignore_index=True)
    return frame[["curve", *columns]]


def synthetic_measurement(scenario: Scenario, path: Path) -> tuple[Vehicle, pd.DataFrame]:
    """The gallery's stand-in for the thesis's measurements (not public): the bundled vehicle
    launched under ``scenario`` with the quasi-dynamic (Drenth) model of its converter, logged at
    :data:`LOG_STEP_S` with :data:`CHANNELS` and written to ``path`` (CSV). Returns the vehicle and
    the log."""
    vehicle = load_vehicle(VEHICLE)
    frame = run_comparison(vehicle, scenario, models=["quasi-dynamic"]).frames["quasi-dynamic"]
    t = np.round(np.arange(0.0, scenario.end_time_s + 1e-9, LOG_STEP_S), 9)
    log = pd.DataFrame({c: np.interp(t, frame["time_s"], frame[c]) for c in CHANNELS[1:]}).assign(time_s=t)
    log = log[CHANNELS]
    log.to_csv(path, index=False)
    return vehicle, log
