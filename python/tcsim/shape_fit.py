"""``tcsim.shape_fit``: shape effects fitted to a measurement, and the sweep (docs/shape_fit.md), kept
as a facade. The code lives in :mod:`tcsim.analysis.shape_fit`, :mod:`tcsim.models.shape_effects`,
:mod:`tcsim.plots.shape_sweep` and :mod:`tcsim.cli.fit_shapes`."""

from __future__ import annotations

from .analysis.effective import measured_effective_torques, smoothed_rate
from .analysis.shape_fit import ShapeFitResult, fit_shape_effects, shape_effect_sweep, sweep_minima
from .cli.fit_shapes import shape_fit_command
from .models.shape_effects import THESIS_PAIR_M2, THESIS_VALUES_M2, MassMatrixBound, mass_matrix_bound
from .plots.shape_sweep import plot_shape_effect_sweep

__all__ = [
    "THESIS_PAIR_M2",
    "THESIS_VALUES_M2",
    "MassMatrixBound",
    "ShapeFitResult",
    "fit_shape_effects",
    "mass_matrix_bound",
    "measured_effective_torques",
    "plot_shape_effect_sweep",
    "shape_effect_sweep",
    "shape_fit_command",
    "smoothed_rate",
    "sweep_minima",
]
