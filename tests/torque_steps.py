"""The synthetic time-to-torque record of the ``tcsim torque-estimate`` tests (unit and CLI): load
steps as half-cosines from their initial to their final level over their rise time, held, and
released the same way (exact plateaus)."""

from __future__ import annotations

import numpy as np

#: Load steps: (onset s, initial N·m, final N·m, rise s, release s).
STEPS = [(2.0, 30.0, 380.0, 0.6, 6.0), (9.0, 30.0, 250.0, 0.4, 12.0)]


def load_response(t: np.ndarray) -> np.ndarray:
    """The record at times ``t`` (s), N·m."""
    out = np.full_like(t, 30.0, dtype=float)
    for onset, low, high, rise, release in STEPS:
        up = np.clip((t - onset) / rise, 0.0, 1.0)
        down = np.clip((t - release) / rise, 0.0, 1.0)
        out += (high - low) * ((1 - np.cos(np.pi * up)) - (1 - np.cos(np.pi * down))) / 2
    return out
