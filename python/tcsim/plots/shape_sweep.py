"""Figures of the shape-effect sweep (Li & Sundén 2016, figures 4.1/4.2)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import pandas as pd

from .common import mpl_text, plt, save_figure
from .styles import model_line

_PLOTS = (
    ("time_s", "effective_torque_ratio", "Time [s]", "Effective torque ratio [-]", "effective_torque_ratio_time.png"),
    (
        "speed_ratio",
        "effective_torque_ratio",
        "Speed ratio [-]",
        "Effective torque ratio [-]",
        "effective_torque_ratio_speed_ratio.png",
    ),
    (
        "time_s",
        "effective_turbine_torque_nm",
        "Time [s]",
        "Effective turbine output torque [N·m]",
        "effective_turbine_torque_time.png",
    ),
)


def plot_shape_effect_sweep(
    df: pd.DataFrame,
    out_dir,
    title: str,
    measured: pd.DataFrame | Mapping | None = None,
    steady: pd.DataFrame | Mapping | None = None,
) -> list[Path]:
    """Effective TR against time and against SR, and the effective turbine torque against time,
    one line per admissible shape-effect pair (like thesis figures 4.1/4.2), with the measurement
    (black) and the steady-state table model (dashed) when given. PNG files in ``out_dir``."""
    extra = [
        (d, style)
        for d, style in (
            (steady, model_line("table", label="SS model")),
            (measured, dict(color="k", lw=1.2, label="Measurement")),
        )
        if d is not None
    ]
    paths = []
    for x, y, xlabel, ylabel, filename in _PLOTS:
        fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
        for label, g in df[df["admissible"]].groupby("label", sort=False):
            ax.plot(g[x], g[y], lw=1.0, label=mpl_text(label))
        for d, style in extra:
            d = pd.DataFrame(d)
            if x in d and y in d:
                ax.plot(d[x], d[y], **style)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(mpl_text(title))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
        path = Path(out_dir) / filename
        save_figure(fig, path)
        plt.close(fig)
        paths.append(path)
    return paths
