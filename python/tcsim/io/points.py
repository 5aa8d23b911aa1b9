"""The points file of ``tcsim operating-point``: turbine speeds with torques or powers (CSV or Parquet)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from .measurement import check_finite, check_numeric, reader_for

#: The column of the turbine speed, rad/s.
SPEED_COLUMN = "turbine_speed_rad_s"
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


def read_points(path) -> Points:
    """Read a points file: a CSV or Parquet file with ``turbine_speed_rad_s`` and exactly one of
    ``turbine_torque_nm`` and ``turbine_power_w`` (other columns are ignored), at least one row,
    finite numbers only. Anything else is an :class:`InputError` naming the file, the column and the
    value."""
    path = Path(path)
    if path.suffix.lower() not in POINT_SUFFIXES:
        expected = f"a points file ending in one of {', '.join(POINT_SUFFIXES)}"
        raise InputError(str(path), "(extension)", path.suffix or "(none)", expected)
    reader = reader_for(path, "points")
    wanted = (SPEED_COLUMN, *LOAD_COLUMNS)

    def pick(names: Sequence[str]) -> list[str]:
        return [n for n in names if n in wanted]

    columns, _ = reader(path, pick)
    if SPEED_COLUMN not in columns:
        raise InputError(str(path), SPEED_COLUMN, "missing", f"a column {SPEED_COLUMN} (turbine speed, rad/s)")
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
    for name in (SPEED_COLUMN, loads[0]):
        v = check_numeric(path, name, np.asarray(columns[name]), None)
        check_finite(path, name, v, None)
        values[name] = v
    if not len(values[SPEED_COLUMN]):
        raise InputError(str(path), "(rows)", 0, "at least one point")
    return Points(str(path), values[SPEED_COLUMN], loads[0], values[loads[0]])
