"""The one number formatter of the reports and summaries, and the one escape of text for rich."""

from __future__ import annotations

import math
import re
from typing import Any

#: What rich reads as a markup tag (``[bold]``, ``[/]``, ``[link=…]``, ``[#fff]``, ``[@click]``), with
#: the backslashes before it (rich.markup's own pattern).
_TAG = re.compile(r"(\\*)(\[[a-z#/@][^[]*?])")


def fmt_number(x: Any, spec: str = ".6g", missing: str = "–") -> str:
    """``x`` formatted with ``spec``; ``missing`` for None, NaN and infinities."""
    return missing if x is None or not math.isfinite(x) else format(x, spec)


def rich_text(text: Any) -> str:
    """``text`` (a path, a name, a whole plain line) safe to hand to rich: shown as it is, never read
    as markup (``[/]``, ``[red]`` …). Every user string that reaches rich goes through here.

    Like ``rich.markup.escape`` without its doubling of a trailing backslash (which shows as two),
    so the result must stand alone or end the markup string, as it does everywhere in tcsim."""
    return _TAG.sub(lambda m: f"{m.group(1)}{m.group(1)}\\{m.group(2)}", str(text))
