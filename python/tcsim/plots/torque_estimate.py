"""Figures of ``tcsim torque-estimate``: the estimated against the measured engine torque (Li &
Sundén 2016, §3.3): over the whole record as logged and aligned with the error (cf. fig. 3.8), and
each load step zoomed (cf. figs 3.7 and 3.8). Measured: black; estimate as logged: red, its samples
marked; aligned estimate: blue dashed. Long series are drawn by :func:`drawn` (every peak kept)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..analysis.torque_estimate import TorqueComparison
from .common import mpl_text, plt, save_figure

#: The most steps drawn in ``steps.png`` (the first ones; steps.csv lists all).
MAX_STEP_PANELS = 12
#: Longer series are drawn as the smallest and the largest value of each of MAX_DRAWN / 2 bins (every
#: peak kept; the CSV files hold every sample).
MAX_DRAWN = 20_000
#: The estimate's samples are marked when a panel shows at most this many.
MAX_MARKERS = 2_000


def drawn(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(t, y)`` as drawn: as they are up to :data:`MAX_DRAWN` points, else the smallest and the
    largest value of each of ``MAX_DRAWN // 2`` consecutive bins, in time order (all-NaN bins stay
    gaps)."""
    n = len(t)
    if n <= MAX_DRAWN:
        return t, y
    size = math.ceil(n / (MAX_DRAWN // 2))
    bins = math.ceil(n / size)
    padded = np.full(bins * size, np.nan)
    padded[:n] = y
    blocks = padded.reshape(bins, size)
    base = np.arange(bins) * size
    lowest = base + np.argmin(np.where(np.isnan(blocks), np.inf, blocks), axis=1)
    highest = base + np.argmax(np.where(np.isnan(blocks), -np.inf, blocks), axis=1)
    picks = np.unique(np.minimum(np.concatenate([lowest, highest]), n - 1))
    return t[picks], y[picks]


def _as_logged(ax, comparison: TorqueComparison, lo: float, hi: float) -> None:
    """The estimate's own samples within [lo, hi] s, linear between them (what the grid holds)."""
    est = comparison.estimate
    keep = (est.time_s >= lo) & (est.time_s <= hi)
    marker = "." if keep.sum() <= MAX_MARKERS else None
    t, y = drawn(est.time_s[keep], est.torque_nm[keep])
    ax.plot(t, y, color="tab:red", lw=1.0, marker=marker, ms=3, label="estimate")


def plot_overview(comparison: TorqueComparison, out_dir: Path) -> Path:
    """``torque_estimate.png``: as logged (top), aligned by the delay (middle), errors (bottom)."""
    c = comparison
    t = c.time_s
    fig, axes = plt.subplots(3, 1, figsize=(7.2, 7.2), sharex=True, layout="constrained")
    axes[0].plot(*drawn(t, c.measured_nm), color="k", lw=1.2, label="measured")
    _as_logged(axes[0], c, t[0], t[-1])
    axes[0].set_ylabel("Engine torque [N·m]")
    axes[0].set_title(mpl_text(f"As logged: {Path(c.estimate.source).name} vs {Path(c.measured.source).name}"))
    axes[1].plot(*drawn(t, c.measured_nm), color="k", lw=1.2, label="measured")
    axes[1].plot(
        *drawn(t, c.aligned_nm), color="tab:blue", lw=1.0, ls="--", label=f"estimate shifted by {-c.delay_s:.4g} s"
    )
    axes[1].set_ylabel("Engine torque [N·m]")
    axes[1].set_title(f"Aligned: delay {c.delay_s:.4g} s (positive: the estimate lags)")
    axes[2].plot(*drawn(t, c.estimate_nm - c.measured_nm), color="tab:red", lw=1.0, label="as logged")
    axes[2].plot(*drawn(t, c.aligned_nm - c.measured_nm), color="tab:blue", lw=1.0, ls="--", label="aligned")
    axes[2].axhline(0.0, color="0.5", lw=0.8)
    axes[2].set_ylabel("Error, estimate − measured [N·m]")
    axes[2].set_xlabel("Time [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    path = Path(out_dir) / "torque_estimate.png"
    save_figure(fig, path)
    plt.close(fig)
    return path


def plot_steps(comparison: TorqueComparison, out_dir: Path) -> Path | None:
    """``steps.png``: each load step (the first :data:`MAX_STEP_PANELS`) with its 90 % level and
    the times each signal reaches it; None without steps."""
    c = comparison
    steps = c.steps[:MAX_STEP_PANELS]
    if not steps:
        return None
    cols = min(3, len(steps))
    rows = math.ceil(len(steps) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.0 * cols, 3.2 * rows), squeeze=False, layout="constrained")
    for number, (ax, s) in enumerate(zip(axes.flat, steps), start=1):
        window = slice(s.first, s.end)
        t = c.time_s[window]
        ax.plot(*drawn(t, c.measured_nm[window]), color="k", lw=1.2, label="measured")
        _as_logged(ax, c, t[0], t[-1])
        ax.plot(*drawn(t, c.aligned_nm[window]), color="tab:blue", lw=1.0, ls="--", label="aligned")
        ax.axhline(s.initial_nm + 0.9 * (s.final_nm - s.initial_nm), color="0.5", lw=0.8, ls=":", label="90 %")
        for when, colour in ((s.measured_t90_s, "k"), (s.estimate_t90_s, "tab:red")):
            if np.isfinite(when):
                ax.axvline(when, color=colour, lw=0.8, ls=":")
        error = s.estimate_t90_s - s.measured_t90_s
        ax.set_title(f"Step {number}: t90 error {error:.3g} s, RMSE {s.errors.rmse_nm:.3g} N·m", fontsize="small")
        ax.set_xlabel("Time [s]")
        ax.set_ylabel("Engine torque [N·m]")
        ax.grid(True, alpha=0.3)
    for ax in list(axes.flat)[len(steps) :]:
        ax.set_visible(False)
    axes.flat[0].legend(fontsize="x-small")
    if len(c.steps) > len(steps):
        fig.suptitle(f"The first {len(steps)} of {len(c.steps)} load steps (steps.csv lists all)", fontsize="medium")
    path = Path(out_dir) / "steps.png"
    save_figure(fig, path)
    plt.close(fig)
    return path


def plot_torque_estimate(comparison: TorqueComparison, out_dir: Path) -> list[Path]:
    """Every figure of a comparison into ``out_dir``; the paths written."""
    paths = [plot_overview(comparison, out_dir)]
    steps = plot_steps(comparison, out_dir)
    return paths + ([steps] if steps is not None else [])
