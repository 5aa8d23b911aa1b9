"""The one-liners of the top-level API (:func:`characterise`, :func:`steady_state`,
:func:`operating_point`), re-exported by :mod:`tcsim` on first use (``import tcsim`` stays light)."""

from __future__ import annotations

from pathlib import Path

from .errors import InputError
from .models import operating_point as _operating_point
from .models import steady as _steady
from .models.converter import Converter, load_converter
from .units import DEFAULT_PUMP_SPEED_RPM

__all__ = ["characterise", "operating_point", "steady_state"]


def characterise(
    converter,
    model: str = "hrovat-tobler",
    pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM,
    speed_ratio=None,
    input_torque_nm: float | None = None,
    allow_implausible: bool = False,
):
    """Steady-state characteristic of a converter (bundled name, path or :class:`Converter`) at a fixed
    pump speed, or with ``input_torque_nm`` (N·m) at a fixed pump torque, the pump speed solved
    (docs/torque_capacity.md). A speed or torque outside its plausible range is an
    :class:`~tcsim.InputError` unless ``allow_implausible``, which warns instead."""
    conv = _converter(converter)
    return _steady.characterise(
        conv, model, pump_speed_rpm, speed_ratio, allow_implausible=allow_implausible, input_torque_nm=input_torque_nm
    )


def steady_state(converter, model: str, pump_speed_rad_s, turbine_speed_rad_s):
    """Steady states of ``model`` at any pump and turbine speeds, rad/s (arrays, broadcast, any sign):
    one row per point with the columns of ``characteristic.csv``; see
    :func:`tcsim.steady.steady_state`. ``converter`` is a bundled name, a path or a :class:`Converter`."""
    conv = _converter(converter)
    return _steady.steady_state(conv, model, pump_speed_rad_s, turbine_speed_rad_s)


def operating_point(
    converter,
    turbine_speed_rad_s,
    turbine_torque_nm=None,
    model: str = "table",
    pump_speed_limit_rad_s: float | None = None,
    *,
    turbine_power_w=None,
):
    """Backward operating points: pump speed and torque of ``model``'s steady state at turbine speeds,
    rad/s, delivering torques, N·m (or powers ``turbine_power_w``, W), with an optional pump speed
    limit, rad/s; one row per point with ``valid`` and ``reason``. See
    :func:`tcsim.models.operating_point.operating_point`. ``converter`` is a bundled name, a path or a
    :class:`Converter`."""
    conv = _converter(converter)
    return _operating_point.operating_point(
        conv, turbine_speed_rad_s, turbine_torque_nm, model, pump_speed_limit_rad_s, turbine_power_w=turbine_power_w
    )


def _converter(converter) -> Converter:
    """The :class:`Converter` an API function was given (itself, a bundled name or a file), else an
    :class:`~tcsim.InputError` about the argument ``converter``."""
    if isinstance(converter, Converter):
        return converter
    if not isinstance(converter, str | Path):
        expected = "a Converter, a bundled converter's name (tcsim.bundled_names()) or a file"
        raise InputError.argument("converter", type(converter).__name__, expected)
    return load_converter(converter)
