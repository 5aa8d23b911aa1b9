"""Figures of the parameter study (Li & Sundén 2016, figures D.1–D.15)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis.study import ParameterRange
from .common import mpl_text, plt, save_figure

_PANELS = (
    ("torque_ratio", "Torque ratio [-]"),
    ("capacity_factor_nm_s2", "Capacity factor [N·m/(rad/s)²]"),
    ("flow_m3_s", "Volume flow [m³/s]"),
)


def _figure_path(out_dir: Path, key: str) -> Path:
    return Path(out_dir) / f"study_{key}.png"


def plot_parameter(
    df: pd.DataFrame, p: ParameterRange, reference: float, path: Path, title: str, dpi: int = 100
) -> Path:
    """Three panels (TR, CF, volume flow against SR), one line per value; the reference in black;
    saved at ``dpi`` dots per inch."""
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.2), layout="constrained")
    rows = df[df["parameter"] == p.key]
    values = rows["parameter_value"].unique()
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, len(values)))
    for value, colour in zip(values, colours):
        curve = rows[rows["parameter_value"] == value]
        is_ref = value == reference
        label = f"{value:.4g} {p.unit}" + (" (reference)" if is_ref else "")
        style = dict(color="k", lw=2.0, zorder=3) if is_ref else dict(color=colour, lw=1.3)
        for ax, (column, _) in zip(axes, _PANELS):
            ax.plot(curve["speed_ratio"], curve[column], marker=".", ms=4, label=mpl_text(label), **style)
    for ax, (_, ylabel) in zip(axes, _PANELS):
        ax.set_xlabel("Speed ratio [-]")
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    axes[0].legend(title=mpl_text(f"{p.label} [{p.unit}]"), fontsize="small")
    fig.suptitle(mpl_text(f"Effect of parameter '{p.label}': {title}"))
    save_figure(fig, path, dpi)
    plt.close(fig)
    return path


def plot_study(
    df: pd.DataFrame,
    parameters: Sequence[ParameterRange],
    references: Mapping[str, float],
    title: str,
    out_dir: Path,
) -> list[Path]:
    """One PNG per parameter, ``study_<parameter>.png``, like thesis figures D.1–D.15; ``references``
    holds the converter's own value of each parameter (drawn in black)."""
    return [plot_parameter(df, p, references[p.key], _figure_path(out_dir, p.key), title) for p in parameters]
