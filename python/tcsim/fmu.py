"""``tcsim.fmu``: FMU export (docs/fmu.md), kept as a facade of :mod:`tcsim.io.fmu`."""

from __future__ import annotations

from .io.fmu import (
    CAUSALITIES,
    FMI2,
    SIGNALS,
    FmuLibraryError,
    export_fmu,
    find_libraries,
    fmu_parameters,
    model_description_xml,
    model_json,
)
from .io.fmu3 import FMI3, fmi_version

__all__ = [
    "CAUSALITIES",
    "FMI2",
    "FMI3",
    "SIGNALS",
    "FmuLibraryError",
    "export_fmu",
    "find_libraries",
    "fmi_version",
    "fmu_parameters",
    "model_description_xml",
    "model_json",
]
