"""Measured time series for ``tcsim replay``: CSV, Parquet, MATLAB ``.mat`` (v5 and v7.3), ASAM MDF4.

Every reader lists the columns a file has, the wanted ones are picked by name, loaded, converted
to SI and checked. A wanted canonical name (``INPUT_CHANNELS``) is found, in this order:

1. through an explicit mapping ``--channel TARGET=COLUMN`` (the column must exist);
2. as the canonical name itself (``pump_torque_nm``);
3. as the same quantity with another unit suffix (``pump_torque_knm``, ``turbine_speed_rpm``,
   ``time_ms``, ...), converted.

A unit in the file's metadata (MDF4 channels carry one) decides the conversion when present; an
unconvertible unit is an error. Without one, a mapped column's own unit suffix is used if it has
one of the target's quantity, otherwise the values are taken as SI.

Everything the user can get wrong (a missing channel, NaN, time going backwards, a column name
that appears twice, a cell that holds no real number, an MDF channel that does not cover the
record, values that look like the wrong unit, a corrupt file) is an
:class:`~tcsim.errors.InputError` naming the file, the column, the value and what was expected; the
first problem found wins. The wrong-unit checks use the core's plausibility ranges
(``speed_rad_s``, ``torque_nm``, ``sample_spacing_s`` for the median time step:
:mod:`tcsim.models.plausibility`) and are overridable (``allow_implausible``); a record spanning
more than :data:`MAX_TIME_SPAN_S` is always refused.
"""

from __future__ import annotations

import contextlib
import gc
import math
import re
import sys
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import numpy as np
import pandas as pd

from .. import _core
from ..errors import ALLOW_IMPLAUSIBLE, InputError, TcsimWarning, not_utf8
from ..models.measurement import Measurement
from ..models.plausibility import check_plausible
from ..units import LBF_FT_IN_NM, RAD_S_PER_RPM

#: Name suffix -> factor to SI, per quantity; the first suffix of each is the SI one.
_SUFFIXES: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3},
    "speed": {"rad_s": 1.0, "rpm": RAD_S_PER_RPM, "deg_s": math.pi / 180.0},
    "torque": {"nm": 1.0, "knm": 1e3, "lbf_ft": LBF_FT_IN_NM},
    "flow": {"m3_s": 1.0, "l_s": 1e-3},
}

#: Unit strings from file metadata (normalised by :func:`_normalise_unit`) -> factor to SI.
_UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3},
    "speed": {
        "rad/s": 1.0,
        "1/s": 1.0,
        "rpm": RAD_S_PER_RPM,
        "1/min": RAD_S_PER_RPM,
        "min-1": RAD_S_PER_RPM,
        "deg/s": math.pi / 180.0,
    },
    "torque": {"nm": 1.0, "knm": 1e3, "lbfft": LBF_FT_IN_NM},
    "flow": {"m3/s": 1.0, "l/s": 1e-3},
}

#: Canonical name -> quantity.
_QUANTITY: dict[str, str] = {
    "time_s": "time",
    "pump_speed_rad_s": "speed",
    "turbine_speed_rad_s": "speed",
    "stator_speed_rad_s": "speed",
    "pump_torque_nm": "torque",
    "turbine_torque_nm": "torque",
    "turbine_load_torque_nm": "torque",
    "flow_m3_s": "flow",
    "lockup_capacity_nm": "torque",
    "engine_torque_nm": "torque",  # tcsim torque-estimate
}

INPUT_CHANNELS: tuple[str, ...] = tuple(_QUANTITY)

#: Quantity -> its plausibility range (``tcsim.models.plausibility``, owned by the core).
_RANGE_OF = {"speed": "speed_rad_s", "torque": "torque_nm"}
#: The longest record, s: a longer one is almost surely milliseconds read as seconds.
MAX_TIME_SPAN_S = 1e6

_MDF_TIME = "time_s"  # the virtual column holding an MDF file's time base


# --------------------------------------------------------------------------------------------
# channel names and units


def _stem(canonical: str) -> str:
    quantity = _QUANTITY[canonical]
    return canonical[: -len(next(iter(_SUFFIXES[quantity])))].rstrip("_")


