"""The points file of ``tcsim operating-point``: turbine speeds with torques or powers (CSV or Parquet)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..models.plausibility import check_plausible
from ..units import RAD_S_PER_RPM
from .measurement import check_finite, check_numeric, reader_for

#: The column of the turbine speed, rad/s.
SPEED_COLUMN = "turbine_speed_rad_s"
#: The turbine speed in rpm instead (converted to rad/s).
SPEED_RPM_COLUMN = "turbine_speed_rpm"
#: The load columns, exactly one of which a points file has: torque delivered (N·m) or power (W).
LOAD_COLUMNS: tuple[str, ...] = ("turbine_torque_nm", "turbine_power_w")
#: The file types a points file may have.
POINT_SUFFIXES: tuple[str, ...] = (".csv", ".parquet")


@dataclass(frozen=True)
class Points:
    """Turbine speeds (rad/s) and the load: ``load`` names the column, ``values`` are N·m or W."""

    source: str
    turbine_speed_rad_s: np.ndarray
    load: str
    values: np.ndarray


def read_points(path, allow_implausible: bool = False) -> Points:
    """Read a points file: a CSV or Parquet file with ``turbine_speed_rad_s`` (or
    ``turbine_speed_rpm``) and exactly one of ``turbine_torque_nm`` and ``turbine_power_w`` (other
    columns are ignored), at least one row, finite numbers only, speeds and torques within the
    plausibility ranges (rpm under a rad/s name is refused; ``allow_implausible`` makes that a
    warning). Anything else is an :class:`InputError` naming the file, the column and the value."""
    path = Path(path)
    if path.suffix.lower() not in POINT_SUFFIXES:
        expected = f"a points file ending in one of {', '.join(POINT_SUFFIXES)}"
        raise InputError(str(path), "(extension)", path.suffix or "(none)", expected)
    reader = reader_for(path, "points")
    wanted = (SPEED_COLUMN, SPEED_RPM_COLUMN, *LOAD_COLUMNS)

    def pick(names: Sequence[str]) -> list[str]:
        return [n for n in names if n in wanted]

    columns, _ = reader(path, pick)
    speeds = [c for c in (SPEED_COLUMN, SPEED_RPM_COLUMN) if c in columns]
    if len(speeds) != 1:
        given = "both" if speeds else "missing"
        expected = f"exactly one of the columns {SPEED_COLUMN} and {SPEED_RPM_COLUMN} (turbine speed)"
        raise InputError(str(path), f"{SPEED_COLUMN} / {SPEED_RPM_COLUMN}", given, expected)
    loads = [c for c in LOAD_COLUMNS if c in columns]
    if len(loads) != 1:
        given = "both" if loads else "missing"
        raise InputError(
            str(path),
            " / ".join(LOAD_COLUMNS),
            given,
            "exactly one of the columns turbine_torque_nm (N·m) and turbine_power_w (W)",
        )
    values = {}
    for name in (speeds[0], loads[0]):
        v = check_numeric(path, name, np.asarray(columns[name]), None)
        check_finite(path, name, v, None)
        values[name] = v
    if not len(values[speeds[0]]):
        raise InputError(str(path), "(rows)", 0, "at least one point")
    speed = values[speeds[0]] * (RAD_S_PER_RPM if speeds[0] == SPEED_RPM_COLUMN else 1.0)
    _check_plausible(path, speeds[0], speed, loads[0], values[loads[0]], allow_implausible)
    return Points(str(path), speed, loads[0], values[loads[0]])


def _check_plausible(path: Path, speed_column: str, speed_rad_s, load: str, values, allow: bool) -> None:
    """The plausibility ranges of the speeds (in rad/s, whatever the column's unit) and of the torques."""

    def row(i: int) -> str:
        return f"row {i + 1}"

    check_plausible("speed_rad_s", speed_rad_s, str(path), speed_column, allow, locate=row)
    if load == "turbine_torque_nm":
        check_plausible("torque_nm", values, str(path), load, allow, locate=row)
