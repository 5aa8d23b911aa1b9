"""Figures of a Monte Carlo study (``tcsim monte-carlo``): one histogram per output, one outline per
model, over the cases whose run finished."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis.launch import SUMMARY_LABELS
from .common import finish_figure, mpl_text, plt
from .styles import model_style

#: Bins of each histogram (at most; fewer for few cases).
BINS = 40


def figure_name(output: str) -> str:
    """``monte_carlo_<output>.png``."""
    return f"monte_carlo_{output}.png"


#: A model whose values fill fewer of the shared bins than this gets bins of its own.
MIN_SHARED_BINS = 4


def histogram_bins(finite: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Each model's bin edges: the same bins for every model over all the values, unless a model
    whose values spread fills fewer than :data:`MIN_SHARED_BINS` of them (models far apart, each
    narrow: a trial's spread showed as one bar); then each model has bins over its own values."""
    everything = np.concatenate([v for v in finite.values()] or [np.empty(0)])
    if not everything.size:  # no run has a value (an output never reached, e.g. 0–100 km/h at part pedal)
        return {}
    count = min(BINS, max(5, int(np.sqrt(everything.size))))

    def edges(v: np.ndarray) -> np.ndarray:
        lo, hi = float(v.min()), float(v.max())
        return np.linspace(lo, hi if hi > lo else lo + 1.0, count + 1)

    shared = edges(everything)
    narrow = any(
        v.max() > v.min() and np.unique(np.digitize(v, shared[1:-1])).size < MIN_SHARED_BINS
        for v in finite.values()
        if v.size
    )
    return {m: edges(v) if narrow else shared for m, v in finite.items() if v.size}


def plot_histogram(df: pd.DataFrame, output: str, models: Sequence[str], path: Path, title: str) -> Path:
    """The histogram of ``output`` per model (its finite values) on :func:`histogram_bins`, and each
    model's mean and standard deviation in the legend."""
    fig, ax = plt.subplots(figsize=(7.5, 4.5), layout="constrained")
    values = {m: df.loc[df["model"] == m, output].to_numpy(dtype=float) for m in models}
    finite = {m: v[np.isfinite(v)] for m, v in values.items()}
    bins = histogram_bins(finite)
    for i, m in enumerate(models):
        v = finite[m]
        if not v.size:
            continue
        style = model_style(m, i)
        sd = float(v.std(ddof=1)) if v.size > 1 else float("nan")
        label = f"{style.label}: mean {v.mean():.4g}, std {sd:.3g} ({v.size} of {values[m].size} runs)"
        ax.hist(
            v, bins=bins[m].tolist(), histtype="step", color=style.colour, lw=style.linewidth, label=mpl_text(label)
        )
    if not bins:
        ax.text(0.5, 0.5, "no finished run has a value", transform=ax.transAxes, ha="center")
    ax.set_ylabel("Cases [-]")
    return finish_figure(fig, ax, path, title, xlabel=mpl_text(SUMMARY_LABELS.get(output, output)))


def plot_monte_carlo(
    df: pd.DataFrame, outputs: Sequence[str], models: Sequence[str], title: str, out_dir: Path
) -> list[Path]:
    """One PNG per output, :func:`figure_name`, into ``out_dir``."""
    return [plot_histogram(df, o, models, Path(out_dir) / figure_name(o), f"{title}: {o}") for o in outputs]
