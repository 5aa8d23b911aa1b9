"""Property-based tests of the readers (hypothesis; profiles in tests/conftest.py, how to run the long
one in tests/cli/bad_inputs/README.md).

For any file a user or a script could write, a reader either returns a valid object or raises
:class:`tcsim.errors.InputError` whose text is one line naming the file: never another exception,
never a panic of the core (``pyo3_runtime.PanicException``, a ``BaseException``), and never a
non-finite number in a returned object where the schema forbids it.
"""

from __future__ import annotations

import math
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import assume, example, given
from hypothesis import strategies as st

from tcsim.analysis.fitting import parse_bounds, parse_free
from tcsim.analysis.replay import parse_initial
from tcsim.errors import InputError
from tcsim.io.measurement import parse_channel_map, read_measurement
from tcsim.io.scenario import read_scenario
from tcsim.models.characteristic import CAPACITY_KEYS, Characteristic
from tcsim.models.converter import Converter, load_converter
from tcsim.models.vehicle import Vehicle, read_vehicle_text

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "cli" / "bad_inputs"))
import make  # noqa: E402  the catalogue's file writers (tests/cli/bad_inputs/make.py)

BUNDLED_CONVERTER = (REPO / "python" / "tcsim" / "data" / "converters" / "li-sunden-2016.toml").read_text()
BUNDLED_VEHICLE = (REPO / "python" / "tcsim" / "data" / "vehicles" / "midsize-awd-8at.toml").read_text()
TABLE_C1 = (REPO / "tests" / "data" / "converters" / "li_sunden_2016_table_c1.csv").read_text()


# --------------------------------------------------------------------------------------------
# the contract


@contextmanager
def scratch() -> Iterator[Path]:
    """A fresh folder per example (hypothesis runs many examples in one test)."""
    with tempfile.TemporaryDirectory(prefix="tcsim-prop-") as d:
        yield Path(d)