def _candidates(canonical: str) -> list[tuple[str, float]]:
    """Column names that hold ``canonical``, canonical first, each with its factor to SI."""
    stem = _stem(canonical)
    return [(f"{stem}_{suffix}", factor) for suffix, factor in _SUFFIXES[_QUANTITY[canonical]].items()]


def _suffix_factor(column: str, quantity: str) -> float:
    """The factor to SI implied by a column name's unit: a unit of ``quantity`` in brackets at its end
    (``turbine speed [rpm]``, ``EngTrq (Nm)``, as loggers write them), else its unit suffix
    (``GbxInSpd_rpm``); 1 if it has none of ``quantity``."""
    bracketed = re.search(r"[\[(]\s*([^\[\]()]+?)\s*[\])]\s*$", column)
    if bracketed is not None:
        factor = _UNITS[quantity].get(_normalise_unit(bracketed.group(1)))
        if factor is not None:
            return factor
    lower = column.lower()
    for suffix, factor in _SUFFIXES[quantity].items():
        if lower.endswith("_" + suffix):
            return factor
    return 1.0


def _normalise_unit(unit: str) -> str:
    text = unit.strip().lower().replace("³", "3").replace("^", "")
    for sep in (" ", "·", "⋅", "*", "."):
        text = text.replace(sep, "")
    return text


def _unit_factor(path: Path, column: str, unit: str, canonical: str) -> float:
    quantity = _QUANTITY[canonical]
    factor = _UNITS[quantity].get(_normalise_unit(unit))
    if factor is None:
        accepted = ", ".join(_UNITS[quantity])
        raise InputError(
            str(path), f"{column} (unit)", unit, f"a {quantity} unit for {canonical} (one of {accepted}): wrong units"
        )
    return factor


_MAP_EXPECTED = f"TARGET=SOURCE with TARGET one of {', '.join(INPUT_CHANNELS)}"


def parse_channel_map(items: Sequence[str], source: str = "command line") -> dict[str, str]:
    """``["pump_torque_nm=EngTrq_Nm", ...]`` (TARGET=COLUMN) -> ``{"pump_torque_nm": "EngTrq_Nm"}``."""
    mapping: dict[str, str] = {}
    for item in items:
        target, sep, column = (part.strip() for part in item.partition("="))
        if not sep or not column or target not in _QUANTITY:
            raise InputError(source, "--channel", item, _MAP_EXPECTED)
        if target in mapping:
            raise InputError(source, "--channel", item, f"{_MAP_EXPECTED}, each TARGET at most once")
        mapping[target] = column
    return mapping


def _shorten(names: Sequence[str], limit: int = 12) -> str:
    if not names:
        return "(none)"
    shown = ", ".join(names[:limit])
    return shown if len(names) <= limit else f"{shown}, ... ({len(names) - limit} more)"


@dataclass(frozen=True)
class _Pick:
    """Where one canonical channel comes from: a column of the file, and the factor its name implies."""

    canonical: str
    column: str
    name_factor: float


class _Picker:
    """Called by a format reader with the file's column names; picks the wanted ones, time first.

    Returns the columns to load; ``picks`` keeps where each canonical channel comes from.
    """

    def __init__(self, path: Path, channels: Mapping[str, str], required: Sequence[str], optional: Sequence[str]):
        self.path = path
        self.channels = channels
        self.wanted = list(dict.fromkeys(["time_s", *required, *channels, *optional]))
        self.needed = {"time_s", *required, *channels}
        self.picks: list[_Pick] = []

    def __call__(self, names: Sequence[str]) -> list[str]:
        picks = (self._pick(canonical, names) for canonical in self.wanted)
        self.picks = [p for p in picks if p is not None]
        columns = list(dict.fromkeys(p.column for p in self.picks))
        refuse_duplicates(self.path, names, columns)
        return columns

    def _pick(self, canonical: str, names: Sequence[str]) -> _Pick | None:
        quantity = _QUANTITY[canonical]
        if canonical in self.channels:
            column = self.channels[canonical]
            if column not in names:
                raise InputError(
                    str(self.path),
                    column,
                    "missing",
                    f"a column named {column} (--channel {canonical}={column}); columns found: {_shorten(list(names))}",
                )
            return _Pick(canonical, column, _suffix_factor(column, quantity))
        candidates = _candidates(canonical)
        for column, factor in candidates:
            if column in names:
                return _Pick(canonical, column, factor)
        if canonical in self.needed:
            alternatives = " or ".join(c for c, _ in candidates[1:])
            raise InputError(
                str(self.path),
                canonical,
                "missing",
                f"a column named {canonical} or {alternatives}, or --channel "
                f"{canonical}=COLUMN; columns found: {_shorten(list(names))}",
            )
        return None


