"""The one owner of how a converter model looks in a figure: colour, line style, marker and marker
spacing per model, used by every figure that overlays the models (launch, replay, characterise,
drive, the launch's shape-effect sweep) and by the other lines of a figure (fit, design).

Lines of the three models often lie on top of each other (the stall phase, after the coupling
point), so they differ in line style and marker as well as in colour, and the colours are from the
Okabe & Ito palette, which stays distinct with the common colour-vision deficiencies (Okabe & Ito
2008, "Color Universal Design", https://jfly.uni-koeln.de/color/):

=================  ===========  ==========  ======  =================================
model              colour       line        marker  markers at
=================  ===========  ==========  ======  =================================
table              blue         solid, 2.0  none    –
quasi-dynamic      vermillion   dashed      circle  every 10 % of the axes' diagonal
hrovat-tobler      green        dash-dot    square  the same, offset by half a spacing
=================  ===========  ==========  ======  =================================

The table line is the widest and drawn underneath, so it shows around the dashed lines on top.
Marker spacing is in display space (matplotlib's ``markevery`` as a fraction), so it does not
depend on the sampling. Other lines (a fit's start and result, a sweep's values) take
:data:`OTHER_STYLES` in turn.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: Okabe & Ito colours by name.
OKABE_ITO = {
    "black": "#000000",
    "orange": "#E69F00",
    "sky blue": "#56B4E9",
    "green": "#009E73",
    "yellow": "#F0E442",
    "blue": "#0072B2",
    "vermillion": "#D55E00",
    "purple": "#CC79A7",
}


@dataclass(frozen=True)
class ModelStyle:
    """How one model's line is drawn: colour, line style, line width [pt], marker, ``markevery``
    (matplotlib: a float spacing or a (start, spacing) pair, fractions of the axes' diagonal),
    z-order, and the legend label."""

    colour: str
    linestyle: str | tuple[int, tuple[int, ...]]
    linewidth: float
    marker: str | None
    markevery: float | tuple[float, float] | None
    zorder: float
    label: str

    def line_kwargs(self, label: str | None = None) -> dict[str, Any]:
        """Keyword arguments of ``Axes.plot`` for this style (``label`` overrides the model's)."""
        kw: dict[str, Any] = {
            "color": self.colour,
            "ls": self.linestyle,
            "lw": self.linewidth,
            "zorder": self.zorder,
            "label": self.label if label is None else label,
        }
        if self.marker is not None:
            kw.update(marker=self.marker, markevery=self.markevery, ms=4.5, mfc="none", mew=1.0)
        return kw


MODEL_STYLES: dict[str, ModelStyle] = {
    "table": ModelStyle(OKABE_ITO["blue"], "-", 2.0, None, None, 2.0, "SS (table) model"),
    "quasi-dynamic": ModelStyle(OKABE_ITO["vermillion"], "--", 1.4, "o", 0.1, 2.2, "quasi-dynamic model"),
    "hrovat-tobler": ModelStyle(OKABE_ITO["green"], "-.", 1.4, "s", (0.05, 0.1), 2.1, "H&T model"),
}
#: Styles of lines that are not one of the three models, in turn.
OTHER_STYLES: tuple[ModelStyle, ...] = (
    ModelStyle(OKABE_ITO["orange"], ":", 1.6, "^", 0.1, 2.0, ""),
    ModelStyle(OKABE_ITO["purple"], (0, (5, 1, 1, 1, 1, 1)), 1.4, "v", (0.03, 0.1), 2.0, ""),
    ModelStyle(OKABE_ITO["sky blue"], (0, (1, 1)), 1.4, "D", (0.07, 0.1), 2.0, ""),
    ModelStyle(OKABE_ITO["black"], (0, (8, 2)), 1.2, "x", (0.02, 0.1), 2.0, ""),
)


def model_key(name: str) -> str | None:
    """The model of a line named ``name`` (``"table"``, ``"hrovat-tobler model"``), or None."""
    key = str(name).strip().removesuffix(" model")
    return key if key in MODEL_STYLES else None


def model_style(name: str, index: int = 0) -> ModelStyle:
    """The style of a line named ``name``: its model's, else the ``index``-th of
    :data:`OTHER_STYLES` (cycled) labelled ``name``."""
    key = model_key(name)
    if key is not None:
        return MODEL_STYLES[key]
    other = OTHER_STYLES[index % len(OTHER_STYLES)]
    return ModelStyle(
        other.colour, other.linestyle, other.linewidth, other.marker, other.markevery, other.zorder, str(name)
    )


def model_line(name: str, index: int = 0, label: str | None = None, y: Any = None) -> dict[str, Any]:
    """``Axes.plot`` keyword arguments of the line named ``name`` (see :func:`model_style`). Given the
    line's values ``y``, a line without a finite value has no markers: matplotlib (3.10) fails to draw
    a fractional ``markevery`` on it (an IndexError that ended ``tcsim characterise`` of a fitted
    converter whose Hrovat & Tobler characteristic has no steady state)."""
    kw = model_style(name, index).line_kwargs(label)
    if y is not None and not np.isfinite(np.asarray(y, dtype=float)).any():
        for key in ("marker", "markevery", "ms", "mfc", "mew"):
            kw.pop(key, None)
    return kw
