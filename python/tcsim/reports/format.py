"""The one number formatter of the reports and summaries."""

from __future__ import annotations

import math
from typing import Any


def fmt_number(x: Any, spec: str = ".6g", missing: str = "–") -> str:
    """``x`` formatted with ``spec``; ``missing`` for None, NaN and infinities."""
    return missing if x is None or not math.isfinite(x) else format(x, spec)