# --------------------------------------------------------------------------------------------
# formats: each lists the file's columns, lets ``pick`` choose, and returns (columns, units)

_Loaded = tuple[dict[str, np.ndarray], dict[str, str]]
_Chooser = Callable[[Sequence[str]], list[str]]
_T = TypeVar("_T")


def _guarded(path: Path, what: str, read: Callable[[], _T]) -> _T:
    """``read()``, with any failure of a third-party reader turned into an InputError naming the
    file. The InputError is raised once the library's exception is gone (it is not chained to it),
    so that the objects its frames held are cleaned up before the message is printed."""
    try:
        return read()
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - a corrupt file can fail in any way inside a library
        # a file the system cannot read says why (its errno's text); a library's failure says what it is
        failure = e.strerror if isinstance(e, OSError) and e.strerror else f"{type(e).__name__}: {e}"
    gc.collect()
    raise InputError(str(path), "(file)", failure, f"a readable {what} file")


@contextlib.contextmanager
def _quiet_mdf_cleanup() -> Iterator[None]:
    """asammdf's ``MDF4.__del__`` fails on an object whose constructor failed (a corrupt file): the
    interpreter would print that failure as "Exception ignored ..." with a traceback after tcsim's
    message. Silence exactly those (objects of asammdf) while an MDF file is read."""
    previous = sys.unraisablehook

    def hook(unraisable) -> None:
        where = unraisable.object  # the failing __del__ method, or the object
        module = getattr(where, "__module__", None) or type(where).__module__
        if not str(module).startswith("asammdf"):
            previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        gc.collect()
        sys.unraisablehook = previous


def refuse_duplicates(path: Path, names: Sequence[str], columns: Sequence[str] | None = None) -> None:
    """An InputError naming the first column name that appears more than once in ``names`` (among
    ``columns`` only, when given): a duplicated header makes it ambiguous which column is meant."""
    seen: set[str] = set()
    for name in names:
        if name in seen and (columns is None or name in columns):
            count = sum(n == name for n in names)
            raise InputError(str(path), name, f"{count} columns", "each column name at most once in the file")
        seen.add(name)


def read_csv_frame(path: Path, what: str = "CSV") -> pd.DataFrame:
    """A CSV file as a DataFrame: ``#`` comments, a UTF-8 byte-order mark, blanks after the commas
    and a comma at the end of the rows allowed, the header's names stripped; an InputError for an
    empty or unreadable file, a file that is not UTF-8, a header separated by ``;`` or tabs, a row
    with more values than the header has columns (pandas would take the first as the row's index and
    shift the others, silently), and a column name that appears twice (pandas would rename the second
    one silently)."""
    options: dict = {"comment": "#", "skipinitialspace": True, "encoding": "utf-8-sig"}

    def read() -> tuple[pd.DataFrame, pd.DataFrame]:
        try:
            header = pd.read_csv(path, header=None, nrows=1, dtype=str, keep_default_na=False, **options)
            with warnings.catch_warnings():
                # index_col=False: never a first column as the index; a longer row warns, refused below
                warnings.simplefilter("error", pd.errors.ParserWarning)
                return pd.read_csv(path, index_col=False, **options), header
        except pd.errors.EmptyDataError:
            raise InputError(str(path), "(file)", "empty", "a header line and data rows") from None
        except pd.errors.ParserWarning:
            raise _longer_row(path) from None
        except UnicodeDecodeError as e:
            raise not_utf8(path, e) from None

    frame, header = _guarded(path, what, read)
    # an empty name gets pandas' own (``Unnamed: 3``), which --channel can map
    names = [str(c).strip() or f"Unnamed: {i}" for i, c in enumerate(header.iloc[0])]
    if len(names) == 1 and (";" in names[0] or "\t" in names[0]):
        sep = "';'" if ";" in names[0] else "tabs"
        expected = f"columns separated by commas (this header is separated by {sep}: save the file as comma-separated)"
        raise InputError(str(path), "(header)", names[0], expected)
    refuse_duplicates(path, names)
    frame.columns = names
    return frame


