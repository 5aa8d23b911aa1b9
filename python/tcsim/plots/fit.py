"""Figures of ``tcsim fit``: the fitted and start models against the target table, over the drive range.

The axes span SR 0–1 (the fitted range and the model's free-wheeling part), whatever else the table
holds: the rows of a table with coast rows (SR > 1) or reverse rows (SR < 0) lie outside what was
fitted and would squeeze it into a corner (their CF changes sign), so they are left out and the
legend counts them. The fitted range SR 0–SR_max is shaded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..models.characteristic import Characteristic
from .characteristic import QUANTITIES, table_columns
from .common import mpl_text, plt, save_figure
from .styles import model_line

#: The speed-ratio span of the figures: the drive range the fit's model covers.
SR_SPAN = (0.0, 1.0)


def _limits(values: list[np.ndarray]) -> tuple[float, float] | None:
    finite = np.concatenate([v[np.isfinite(v)] for v in values]) if values else np.array([])
    if finite.size == 0:
        return None
    lo, hi = float(finite.min()), float(finite.max())
    pad = 0.05 * (hi - lo) if hi > lo else 0.05 * max(abs(hi), 1e-12)
    return lo - pad, hi + pad


def fit_figure(
    column: str,
    curves: dict[str, pd.DataFrame],
    title: str,
    table: Characteristic,
    speed_ratio_max: float,
    coupling_point: float | None = None,
):
    """The figure of one quantity (a key of :data:`~.characteristic.QUANTITIES`) against SR 0–1, open:
    model curves as lines of distinct styles (:mod:`tcsim.plots.styles`), the table's rows in SR 0–1
    as markers (the legend counts those left out), the fitted range SR 0–``speed_ratio_max`` shaded,
    the y-axis fitted to what is shown."""
    ref = table_columns(table)
    sr = ref["speed_ratio"].to_numpy(dtype=float)
    inside = (sr >= SR_SPAN[0]) & (sr <= SR_SPAN[1])
    left_out = int((~inside).sum())
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    shown = []
    for i, (name, df) in enumerate(curves.items()):
        x, y = df["speed_ratio"].to_numpy(dtype=float), df[column].to_numpy(dtype=float)
        y = np.where(np.isfinite(y) & (x >= SR_SPAN[0]) & (x <= SR_SPAN[1]), y, np.nan)
        ax.plot(x, y, **model_line(name, i, label=mpl_text(name), y=y))
        shown.append(y)
    y = ref[column].to_numpy(dtype=float)[inside]
    rows = f"Target table ({left_out} rows outside SR 0–1 not shown)" if left_out else "Target table"
    ax.plot(sr[inside], y, "o", mfc="none", color="k", label=mpl_text(rows))
    shown.append(y)
    ax.axvspan(0.0, speed_ratio_max, color="0.9", zorder=0, label=f"fitted range SR 0–{speed_ratio_max:g}")
    if coupling_point is not None:
        ax.axvline(coupling_point, color="0.6", ls=":", lw=1, label=f"coupling point SR {coupling_point:.3f}")
    ax.set_xlim(*SR_SPAN)
    limits = _limits(shown)
    if limits is not None:
        ax.set_ylim(*limits)
    ax.set_xlabel("Speed ratio [-]")
    ax.set_ylabel(QUANTITIES[column][0])
    ax.set_title(mpl_text(title))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig, ax


def plot_fit(
    curves: dict[str, pd.DataFrame],
    out_dir: Path,
    title: str,
    table: Characteristic,
    speed_ratio_max: float,
    coupling_point: float | None = None,
) -> list[Path]:
    """One PNG per quantity (``torque_ratio.png`` …): :func:`fit_figure` of each, at 120 dpi."""
    paths = []
    for column, (_, filename) in QUANTITIES.items():
        fig, _ = fit_figure(column, curves, title, table, speed_ratio_max, coupling_point)
        path = out_dir / filename
        save_figure(fig, path)
        plt.close(fig)
        paths.append(path)
    return paths
