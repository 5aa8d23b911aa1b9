"""``tcsim.fmu``: FMU export (docs/fmu.md), kept as a facade of :mod:`tcsim.io.fmu`."""

from __future__ import annotations

from .io.fmu import (
    CAUSALITIES,
    SIGNALS,
    FmuLibraryError,
    export_fmu,
    find_libraries,
    fmu_parameters,
    model_description_xml,
    model_json,
)

__all__ = [
    "CAUSALITIES",
    "SIGNALS",
    "FmuLibraryError",
    "export_fmu",
    "find_libraries",
    "fmu_parameters",
    "model_description_xml",
    "model_json",
]
