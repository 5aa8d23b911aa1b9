"""Figures: steady-state characteristics (thesis figures 3.3, 3.4, C.1, C.2). A curve named after a
model (``"hrovat-tobler model"``) is drawn in that model's style, others in turn in the other
styles of :mod:`tcsim.plots.styles`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..models.characteristic import Characteristic
from ..models.steady import ratio_frame
from .common import mpl_text, plt, save_figure
from .styles import model_line

QUANTITIES = {
    "torque_ratio": ("Torque ratio [-]", "torque_ratio.png"),
    "capacity_factor_nm_s2": ("Capacity factor [N·m/(rad/s)²]", "capacity_factor.png"),
    "k_factor_rpm_per_sqrt_nm": ("K-factor [rpm/√(N·m)]", "k_factor.png"),
    "efficiency": ("Efficiency [-]", "efficiency.png"),
}


def table_columns(table: Characteristic) -> pd.DataFrame:
    return ratio_frame(*table.arrays())


def plot_characteristic(
    curves: dict[str, pd.DataFrame],
    out_dir: Path,
    title: str,
    table: Characteristic | None = None,
    table_label: str = "Manufacturer table",
    coupling_point: float | None = None,
) -> list[Path]:
    """One PNG per quantity against SR; model curves as lines, the table as markers beside them."""
    ref = table_columns(table) if table is not None else None
    paths = []
    for column, (label, filename) in QUANTITIES.items():
        fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
        for i, (name, df) in enumerate(curves.items()):
            y = np.where(np.isfinite(df[column].to_numpy(dtype=float)), df[column].to_numpy(dtype=float), np.nan)
            ax.plot(df["speed_ratio"], y, **model_line(name, i, label=mpl_text(name), y=y))
        if ref is not None:
            y = ref[column].to_numpy(dtype=float)
            y = np.where(np.isfinite(y), y, np.nan)
            ax.plot(ref["speed_ratio"], y, "o", mfc="none", color="k", label=mpl_text(table_label))
        if coupling_point is not None:
            ax.axvline(coupling_point, color="0.6", ls=":", lw=1, label=f"coupling point SR {coupling_point:.3f}")
        ax.set_xlabel("Speed ratio [-]")
        ax.set_ylabel(label)
        ax.set_title(mpl_text(title))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
        path = out_dir / filename
        save_figure(fig, path)
        plt.close(fig)
        paths.append(path)
    return paths