def _longer_row(path: Path) -> InputError:
    """The refusal of the first line of ``path`` with more values than its header has columns (an
    empty value after a last comma is no value)."""
    import csv  # noqa: PLC0415  lazy: only on this error

    with open(path, encoding="utf-8-sig", newline="") as f:
        rows = [(n, r) for n, r in enumerate(csv.reader(f), start=1) if r and not r[0].lstrip().startswith("#")]
    width = len(rows[0][1])
    for n, row in rows[1:]:
        values = row[:-1] if row and not row[-1].strip() else row
        if len(values) > width:
            expected = f"at most {width} values, one per column of the header ({', '.join(rows[0][1])})"
            return InputError(str(path), f"line {n}", f"{len(values)} values", expected)
    return InputError(str(path), "(file)", "a row longer than the header", f"at most {width} values a row")


def _read_csv(path: Path, pick: _Chooser) -> _Loaded:
    frame = read_csv_frame(path)
    return {c: frame[c].to_numpy() for c in pick(list(frame.columns))}, {}


def _read_parquet(path: Path, pick: _Chooser) -> _Loaded:
    import pyarrow.parquet as pq  # noqa: PLC0415  lazy: start-up time

    names = _guarded(path, "Parquet", lambda: pq.read_schema(path).names)
    refuse_duplicates(path, names)
    columns = pick(names)
    table = _guarded(path, "Parquet", lambda: pq.read_table(path, columns=columns))
    # a column of lists or structs becomes an object array, refused by check_numeric
    return {c: _guarded(path, "Parquet", table.column(c).to_numpy) for c in columns}, {}


def _is_vector(shape: tuple[int, ...], dtype: np.dtype) -> bool:
    """A MATLAB variable tcsim reads: numeric (complex ones too, refused by :func:`check_numeric`
    with their own message), with at most one dimension longer than 1."""
    return (dtype.kind in "iufc" or _is_complex_compound(dtype)) and sum(n > 1 for n in shape) <= 1


def _is_complex_compound(dtype: np.dtype) -> bool:
    """How MATLAB v7.3 (HDF5) stores a complex variable: a compound of ``real`` and ``imag``."""
    return dtype.names is not None and set(dtype.names) == {"real", "imag"}


def _read_mat_v5(path: Path, pick: _Chooser) -> _Loaded:
    import scipy.io  # noqa: PLC0415  lazy: start-up time

    variables = _guarded(path, "MATLAB .mat", lambda: scipy.io.loadmat(path))
    variables = {k: v for k, v in variables.items() if not k.startswith("__")}
    columns = pick(list(variables))
    for c in columns:
        _require_vector(path, c, variables[c])
    return {c: variables[c].ravel() for c in columns}, {}


def _require_vector(path: Path, name: str, value: object) -> None:
    """An InputError unless the MATLAB variable ``name`` is a numeric vector (its shape and kind
    named: a matrix, a struct, a cell array, text)."""
    shape = getattr(value, "shape", ())
    dtype = getattr(value, "dtype", np.dtype(object))
    if isinstance(value, np.ndarray) and _is_vector(shape, dtype):
        return
    kind = {"O": "cell array", "V": "struct", "U": "char array", "S": "char array"}.get(dtype.kind, "matrix")
    size = "x".join(str(n) for n in shape) or "scalar"
    raise InputError(str(path), name, f"a {size} {kind}", "a numeric vector (one row or one column)")


