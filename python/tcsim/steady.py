"""``tcsim.steady``: steady-state characteristics per model, kept as a facade of :mod:`tcsim.models.steady`."""

from __future__ import annotations

from .models.steady import (
    characterise,
    characterise_hrovat_tobler,
    characterise_quasi_dynamic,
    characterise_table,
    coupling_point,
    hrovat_tobler_steady_state,
    steady_state,
)

__all__ = [
    "characterise",
    "characterise_hrovat_tobler",
    "characterise_quasi_dynamic",
    "characterise_table",
    "coupling_point",
    "hrovat_tobler_steady_state",
    "steady_state",
]
