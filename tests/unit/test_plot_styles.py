"""Model line styles (tcsim.plots.styles): a model curve without a finite value is drawn (issue 14:
``tcsim characterise`` of a fitted converter whose Hrovat & Tobler characteristic had no steady state
ended with matplotlib's IndexError on the markers)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from tcsim.plots.characteristic import QUANTITIES, plot_characteristic
from tcsim.plots.common import plt, save_figure
from tcsim.plots.styles import model_line


def test_a_line_without_finite_values_has_no_markers():
    assert "markevery" in model_line("hrovat-tobler", y=[1.0, np.nan])
    assert "markevery" not in model_line("hrovat-tobler", y=[np.nan, np.nan])


def test_a_model_with_no_steady_state_is_plotted(tmp_path):
    sr = np.linspace(0.0, 1.0, 11)
    finite = pd.DataFrame({"speed_ratio": sr, **{c: 1.0 + sr for c in QUANTITIES}})
    empty = pd.DataFrame({"speed_ratio": sr, **{c: np.full_like(sr, np.nan) for c in QUANTITIES}})
    paths = plot_characteristic({"table": finite, "hrovat-tobler": empty}, tmp_path, "no steady state")
    assert len(paths) == len(QUANTITIES) and all(p.stat().st_size > 0 for p in paths)


def test_a_saved_figure_with_a_line_without_points_is_drawn(tmp_path):
    # fresh-eyes trial: a launch whose converter transmitted nothing ended in an IndexError from
    # matplotlib's fractional markevery on an all-NaN line (plot_launch has no y= at its lines)
    fig, ax = plt.subplots()
    ax.plot([0.0, 1.0, 2.0], [np.nan] * 3, **model_line("hrovat-tobler"))
    ax.plot([0.0, 1.0, 2.0], [1.0, 2.0, 3.0], **model_line("table"))
    save_figure(fig, tmp_path / "f.png")
    plt.close(fig)
    assert (tmp_path / "f.png").stat().st_size > 0