def _read_mat_v73(path: Path, pick: _Chooser) -> _Loaded:
    """MATLAB v7.3 is HDF5: one dataset per variable, (1, N) or (N, 1); char and logical left out."""
    import h5py  # noqa: PLC0415  lazy: start-up time

    def read() -> dict[str, np.ndarray]:
        with h5py.File(path, "r") as f:
            datasets = {k: v for k, v in f.items() if isinstance(v, h5py.Dataset)}
            columns = pick(list(datasets))
            for c in columns:
                matlab_class = datasets[c].attrs.get("MATLAB_class", b"double")
                if matlab_class in (b"char", b"logical", b"cell", b"struct"):
                    kind = matlab_class.decode()
                    shape = "x".join(str(n) for n in datasets[c].shape)
                    raise InputError(
                        str(path), c, f"a {shape} {kind} array", "a numeric vector (one row or one column)"
                    )
                _require_vector(path, c, np.empty(datasets[c].shape, datasets[c].dtype))
            return {c: np.asarray(datasets[c][()]).ravel() for c in columns}

    loaded = _guarded(path, "MATLAB v7.3 (HDF5) .mat", read)
    return {c: v["real"] + 1j * v["imag"] if _is_complex_compound(v.dtype) else v for c, v in loaded.items()}, {}


def _read_mat(path: Path, pick: _Chooser) -> _Loaded:
    """MATLAB v5 through scipy, v7.3 (recognised by its HDF5 signature) through h5py."""
    import h5py  # noqa: PLC0415  lazy: start-up time

    return (_read_mat_v73 if h5py.is_hdf5(path) else _read_mat_v5)(path, pick)


def _read_mdf(path: Path, pick: _Chooser) -> _Loaded:
    """ASAM MDF: the first picked data channel's timestamps are the time base (``time_s``), the
    other channels are linearly interpolated onto it; units come from the channel metadata. Every
    picked channel must cover the time span of the others (:func:`_check_coverage`)."""
    from asammdf import MDF  # noqa: PLC0415  lazy: start-up time

    def read() -> tuple[dict, list[str], bool]:
        with MDF(path) as mdf:
            found = {}  # channel name -> its (group, index) occurrences, masters left out
            for name, occurrences in mdf.channels_db.items():
                data = [(g, i) for g, i in occurrences if mdf.masters_db.get(g) != i]
                if data:
                    found[name] = data
            virtual_time = _MDF_TIME not in found
            columns = pick([*found, _MDF_TIME] if virtual_time else list(found))
            signals = {c: _one_mdf_signal(path, mdf, c, found[c]) for c in columns if c in found}
            return signals, columns, virtual_time

    with _quiet_mdf_cleanup():
        signals, columns, virtual_time = _guarded(path, "ASAM MDF", read)
    if not signals:
        raise InputError(str(path), "(file)", "no data channel picked", "at least one measured channel")
    _check_coverage(path, {c: np.asarray(s.timestamps, dtype=float) for c, s in signals.items()})
    base = np.asarray(next(iter(signals.values())).timestamps)
    out = {c: _resample(s.samples, s.timestamps, base) for c, s in signals.items()}
    if virtual_time and _MDF_TIME in columns:
        out[_MDF_TIME] = base
    return out, {c: str(s.unit or "") for c, s in signals.items()}


def _one_mdf_signal(path: Path, mdf, name: str, occurrences: Sequence[tuple[int, int]]):
    """The channel ``name``: its first occurrence, and an InputError if another channel group holds
    a channel of that name with other samples (which one is meant would be a guess)."""
    signal = mdf.get(group=occurrences[0][0], index=occurrences[0][1])
    for group, index in occurrences[1:]:
        other = mdf.get(group=group, index=index)
        same = np.array_equal(other.timestamps, signal.timestamps) and np.array_equal(other.samples, signal.samples)
        if not same:
            raise InputError(
                str(path),
                name,
                f"{len(occurrences)} channels (groups {', '.join(str(g) for g, _ in occurrences)})",
                "each channel name at most once in the file, or in several channel groups with the same samples",
            )
    return signal


