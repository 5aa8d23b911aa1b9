"""``tcsim.fitting``: the fit of Hrovat & Tobler parameters (docs/fitting.md), kept as a facade of
:mod:`tcsim.analysis.fitting`."""

from __future__ import annotations

from .analysis.fitting import DEFAULT_FREE, FitResult, fit_hrovat_tobler

__all__ = ["DEFAULT_FREE", "FitResult", "fit_hrovat_tobler"]
