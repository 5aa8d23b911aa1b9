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

Everything the user can get wrong (a missing channel, NaN, time going backwards, values that look
like the wrong unit, a corrupt file) is an :class:`~tcsim.errors.InputError` naming the file, the
column, the value and what was expected; the first problem found wins.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError
from ..models.measurement import Measurement
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
}

INPUT_CHANNELS: tuple[str, ...] = tuple(_QUANTITY)

#: |value| in SI above which a channel's unit is probably wrong, and what to say then.
_PLAUSIBLE_MAX = {"speed": 1500.0, "torque": 20_000.0}
_IMPLAUSIBLE = {
    "speed": "a speed in rad/s (values look like rpm; name the column *_rpm or map it with --channel)",
    "torque": "a torque in N·m below 20 000 N·m (values look like another unit, e.g. N·mm; "
    "check the column's unit or map it with --channel)",
}
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
    """The factor to SI implied by a column name's unit suffix; 1 if it has none of ``quantity``."""
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


def parse_channel_map(items: Sequence[str], source: str = "--channel") -> dict[str, str]:
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
        return list(dict.fromkeys(p.column for p in self.picks))

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


@contextlib.contextmanager
def _reading(path: Path, what: str) -> Iterator[None]:
    """Turn any failure of a third-party reader into an InputError naming the file."""
    try:
        yield
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - a corrupt file can fail in any way inside a library
        raise InputError(str(path), "(file)", f"{type(e).__name__}: {e}", f"a readable {what} file") from None


def _read_csv(path: Path, pick: _Chooser) -> _Loaded:
    with _reading(path, "CSV"):
        try:
            frame = pd.read_csv(path, comment="#", skipinitialspace=True, encoding="utf-8-sig")
        except pd.errors.EmptyDataError:
            raise InputError(str(path), "(file)", "empty", "a header line and at least two data rows") from None
    frame.columns = [str(c).strip() for c in frame.columns]
    return {c: frame[c].to_numpy() for c in pick(list(frame.columns))}, {}


def _read_parquet(path: Path, pick: _Chooser) -> _Loaded:
    import pyarrow.parquet as pq  # noqa: PLC0415  lazy: start-up time

    with _reading(path, "Parquet"):
        columns = pick(pq.read_schema(path).names)
        frame = pq.read_table(path, columns=columns).to_pandas()
    return {c: frame[c].to_numpy() for c in columns}, {}


def _is_vector(shape: tuple[int, ...], dtype: np.dtype) -> bool:
    """A MATLAB variable tcsim reads: numeric, with at most one dimension longer than 1."""
    return dtype.kind in "iuf" and sum(n > 1 for n in shape) <= 1


def _read_mat_v5(path: Path, pick: _Chooser) -> _Loaded:
    import scipy.io  # noqa: PLC0415  lazy: start-up time

    with _reading(path, "MATLAB .mat"):
        variables = scipy.io.loadmat(path)
    vectors = {
        k: v
        for k, v in variables.items()
        if not k.startswith("__") and isinstance(v, np.ndarray) and _is_vector(v.shape, v.dtype)
    }
    return {c: vectors[c].ravel() for c in pick(list(vectors))}, {}


def _read_mat_v73(path: Path, pick: _Chooser) -> _Loaded:
    """MATLAB v7.3 is HDF5: one dataset per variable, (1, N) or (N, 1); char and logical left out."""
    import h5py  # noqa: PLC0415  lazy: start-up time

    with _reading(path, "MATLAB v7.3 (HDF5) .mat"), h5py.File(path, "r") as f:
        datasets = {
            k: v
            for k, v in f.items()
            if isinstance(v, h5py.Dataset)
            and _is_vector(v.shape, v.dtype)
            and v.attrs.get("MATLAB_class", b"double") not in (b"char", b"logical")
        }
        return {c: np.asarray(datasets[c][()]).ravel() for c in pick(list(datasets))}, {}


def _read_mat(path: Path, pick: _Chooser) -> _Loaded:
    """MATLAB v5 through scipy, v7.3 (recognised by its HDF5 signature) through h5py."""
    import h5py  # noqa: PLC0415  lazy: start-up time

    return (_read_mat_v73 if h5py.is_hdf5(path) else _read_mat_v5)(path, pick)


