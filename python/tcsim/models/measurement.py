"""A measured time series in SI (the data the measurement readers of :mod:`tcsim.io.measurement` return)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class Measurement:
    """A measured time series in SI: ``time_s`` and canonical, unit-suffixed channels."""

    source: str
    time_s: np.ndarray
    channels: dict[str, np.ndarray] = field(default_factory=dict)

    def has(self, name: str) -> bool:
        """Whether the channel ``name`` (a canonical name, or ``time_s``) was found."""
        return name == "time_s" or name in self.channels

    def to_frame(self) -> pd.DataFrame:
        """The measurement as a DataFrame: ``time_s`` first, then the channels."""
        return pd.DataFrame({"time_s": self.time_s, **self.channels})