def _check_coverage(path: Path, timestamps: Mapping[str, np.ndarray]) -> None:
    """Refuse a channel whose samples do not span the record (the span of all the picked channels)
    within one sample step (the largest median step of the channels): it would be held constant
    before its first sample or after its last."""
    spans = {c: (float(t[0]), float(t[-1])) for c, t in timestamps.items() if len(t) >= 2}
    if len(spans) < 2:
        return
    start, end = min(a for a, _ in spans.values()), max(b for _, b in spans.values())
    step = max(float(np.median(np.diff(timestamps[c]))) for c in spans)
    for column, (a, b) in spans.items():
        if a > start + step or b < end - step:
            raise InputError(
                str(path),
                column,
                f"samples from {a:g} s to {b:g} s",
                f"a channel covering the record, {start:g} s to {end:g} s, within one sample step "
                f"({step:g} s); a channel is not held beyond its samples",
            )


def _resample(samples: np.ndarray, timestamps: np.ndarray, base: np.ndarray) -> np.ndarray:
    if np.array_equal(timestamps, base) or samples.dtype.kind not in "iuf" or len(timestamps) < 2:
        return samples  # the last two are reported as non-numeric or too short by the checks
    return np.interp(base, timestamps, samples.astype(np.float64))


READERS: dict[str, Callable[[Path, _Chooser], _Loaded]] = {
    ".csv": _read_csv,
    ".parquet": _read_parquet,
    ".mat": _read_mat,
    ".mf4": _read_mdf,
    ".mdf": _read_mdf,
}


# --------------------------------------------------------------------------------------------
# checks


def reader_for(path: Path, what: str) -> Callable[[Path, _Chooser], _Loaded]:
    """The reader of a time-series file by its extension (:data:`READERS`); an :class:`InputError`
    naming the file when the extension is unknown or the file does not exist (``what`` says which
    kind of file the command wanted: ``measurement``, ``scenario``)."""
    reader = READERS.get(path.suffix.lower())
    if reader is None:
        raise InputError(
            str(path), "(extension)", path.suffix or "(none)", f"a {what} file ending in one of {', '.join(READERS)}"
        )
    if not path.is_file():
        found = "a directory" if path.is_dir() else "not found"
        raise InputError(str(path), "(file)", found, f"an existing {what} file")
    return reader


def _at(row: int, time_s: np.ndarray | None) -> str:
    """Where a value is: the 1-based data row, and the time once that is known."""
    return f"row {row + 1}" + (f" (time_s {time_s[row]:g})" if time_s is not None else "")


def check_column(
    path: Path, column: str, values, n: int, time_column: str, time_s: np.ndarray | None, is_time: bool
) -> np.ndarray:
    """One column of a time table as float64: ``n`` samples (as many as ``time_column``), real
    numbers, finite, and strictly increasing if it is the time; else an InputError naming the first
    bad value (the one check of measurements, scenarios and drive cycles)."""
    values = np.asarray(values)
    if len(values) != n:
        raise InputError(str(path), column, f"{len(values)} samples", f"as many as {time_column} ({n})")
    values = check_numeric(path, column, values, time_s)
    check_finite(path, column, values, time_s)
    if is_time:
        check_increasing(path, column, values)
    return values


