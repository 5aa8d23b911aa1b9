"""Steady-state characteristics: one function per model.

* :func:`characterise_table`: the look-up-table model, Li & Sundén (2016) eqs 2.8–2.9.
* :func:`characterise_hrovat_tobler`: the closed-form steady state of Hrovat & Tobler (1985),
  Li & Sundén (2016) eqs 2.12–2.25 with zero left-hand sides, one-way stator clutch included.
* :func:`characterise_quasi_dynamic`: the quasi-dynamic model, whose steady state is its table
  by construction (docs/physics.md §5, property 2).

Each returns a :class:`pandas.DataFrame` with the columns of ``characteristic.csv``
(``conventions.md``). Speeds are in rad/s in the core; ``pump_speed_rpm`` is for people.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import _core
from ..errors import ARGUMENT, InputError, core_value, from_core
from ..units import DEFAULT_PUMP_SPEED_RPM, RAD_S_PER_RPM
from .arguments import float_array, real_number, worker_count
from .converter import Converter, load_converter
from .plausibility import check_plausible, check_plausible_rpm

#: Codes of the ``stator_mode`` column of the core's steady states and their names (the core's).
STATOR_MODES: dict[int, str] = _core.steady_mode_names()


def k_factor_rpm_per_sqrt_nm(capacity_factor_nm_s2: np.ndarray) -> np.ndarray:
    """K-factor, rpm/√(N·m), of capacity factors in N·m/(rad/s)² (the core's conversion; inf at CF 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return _core.cf_to_capacity("k_factor_rpm_per_sqrt_nm", np.ascontiguousarray(capacity_factor_nm_s2))


def ratio_frame(speed_ratio: np.ndarray, torque_ratio: np.ndarray, capacity_factor_nm_s2: np.ndarray) -> pd.DataFrame:
    """SR, TR and CF with what follows from them: the K-factor and the efficiency TR·SR."""
    return pd.DataFrame(
        {
            "speed_ratio": speed_ratio,
            "torque_ratio": torque_ratio,
            "capacity_factor_nm_s2": capacity_factor_nm_s2,
            "k_factor_rpm_per_sqrt_nm": k_factor_rpm_per_sqrt_nm(capacity_factor_nm_s2),
            "efficiency": torque_ratio * speed_ratio,
        }
    )


def _derived(df: pd.DataFrame) -> pd.DataFrame:
    """Add CF, K-factor and efficiency from torques and speeds: CF = T_p/(ω_p|ω_p|), the table law's
    signed square, so a reversed pump in drive has the same CF as the forward one; NaN with the pump
    at rest."""
    wp = df["pump_speed_rad_s"].to_numpy()
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        cf = np.where(wp != 0.0, df["pump_torque_nm"].to_numpy() / (wp * np.abs(wp)), np.nan)
    df["capacity_factor_nm_s2"] = cf
    df["k_factor_rpm_per_sqrt_nm"] = k_factor_rpm_per_sqrt_nm(cf)
    df["efficiency"] = df["torque_ratio"] * df["speed_ratio"]
    return df


#: The slowest pump speed of a characterisation, rpm: far below any use, and above the speeds whose
#: torques (∝ ω²) underflow and leave the capacity factor 0/0.
MIN_PUMP_SPEED_RPM = 1.0


def _check_speed(pump_speed_rpm: float, allow_implausible: bool = False) -> float:
    """The pump speed in rad/s: finite and positive, and plausible (``speed_rad_s``) unless
    ``allow_implausible`` (``--allow-implausible``), which warns instead."""
    if not (np.isfinite(pump_speed_rpm) and pump_speed_rpm >= MIN_PUMP_SPEED_RPM):
        raise InputError.argument(
            "pump_speed_rpm",
            pump_speed_rpm,
            f"a finite pump speed of at least {MIN_PUMP_SPEED_RPM:g} rpm (below it the torques underflow)",
        )
    check_plausible_rpm(pump_speed_rpm, ARGUMENT, "pump_speed_rpm", allow_implausible)
    return pump_speed_rpm * RAD_S_PER_RPM


def _speed_error(e: Exception, pump_speed_rpm: float, converter_file: str, field_prefix: str = "") -> InputError:
    """A core error of a sweep: about the commanded speed (source ``drive``) it names the argument
    ``speed_ratio`` when the core refused a speed ratio, else ``pump_speed_rpm`` (the steady state
    overflowed); any other error names the converter file."""
    if e.args[4] == "drive" and str(e.args[1]).startswith("speed_ratio"):
        return InputError.argument("speed_ratio", core_value(e.args[2]), e.args[3], core_source="drive")
    if e.args[4] == "drive":
        return InputError.argument("pump_speed_rpm", pump_speed_rpm, e.args[3], core_source="drive")
    return from_core(e, converter_file, field_prefix)


def _own_points(conv: Converter, model: str) -> np.ndarray:
    """The speed ratios every sweep of ``model`` holds: the table's own (table, quasi-dynamic) or
    the coupling point (hrovat-tobler; none without one)."""
    if model == "hrovat-tobler":
        cp = coupling_point(conv)
        return np.array([] if cp is None else [cp])
    assert conv.characteristic is not None  # the callers' conv.require checked it
    return np.concatenate([t.speed_ratio for t in conv.characteristic.tables()])


def table_speed_ratios(conv: Converter, n: int = 101) -> np.ndarray:
    """A sweep over the table's own range that contains every table point."""
    sr = _own_points(conv, "table")
    lo, hi = float(sr.min()), float(sr.max())
    return with_points(np.linspace(lo, hi, n), sr, lo, hi)


def ht_speed_ratios(conv: Converter) -> np.ndarray:
    """The default Hrovat & Tobler sweep: SR 0–1 in steps of 0.01 with the coupling point."""
    return with_points(np.linspace(0.0, 1.0, 101), _own_points(conv, "hrovat-tobler"), 0.0, 1.0)


def with_points(grid: np.ndarray, points: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The sorted ``grid`` (equal steps) with the ``points`` that lie in ``[lo, hi]`` added, a grid
    point within 1e-9 of a step of one of them replaced by it (0.05·6 is the table's 0.3: one row,
    not 0.3 and 0.30000000000000004)."""
    step = float(grid[1] - grid[0]) if grid.size > 1 else 1.0
    inside = np.unique(points[(points >= lo) & (points <= hi)])
    near = np.zeros(grid.shape, dtype=bool)
    for x in inside:
        near |= np.abs(grid - x) <= 1e-9 * step
    return np.unique(np.concatenate([grid[~near], inside]))


def characterise_table(
    conv: Converter,
    pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM,
    speed_ratio: np.ndarray | None = None,
    allow_implausible: bool = False,
) -> pd.DataFrame:
    """Steady state of the table model at a fixed pump speed over ``speed_ratio``.

    Inside the table TR and CF are interpolated linearly; outside it the core's rules for every
    quadrant apply and the ``extrapolated`` column says so; a warning says when the overrun rule
    extended the table (``docs/models.md``).
    """
    conv.require("table")
    wp = _check_speed(pump_speed_rpm, allow_implausible)
    sr = table_speed_ratios(conv) if speed_ratio is None else np.asarray(speed_ratio, dtype=float)
    pump = np.full(sr.shape, wp)
    assert conv.characteristic is not None  # conv.require("table") checked it
    table = conv.characteristic.core_table()
    try:
        out = _core.table_steady_states(
            **table, pump_speed_rad_s=pump, turbine_speed_rad_s=np.ascontiguousarray(sr * wp)
        )
    except _core.CoreInputError as e:
        raise _speed_error(e, pump_speed_rpm, conv.path) from None
    conv.characteristic.warn_if_extended(pump, sr * wp, "the characteristic")
    return _order(_derived(_table_frame(out, sr, pump, sr * wp)))


def _table_frame(out: dict, sr: np.ndarray, wp: np.ndarray, wt: np.ndarray) -> pd.DataFrame:
    """The table model's columns from the core's steady states ``out`` at speeds ``wp``, ``wt``, rad/s."""
    return pd.DataFrame(
        {
            "speed_ratio": sr,
            "torque_ratio": out["torque_ratio"],
            "pump_speed_rad_s": wp,
            "turbine_speed_rad_s": wt,
            "pump_torque_nm": out["pump_torque_nm"],
            "turbine_torque_nm": out["turbine_torque_nm"],
            "stator_torque_nm": out["stator_torque_nm"],
            "extrapolated": out["extrapolated"],
        }
    )


def characterise_quasi_dynamic(
    conv: Converter,
    pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM,
    speed_ratio: np.ndarray | None = None,
    allow_implausible: bool = False,
) -> pd.DataFrame:
    """The quasi-dynamic model at steady state is its table, for any shape effect."""
    conv.require("quasi-dynamic")
    return characterise_table(conv, pump_speed_rpm, speed_ratio, allow_implausible)


def hrovat_tobler_steady_state(
    geometry: np.ndarray, pump_speed_rad_s, turbine_speed_rad_s, strict: bool = True, threads: int = 0
) -> dict[str, np.ndarray]:
    """Closed-form steady states, batched in the core (GIL released).

    ``geometry`` is one row of the fifteen core parameters (``tcsim._core.ht_parameter_names()``,
    angles in radians) or one row per point. Returns flow (m³/s), stator speed (rad/s), the three
    torques (N·m; pump and stator external, turbine delivered) and the stator mode per point.
    ``threads`` workers share the points (0: one per core; a worker gets at least 16 384 points,
    so smaller batches run on fewer threads); the results do not depend on it.
    """
    names = _core.ht_parameter_names()
    geometry = np.atleast_2d(float_array("geometry", geometry))
    if geometry.ndim != 2 or geometry.shape[1] != len(names):
        expected = f"one row, or one per point, of the {len(names)} core parameters ({', '.join(names)})"
        raise InputError.argument("geometry", f"shape {geometry.shape}", expected)
    wp, wt = _speed_pairs(pump_speed_rad_s, turbine_speed_rad_s)
    if len(geometry) not in (1, wp.size):
        expected = f"one row, or one per point ({wp.size} points)"
        raise InputError.argument("geometry", f"{len(geometry)} rows", expected)
    if not isinstance(strict, (bool, np.bool_)):
        raise InputError.argument("strict", strict, "True or False")
    geometry = np.ascontiguousarray(geometry)
    threads = worker_count(threads)
    try:
        return _core.ht_steady_states(geometry, wp, wt, strict, threads)
    except _core.CoreInputError as e:  # a geometry the core refuses, a NaN speed
        _message, field, value, expected, source = e.args[:5]
        if source == "converter":  # a parameter of the geometry: named in what is expected
            field, expected = "geometry", f"{field}: {expected}"
        raise InputError.argument(field, core_value(value), expected, core_source=source) from None


def _speed_pairs(pump_speed_rad_s: Any, turbine_speed_rad_s: Any) -> tuple[np.ndarray, np.ndarray]:
    """The pump and turbine speeds as two flat arrays of one length, broadcast against each other
    (a scalar with an array, as :func:`steady_state` does); shapes that do not broadcast are an
    :class:`InputError` about the turbine speeds."""
    wp = float_array("pump_speed_rad_s", pump_speed_rad_s)
    wt = float_array("turbine_speed_rad_s", turbine_speed_rad_s)
    try:
        wp, wt = np.broadcast_arrays(wp, wt)
    except ValueError:
        expected = f"a shape that broadcasts with the pump speeds' {wp.shape}"
        raise InputError.argument("turbine_speed_rad_s", f"shape {wt.shape}", expected) from None
    return np.ascontiguousarray(wp.reshape(-1)), np.ascontiguousarray(wt.reshape(-1))


def steady_torque_ratio(out: dict[str, np.ndarray]) -> np.ndarray:
    """TR of the steady states ``out`` of :func:`hrovat_tobler_steady_state`, by the core's rule
    (``tcsim._core.steady_torque_ratio``): 1 in no-flow, ``T_t/T_p`` otherwise, NaN without a
    steady state."""
    return _core.steady_torque_ratio(out["stator_mode"], out["pump_torque_nm"], out["turbine_torque_nm"])


def coupling_point(conv: Converter | str | Path) -> float | None:
    """Speed ratio where the Hrovat & Tobler stator clutch releases, or None below SR = 1; ``conv``
    is a :class:`Converter`, a bundled name or a file."""
    if not isinstance(conv, Converter):
        conv = load_converter(conv)
    conv.require("hrovat-tobler")
    return _core.ht_coupling_point(conv.core_geometry())


def characterise_hrovat_tobler(
    conv: Converter,
    pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM,
    speed_ratio: np.ndarray | None = None,
    allow_implausible: bool = False,
) -> pd.DataFrame:
    """Closed-form steady state over ``speed_ratio`` (default SR 0–1 in steps of 0.01 with the
    coupling point) with the one-way clutch; a speed ratio the core does not solve is an error about
    ``speed_ratio``. A steady state that overflows (pump speeds above about 1e150 rad/s) is an
    error about ``pump_speed_rpm``, never a ``no-flow`` point."""
    conv.require("hrovat-tobler")
    wp = _check_speed(pump_speed_rpm, allow_implausible)
    sr = ht_speed_ratios(conv) if speed_ratio is None else np.asarray(speed_ratio, dtype=float)
    pump = np.full(sr.shape, wp)
    try:
        df = _ht_frame(conv, pump, sr * wp, sr)
    except _core.CoreInputError as e:
        raise _speed_error(e, pump_speed_rpm, conv.path, "[geometry] at ") from None
    return _order(_derived(df))


def _ht_frame(conv: Converter, wp: np.ndarray, wt: np.ndarray, sr: np.ndarray, strict: bool = True) -> pd.DataFrame:
    """Hrovat & Tobler's columns at speeds ``wp``, ``wt``, rad/s (``strict``: the core's error at the
    first point without a steady state, else a NaN row with mode ``no-steady-state``)."""
    geometry = np.atleast_2d(conv.core_geometry()).astype(float)
    speeds = (np.ascontiguousarray(wp, dtype=float), np.ascontiguousarray(wt, dtype=float))
    out = _core.ht_steady_states(geometry, speeds[0], speeds[1], strict, 0)
    return pd.DataFrame(
        {
            "speed_ratio": sr,
            "torque_ratio": steady_torque_ratio(out),
            "pump_speed_rad_s": wp,
            "turbine_speed_rad_s": wt,
            "pump_torque_nm": out["pump_torque_nm"],
            "turbine_torque_nm": out["turbine_torque_nm"],
            "stator_torque_nm": out["stator_torque_nm"],
            "flow_m3_s": out["flow_m3_s"],
            "stator_speed_rad_s": out["stator_speed_rad_s"],
            "stator_mode": [STATOR_MODES[int(m)] for m in out["stator_mode"]],
        }
    )


CHARACTERISE = {
    "table": characterise_table,
    "hrovat-tobler": characterise_hrovat_tobler,
    "quasi-dynamic": characterise_quasi_dynamic,
}

_FIRST = [
    "speed_ratio",
    "torque_ratio",
    "capacity_factor_nm_s2",
    "k_factor_rpm_per_sqrt_nm",
    "efficiency",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "pump_torque_nm",
    "turbine_torque_nm",
    "stator_torque_nm",
]


def _order(df: pd.DataFrame) -> pd.DataFrame:
    return df[_FIRST + [c for c in df.columns if c not in _FIRST]]


#: The largest magnitude of a speed ratio a ``--speed-ratio`` sweep may reach.
MAX_ABS_SPEED_RATIO = 100.0
#: The most grid points of a ``--speed-ratio`` sweep.
MAX_SWEEP_POINTS = 100_001


def parse_speed_ratio_sweep(text: str) -> tuple[float, float, float]:
    """``MIN:MAX:STEP`` of ``--speed-ratio`` as three numbers, else an :class:`InputError` about it."""
    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        lo, hi, step = (float(p) for p in parts)
    except ValueError:
        raise InputError(
            "command line", "--speed-ratio", text, "MIN:MAX:STEP, three numbers (for example 0:1:0.01)"
        ) from None
    return lo, hi, step


def speed_ratio_sweep(text: str) -> np.ndarray:
    """The grid of ``--speed-ratio MIN:MAX:STEP``: MIN, MIN + STEP, ... up to MAX (included when it
    falls on the grid to 1e-9 of a step).

    Rules (else an :class:`InputError` about ``--speed-ratio``): finite numbers,
    ``-MAX_ABS_SPEED_RATIO ≤ MIN < MAX ≤ MAX_ABS_SPEED_RATIO``, ``STEP > 0``, at most
    :data:`MAX_SWEEP_POINTS` points.
    """
    lo, hi, step = parse_speed_ratio_sweep(text)
    limit = MAX_ABS_SPEED_RATIO
    if not all(np.isfinite([lo, hi, step])):
        raise InputError("command line", "--speed-ratio", text, "finite numbers MIN:MAX:STEP")
    if not (-limit <= lo < hi <= limit):
        raise InputError(
            "command line", "--speed-ratio", text, f"MIN < MAX, both from {-limit:g} to {limit:g} (MIN:MAX:STEP)"
        )
    if not step > 0:
        raise InputError("command line", "--speed-ratio", text, "a positive STEP (MIN:MAX:STEP)")
    n = int(np.floor((hi - lo) / step + 1e-9)) + 1
    if n > MAX_SWEEP_POINTS:
        raise InputError(
            "command line", "--speed-ratio", text, f"at most {MAX_SWEEP_POINTS} points (this sweep has {n})"
        )
    grid = lo + step * np.arange(n)
    if n >= 2 and abs(grid[-1] - hi) <= 1e-9 * step:
        grid[-1] = hi
    return grid


def sweep_speed_ratios(conv: Converter, model: str, text: str) -> np.ndarray:
    """The speed ratios of ``characterise --speed-ratio text``: the grid of :func:`speed_ratio_sweep`
    with the table's own speed ratios (table, quasi-dynamic) or the coupling point (hrovat-tobler)
    that lie in [MIN, MAX], as in the default sweeps (:func:`with_points`)."""
    lo, hi, _ = parse_speed_ratio_sweep(text)
    # the points in [MIN, MAX], also past the grid's last step (0:1:0.7 keeps the table's 0.8–1)
    return with_points(speed_ratio_sweep(text), _own_points(conv, model), lo, hi)


#: The models :func:`steady_state` and :func:`characterise` know.
MODELS: tuple[str, ...] = ("table", "quasi-dynamic", "hrovat-tobler")


def _finite_speeds(**speeds) -> tuple[np.ndarray, np.ndarray]:
    """The two speed arguments as flat float arrays, broadcast against each other; a value that is not
    a finite number is an :class:`InputError` naming the argument and its index."""
    arrays = []
    for name, value in speeds.items():
        a = float_array(name, value, "numbers (rad/s)")
        if a.ndim == 0 and not np.isfinite(a):  # argwhere of a 0-d array finds nothing: a scalar NaN passed
            raise InputError.argument(name, float(a), "a finite speed in rad/s")
        bad = np.argwhere(~np.isfinite(a))
        if bad.size:
            index = tuple(int(i) for i in bad[0])
            where = "[" + ", ".join(map(str, index)) + "]" if index else ""
            raise InputError.argument(f"{name}{where}", float(a[index]), "a finite speed in rad/s")
        arrays.append(a)
    try:
        wp, wt = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = " and ".join(str(a.shape) for a in arrays)
        raise InputError.argument("turbine_speed_rad_s", f"shape {shapes}", "shapes that broadcast") from None
    return np.ascontiguousarray(wp, dtype=float).reshape(-1), np.ascontiguousarray(wt, dtype=float).reshape(-1)


def steady_state(conv: Converter, model: str, pump_speed_rad_s, turbine_speed_rad_s) -> pd.DataFrame:
    """Steady states of ``model`` at arbitrary pump and turbine speeds, any sign, in the core.

    Parameters
    ----------
    conv : Converter
        The converter; it must have the sections of ``model``.
    model : str
        ``"table"``, ``"quasi-dynamic"`` or ``"hrovat-tobler"``.
    pump_speed_rad_s, turbine_speed_rad_s : array_like
        Speeds, rad/s, any sign; broadcast against each other and flattened (C order), one row per point.

    Returns
    -------
    pandas.DataFrame
        The columns of ``characteristic.csv`` for ``model`` in the same order (as :func:`characterise`),
        ``speed_ratio`` = ω_t/ω_p. Every quadrant is defined (docs/models.md); with the pump at rest
        ``speed_ratio``, the capacity factor and the K-factor are NaN or infinite but the torques are
        the model's. A point where the model has no finite steady state (torques that overflow) is a
        row of NaN torques and ratios: ``stator_mode`` ``no-steady-state`` (Hrovat & Tobler),
        ``extrapolated`` false (table, quasi-dynamic). Never an error for such a point.

    Raises
    ------
    InputError
        An unknown model, a converter without the model's sections, a speed that is not finite
        (``pump_speed_rad_s[i]``) or shapes that do not broadcast.
    """
    if model not in MODELS:
        raise InputError.argument("model", model, f"one of {', '.join(MODELS)}")
    conv.require(model)
    wp, wt = _finite_speeds(pump_speed_rad_s=pump_speed_rad_s, turbine_speed_rad_s=turbine_speed_rad_s)
    with np.errstate(divide="ignore", invalid="ignore"):
        if model == "hrovat-tobler":
            df = _ht_frame(conv, wp, wt, wt / wp, strict=False)
        else:
            assert conv.characteristic is not None  # conv.require checked it
            table = conv.characteristic.core_table()
            out = _core.table_steady_states(**table, pump_speed_rad_s=wp, turbine_speed_rad_s=wt, lenient=True)
            conv.characteristic.warn_if_extended(wp, wt, "the steady states")
            df = _table_frame(out, out["speed_ratio"], wp, wt)
        return _order(_derived(df))


def characterise(
    conv: Converter,
    model: str = "hrovat-tobler",
    pump_speed_rpm: float = DEFAULT_PUMP_SPEED_RPM,
    speed_ratio: np.ndarray | None = None,
    allow_implausible: bool = False,
    input_torque_nm: float | None = None,
) -> pd.DataFrame:
    """Steady-state characteristic of ``conv`` with ``model`` (``table``, ``hrovat-tobler``, ``quasi-dynamic``).

    At the fixed pump speed ``pump_speed_rpm``, or with ``input_torque_nm`` (N·m) at that fixed pump
    (input) torque, the pump speed solved at each speed ratio (:func:`characterise_at_input_torque`).
    A pump speed outside the plausible range (``speed_rad_s``) is refused unless ``allow_implausible``."""
    conv.require(model)
    speed_ratio = _speed_ratio_argument(speed_ratio)
    if input_torque_nm is not None:
        torque = real_number("input_torque_nm", input_torque_nm)
        return characterise_at_input_torque(conv, model, torque, speed_ratio, allow_implausible)
    return CHARACTERISE[model](conv, real_number("pump_speed_rpm", pump_speed_rpm), speed_ratio, allow_implausible)


def _speed_ratio_argument(speed_ratio: object) -> np.ndarray | None:
    """The speed ratios a caller gave (a number, a list or a 1-D array) as a 1-D float array, None
    when not given; anything else, or a ratio that is not finite, is an :class:`InputError` about the
    argument ``speed_ratio`` (NaN was blamed on the converter file's turbine speed)."""
    if speed_ratio is None:
        return None
    sr = np.atleast_1d(float_array("speed_ratio", speed_ratio, "speed ratios: a number, a list or a 1-D array"))
    if sr.ndim != 1:
        raise InputError.argument("speed_ratio", f"{sr.ndim}-D array", "speed ratios: a number, a list or a 1-D array")
    bad = np.flatnonzero(~np.isfinite(sr))
    if bad.size:
        raise InputError.argument(f"speed_ratio[{bad[0]}]", float(sr[bad[0]]), "a finite speed ratio")
    return sr


def characterise_at_input_torque(
    conv: Converter,
    model: str,
    input_torque_nm: float,
    speed_ratio: np.ndarray | None = None,
    allow_implausible: bool = False,
) -> pd.DataFrame:
    """Steady states at a fixed pump (input) torque ``input_torque_nm``, N·m, over ``speed_ratio``
    (default: the sweep of :func:`characterise`), the positive pump speed solved in the core.

    Table and quasi-dynamic: ``ω_p = √(T/CF(SR, T))``, the tables weighted at T
    (docs/torque_capacity.md). Hrovat & Tobler: the pump speed at which its steady state carries T
    (a 1-D iteration in the core). A speed ratio at which no positive pump speed carries T (T of the
    other sign than the model's pump torque there, e.g. a drive torque in overrun) is a row of NaN
    (``extrapolated`` false; Hrovat & Tobler: ``stator_mode`` ``no-steady-state``).

    Raises
    ------
    InputError
        ``input_torque_nm`` not a finite, non-zero number; outside the plausible ``torque_nm``
        unless ``allow_implausible``; or carried at no speed ratio of the sweep (a negative torque
        over speed ratios 0–1 gave every row NaN with exit 0).
    """
    conv.require(model)
    if not (np.isfinite(input_torque_nm) and input_torque_nm != 0.0):
        raise InputError.argument("input_torque_nm", input_torque_nm, "a finite, non-zero torque in N·m")
    check_plausible("torque_nm", [input_torque_nm], ARGUMENT, "input_torque_nm", allow_implausible)
    frame = _at_input_torque(conv, model, float(input_torque_nm), speed_ratio)
    if not np.isfinite(frame["pump_speed_rad_s"].to_numpy(dtype=float)).any():
        sr = frame["speed_ratio"].to_numpy(dtype=float)
        need = (
            "a negative (coast) torque needs speed ratios above 1 (for example 1 to 2)"
            if input_torque_nm < 0
            else "a positive (drive) torque needs speed ratios below 1 (for example 0 to 1)"
        )
        expected = (
            f"a torque the converter carries at some speed ratio of the sweep ({sr.min():g} to {sr.max():g}); {need}"
        )
        raise InputError.argument("input_torque_nm", input_torque_nm, expected)
    return frame


def _at_input_torque(conv: Converter, model: str, t: float, speed_ratio: np.ndarray | None) -> pd.DataFrame:
    """The frame of :func:`characterise_at_input_torque` (rows of NaN where no pump speed carries t)."""
    if model == "hrovat-tobler":
        sr = np.ascontiguousarray(ht_speed_ratios(conv) if speed_ratio is None else speed_ratio, dtype=float)
        wp = _core.ht_pump_speeds_at_pump_torque(conv.core_geometry(), t, sr)
        with np.errstate(invalid="ignore"):
            return _order(_derived(_ht_frame(conv, wp, sr * wp, sr, strict=False)))
    sr = np.ascontiguousarray(table_speed_ratios(conv) if speed_ratio is None else speed_ratio, dtype=float)
    assert conv.characteristic is not None  # conv.require checked it
    out = _core.table_steady_states_at_pump_torque(
        **conv.characteristic.core_table(), pump_torque_nm=t, at_speed_ratio=sr
    )
    wp, wt = out["pump_speed_rad_s"], out["turbine_speed_rad_s"]
    conv.characteristic.warn_if_extended(wp, wt, "the characteristic")
    with np.errstate(invalid="ignore", divide="ignore"):
        return _order(_derived(_table_frame(out, sr, wp, wt)))
