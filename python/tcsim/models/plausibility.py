"""Physical plausibility ranges, read from the core (``tcsim_core::plausibility``, their one owner).

A value outside its range is suspicious rather than impossible: most often a unit mistake (rpm in a
rad/s column, milliseconds in a ``time_s`` column) or a typo. Two ways to act on it:

* :func:`check_plausible` for measured and commanded values: an :class:`~tcsim.errors.InputError`
  (exit 2) that names the range and the override, or with ``allow=True`` (the command line's
  ``--allow-implausible``) a :class:`~tcsim.errors.TcsimWarning`;
* :func:`warn_implausible` for a converter's design values: always a warning.

Values that make the numbers non-finite are refused by the readers and the core whatever the ranges
say. ``docs/guarantees.md`` lists the ranges.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import _core
from ..errors import ALLOW_IMPLAUSIBLE, CoreText, InputError, TcsimWarning
from ..units import RAD_S_PER_RPM


@dataclass(frozen=True)
class PlausibleRange:
    """One quantity's plausible range, closed at both ends, in ``unit``."""

    quantity: str
    unit: str
    low: float
    high: float
    why: str

    def describe(self) -> str:
        """``-1100 to 1100 rad/s (shaft speeds …)``."""
        unit = f" {self.unit}" if self.unit else ""
        return f"{self.low:g} to {self.high:g}{unit} ({self.why})"


#: Every range by quantity, from the core.
RANGES: dict[str, PlausibleRange] = {r[0]: PlausibleRange(*r) for r in _core.plausibility_ranges()}


def _first_outside(quantity: str, values: object) -> tuple[PlausibleRange, float | None, int]:
    rng = RANGES[quantity]
    v = np.atleast_1d(np.asarray(values, dtype=float))
    outside = np.flatnonzero(np.isfinite(v) & ((v < rng.low) | (v > rng.high)))
    return rng, (float(v[outside[0]]) if len(outside) else None), (int(outside[0]) if len(outside) else -1)


def check_plausible(
    quantity: str,
    values: object,
    source: str,
    field: str,
    allow: bool = False,
    locate: Callable[[int], str] | None = None,
) -> None:
    """Refuse the first of ``values`` outside the range of ``quantity`` (an :class:`InputError` of
    ``source``/``field`` naming the range and the override ``allow_implausible``), or with ``allow`` warn.
    ``locate(i)`` says where the ``i``-th value is (``row 5 (time_s 0.04)``), shown after the value
    and its unit. Non-finite values are the readers' to refuse and are skipped here."""
    rng, bad, index = _first_outside(quantity, values)
    if bad is None:
        return
    shown: object = bad if locate is None else CoreText(f"{bad:.6g} {rng.unit} at {locate(index)}".replace("  ", " "))
    if not allow:
        raise InputError(source, field, shown, f"a plausible value, {rng.describe()}", override=ALLOW_IMPLAUSIBLE)
    _warn(rng, bad, source, field)


def warn_implausible(quantity: str, values: object, source: str, field: str | Callable[[int], str]) -> None:
    """Warn (a :class:`TcsimWarning`) about the first of ``values`` outside the range of ``quantity``;
    ``field`` is the field's name, or gives the name of the ``i``-th value (``line 6, torque_ratio``)."""
    rng, bad, index = _first_outside(quantity, values)
    if bad is not None:
        _warn(rng, bad, source, field(index) if callable(field) else field)


def _warn(rng: PlausibleRange, value: float, source: str, field: str) -> None:
    message = f"{source}: {field} = {value:.6g} is outside the plausible {rng.describe()}"
    warnings.warn(message, TcsimWarning, stacklevel=3)


def check_plausible_rpm(rpm: float, source: str, field: str, allow: bool = False) -> None:
    """:func:`check_plausible` of a speed given in rpm (a command-line speed such as
    ``--pump-speed-rpm``) against the range of ``speed_rad_s``, the message in rpm."""
    rng = RANGES["speed_rad_s"]
    rad_s = rpm * RAD_S_PER_RPM
    if not np.isfinite(rad_s) or rng.low <= rad_s <= rng.high:
        return
    shown = f"{rng.low / RAD_S_PER_RPM:.0f} to {rng.high / RAD_S_PER_RPM:.0f} rpm, i.e. {rng.describe()}"
    if not allow:
        raise InputError(source, field, rpm, f"a plausible speed, {shown}", override=ALLOW_IMPLAUSIBLE)
    warnings.warn(f"{source}: {field} = {rpm:.6g} is outside the plausible {shown}", TcsimWarning, stacklevel=2)
