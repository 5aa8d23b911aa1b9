"""``tcsim.replay``: the documented Python API of ``tcsim replay`` (docs/replay.md), kept as a facade.

The code lives in :mod:`tcsim.analysis.replay` (the computation), :mod:`tcsim.cli.replay` (reading
and writing) and :mod:`tcsim.analysis.effective`.
"""

from __future__ import annotations

from .analysis.effective import smoothed_rate
from .analysis.replay import Replay, error_metrics
from .cli.replay import replay_files as replay
from .cli.replay import write_replay

__all__ = ["Replay", "error_metrics", "replay", "smoothed_rate", "write_replay"]
