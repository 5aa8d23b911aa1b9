"""What every figure shares: the non-interactive Agg backend, the one escape of text for
matplotlib and the common finisher."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

__all__ = ["finish_figure", "fixed_figure", "mpl_text", "plt"]

#: Control characters, tab and newline included (shown as ``\x01``, ``\t``), and lone surrogates (a
#: non-UTF-8 file name decoded with ``surrogateescape``; shown as U+FFFD): matplotlib cannot draw them.
_UNDRAWABLE = re.compile("[\x00-\x1f\x7f\ud800-\udfff]")


def _undrawable(match: re.Match[str]) -> str:
    c = match.group()
    return "\ufffd" if "\ud800" <= c <= "\udfff" else c.encode("unicode_escape").decode("ascii")


def mpl_text(text: Any) -> str:
    """``text`` (a title, label or legend entry built from user strings) drawn by matplotlib as it
    is: ``$`` escaped so that nothing is read as mathtext, undrawable characters replaced. Every user
    string that reaches matplotlib goes through here."""
    return _UNDRAWABLE.sub(_undrawable, str(text)).replace("$", r"\$")


#: Margins of a figure of one axes and of two stacked axes, fractions of the figure: room for the
#: tick labels and the axis label on the left, the x label below and a one-line title above at the
#: sizes :func:`fixed_figure` is used with (6.4–7.2 in wide, 4.2–5.6 in high).
MARGINS_ONE = {"left": 0.11, "right": 0.97, "bottom": 0.12, "top": 0.91}
MARGINS_TWO = {"left": 0.11, "right": 0.97, "bottom": 0.09, "top": 0.93}


def fixed_figure(figsize: tuple[float, float], height_ratios: tuple[float, ...] | None = None, hspace: float = 0.08):
    """A figure of one axes, or of ``len(height_ratios)`` stacked axes sharing x, with fixed margins.

    Fixed margins instead of matplotlib's constrained layout: the layout engine draws every figure
    twice (once to measure its text), which made the six figures of ``tcsim launch`` take 0.55 s
    more CPU (1.40 s against 0.85 s, measured 2026-11-24). ``hspace``: the gap between stacked axes
    (fraction of their mean height; 0.2 leaves room for a one-line title of the lower axes).
    Returns ``(fig, ax)`` or ``(fig, axes)``."""
    if height_ratios is None:
        fig, ax = plt.subplots(figsize=figsize)
        fig.subplots_adjust(**MARGINS_ONE)
        return fig, ax
    fig, axes = plt.subplots(
        len(height_ratios), 1, figsize=figsize, sharex=True, gridspec_kw={"height_ratios": list(height_ratios)}
    )
    fig.subplots_adjust(**{**MARGINS_TWO, "hspace": hspace})
    return fig, axes


def _no_markers_without_points(fig) -> None:
    """Drop the markers of every line without a finite point: matplotlib (3.10) fails to draw a
    fractional ``markevery`` on one (an IndexError that ended a launch whose converter transmits
    nothing, found by a fresh-eyes trial; before it ``tcsim characterise`` of a fitted converter)."""
    for ax in fig.axes:
        for line in ax.get_lines():
            try:
                x, y = (np.asarray(v, dtype=float) for v in line.get_data())
            except (TypeError, ValueError):  # not numbers (no such line here): matplotlib's business
                continue
            if not (np.isfinite(x) & np.isfinite(y)).any():
                line.set_marker("")
                line.set_markevery(None)


def save_figure(fig, path: Path, dpi: int = 120) -> None:
    """Save ``fig`` as every figure of tcsim is saved (markers only on lines that have points)."""
    _no_markers_without_points(fig)
    fig.savefig(path, dpi=dpi)


def finish_figure(fig, ax, path: Path, title: str, xlabel: str = "Time [s]") -> Path:
    """Label, grid, legend (when there are labelled lines), save at 120 dpi and close."""
    ax.set_xlabel(xlabel)
    ax.set_title(mpl_text(title), fontsize="medium")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    save_figure(fig, path)
    plt.close(fig)
    return path
