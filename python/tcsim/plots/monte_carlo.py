"""Figures of a Monte Carlo study (``tcsim monte-carlo``): one histogram per output, one outline per
model, over the cases whose run finished."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .common import finish_figure, mpl_text, plt
from .styles import model_style

#: Bins of each histogram (at most; fewer for few cases).
BINS = 40


def figure_name(output: str) -> str:
    """``monte_carlo_<output>.png``."""
    return f"monte_carlo_{output}.png"


def plot_histogram(df: pd.DataFrame, output: str, models: Sequence[str], path: Path, title: str) -> Path:
    """The histogram of ``output`` per model (its finite values), the same bins for every model, and
    each model's mean and standard deviation in the legend."""
    fig, ax = plt.subplots(figsize=(7.5, 4.5), layout="constrained")
    values = {m: df.loc[df["model"] == m, output].to_numpy(dtype=float) for m in models}
    finite = {m: v[np.isfinite(v)] for m, v in values.items()}
    everything = np.concatenate([v for v in finite.values()] or [np.empty(0)])
    if everything.size:
        lo, hi = float(everything.min()), float(everything.max())
        bins = np.linspace(lo, hi if hi > lo else lo + 1.0, min(BINS, max(5, int(np.sqrt(everything.size)))) + 1)
        for i, m in enumerate(models):
            v = finite[m]
            if not v.size:
                continue
            style = model_style(m, i)
            sd = float(v.std(ddof=1)) if v.size > 1 else float("nan")
            label = f"{style.label}: mean {v.mean():.4g}, std {sd:.3g} ({v.size} of {values[m].size} runs)"
            ax.hist(
                v, bins=bins.tolist(), histtype="step", color=style.colour, lw=style.linewidth, label=mpl_text(label)
            )
    else:
        ax.text(0.5, 0.5, "no finished run has a value", transform=ax.transAxes, ha="center")
    ax.set_ylabel("Cases [-]")
    return finish_figure(fig, ax, path, title, xlabel=mpl_text(output))


def plot_monte_carlo(
    df: pd.DataFrame, outputs: Sequence[str], models: Sequence[str], title: str, out_dir: Path
) -> list[Path]:
    """One PNG per output, :func:`figure_name`, into ``out_dir``."""
    return [plot_histogram(df, o, models, Path(out_dir) / figure_name(o), f"{title}: {o}") for o in outputs]