def outcome(read: Callable[[], Any], source: str) -> Any:
    """``read()``'s object, or None when it raised an InputError that is one line naming ``source``;
    any other exception (a panic included) propagates and fails the test."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # implausible values may warn; warnings are not the subject
        try:
            return read()
        except InputError as e:
            text = str(e)
            assert "\n" not in text and "\r" not in text, f"message on more than one line: {text!r}"
            assert text.startswith(source + ": "), f"message does not name {source}: {text!r}"
            return None


def assert_finite(where: str, *arrays: Any) -> None:
    for a in arrays:
        assert np.all(np.isfinite(np.asarray(a, dtype=float))), f"non-finite value in {where}: {a}"


def capacity_underflow(conv: Converter | None) -> bool:
    """A positive capacity that underflowed to a capacity factor of 0 on conversion (MP1000 5e-324,
    a K-factor of 1e200): accepted before issue 10, refused since."""
    c = conv.characteristic if conv is not None else None
    return c is not None and bool(np.any(c.capacity_factor_nm_s2[c.speed_ratio < 1.0] == 0.0))


def check_characteristic(c: Characteristic) -> None:
    assert_finite("characteristic", c.speed_ratio, c.torque_ratio, c.capacity_factor_nm_s2)
    assert len(c.speed_ratio) >= 2 and np.all(np.diff(c.speed_ratio) > 0)
    drive = c.speed_ratio < 1.0
    assert np.all(c.torque_ratio[drive] > 0) and np.all(c.capacity_factor_nm_s2[drive] > 0)


def check_converter(conv: Converter) -> None:
    if conv.characteristic is not None:
        check_characteristic(conv.characteristic)
    for section in (conv.inertia, conv.geometry, conv.quasi_dynamic):
        if section is not None:
            values = [v for v in section.model_dump().values() if v is not None]
            assert_finite(type(section).__name__, values)
    if conv.inertia is not None:
        assert min(conv.inertia.model_dump().values()) > 0


# --------------------------------------------------------------------------------------------
# strategies

#: Numbers a file could hold: ordinary, zero, negative, tiny, huge, non-finite.
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(-1e3, 1e3),
    st.sampled_from([0.0, -0.0, 1e-300, 5e-324, 1e300, -1e300, 1.7976931348623157e308]),
    st.integers(-(10**20), 10**20),
)


def toml_value(x: Any) -> str:
    if isinstance(x, float):
        return "nan" if math.isnan(x) else ("inf" if x == math.inf else "-inf" if x == -math.inf else repr(x))
    return str(x)


toml_values = st.one_of(
    numbers.map(toml_value),
    st.lists(numbers, max_size=15).map(lambda xs: "[" + ", ".join(toml_value(x) for x in xs) + "]"),
    st.text(max_size=12).map(lambda s: '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'),
    st.sampled_from(["true", "[]", "{}", '"1e3"', "1979-05-27", "[[1.0], [2.0]]"]),
)
junk = st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=20)


def mutate_toml(draw: st.DrawFn, text: str) -> str:
    """One to three edits of a TOML file: a key's value replaced, a line deleted or duplicated, junk
    inserted."""
    lines = text.splitlines()
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["value", "value", "value", "delete", "duplicate", "junk"]))
        if kind == "value" and "=" in lines[i] and not lines[i].lstrip().startswith("#"):
            key = lines[i].split("=", 1)[0]
            lines[i] = f"{key}= {draw(toml_values)}"
        elif kind == "delete":
            del lines[i]
        elif kind == "duplicate":
            lines.insert(i, lines[i])
        else:
            lines.insert(i, draw(junk))
        if not lines:
            lines = [""]
    return "\n".join(lines) + "\n"


@st.composite
def converter_texts(draw: st.DrawFn) -> str:
    return mutate_toml(draw, BUNDLED_CONVERTER)


@st.composite
def vehicle_texts(draw: st.DrawFn) -> str:
    return mutate_toml(draw, BUNDLED_VEHICLE)


def csv_cell(x: Any) -> str:
    return toml_value(x) if isinstance(x, float) else str(x)


@st.composite
def table_texts(draw: st.DrawFn) -> str:
    """A characteristic table CSV: the published one with cells replaced, or random columns."""
    if draw(st.booleans()):
        lines = TABLE_C1.splitlines()
        for _ in range(draw(st.integers(1, 4))):
            i = draw(st.integers(0, len(lines) - 1))
            cells = lines[i].split(",")
            j = draw(st.integers(0, len(cells) - 1))
            cells[j] = draw(st.one_of(numbers.map(csv_cell), junk.filter(lambda s: "\n" not in s and "\r" not in s)))
            lines[i] = ",".join(cells)
        return "\n".join(lines) + "\n"
    names = ["speed_ratio", "torque_ratio", *CAPACITY_KEYS, "k_factor", ""]
    header = draw(st.lists(st.sampled_from(names), min_size=0, max_size=4))
    rows = draw(st.lists(st.lists(numbers.map(csv_cell), min_size=len(header), max_size=len(header)), max_size=6))
    return "\n".join([",".join(header), *(",".join(r) for r in rows)]) + "\n"


@st.composite
def vtcc_texts(draw: st.DrawFn) -> str:
    header = draw(st.sampled_from(["Speed Ratio, Torque Ratio,MP1000", "", "ratio,mu,torque", "# comment"]))
    rows = draw(st.lists(st.lists(numbers.map(csv_cell), min_size=3, max_size=3), max_size=6))
    if rows and draw(st.booleans()):  # a plausible table: SR increasing, positive values
        rows = [[str(i / len(rows)), str(2.0 - i / len(rows)), str(300.0 - i)] for i in range(len(rows))]
        rows[draw(st.integers(0, len(rows) - 1))][draw(st.integers(0, 2))] = csv_cell(draw(numbers))
    return "\n".join([header, *(",".join(r) for r in rows)]) + "\n"


# --------------------------------------------------------------------------------------------
# converters and tables


@given(text=converter_texts())
def test_converter_toml_is_read_or_refused_in_one_line(text):
    with scratch() as d:
        path = d / "conv.toml"
        path.write_text(text, encoding="utf-8")
        conv = outcome(lambda: load_converter(path), str(path))
        if conv is not None:
            check_converter(conv)


@given(text=table_texts())
def test_table_csv_is_read_or_refused_in_one_line(text):
    with scratch() as d:
        path = d / "table.csv"
        path.write_text(text, encoding="utf-8")
        conv = outcome(lambda: load_converter(path), str(path))
        if conv is not None:
            assert conv.characteristic is not None
            check_characteristic(conv.characteristic)


@given(text=vtcc_texts())
def test_vtcc_is_read_or_refused_in_one_line(text):
    with scratch() as d:
        path = d / "table.vtcc"
        path.write_text(text, encoding="utf-8")
        conv = outcome(lambda: load_converter(path), str(path))
        if conv is not None:
            assert conv.characteristic is not None
            check_characteristic(conv.characteristic)


@given(text=st.sampled_from(["Speed Ratio, Torque Ratio,MP1000\n0.0,1.0,5e-324\n1,0.0,0.0\n"]))
@example(text="speed_ratio,torque_ratio,k_factor_rad_s_per_sqrt_nm\n0.0,2.0,1e200\n0.5,1.5,15\n1.0,1.0,35\n")
def test_capacity_underflowing_on_conversion_is_refused(text):
    with scratch() as d:
        path = d / ("table.vtcc" if text.startswith("Speed") else "table.csv")
        path.write_text(text, encoding="utf-8")
        conv = outcome(lambda: load_converter(path), str(path))
        assert conv is None or not capacity_underflow(conv)


@given(data=st.binary(max_size=200), suffix=st.sampled_from([".toml", ".csv", ".vtcc"]))
def test_converter_files_of_random_bytes_are_refused_in_one_line(data, suffix):
    with scratch() as d:
        path = d / f"conv{suffix}"
        path.write_bytes(data)
        conv = outcome(lambda: load_converter(path), str(path))
        if conv is not None:
            check_converter(conv)


# --------------------------------------------------------------------------------------------
# vehicles


def _vehicle_numbers(value: Any) -> list[float]:
    if isinstance(value, bool) or isinstance(value, str) or value is None:
        return []
    if isinstance(value, (int, float)):
        return [float(value)]
    if isinstance(value, dict):
        return [x for v in value.values() for x in _vehicle_numbers(v)]
    return [x for v in value for x in _vehicle_numbers(v)]


@given(text=vehicle_texts())
def test_vehicle_toml_is_read_or_refused_in_one_line(text):
    veh = outcome(lambda: read_vehicle_text(text, "veh.toml"), "veh.toml")
    if veh is not None:
        assert isinstance(veh, Vehicle)
        assert_finite("vehicle", _vehicle_numbers(veh.core_spec()))
        check_converter(veh.converter)


# --------------------------------------------------------------------------------------------
# scenarios and measurements, every format

FORMATS = ["csv", "parquet", "mat", "v73.mat", "mf4"]
MEASUREMENT_NAMES = [
    "time_s",
    "time_ms",
    "pump_torque_nm",
    "pump_torque_knm",
    "turbine_speed_rad_s",
    "turbine_speed_rpm",
    "pump_speed_rad_s",
    "turbine_torque_nm",
    "flow_m3_s",
    "speed",
]
SCENARIO_NAMES = [
    "time_s",
    "time_ms",
    "accelerator_pedal",
    "accelerator_pedal_percent",
    "brake_pedal",
    "brake_pedal_percent",
    "engine_torque_nm",
    "pedal",
]
#: Values a logged channel could hold (kept to magnitudes a solver-free reader can see).
sample = st.one_of(
    st.floats(-2.0, 2.0), st.floats(-1e4, 1e4), st.sampled_from([math.nan, math.inf, -math.inf, 0.0, 1e300, 100.0])
)


@st.composite
def time_series(draw: st.DrawFn, names: list[str], required: list[str]) -> tuple[dict[str, np.ndarray], dict]:
    """Random columns: some of ``names`` (``required`` more often than not), 0–8 rows, time stamps
    increasing, shuffled, repeated or random; MDF4 units sometimes."""
    n = draw(st.integers(0, 8))
    chosen = [c for c in required if draw(st.integers(0, 4))] + draw(st.lists(st.sampled_from(names), max_size=3))
    chosen = list(dict.fromkeys(chosen))
    columns = {c: np.array(draw(st.lists(sample, min_size=n, max_size=n)), dtype=float) for c in chosen}
    for c in ("time_s", "time_ms"):
        if c in columns and draw(st.booleans()):
            step = draw(st.sampled_from([1e-3, 0.1, 1.0, 0.0, -0.1, 1e-12]))
            columns[c] = draw(st.sampled_from([0.0, 5.0, 1e5])) + step * np.arange(n)
    units = {c: draw(st.sampled_from(["", "s", "rad/s", "rpm", "Nm", "%", "bar"])) for c in chosen}
    return columns, units


def write(path: Path, columns: dict[str, np.ndarray], units: dict[str, str]) -> bool:
    """Write the columns in the format of ``path``; False when the format cannot hold them."""
    if path.suffix == ".mf4" and "time_s" not in columns:
        return False
    try:
        make.write_columns(path, columns, units, v73=path.name.endswith("v73.mat"))
    except Exception:  # noqa: BLE001  a writer refusing the data (e.g. MDF4 with decreasing time) is not under test
        return False
    return path.exists()


@given(
    series=time_series(MEASUREMENT_NAMES, ["time_s", "pump_torque_nm", "turbine_speed_rad_s"]),
    fmt=st.sampled_from(FORMATS),
)
def test_measurement_is_read_or_refused_in_one_line(series, fmt):
    columns, units = series
    with scratch() as d:
        path = d / f"m.{fmt}"
        assume(write(path, columns, units))
        meas = outcome(lambda: read_measurement(path), str(path))
        if meas is not None:
            assert len(meas.time_s) >= 2 and np.all(np.diff(meas.time_s) > 0)
            assert_finite("measurement time", meas.time_s)
            for name, values in meas.channels.items():
                assert len(values) == len(meas.time_s), name
                assert_finite(name, values)


@given(series=time_series(SCENARIO_NAMES, ["time_s", "accelerator_pedal", "brake_pedal"]), fmt=st.sampled_from(FORMATS))
def test_scenario_is_read_or_refused_in_one_line(series, fmt):
    columns, units = series
    with scratch() as d:
        path = d / f"s.{fmt}"
        assume(write(path, columns, units))
        scen = outcome(lambda: read_scenario(path), str(path))
        if scen is not None:
            assert scen.time_s[0] == 0.0 and np.all(np.diff(scen.time_s) > 0)
            assert_finite("scenario", scen.time_s, scen.accelerator_pedal, scen.brake_pedal, [scen.end_time_s])
            for pedal in (scen.accelerator_pedal, scen.brake_pedal):
                assert np.all((pedal >= 0) & (pedal <= 1))


@given(data=st.binary(max_size=300), fmt=st.sampled_from(FORMATS))
def test_time_series_files_of_random_bytes_are_refused_in_one_line(data, fmt):
    with scratch() as d:
        path = d / f"m.{fmt}"
        path.write_bytes(data)
        assert outcome(lambda: read_measurement(path), str(path)) is None
        assert outcome(lambda: read_scenario(path), str(path)) is None


# --------------------------------------------------------------------------------------------
# command-line items

items = st.lists(st.text(max_size=30), max_size=3)


@pytest.mark.parametrize(
    ("parse", "source"),
    [(parse_initial, "command line"), (parse_channel_map, "command line"), (parse_bounds, "command line")],
    ids=["--initial", "--channel", "--bound"],
)
@given(values=items)
def test_option_items_are_parsed_or_refused_in_one_line(parse, source, values):
    parsed = outcome(lambda: parse(values), source)
    if parsed is not None and parse is parse_initial:
        assert_finite("--initial", list(parsed.values()))


@given(text=st.one_of(st.none(), st.text(max_size=40)))
def test_free_parameters_are_parsed_or_refused_in_one_line(text):
    outcome(lambda: parse_free(text), "command line")
