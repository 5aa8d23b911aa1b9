"""The runs behind the golden results: each takes a fresh output folder and the golden data
folder, runs one command of the public command line in-process, and returns its result files as
frames (decimated where a file is long), keyed by their path under the run's golden folder."""

from __future__ import annotations

import tomllib
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
    _run("fit", "li-sunden-2016", "--target", TABLE_C1, "--out", out)
    fitted = tomllib.loads((out / "fitted.toml").read_text())
    rows = [
        (f"{section}.{key}", float(value))
        for section, table in sorted(fitted.items())
        if isinstance(table, dict)
        for key, value in sorted(table.items())
        if isinstance(value, (int, float)) and not isinstance(value, bool)
    ]
    return {"fitted.csv": pd.DataFrame(rows, columns=["parameter", "value"])}


RUNS: dict[str, Callable[[Path, Path], Frames]] = {
    "launch": launch,
    "replay": replay,
    "characterise": characterise,
    "study": study,
    "fit": fit,
}
