"""``tcsim.measurement``: measured time series (docs/replay.md), kept as a facade of
:mod:`tcsim.io.measurement` and :mod:`tcsim.models.measurement`."""

from __future__ import annotations

from .io.measurement import INPUT_CHANNELS, parse_channel_map, read_measurement
from .models.measurement import Measurement

__all__ = ["INPUT_CHANNELS", "Measurement", "parse_channel_map", "read_measurement"]
