"""Result tables in the file format and the speed unit the user chose: the one owner of
``--format`` and ``--speed-unit`` of every command that writes tables of results.

Formats (``--format``, :data:`FORMATS`; default ``csv``)
---------------------------------------------------------
* ``csv``: comma-separated, a header row, no index (what every command wrote before the option).
* ``parquet``: Apache Parquet through pyarrow, one column per column; text columns that mix
  numbers and text are written as text.
* ``mat``: MATLAB v5 ``.mat`` through ``scipy.io.savemat``, one variable per column, each an N×1
  column vector in the column's order: numbers as ``double`` (integers as ``int64``), true/false
  columns as ``logical``, text columns as an N×1 cell array of char (an empty cell text for a
  missing value); compressed. A column name that is not a valid MATLAB identifier (a letter first,
  then letters, digits and ``_``, at most 63 characters, not a keyword) is mapped by
  :func:`matlab_name`; no column tcsim writes today needs it.

Every file keeps its name with the format's suffix (``summary.csv`` → ``summary.mat``). Files are
written into the staging folder of :func:`tcsim.io.outputs.output_dir`, so a run's files appear
whole or not at all, whatever the format.

Speed unit (``--speed-unit``, :data:`SPEED_UNITS`; default ``rad/s``)
-----------------------------------------------------------------------
With ``rpm`` every column of angular speed, ``<name>_rad_s``, becomes ``<name>_rpm`` (values ÷
:data:`tcsim.units.RAD_S_PER_RPM`), and every angular acceleration, ``<name>_rad_s2``, becomes
``<name>_rpm_per_s``; the unit stays in the column name, and no other column changes
(:func:`to_speed_unit`). Figures stay in rad/s.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError
from ..units import RAD_S_PER_RPM

#: The result file formats, the first the default; each name is also the file's suffix.
FORMATS: tuple[str, ...] = ("csv", "parquet", "mat")
#: The units of the angular speed columns, the first the default (tcsim's SI unit).
SPEED_UNITS: tuple[str, ...] = ("rad/s", "rpm")
#: The longest MATLAB identifier (``namelengthmax``).
MATLAB_NAME_MAX = 63
#: MATLAB's keywords (``iskeyword``), which cannot name a variable.
MATLAB_KEYWORDS = frozenset(
    "break case catch classdef continue else elseif end for function global if otherwise parfor persistent "
    "return spmd switch try while".split()
)
_MATLAB_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
#: Column suffixes of angular speed and acceleration and what they become in rpm.
_RPM_SUFFIXES: tuple[tuple[str, str], ...] = (("_rad_s2", "_rpm_per_s"), ("_rad_s", "_rpm"))


def _choice(parameter: str, value: str, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise InputError.argument(parameter, value, f"one of {', '.join(choices)}")
    return value


@dataclass(frozen=True)
class TableFormat:
    """How result tables are written: the file format (:data:`FORMATS`) and the unit of angular
    speeds (:data:`SPEED_UNITS`). Anything else is an :class:`InputError` of the command line."""

    format: str = FORMATS[0]
    speed_unit: str = SPEED_UNITS[0]

    def __post_init__(self) -> None:
        _choice("format", self.format, FORMATS)
        _choice("speed_unit", self.speed_unit, SPEED_UNITS)

    def file_name(self, name: str) -> str:
        """``name`` (``summary.csv``) with this format's suffix (``summary.mat``)."""
        return f"{Path(name).stem}.{self.format}"


#: The default: CSV in rad/s.
CSV = TableFormat()


def matlab_name(column: str) -> str:
    """``column`` as a MATLAB variable name: itself when it is a valid identifier; otherwise every
    character other than an ASCII letter, digit or ``_`` replaced by ``_``, ``x`` put before a
    first character that is not a letter, ``_`` after a keyword, and cut to
    :data:`MATLAB_NAME_MAX` characters."""
    name = str(column)
    if _MATLAB_NAME.fullmatch(name) and len(name) <= MATLAB_NAME_MAX and name not in MATLAB_KEYWORDS:
        return name
    name = re.sub(r"[^A-Za-z0-9_]", "_", name)
    if not name[:1].isascii() or not name[:1].isalpha():
        name = "x" + name
    if name in MATLAB_KEYWORDS:
        name += "_"
    return name[:MATLAB_NAME_MAX]


def column_in_unit(column: str, unit: str) -> str:
    """The name of the column ``column`` (named in rad/s) with angular speeds in ``unit``:
    ``pump_speed_rad_s`` → ``pump_speed_rpm``, ``pump_accel_rad_s2`` → ``pump_accel_rpm_per_s``."""
    _choice("speed_unit", unit, SPEED_UNITS)
    column = str(column)
    if unit == "rpm":
        for suffix, rpm in _RPM_SUFFIXES:
            if column.endswith(suffix):
                return column[: -len(suffix)] + rpm
    return column


