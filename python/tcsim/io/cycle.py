"""Speed traces for ``tcsim drive --cycle NAME|FILE``: the bundled cycles and a user's trace file
(CSV, Parquet, ``.mat`` or MDF4, read by the readers of :mod:`tcsim.io.measurement`), and the
files of a drive.

A trace file has ``time_s`` (s, strictly increasing; shifted so that the first sample is time 0),
``vehicle_speed_m_s`` (m/s, starting at rest) or ``vehicle_speed_km_h`` (km/h, as cycles are
published; not both) and optionally ``grade_percent`` (%, positive uphill); linear between samples.
The core checks the ranges (speed 0–250 km/h, grade ±30 %, the first speed at rest);
:func:`tcsim.analysis.drive.located` names the file, the column, the value, its data row and time
stamp, as for the other problems of the file.
"""

from __future__ import annotations

from collections.abc import Sequence
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis.drive import BUNDLED_CYCLES, Cycle, Drive
from ..errors import InputError
from .measurement import check_column, reader_for, refuse_duplicates
from .results import write_frames
from .tables import CSV, TableFormat

_REQUIRED = ("time_s", "vehicle_speed_m_s")
_OPTIONAL = ("grade_percent",)
#: The speed in km/h, as drive cycles are published (a trial had only m/s): read and divided by 3.6.
_SPEED_KM_H = "vehicle_speed_km_h"
#: The unit each column's name states, as a file's unit metadata (MDF4 channels) may spell it
#: (lower case, no spaces); any other unit there is refused, no unit is the name's.
_UNITS: dict[str, tuple[str, ...]] = {
    "time_s": ("s",),
    "vehicle_speed_m_s": ("m/s",),
    _SPEED_KM_H: ("km/h", "kph"),
    "grade_percent": ("%", "percent"),
}


def bundled_cycle_path(name: str) -> Path:
    """The file of the bundled cycle ``name`` (a key of :data:`BUNDLED_CYCLES`)."""
    return Path(str(resources.files("tcsim") / "data" / "cycles" / BUNDLED_CYCLES[name]))


class _CyclePicker:
    """Picks the trace's columns from a file's column names."""

    def __init__(self, path: Path):
        self.path = path
        self.found: list[str] = []
        self.speed = "vehicle_speed_m_s"  # or _SPEED_KM_H, as the file gives it

    def __call__(self, names: Sequence[str]) -> list[str]:
        speed = _SPEED_KM_H if _SPEED_KM_H in names and "vehicle_speed_m_s" not in names else "vehicle_speed_m_s"
        if _SPEED_KM_H in names and "vehicle_speed_m_s" in names:
            raise InputError(str(self.path), _SPEED_KM_H, "given too", "one speed column: vehicle_speed_m_s or km/h")
        for column in ("time_s", speed):
            if column not in names:
                shown = ", ".join(list(names)[:12]) + (" ..." if len(names) > 12 else "")
                also = f" (or {_SPEED_KM_H})" if column == "vehicle_speed_m_s" else ""
                expected = f"a column named {column}{also}; columns found: {shown or '(none)'}"
                raise InputError(str(self.path), column, "missing", expected)
        self.found = [c for c in ("time_s", speed, *_OPTIONAL) if c in names]
        self.speed = speed
        refuse_duplicates(self.path, names, self.found)
        return self.found


def _check_unit(path: Path, column: str, unit: str) -> None:
    """Refuse a unit in the file's metadata that is not the one ``column``'s name states."""
    unit = unit.strip()
    if unit and unit.lower().replace(" ", "") not in _UNITS[column]:
        accepted = " or ".join(_UNITS[column])
        expected = f"{accepted} (the unit its name states), or none: wrong units"
        raise InputError(str(path), f"{column} (unit)", unit, expected)


def read_cycle(path: str | Path, name: str | None = None) -> Cycle:
    """A speed trace from a file: each problem (missing column, a unit in the file's metadata other
    than the column name's, fewer than 2 rows, a value that is not a finite number, times not
    strictly increasing) an :class:`InputError` naming the file, the column and the value."""
    path = Path(path)
    reader = reader_for(path, "cycle")
    picker = _CyclePicker(path)
    raw, units = reader(path, picker)
    n = len(raw["time_s"])
    if n < 2:
        raise InputError(str(path), "time_s", f"{n} rows", "at least 2 data rows")
    out: dict[str, np.ndarray] = {}
    time_s = None
    for column in picker.found:
        _check_unit(path, column, units.get(column, ""))
        values = check_column(path, column, raw[column], n, "time_s", time_s, column == "time_s")
        if column == "time_s":
            time_s = values
        out[column] = values
    speed = out[picker.speed] / 3.6 if picker.speed == _SPEED_KM_H else out[picker.speed]
    return Cycle(
        name or path.stem,
        str(path),
        out["time_s"] - out["time_s"][0],
        speed,
        out.get("grade_percent"),
        float(out["time_s"][0]),
        picker.speed,
    )


def cycle_from_option(option: str) -> Cycle:
    """``--cycle``: a bundled name (:data:`BUNDLED_CYCLES`) or a trace file; a name that is neither
    (no extension, no such file) is refused as a command-line value."""
    if option in BUNDLED_CYCLES:
        return read_cycle(bundled_cycle_path(option), option)
    if not Path(option).suffix and not Path(option).exists():
        raise InputError("command line", "--cycle", option, f"one of {', '.join(BUNDLED_CYCLES)} or a trace file")
    return read_cycle(option)


def write_drive_files(result: Drive, out_dir: Path, table_format: TableFormat = CSV) -> list[Path]:
    """The tables of a drive (``table_format``, default CSV): ``<model>.csv``, ``summary.csv``,
    ``events.csv``, ``cycle.csv``."""
    c = result.cycle
    trace = {"time_s": c.time_s, "vehicle_speed_m_s": c.vehicle_speed_m_s}
    if c.grade_percent is not None:
        trace["grade_percent"] = c.grade_percent
    files: dict[str, pd.DataFrame] = {f"{name}.csv": run.frame for name, run in result.runs.items()}
    files.update({"summary.csv": result.summary, "events.csv": result.events(), "cycle.csv": pd.DataFrame(trace)})
    return write_frames(files, out_dir, table_format)
