"""The backward (quasi-static) operating point: pump speed and torque from turbine speed and torque.

Backward-facing simulators (VECTO, ADVISOR, CO2MPAS) ask the converter: given the turbine speed and
the torque the gearbox needs, what are the pump speed and torque? The core answers it
(``tcsim-core``'s ``converter::backward``; equations in ``docs/operating_point.md``); this module
checks the arguments and builds the table.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _core
from ..errors import ARGUMENT, InputError
from .arguments import float_array
from .converter import Converter
from .steady import MODELS

#: Reason codes of the core: code → (name, whether the point is a valid operating point).
REASONS: dict[int, tuple[str, bool]] = _core.operating_point_reasons()

#: The columns of :func:`operating_point`, in order.
COLUMNS: tuple[str, ...] = (
    "turbine_speed_rad_s",
    "turbine_torque_nm",
    "pump_speed_rad_s",
    "pump_torque_nm",
    "speed_ratio",
    "torque_ratio",
    "efficiency",
    "valid",
    "reason",
)


def check_pump_speed_limit(source: str, field: str, limit_rad_s: float | None) -> float | None:
    """A pump speed limit in rad/s: None (no limit) or a positive number (``inf`` allowed); else an
    :class:`InputError` about ``field`` of ``source``."""
    if limit_rad_s is None:
        return None
    try:
        value = float(limit_rad_s)
    except (TypeError, ValueError):
        raise InputError(source, field, limit_rad_s, "a positive pump speed limit") from None
    if not value > 0.0:  # NaN too
        raise InputError(source, field, limit_rad_s, "a positive pump speed limit")
    return value


def _load(source: str, wt, torque, power) -> tuple[np.ndarray, np.ndarray, str]:
    """Turbine speeds and the load (torque or power) as flat float arrays broadcast against each
    other, and which load it is (``turbine_torque_nm`` or ``turbine_power_w``)."""
    if (torque is None) == (power is None):
        if torque is not None:
            raise InputError(
                source, "turbine_power_w", "given too", "either turbine_torque_nm or turbine_power_w, not both"
            )
        raise InputError(source, "turbine_torque_nm", None, "a turbine torque, or turbine_power_w (one of them)")
    name = "turbine_torque_nm" if torque is not None else "turbine_power_w"
    speeds = float_array("turbine_speed_rad_s", wt, "numbers")
    load = float_array(name, torque if torque is not None else power, "numbers")
    try:
        speeds, load = np.broadcast_arrays(speeds, load)
    except ValueError:
        raise InputError(source, name, f"shape {load.shape}", f"a shape that broadcasts with {speeds.shape}") from None
    flat = [np.ascontiguousarray(a, dtype=float).reshape(-1) for a in (speeds, load)]
    return flat[0], flat[1], name


def _table_points(conv: Converter, wt: np.ndarray, torque, limit, power) -> dict:
    """The core's backward points of the converter's single table (the table and quasi-dynamic
    models); a torque-dependent characteristic is refused."""
    c = conv.characteristic
    assert c is not None  # conv.require checked it
    if c.by_torque:
        raise InputError(
            conv.path,
            "[characteristic]",
            f"{len(c.by_torque)} tables by input torque",
            "a single table: the backward operating point of a torque-dependent capacity is not built"
            " (docs/operating_point.md)",
        )
    out = _core.table_operating_points(*c.arrays(), wt, torque, limit, **c.core_rules(), turbine_power_w=power)
    overrun = out["speed_ratio"] > 1.0  # only overrun can reach the mirror extension (NaN: false)
    c.warn_if_extended(out["pump_speed_rad_s"][overrun], wt[overrun], "the operating points")
    return out


def operating_point(
    conv: Converter,
    turbine_speed_rad_s,
    turbine_torque_nm=None,
    model: str = "table",
    pump_speed_limit_rad_s: float | None = None,
    *,
    turbine_power_w=None,
) -> pd.DataFrame:
    """Backward operating points: the steady state that delivers a torque at a turbine speed.

    Parameters
    ----------
    conv : Converter
        The converter; it must have the sections of ``model``.
    turbine_speed_rad_s : array_like
        Turbine speed ω_t, rad/s, any sign.
    turbine_torque_nm : array_like, optional
        Torque the turbine delivers to the gearbox, N·m: positive in drive, negative in coast (the
        turbine driven by the vehicle). Broadcast against ``turbine_speed_rad_s``, flattened (C order).
    model : str
        ``"table"`` (closed form per table segment, as VECTO does), ``"quasi-dynamic"`` (its steady
        state is its table) or ``"hrovat-tobler"`` (a bracketed 1-D root find on its steady state).
    pump_speed_limit_rad_s : float, optional
        Highest pump speed |ω_p|, rad/s; a point that needs more is flagged
        ``above-pump-speed-limit``. None: no limit.
    turbine_power_w : array_like, optional
        Instead of ``turbine_torque_nm``: the power delivered, W; the torque is P/ω_t (a point with
        ω_t = 0 is flagged ``power-at-standstill``).

    Returns
    -------
    pandas.DataFrame
        One row per point: ``turbine_speed_rad_s``, ``turbine_torque_nm`` (given, or P/ω_t),
        ``pump_speed_rad_s`` (rad/s), ``pump_torque_nm`` (N·m, positive in drive), ``speed_ratio``
        (ω_t/ω_p), ``torque_ratio`` (the forward model's TR), ``efficiency`` (SR·TR), ``valid`` and
        ``reason`` (categorical: ``ok``, ``at-rest``, ``non-finite-input``, ``above-pump-speed-limit``,
        ``pump-backwards``, ``no-steady-state``, ``overflow``, ``power-at-standstill``;
        docs/operating_point.md). Where several pump speeds give the torque: the lowest one turning
        forwards (the engine's way, also while the vehicle rolls back: ω_t < 0, ω_p > 0). A NaN
        value always comes with a reason other than ``ok`` (or ``at-rest``, where the ratios are
        undefined).

    Raises
    ------
    InputError
        An unknown model, a converter without the model's sections, both or neither of torque and
        power, arguments that are not numbers or do not broadcast, a pump speed limit that is not
        positive; for the table and quasi-dynamic models, a converter with several tables by input
        torque (``[[characteristic]]``; not built).

    References
    ----------
    VECTO (European Commission), torque converter in the backward-facing simulation: on each
    segment of the characteristic the output torque is a quadratic in the input speed, solved in
    closed form.
    """
    source = ARGUMENT
    if model not in MODELS:
        raise InputError(source, "model", model, f"one of {', '.join(MODELS)}")
    conv.require(model)
    limit = check_pump_speed_limit(source, "pump_speed_limit_rad_s", pump_speed_limit_rad_s)
    wt, values, load = _load(source, turbine_speed_rad_s, turbine_torque_nm, turbine_power_w)
    torque, power = (values, None) if load == "turbine_torque_nm" else (None, values)
    if model == "hrovat-tobler":
        out = _core.ht_operating_points(conv.core_geometry(), wt, torque, limit, turbine_power_w=power)
    else:
        out = _table_points(conv, wt, torque, limit, power)
    names = pd.Index([REASONS[code][0] for code in sorted(REASONS)])
    out["reason"] = pd.Categorical.from_codes(np.asarray(out["reason"], dtype=np.intp), categories=names)
    return pd.DataFrame({"turbine_speed_rad_s": wt, **out}, columns=list(COLUMNS))
