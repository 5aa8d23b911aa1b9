"""Scenario files for ``tcsim launch --scenario FILE`` (CSV, Parquet, ``.mat``, MDF4, read by the
measurement readers of :mod:`tcsim.io.measurement`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..models.plausibility import check_plausible
from ..simulation.scenarios import Scenario, brake_release_time, flip_flop, part_pedal
from .measurement import check_column, reader_for, refuse_duplicates

_PEDALS = ("accelerator_pedal", "brake_pedal")
_TIME_COLUMNS = {"time_s": 1.0, "time_ms": 1e-3}


def _pedal_columns(name: str) -> dict[str, float]:
    return {name: 1.0, f"{name}_percent": 0.01}


def _unit_scale(path: Path, column: str, unit: str, is_time: bool) -> float | None:
    """Factor to SI from a file's unit metadata (MDF4); None when there is no unit."""
    u = unit.strip().lower()
    if not u or u in ("-", "1"):
        return None
    table = {"s": 1.0, "ms": 1e-3} if is_time else {"%": 0.01, "percent": 0.01}
    if u not in table:
        accepted = ", ".join(table) + ("" if is_time else ", or none (0..1)")
        raise InputError(str(path), f"{column} (unit)", unit, f"one of {accepted}")
    return table[u]


class _ScenarioPicker:
    """Picks the time and the two pedal columns from a file's column names (see measurement.py)."""

    def __init__(self, path: Path):
        self.path = path
        self.picks: dict[str, tuple[str, float]] = {}

    def _one(self, canonical: str, options: Mapping[str, float], names: Sequence[str]) -> None:
        for column, factor in options.items():
            if column in names:
                self.picks[canonical] = (column, factor)
                return
        shown = ", ".join(list(names)[:12]) + (" ..." if len(names) > 12 else "")
        raise InputError(
            str(self.path),
            canonical,
            "missing",
            f"a column named {' or '.join(options)}; columns found: {shown or '(none)'}",
        )

    def __call__(self, names: Sequence[str]) -> list[str]:
        self._one("time_s", _TIME_COLUMNS, names)
        for pedal in _PEDALS:
            self._one(pedal, _pedal_columns(pedal), names)
        if "engine_torque_nm" in names:  # optional: a logged engine torque to replay
            self.picks["engine_torque_nm"] = ("engine_torque_nm", 1.0)
        columns = list(dict.fromkeys(c for c, _ in self.picks.values()))
        refuse_duplicates(self.path, names, columns)
        return columns


def read_scenario(
    path, stop_speed_m_s: float | None = None, end_time_s: float | None = None, allow_implausible: bool = False
) -> Scenario:
    """A user scenario from a CSV, Parquet, ``.mat`` or MDF4 file (the formats of
    :func:`tcsim.measurement.read_measurement`): ``time_s`` (or ``time_ms``), ``accelerator_pedal``
    and ``brake_pedal`` from 0 to 1 (or ``*_percent`` from 0 to 100; MDF4 ``%`` units are read),
    and optionally ``engine_torque_nm``, a logged crank torque replayed instead of the engine model.

    Time strictly increasing, no NaN, pedals within range; each problem an InputError naming the
    file, the column, the row and the value. Runs to ``end_time_s`` (default the last time stamp)
    or ``stop_speed_m_s``; the brake release time is :func:`brake_release_time`. Times are
    shifted so that the first sample is time 0 (runs start at time 0, braked and at rest).

    Plausibility (refused unless ``allow_implausible``, then a warning): the time span against
    ``scenario_duration_s`` (a ``time_ms`` column read as seconds spans a thousand times too long;
    the rows of a pedal scenario may be far apart, so their spacing is not checked) and a logged
    engine torque against ``torque_nm``."""
    path = Path(path)
    reader = reader_for(path, "scenario")
    picker = _ScenarioPicker(path)
    raw, units = reader(path, picker)
    time_column, time_factor = picker.picks["time_s"]
    n = len(raw[time_column])
    if n < 2:
        raise InputError(str(path), time_column, f"{n} rows", "at least 2 data rows")
    out: dict[str, np.ndarray] = {}
    time_s = None
    for canonical in ("time_s", *_PEDALS, *(["engine_torque_nm"] if "engine_torque_nm" in picker.picks else [])):
        column, factor = picker.picks[canonical]
        values = check_column(path, column, raw[column], n, time_column, time_s, canonical == "time_s")
        unit_factor = _unit_scale(path, column, units.get(column, ""), canonical == "time_s")
        scale = unit_factor if unit_factor is not None else factor
        if canonical == "engine_torque_nm":
            check_plausible("torque_nm", values, str(path), column, allow_implausible, _locate(time_s))
            out[canonical] = values
            continue
        if canonical != "time_s":
            limit = 1.0 / scale
            bad = np.flatnonzero((values < 0) | (values > limit * (1 + 1e-12)))
            if bad.size:
                row = int(bad[0])
                assert time_s is not None  # the time column comes first
                raise InputError(
                    str(path),
                    column,
                    f"{values[row]:g} at row {row + 1} (time_s {time_s[row]:g})",
                    f"a pedal position from 0 to {limit:g}",
                )
        values = np.clip(values * scale, 0.0, 1.0) if canonical != "time_s" else values * scale
        out[canonical] = values
        if canonical == "time_s":
            time_s = values
            span = f"{column} (time span, s)"
            check_plausible("scenario_duration_s", values[-1] - values[0], str(path), span, allow_implausible)
    t = out["time_s"] - out["time_s"][0]
    end = float(t[-1]) if end_time_s is None else end_time_s
    release = brake_release_time(t, out["brake_pedal"])
    return Scenario(
        path.stem,
        t,
        out["accelerator_pedal"],
        out["brake_pedal"],
        end,
        stop_speed_m_s,
        min(release, end),
        str(path),
        out.get("engine_torque_nm"),
    )


def _locate(time_s: np.ndarray | None):
    return lambda row: f"row {row + 1}" + (f" (time_s {time_s[row]:g})" if time_s is not None else "")


def scenario_from_option(value: str, allow_implausible: bool = False) -> Scenario:
    """``--scenario``: ``flip-flop``, ``part-pedal`` or a scenario file (its implausible values
    refused unless ``allow_implausible``: :func:`read_scenario`)."""
    if value == "flip-flop":
        return flip_flop()
    if value == "part-pedal":
        return part_pedal()
    if not Path(value).is_file():
        raise InputError(
            "command line",
            "--scenario",
            value,
            "flip-flop, part-pedal, or an existing scenario file (.csv, .parquet, .mat, .mf4/.mdf)",
        )
    return read_scenario(value, allow_implausible=allow_implausible)