def check_numeric(path: Path, column: str, values: np.ndarray, time_s: np.ndarray | None) -> np.ndarray:
    """``values`` as float64, or an InputError naming the first value that is not a real number
    (text, a boolean, a date, a list or a structure of a Parquet column, a complex number)."""
    if values.dtype.kind in "iuf":
        return values.astype(np.float64)
    if values.dtype.kind == "c":
        bad = np.flatnonzero(values.imag != 0)
        if not len(bad):
            return values.real.astype(np.float64)
        row = int(bad[0])
        raise InputError(str(path), column, f"{values[row]} at {_at(row, time_s)}", "real numbers, not complex values")
    row = 0  # booleans, dates, ...
    if values.dtype.kind in "OUS":
        series = pd.Series(values)
        objects = values if values.dtype.kind == "O" else ()
        nested = np.flatnonzero([not np.isscalar(v) and v is not None for v in objects])
        if len(nested):
            row = int(nested[0])
            value = values[row].tolist() if isinstance(values[row], np.ndarray) else values[row]
            raise InputError(str(path), column, f"{value!r} at {_at(row, time_s)}", "numbers only, one per row")
        parsed = pd.to_numeric(series, errors="coerce")
        bad = np.flatnonzero(parsed.isna() & series.notna())
        if not len(bad):
            return parsed.to_numpy(dtype=np.float64)
        row = int(bad[0])
    value = np.asarray(values[row]).item()  # a plain Python value, for the message
    raise InputError(str(path), column, f"{value!r} at {_at(row, time_s)}", "numbers only")


def check_finite(path: Path, column: str, values: np.ndarray, time_s: np.ndarray | None) -> None:
    bad = np.flatnonzero(~np.isfinite(values))
    if len(bad):
        value = values[bad[0]]
        shown = "NaN" if np.isnan(value) else str(value)
        raise InputError(
            str(path),
            column,
            f"{shown} at {_at(int(bad[0]), time_s)}",
            "finite numbers (no NaN or inf, no empty cells)",
        )


#: Channels that are a lock-up clutch's capacity command, 0 to the core's limit (docs/lockup.md).
NON_NEGATIVE: tuple[str, ...] = ("lockup_capacity_nm",)
#: The core's capacity limit, N·m, and its wording (``tcsim_core::engine::lockup``).
MAX_CAPACITY_NM, CAPACITY_EXPECTED = _core.lockup_limits()


def check_non_negative(path: Path, column: str, values: np.ndarray, time_s: np.ndarray | None) -> None:
    """An InputError naming the first value outside 0 … :data:`MAX_CAPACITY_NM` (a capacity command
    of a clutch), with its row and time."""
    bad = np.flatnonzero((values < 0) | (values > MAX_CAPACITY_NM))
    if len(bad):
        row = int(bad[0])
        raise InputError(str(path), column, f"{values[row]:g} at {_at(row, time_s)}", CAPACITY_EXPECTED)


def check_increasing(path: Path, column: str, time: np.ndarray) -> None:
    steps = np.flatnonzero(np.diff(time) <= 0)
    if len(steps):
        i = int(steps[0]) + 1
        raise InputError(
            str(path), column, f"{time[i]:g} at row {i + 1} after {time[i - 1]:g}", "time strictly increasing"
        )


#: A time step this many times the median one is a gap in the record, warned of.
GAP_STEPS = 20.0


def _warn_of_a_gap(path: Path, column: str, steps: np.ndarray, median_step_s: float) -> None:
    """One warning for the longest time step when it is over :data:`GAP_STEPS` times the median one
    (rows lost by the logger): every channel is taken as linear across it, a guess, not data."""
    worst = int(np.argmax(steps))
    if not steps[worst] > GAP_STEPS * median_step_s:
        return
    warnings.warn(
        f"{path}: {column}: {steps[worst]:.4g} s between rows {worst + 1} and {worst + 2}, "
        f"{steps[worst] / median_step_s:.0f} times the median step ({median_step_s:.3g} s): rows missing? "
        "The record is taken as linear across the gap",
        TcsimWarning,
        stacklevel=4,
    )


#: The shortest record under a milliseconds name that is not taken for seconds under it, s.
MIN_MS_RECORD_S = 0.1


def _short_ms_record(path: Path, column: str, span_s: float, allow: bool) -> None:
    """Refuse (or with ``allow`` warn of) a record under a milliseconds name shorter than
    :data:`MIN_MS_RECORD_S`: seconds written under ``time_ms`` make a 3 s log 3 ms long, its
    accelerations a thousand times too large (a fresh-eyes trial's replay ran with exit 0)."""
    shown = f"a record of {span_s * 1e3:g} ms"
    expected = (
        f"a record of at least {MIN_MS_RECORD_S * 1e3:g} ms (seconds under a milliseconds name? name the column time_s)"
    )
    if not allow:
        raise InputError(str(path), column, shown, expected, override=ALLOW_IMPLAUSIBLE)
    warnings.warn(f"{path}: {column} = {shown}: expected {expected}", TcsimWarning, stacklevel=4)


