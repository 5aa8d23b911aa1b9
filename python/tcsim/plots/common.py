"""What every figure shares: the non-interactive Agg backend and the common finisher."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

__all__ = ["finish_figure", "plt"]


def finish_figure(fig, ax, path: Path, title: str, xlabel: str = "Time [s]") -> Path:
    """Label, grid, legend (when there are labelled lines), save at 120 dpi and close."""
    ax.set_xlabel(xlabel)
    ax.set_title(title, fontsize="medium")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
