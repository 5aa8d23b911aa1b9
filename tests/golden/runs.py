"""The runs behind the golden results: each takes a fresh output folder and the golden data
folder, runs one command of the public command line in-process, and returns its result files as
frames (decimated where a file is long), keyed by their path under the run's golden folder."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from tcsim.cli import main

Frames = dict[str, pd.DataFrame]

# Li & Sundén (2016) Table C.1, CF in N·m/(rad/s)²: the published table in tests/data
TABLE_C1 = Path(__file__).resolve().parents[1] / "data" / "converters" / "li_sunden_2016_table_c1.csv"


def make_measurement(path: Path) -> None:
    """A synthetic take-off: Hrovat & Tobler under the isolated take-off drive, 0–3 s at 1 kHz."""
    from tcsim import transient

    t = np.round(np.arange(3001) * 1e-3, 12)
    run = transient.simulate("li-sunden-2016", transient.isolated_takeoff(), "hrovat-tobler", times_s=t)
    f = run.frame()[["time_s", "pump_torque_nm", "turbine_speed_rad_s", "pump_speed_rad_s", "turbine_torque_nm"]]
    f.to_csv(path, index=False, float_format="%.17g")


def _run(*args: str) -> None:
    code = main([str(a) for a in args])
    if code != 0:
        raise RuntimeError(f"tcsim {' '.join(args)} exited {code}")


def _every(frame: pd.DataFrame, n: int) -> pd.DataFrame:
    return frame.iloc[::n].reset_index(drop=True)


def launch(out: Path, data: Path) -> Frames:
    _run("launch", "--out", out)
    frames = {"summary.csv": pd.read_csv(out / "summary.csv")}
    for model in ("table", "hrovat-tobler", "quasi-dynamic"):
        frames[f"{model}.csv"] = _every(pd.read_csv(out / f"{model}.csv"), 50)
    return frames


def replay(out: Path, data: Path) -> Frames:
    _run("replay", "li-sunden-2016", data / "takeoff_measurement.csv", "--out", out)
    frames = {"metrics.csv": pd.read_csv(out / "metrics.csv")}
    for model in ("table", "hrovat-tobler", "quasi-dynamic"):
        frames[f"{model}.csv"] = _every(pd.read_csv(out / f"{model}.csv"), 25)
    return frames


def characterise(out: Path, data: Path) -> Frames:
    frames = {}
    for model in ("hrovat-tobler", "table"):
        _run("characterise", "li-sunden-2016", "--model", model, "--out", out / model)
        frames[f"{model}.csv"] = pd.read_csv(out / model / "characteristic.csv")
    return frames


def study(out: Path, data: Path) -> Frames:
    _run("study", "li-sunden-2016", "--out", out)
    return {"study.csv": pd.read_csv(out / "study.csv")}


def fit(out: Path, data: Path) -> Frames:
    """What the fit determines: the fitted converter's characteristic and the fit's errors. Not its
    parameters: their Jacobian has rank 7 of 10 at the optimum (``fit_report.json``), and two BLAS
    kernels of one machine (OpenBLAS Haswell and SkylakeX) end 2e-3 apart in the pump exit angle
    with the same errors to 2e-7 and the same TR to 5e-9 (capacity factor 2.6e-6)."""
    _run("fit", "li-sunden-2016", "--target", TABLE_C1, "--out", out)
    _run("characterise", out / "fitted.toml", "--model", "hrovat-tobler", "--out", out / "characteristic")
    steady = pd.read_csv(out / "characteristic" / "characteristic.csv")
    errors = json.loads((out / "fit_report.json").read_text())["errors"]
    return {
        "characteristic.csv": steady[["speed_ratio", "torque_ratio", "capacity_factor_nm_s2", "efficiency"]],
        "errors.csv": pd.DataFrame(sorted(errors.items()), columns=["error", "value"]),
    }


RUNS: dict[str, Callable[[Path, Path], Frames]] = {
    "launch": launch,
    "replay": replay,
    "characterise": characterise,
    "study": study,
    "fit": fit,
}