def _read_mdf(path: Path, pick: _Chooser) -> _Loaded:
    """ASAM MDF: the first picked data channel's timestamps are the time base (``time_s``), the
    other channels are linearly interpolated onto it; units come from the channel metadata."""
    from asammdf import MDF  # noqa: PLC0415  lazy: start-up time

    with _reading(path, "ASAM MDF"), MDF(path) as mdf:
        first = {}  # channel name -> (group, index) of its first occurrence, masters left out
        for name, occurrences in mdf.channels_db.items():
            data = [(g, i) for g, i in occurrences if mdf.masters_db.get(g) != i]
            if data:
                first[name] = data[0]
        virtual_time = _MDF_TIME not in first
        columns = pick([*first, _MDF_TIME] if virtual_time else list(first))
        signals = {c: mdf.get(group=first[c][0], index=first[c][1]) for c in columns if c in first}
    if not signals:
        raise InputError(str(path), "(file)", "no data channel picked", "at least one measured channel")
    base = np.asarray(next(iter(signals.values())).timestamps)
    out = {c: _resample(s.samples, s.timestamps, base) for c, s in signals.items()}
    if virtual_time and _MDF_TIME in columns:
        out[_MDF_TIME] = base
    return out, {c: str(s.unit or "") for c, s in signals.items()}


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
        raise InputError(str(path), "(file)", "not found", f"an existing {what} file")
    return reader


def _at(row: int, time_s: np.ndarray | None) -> str:
    """Where a value is: the 1-based data row, and the time once that is known."""
    return f"row {row + 1}" + (f" (time_s {time_s[row]:g})" if time_s is not None else "")


def check_numeric(path: Path, column: str, values: np.ndarray, time_s: np.ndarray | None) -> np.ndarray:
    """``values`` as float64, or an InputError naming the first value that is not a number."""
    if values.dtype.kind in "iuf":
        return values.astype(np.float64)
    row = 0  # booleans, dates, ...
    if values.dtype.kind in "OUS":
        series = pd.Series(values)
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


def check_increasing(path: Path, column: str, time: np.ndarray) -> None:
    steps = np.flatnonzero(np.diff(time) <= 0)
    if len(steps):
        i = int(steps[0]) + 1
        raise InputError(
            str(path), column, f"{time[i]:g} at row {i + 1} after {time[i - 1]:g}", "time strictly increasing"
        )


def _plausible(
    path: Path, column: str, canonical: str, values_si: np.ndarray, converted: bool, time_s: np.ndarray | None
) -> None:
    """Values that suggest the wrong unit: a time span over 1e6 s, speeds or torques far too large."""
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
        return
    limit = _PLAUSIBLE_MAX.get(quantity)
    row = int(np.argmax(np.abs(values_si)))
    if limit is not None and abs(values_si[row]) > limit:
        si_unit = "rad/s" if quantity == "speed" else "N·m"
        expected = (
            f"|{canonical}| at most {limit:g} {si_unit} after conversion (check the column's unit)"
            if converted
            else _IMPLAUSIBLE[quantity]
        )
        raise InputError(str(path), column, f"{values_si[row]:g} {si_unit} at {_at(row, time_s)}", expected)


# --------------------------------------------------------------------------------------------


def read_measurement(
    path,
    channels: Mapping[str, str] | None = None,
    required: Sequence[str] = ("pump_torque_nm", "turbine_speed_rad_s"),
    optional: Sequence[str] = ("pump_speed_rad_s", "turbine_torque_nm"),
) -> Measurement:
    """Read a measured time series (CSV, Parquet, .mat v5/v7.3, MDF4) into SI channels.

    ``channels`` maps canonical names to columns of the file (see :func:`parse_channel_map`);
    ``required`` channels must be found, ``optional`` ones are left out when absent. Raises
    :class:`InputError` for anything wrong with the file, the first problem found.
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
        values = np.asarray(raw[p.column])
        if len(values) != n:
            raise InputError(str(path), p.column, f"{len(values)} samples", f"as many as {time_column} ({n})")
        time_s = out.get("time_s")
        values = check_numeric(path, p.column, values, time_s)
        check_finite(path, p.column, values, time_s)
        if p.canonical == "time_s":
            check_increasing(path, p.column, values)
        unit = units.get(p.column, "").strip()
        factor = _unit_factor(path, p.column, unit, p.canonical) if unit else p.name_factor
        if factor != 1.0:
            values = values * factor
        _plausible(path, p.column, p.canonical, values, factor != 1.0, time_s)
        out[p.canonical] = values
    time_s = out.pop("time_s")
    return Measurement(str(path), time_s, out)
