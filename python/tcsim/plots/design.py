"""Figures of ``tcsim design``: the isolated take-off and the vehicle launch of a design against a
reference converter (effective torque ratio and turbine or vehicle speed against time;
docs/design.md, "tcsim design")."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import pandas as pd

from .common import finish_figure, mpl_text, plt
from .styles import model_line

#: The take-off figures: column, axis label, file name.
TAKEOFF_FIGURES = (
    ("effective_torque_ratio", "Effective torque ratio [-]", "takeoff_effective_torque_ratio.png"),
    ("turbine_speed_rad_s", "Turbine speed [rad/s]", "takeoff_turbine_speed.png"),
)
#: The launch figures: column, axis label, file name.
LAUNCH_FIGURES = (
    ("effective_torque_ratio", "Effective torque ratio [-]", "launch_effective_torque_ratio.png"),
    ("vehicle_speed_m_s", "Vehicle speed [m/s]", "launch_vehicle_speed.png"),
)
#: The time window of the take-off's effective-torque-ratio figure, s (the dip is in the first seconds).
DIP_WINDOW_S = (0.0, 3.0)


def _plot_runs(runs: Mapping[str, pd.DataFrame], figures, window_s: float, out_dir: Path, title: str) -> list[Path]:
    """One PNG per ``figures`` entry (column, label, file), a line per run; the effective-TR figure
    over the first ``window_s`` seconds only."""
    paths = []
    for column, label, filename in figures:
        fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
        for i, (name, df) in enumerate(runs.items()):
            frame = df[df["time_s"] <= window_s] if column == "effective_torque_ratio" else df
            y = frame[column]
            ax.plot(frame["time_s"], y, **model_line(name, i, label=mpl_text(name), y=y))
        ax.set_ylabel(label)
        paths.append(finish_figure(fig, ax, Path(out_dir) / filename, title))
    return paths


def plot_design_takeoff(takeoffs: Mapping[str, pd.DataFrame], out_dir: Path, title: str) -> list[Path]:
    """One PNG per :data:`TAKEOFF_FIGURES` entry in ``out_dir``, a line per converter (``takeoffs``:
    converter name → take-off frame with ``time_s`` in s); the paths written."""
    return _plot_runs(takeoffs, TAKEOFF_FIGURES, DIP_WINDOW_S[1], out_dir, title)


def plot_design_launch(launches: Mapping[str, pd.DataFrame], out_dir: Path, title: str) -> list[Path]:
    """One PNG per :data:`LAUNCH_FIGURES` entry in ``out_dir``, a line per converter (``launches``:
    converter name → launch frame with ``time_s`` in s, the brake released at 1 s); the paths
    written."""
    return _plot_runs(launches, LAUNCH_FIGURES, float("inf"), out_dir, title)
