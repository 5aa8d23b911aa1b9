"""The one number formatter of the reports and summaries, and the one escape of text for rich."""

from __future__ import annotations

import math
from typing import Any

from rich.markup import escape


def fmt_number(x: Any, spec: str = ".6g", missing: str = "–") -> str:
    """``x`` formatted with ``spec``; ``missing`` for None, NaN and infinities."""
    return missing if x is None or not math.isfinite(x) else format(x, spec)


def rich_text(text: Any) -> str:
    """``text`` (a path, a name, a whole plain line) safe to hand to rich: shown as it is, never read
    as markup (``[/]``, ``[red]`` …). Every user string that reaches rich goes through here."""
    return escape(str(text))