def to_speed_unit(df: pd.DataFrame, unit: str) -> pd.DataFrame:
    """``df`` with its angular speeds in ``unit`` (see the module's docstring; rpm: value ÷
    :data:`~tcsim.units.RAD_S_PER_RPM`, rpm/s likewise); ``df`` itself for rad/s. A converted name
    that is already a column is an error of tcsim (ValueError)."""
    renamed = {c: column_in_unit(c, unit) for c in df.columns if column_in_unit(c, unit) != c}
    if not renamed:
        return df
    clash = sorted(set(renamed.values()) & (set(df.columns) - set(renamed)))
    if clash:
        raise ValueError(f"the rpm columns {clash} exist already beside their rad/s columns")
    out = df.copy()
    for column in renamed:
        out[column] = out[column] / RAD_S_PER_RPM
    return out.rename(columns=renamed)


def _is_text(col: pd.Series) -> bool:
    return not (pd.api.types.is_numeric_dtype(col) or pd.api.types.is_bool_dtype(col))


def _as_text(col: pd.Series) -> list[str | None]:
    """A text column's values as Python strings, None for a missing value."""
    return [None if pd.api.types.is_scalar(v) and pd.isna(v) else str(v) for v in col.astype(object)]


def write_csv(df: pd.DataFrame, path: Path) -> None:
    """``df`` as CSV at ``path``: a header row, no index."""
    df.to_csv(path, index=False)


def write_parquet(df: pd.DataFrame, path: Path) -> None:
    """``df`` as Parquet at ``path`` (pyarrow; no index). A text column holding other values as
    well (numbers in an event's detail) is written as text."""
    import pyarrow as pa  # noqa: PLC0415  lazy: start-up time (a CSV run never needs pyarrow)
    import pyarrow.parquet as pq  # noqa: PLC0415  lazy: start-up time

    columns = {}
    for name in df.columns:
        col = df[name]
        mixed = col.dtype == object and pd.api.types.infer_dtype(col, skipna=True) not in ("string", "empty")
        columns[str(name)] = pd.Series(_as_text(col), index=col.index, dtype=object) if mixed else col
    pq.write_table(pa.Table.from_pandas(pd.DataFrame(columns), preserve_index=False), path)


def mat_variables(df: pd.DataFrame) -> dict[str, np.ndarray]:
    """The variables of ``df``'s ``.mat`` file: one per column, named by :func:`matlab_name`, in
    the column's order (see the module's docstring for the types). Two columns of one name are an
    error of tcsim (ValueError)."""
    out: dict[str, np.ndarray] = {}
    for column in df.columns:
        name = matlab_name(column)
        if name in out:
            raise ValueError(f"columns {column!r} and another both become the MATLAB variable {name!r}")
        col = df[column]
        if pd.api.types.is_bool_dtype(col):
            out[name] = col.to_numpy(dtype=bool)
        elif pd.api.types.is_integer_dtype(col) and not col.hasnans:
            out[name] = col.to_numpy(dtype=np.int64)
        elif not _is_text(col):
            out[name] = col.to_numpy(dtype=float, na_value=np.nan)
        else:
            text = _as_text(col)
            cells = np.empty(len(col), dtype=object)
            cells[:] = ["" if v is None else v for v in text]
            out[name] = cells
    return out


def write_mat(df: pd.DataFrame, path: Path) -> None:
    """``df`` as a MATLAB v5 ``.mat`` file at ``path``: :func:`mat_variables`, N×1 each, compressed."""
    import scipy.io  # noqa: PLC0415  lazy: start-up time (a CSV run never needs SciPy)

    scipy.io.savemat(path, mat_variables(df), oned_as="column", do_compression=True)


#: The writer of each format.
WRITERS: dict[str, Callable[[pd.DataFrame, Path], None]] = {
    "csv": write_csv,
    "parquet": write_parquet,
    "mat": write_mat,
}


def write_table(df: pd.DataFrame, out_dir: Path, name: str, table_format: TableFormat = CSV) -> Path:
    """``df`` as ``out_dir/<name>`` with ``table_format``'s suffix, speed unit and writer; the path."""
    if not Path(out_dir).is_dir():  # pandas' OSError named neither the argument nor what to do
        raise InputError.argument("out_dir", str(out_dir), "an existing directory")
    path = Path(out_dir) / table_format.file_name(name)
    WRITERS[table_format.format](to_speed_unit(df, table_format.speed_unit), path)
    return path