def _plausible(
    path: Path,
    column: str,
    canonical: str,
    values_si: np.ndarray,
    time_s: np.ndarray | None,
    allow_implausible: bool,
) -> None:
    """Values that suggest the wrong unit: a time span over :data:`MAX_TIME_SPAN_S` or a median
    time step outside ``sample_spacing_s`` (milliseconds read as seconds), speeds outside
    ``speed_rad_s`` (rpm read as rad/s), torques outside ``torque_nm``: the core's plausibility
    ranges, overridable with ``allow_implausible`` (``--allow-implausible``)."""
    quantity = _QUANTITY[canonical]
    if quantity == "time":
        span = values_si[-1] - values_si[0]
        if span > MAX_TIME_SPAN_S:
            raise InputError(
                str(path),
                column,
                f"span {span:g} s",
                f"time in seconds (a span under {MAX_TIME_SPAN_S:g} s; name the column time_ms "
                "or map it with --channel)",
            )
        steps = np.diff(values_si)
        step = float(np.median(steps))
        check_plausible("sample_spacing_s", step, str(path), f"{column} (median time step, s)", allow_implausible)
        _warn_of_a_gap(path, column, steps, step)
        if column.endswith("_ms") and span < MIN_MS_RECORD_S:
            _short_ms_record(path, column, span, allow_implausible)
        return
    if quantity not in _RANGE_OF:
        return
    check_plausible(
        _RANGE_OF[quantity], values_si, str(path), column, allow_implausible, locate=lambda row: _at(row, time_s)
    )


# --------------------------------------------------------------------------------------------


def read_measurement(
    path,
    channels: Mapping[str, str] | None = None,
    required: Sequence[str] = ("pump_torque_nm", "turbine_speed_rad_s"),
    optional: Sequence[str] = ("pump_speed_rad_s", "turbine_torque_nm"),
    allow_implausible: bool = False,
) -> Measurement:
    """Read a measured time series (CSV, Parquet, .mat v5/v7.3, MDF4) into SI channels.

    ``channels`` maps canonical names to columns of the file (see :func:`parse_channel_map`);
    ``required`` channels must be found, ``optional`` ones are left out when absent. Raises
    :class:`InputError` for anything wrong with the file, the first problem found; values outside
    the plausibility ranges (speeds, torques, the median time step) are refused unless
    ``allow_implausible`` (then a warning).
    """
    channels = dict(channels or {})
    for name in [*required, *optional]:
        if name not in _QUANTITY:
            raise ValueError(f"unknown channel {name!r}; known: {', '.join(INPUT_CHANNELS)}")
    for target, column in channels.items():
        if target not in _QUANTITY:
            raise InputError("--channel", "--channel", f"{target}={column}", _MAP_EXPECTED)
    path = Path(path)
    reader = reader_for(path, "measurement")

    picker = _Picker(path, channels, required, optional)
    raw, units = reader(path, picker)
    time_column = picker.picks[0].column
    n = len(raw[time_column])
    if n < 2:
        raise InputError(str(path), time_column, f"{n} rows", "at least 2 data rows")
    out: dict[str, np.ndarray] = {}
    for p in picker.picks:  # time first
        time_s = out.get("time_s")
        values = check_column(path, p.column, raw[p.column], n, time_column, time_s, p.canonical == "time_s")
        unit = units.get(p.column, "").strip()
        factor = _unit_factor(path, p.column, unit, p.canonical) if unit else p.name_factor
        if factor != 1.0:
            values = values * factor
        if p.canonical in NON_NEGATIVE:  # a hard limit first: no plausibility warning for a refused value
            check_non_negative(path, p.column, values, time_s)
        _plausible(path, p.column, p.canonical, values, time_s, allow_implausible)
        out[p.canonical] = values
    time_s = out.pop("time_s")
    return Measurement(str(path), time_s, out)
