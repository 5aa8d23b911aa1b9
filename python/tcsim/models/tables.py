"""Characteristic tables from text files: tcsim CSV (six capacity conventions) and VECTO .vtcc.

CSV: a header with ``speed_ratio``, ``torque_ratio`` and exactly one capacity column
(``capacity_factor_nm_s2``, ``k_factor_rpm_per_sqrt_nm``, ``k_factor_rad_s_per_sqrt_nm``,
``k_factor_rpm_per_sqrt_lbf_ft``, ``capacity_nm_per_rpm2`` or ``mp1000_nm``); lines starting
with ``#`` are comments. An optional ``input_torque_nm`` column makes it the table-alone form of a
torque-dependent converter (docs/torque_capacity.md): the rows with the same input torque form one
table, in their order in the file.

VECTO ``.vtcc`` (VECTO's torque-converter characteristic): a header such as
``Speed Ratio, Torque Ratio,MP1000`` and three columns, speed ratio, torque ratio and the input
torque at 1000 rpm input speed in N·m (negative in overrun); ``#`` starts a comment.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

from ..errors import InputError, read_user_text
from .characteristic import CAPACITY_KEYS, Characteristic


def _rows(path: Path) -> list[tuple[int, list[str]]]:
    """Non-empty, non-comment rows with their 1-based line numbers."""
    text = read_user_text(path)
    out = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        out.append((lineno, [c.strip() for c in next(csv.reader([stripped]))]))
    if not out:
        raise InputError(str(path), "(file)", "no data", "a header line and at least two rows")
    return out


def _number(path: Path, lineno: int, column: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise InputError(str(path), f"line {lineno}, {column}", text, "a number") from None
    if not math.isfinite(value):  # "nan", "inf", or "1e400", which overflows: named as written
        raise InputError(str(path), f"line {lineno}, {column}", text, "a finite number")
    return value


def _columns(path: Path, rows, names: list[str]):
    cols: dict[str, list[float]] = {n: [] for n in names}
    lines = []
    for lineno, cells in rows:
        if len(cells) != len(names):
            raise InputError(
                str(path),
                f"line {lineno}",
                ",".join(cells),
                f"{len(names)} comma-separated values ({', '.join(names)})",
            )
        for n, c in zip(names, cells):
            cols[n].append(_number(path, lineno, n, c))
        lines.append(lineno)
    return cols, lines


def read_table_csv(path: Path) -> Characteristic:
    rows = _rows(path)
    header_line, header = rows[0]
    twice = [h for i, h in enumerate(header) if h in header[:i]]
    if twice:
        raise InputError(
            str(path), f"line {header_line} (header)", twice[0], "each column name once (this one appears twice)"
        )
    for required in ("speed_ratio", "torque_ratio"):
        if required not in header:
            raise InputError(str(path), f"line {header_line} (header)", ",".join(header), f"a {required} column")
    capacity = [h for h in header if h in CAPACITY_KEYS]
    known = ("speed_ratio", "torque_ratio", "input_torque_nm")
    unknown = [h for h in header if h not in CAPACITY_KEYS and h not in known]
    if unknown:
        raise InputError(
            str(path),
            f"line {header_line} (header)",
            unknown[0],
            f"only speed_ratio, torque_ratio, one capacity column of {', '.join(CAPACITY_KEYS)} "
            "and optionally input_torque_nm",
        )
    if len(capacity) != 1:
        raise InputError(
            str(path),
            f"line {header_line} (header)",
            ",".join(header),
            f"exactly one capacity column of {', '.join(CAPACITY_KEYS)}",
        )
    cols, lines = _columns(path, rows[1:], header)
    if "input_torque_nm" in cols:
        table = _torque_tables(path, cols, lines, capacity[0])
    else:
        table = Characteristic.from_columns(
            cols["speed_ratio"], cols["torque_ratio"], cols[capacity[0]], capacity[0], str(path), rows=lines
        )
    for t in table.tables():
        t.warn_if_implausible()
    return table


def _torque_tables(path: Path, cols: dict[str, list[float]], lines: list[int], capacity: str) -> Characteristic:
    """The tables of a CSV with an ``input_torque_nm`` column: the rows of each input torque, in
    file order (each torque finite and positive)."""
    torques: list[float] = []
    for t, line in zip(cols["input_torque_nm"], lines, strict=True):
        if not t > 0:
            raise InputError(str(path), f"line {line}, input_torque_nm", t, "a positive input torque in N·m")
        if t not in torques:
            torques.append(t)
    tables = []
    for t in torques:
        rows = [i for i, v in enumerate(cols["input_torque_nm"]) if v == t]
        sr, tr, cap = ([c[i] for i in rows] for c in (cols["speed_ratio"], cols["torque_ratio"], cols[capacity]))
        line_numbers = [lines[i] for i in rows]
        tables.append(
            Characteristic.from_columns(sr, tr, cap, capacity, str(path), rows=line_numbers, input_torque_nm=t)
        )
    if len(tables) == 1:
        return tables[0]
    return Characteristic.torque_dependent(tables, str(path), [f"rows with input_torque_nm {t:g}, " for t in torques])


def read_vtcc(path: Path) -> Characteristic:
    rows = _rows(path)
    header_line, header = rows[0]
    names = ["speed_ratio", "torque_ratio", "mp1000_nm"]
    try:
        [float(c) for c in header]
        data = rows  # no header line
    except ValueError:
        low = [h.lower() for h in header]
        if len(header) != 3 or "speed" not in low[0] or "torque" not in low[1]:
            raise InputError(
                str(path),
                f"line {header_line} (header)",
                ",".join(header),
                "the VECTO header 'Speed Ratio, Torque Ratio, MP1000'",
            ) from None
        data = rows[1:]
    cols, lines = _columns(path, data, names)
    table = Characteristic.from_columns(
        cols["speed_ratio"], cols["torque_ratio"], cols["mp1000_nm"], "mp1000_nm", str(path), rows=lines
    )
    table.warn_if_implausible()
    return table


def read_table(path: str | Path) -> Characteristic:
    """Read a characteristic table, CSV or VECTO .vtcc by extension."""
    path = Path(path)
    if path.suffix.lower() == ".vtcc":
        return read_vtcc(path)
    return read_table_csv(path)
