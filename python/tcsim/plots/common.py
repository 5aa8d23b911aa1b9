"""What every figure shares: the non-interactive Agg backend, the one escape of text for
matplotlib and the common finisher."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

__all__ = ["finish_figure", "mpl_text", "plt"]

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


def finish_figure(fig, ax, path: Path, title: str, xlabel: str = "Time [s]") -> Path:
    """Label, grid, legend (when there are labelled lines), save at 120 dpi and close."""
    ax.set_xlabel(xlabel)
    ax.set_title(mpl_text(title), fontsize="medium")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
