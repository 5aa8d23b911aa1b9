"""The readers' edges (issue 10, defects 6, 8, 10): every malformed column, header, unit mistake and
encoding is an InputError naming the file, the column and the value, on one line; nothing is
silently held, renamed, dropped or read in the wrong unit."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import scipy.io
from asammdf import MDF, Signal

from tcsim import errors
from tcsim.analysis.drive import BUNDLED_CYCLES, Cycle, trace_acceleration, warn_of_acceleration
from tcsim.errors import InputError, TcsimWarning
from tcsim.io.cycle import bundled_cycle_path, read_cycle
from tcsim.io.measurement import read_measurement
from tcsim.io.scenario import read_scenario
from tcsim.models.converter import load_converter
from tcsim.models.tables import read_table
from tcsim.models.vehicle import load_vehicle

REPO = Path(__file__).resolve().parents[2]
BUNDLED_CONVERTER = REPO / "python" / "tcsim" / "data" / "converters" / "li-sunden-2016.toml"
BUNDLED_VEHICLE = REPO / "python" / "tcsim" / "data" / "vehicles" / "midsize-awd-8at.toml"

N = 200
TIME_S = np.linspace(0.0, 2.0, N)  # 100 Hz
CHANNELS = {"pump_torque_nm": 150.0 + 40.0 * np.sin(3.0 * TIME_S), "turbine_speed_rad_s": 90.0 * TIME_S}


ANYWAY = "allow_implausible=True runs it anyway"


def refused(read, *words: str) -> InputError:
    """The InputError of ``read()``: one line, holding ``words``."""
    with pytest.raises(InputError) as excinfo:
        read()
    text = str(excinfo.value)
    assert "\n" not in text and "\r" not in text, text
    for word in words:
        assert word in text, (word, text)
    return excinfo.value


# --------------------------------------------------------------------------------------------
# defect 8: column types that escaped as ValueError or TypeError


def _parquet(path: Path, **columns) -> Path:
    pq.write_table(pa.table({"time_s": TIME_S, **CHANNELS, **columns}), path)
    return path


@pytest.mark.parametrize(
    ("column", "words"),
    [
        (pa.array([[1.0, 2.0]] * N), ["[1.0, 2.0]", "row 1", "one per row"]),
        (pa.array([{"a": 1.0}] * N), ["{'a': 1.0}", "row 1"]),
        (pa.array([True] * N), ["True", "numbers only"]),
        (pa.array(["12,5"] * N), ["'12,5'", "numbers only"]),
    ],
    ids=["list", "struct", "bool", "string"],
)
def test_a_parquet_column_that_holds_no_numbers_is_named(tmp_path, column, words):
    path = tmp_path / "m.parquet"
    pq.write_table(
        pa.table({"time_s": TIME_S, "pump_torque_nm": column, "turbine_speed_rad_s": CHANNELS["turbine_speed_rad_s"]}),
        path,
    )
    err = refused(lambda: read_measurement(path), str(path), *words)
    assert err.field == "pump_torque_nm"


def test_an_empty_or_row_less_parquet_file_is_refused(tmp_path):
    empty = tmp_path / "empty.parquet"
    empty.write_bytes(b"")
    refused(lambda: read_measurement(empty), "readable Parquet")
    no_rows = tmp_path / "no_rows.parquet"
    pq.write_table(
        pa.table({"time_s": pa.array([], pa.float64()), **{c: pa.array([], pa.float64()) for c in CHANNELS}}), no_rows
    )
    refused(lambda: read_measurement(no_rows), "0 rows", "at least 2")


# --------------------------------------------------------------------------------------------
# defect 10: duplicated column names


def test_a_duplicated_csv_column_is_refused_by_name(tmp_path):
    path = tmp_path / "m.csv"
    rows = "\n".join(f"{t},{p},{w},{p + 1}" for t, p, w in zip(TIME_S, *CHANNELS.values(), strict=True))
    path.write_text("time_s,pump_torque_nm,turbine_speed_rad_s,pump_torque_nm\n" + rows + "\n")
    err = refused(lambda: read_measurement(path), "pump_torque_nm", "2 columns", "at most once")
    assert err.field == "pump_torque_nm"


def test_a_duplicated_parquet_column_is_refused_by_name(tmp_path):
    path = tmp_path / "m.parquet"
    table = pa.Table.from_arrays(
        [pa.array(TIME_S), pa.array(CHANNELS["pump_torque_nm"]), pa.array(TIME_S), pa.array(TIME_S)],
        names=["time_s", "pump_torque_nm", "turbine_speed_rad_s", "turbine_speed_rad_s"],
    )
    pq.write_table(table, path)
    refused(lambda: read_measurement(path), "turbine_speed_rad_s", "2 columns")


def test_a_duplicated_scenario_column_is_refused(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text("time_s,accelerator_pedal,brake_pedal,brake_pedal\n0,0,1,0\n1,1,0,1\n")
    refused(lambda: read_scenario(path), "brake_pedal", "2 columns")


def test_a_duplicated_table_header_is_named_not_blamed_on_torque_ratio(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("speed_ratio,torque_ratio,speed_ratio,capacity_factor_nm_s2\n0,2,0,1e-3\n0.5,1.5,0.5,1e-3\n")
    err = refused(lambda: read_table(path), "line 1 (header)", "'speed_ratio'", "once")
    assert err.value == "speed_ratio"


def test_an_mdf_channel_name_in_two_groups_with_other_samples_is_refused(tmp_path):
    path = tmp_path / "m.mf4"
    mdf = MDF(version="4.10")
    mdf.append([Signal(v, TIME_S, name=k) for k, v in CHANNELS.items()])
    mdf.append([Signal(CHANNELS["pump_torque_nm"] * 2, TIME_S, name="pump_torque_nm")])
    mdf.save(path, overwrite=True)
    mdf.close()
    refused(lambda: read_measurement(path), "pump_torque_nm", "2 channels", "same samples")


# --------------------------------------------------------------------------------------------
# defect 10: complex .mat values


def test_a_complex_mat_v5_channel_is_called_complex_not_missing(tmp_path):
    path = tmp_path / "m.mat"
    scipy.io.savemat(
        path,
        {
            "time_s": TIME_S,
            "pump_torque_nm": CHANNELS["pump_torque_nm"] * (1 + 1j),
            "turbine_speed_rad_s": CHANNELS["turbine_speed_rad_s"],
        },
    )
    err = refused(lambda: read_measurement(path), "complex values", "row 1")
    assert err.field == "pump_torque_nm"


def test_a_complex_mat_v73_channel_is_called_complex_and_a_zero_imaginary_part_is_read(tmp_path):
    path = tmp_path / "m.mat"
    pair = np.dtype([("real", "<f8"), ("imag", "<f8")])
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, values in {"time_s": TIME_S, **CHANNELS}.items():
            data = np.zeros((N, 1), pair)
            data["real"][:, 0] = values
            data["imag"][:, 0] = 1.0 if name == "pump_torque_nm" else 0.0
            f.create_dataset(name, data=data).attrs["MATLAB_class"] = np.bytes_("double")
    refused(lambda: read_measurement(path), "pump_torque_nm", "complex values")
    with h5py.File(path, "r+") as f:
        f["pump_torque_nm"][:, 0] = np.array([(v, 0.0) for v in CHANNELS["pump_torque_nm"]], pair)
    np.testing.assert_array_equal(read_measurement(path).channels["pump_torque_nm"], CHANNELS["pump_torque_nm"])


# --------------------------------------------------------------------------------------------
# defect 6: unit mistakes in measured data, against the core's plausibility ranges


def _csv(path: Path, time_s=TIME_S, **changes) -> Path:
    pd.DataFrame({"time_s": time_s, **CHANNELS, **changes}).to_csv(path, index=False)
    return path


def test_rpm_in_a_rad_s_column_below_1500_is_refused_and_can_be_allowed(tmp_path):
    rpm = 1400.0 * TIME_S / 2.0  # a take-off to 1400 rpm, written in a rad/s column
    path = _csv(tmp_path / "m.csv", turbine_speed_rad_s=rpm)
    err = refused(lambda: read_measurement(path), "turbine_speed_rad_s", "rad/s at row", ANYWAY)
    assert err.field == "turbine_speed_rad_s"
    with pytest.warns(TcsimWarning, match="outside the plausible"):
        m = read_measurement(path, allow_implausible=True)
    np.testing.assert_array_equal(m.channels["turbine_speed_rad_s"], rpm)


def test_a_torque_far_outside_the_range_is_refused(tmp_path):
    path = _csv(tmp_path / "m.csv", pump_torque_nm=CHANNELS["pump_torque_nm"] * 100)
    refused(lambda: read_measurement(path), "pump_torque_nm", "N·m at row", ANYWAY)


def test_milliseconds_in_a_time_s_column_are_refused_by_the_median_step(tmp_path):
    t_ms = np.arange(N) * 1.0  # 1 kHz logged in ms: a 0.2 s record read as 199 s
    path = _csv(tmp_path / "m.csv", time_s=t_ms)
    err = refused(lambda: read_measurement(path), "time_s (median time step, s)", "= 1:", ANYWAY)
    assert err.value == 1.0
    with pytest.warns(TcsimWarning):
        read_measurement(path, allow_implausible=True)


def test_a_scenario_with_a_time_ms_column_read_as_seconds_is_refused(tmp_path):
    path = tmp_path / "s.csv"
    t = np.arange(0.0, 30_001.0, 500.0)  # a 30 s take-off written in ms under time_s
    pd.DataFrame({"time_s": t, "accelerator_pedal": 1.0, "brake_pedal": 0.0}).to_csv(path, index=False)
    refused(lambda: read_scenario(path), "time_s (time span, s)", "30000", "scenario", ANYWAY)
    with pytest.warns(TcsimWarning):
        assert read_scenario(path, allow_implausible=True).end_time_s == 30_000.0
    slow = tmp_path / "slow.csv"  # rows far apart are fine in a pedal scenario
    pd.DataFrame({"time_s": [0.0, 60.0, 600.0], "accelerator_pedal": 0.5, "brake_pedal": 0.0}).to_csv(slow, index=False)
    assert read_scenario(slow).end_time_s == 600.0


def test_a_scenario_engine_torque_outside_the_range_is_refused(tmp_path):
    path = tmp_path / "s.csv"
    frame = pd.DataFrame({"time_s": [0.0, 1.0, 2.0], "accelerator_pedal": 1.0, "brake_pedal": 0.0})
    frame.assign(engine_torque_nm=[100.0, 3e5, 100.0]).to_csv(path, index=False)
    refused(lambda: read_scenario(path), "engine_torque_nm", "300000 N·m at row 2")


# --------------------------------------------------------------------------------------------
# defect 6: an MDF channel that covers part of the record


def test_an_mdf_channel_covering_a_tenth_of_the_record_is_refused(tmp_path):
    path = tmp_path / "m.mf4"
    mdf = MDF(version="4.10")
    mdf.append([Signal(CHANNELS["pump_torque_nm"], TIME_S, name="pump_torque_nm")])
    short = TIME_S[: N // 10]
    mdf.append([Signal(CHANNELS["turbine_speed_rad_s"][: N // 10], short, name="turbine_speed_rad_s")])
    mdf.save(path, overwrite=True)
    mdf.close()
    err = refused(lambda: read_measurement(path), "turbine_speed_rad_s", "from 0 s to 0.19", "0 s to 2 s")
    assert err.field == "turbine_speed_rad_s"


def test_mdf_channels_at_other_rates_that_cover_the_record_are_read(tmp_path):
    path = tmp_path / "m.mf4"
    slow = np.linspace(0.0, 1.95, 40)  # 20 Hz, ending within one of its steps of the 100 Hz channel
    mdf = MDF(version="4.10")
    mdf.append([Signal(CHANNELS["pump_torque_nm"], TIME_S, name="pump_torque_nm")])
    mdf.append([Signal(90.0 * slow, slow, name="turbine_speed_rad_s")])
    mdf.save(path, overwrite=True)
    mdf.close()
    assert len(read_measurement(path).time_s) == N


# --------------------------------------------------------------------------------------------
# defect 10: messages on one line, the file's own values, a byte-order mark in TOML


def test_a_toml_key_with_a_newline_gives_one_line(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text('"pump\\nkg_m2" = 0.1\n' + BUNDLED_CONVERTER.read_text())
    text = str(refused(lambda: load_converter(path)))
    assert "pump\\nkg_m2" in text


def test_error_messages_escape_control_characters_and_undecodable_bytes():
    err = InputError("a\udcffb.csv", "x\ny", "v\x1b[2J", "z\u2028w")
    assert str(err) == "a\\udcffb.csv: x\\ny = 'v\\x1b[2J': expected z\\u2028w"
    assert errors.escape_controls("±10 500 rpm · ü") == "±10 500 rpm · ü"


@pytest.mark.parametrize(("key", "value"), [("k_factor_rpm_per_sqrt_nm", "1e-160"), ("capacity_nm_per_rpm2", "1e307")])
def test_a_capacity_that_overflows_on_conversion_is_named_as_written(tmp_path, key, value):
    table = tmp_path / "t.csv"
    table.write_text(f"# a table\nspeed_ratio,torque_ratio,{key}\n0,2,{value}\n0.5,1.5,{value}\n")
    err = refused(lambda: read_table(table), f"line 3, {key}", value.replace("e-", "e-").replace("1e307", "1e+307"))
    assert err.field == f"line 3, {key}" and err.value == float(value)
    toml = tmp_path / "c.toml"
    toml.write_text(
        f'name = "c"\nsource = "s"\n[characteristic]\nspeed_ratio = [0.0, 0.5]\n'
        f"torque_ratio = [2.0, 1.5]\n{key} = [{value}, 1.0]\n"
    )
    err = refused(lambda: load_converter(toml), f"[characteristic].{key}[0]")
    assert err.value == float(value) and not math.isinf(err.value)


def test_a_byte_order_mark_is_accepted_in_converter_and_vehicle_toml(tmp_path):
    conv = tmp_path / "c.toml"
    conv.write_bytes(b"\xef\xbb\xbf" + BUNDLED_CONVERTER.read_bytes())
    assert load_converter(conv).name == load_converter(BUNDLED_CONVERTER).name
    vehicle = tmp_path / "v.toml"
    vehicle.write_bytes(b"\xef\xbb\xbf" + BUNDLED_VEHICLE.read_bytes())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)
        assert load_vehicle(str(vehicle)).name == load_vehicle(str(BUNDLED_VEHICLE)).name


@pytest.mark.parametrize(
    "edit",
    [
        ("fluid_density_kg_m3 = 840.0", 'fluid_density_kg_m3 = "840"'),
        ("fluid_density_kg_m3 = 840.0", "fluid_density_kg_m3 = true"),
        ("fluid_density_kg_m3 = 840.0", "fluid_density_kg_m3 = { value = 840.0 }"),
        ("fluid_density_kg_m3 = 840.0", "fluid_density_kg_m3 = [840.0]"),
    ],
    ids=["string", "boolean", "table", "array"],
)
def test_converter_toml_values_of_other_types_are_input_errors(tmp_path, edit):
    text = BUNDLED_CONVERTER.read_text()
    assert edit[0] in text
    path = tmp_path / "c.toml"
    path.write_text(text.replace(edit[0], edit[1]))
    refused(lambda: load_converter(path), "[geometry].fluid_density_kg_m3")


@pytest.mark.parametrize("text", ["", "\n# nothing\n"], ids=["empty", "comment only"])
def test_an_empty_converter_toml_is_an_input_error(tmp_path, text):
    path = tmp_path / "c.toml"
    path.write_text(text)
    refused(lambda: load_converter(path), "missing")


@pytest.mark.parametrize(
    ("value", "words"),
    [
        ({"a": 1.0}, ["1x1 struct", "numeric vector"]),
        (np.array([[1.0], "x"], dtype=object), ["cell array"]),
        (np.ones((N, 2)), [f"{N}x2 matrix"]),
    ],
    ids=["struct", "cell", "matrix"],
)
def test_a_mat_variable_that_is_no_vector_is_named_not_missing(tmp_path, value, words):
    path = tmp_path / "m.mat"
    scipy.io.savemat(path, {"time_s": TIME_S, "pump_torque_nm": value, "turbine_speed_rad_s": TIME_S})
    err = refused(lambda: read_measurement(path), "pump_torque_nm", *words)
    assert err.value != "missing"


def test_a_table_value_that_overflows_when_parsed_is_named_as_written(tmp_path):
    path = tmp_path / "t.vtcc"
    path.write_text("Speed Ratio, Torque Ratio, MP1000\n0,2,1e400\n0.5,1.5,100\n")
    err = refused(lambda: load_converter(path), "line 2, mp1000_nm", "'1e400'", "a finite number")
    assert err.value == "1e400"


def test_csv_columns_without_a_name_are_not_duplicates(tmp_path):
    path = tmp_path / "m.csv"
    rows = "\n".join(f"{t},{p},{w},," for t, p, w in zip(TIME_S, *CHANNELS.values(), strict=True))
    path.write_text("time_s,pump_torque_nm,turbine_speed_rad_s,,\n" + rows + "\n")
    assert len(read_measurement(path).time_s) == N


def test_a_comma_at_the_end_of_every_row_reads_as_the_rows_without_it(tmp_path):
    # fresh-eyes trial: pandas took the first value of such rows as their index and shifted the
    # others ("time_s = '170 at row 52 after 170'", a pump torque read as a time)
    rows = ["time_s,pump_torque_nm,turbine_speed_rad_s"] + [f"{0.1 * i:.1f},{40 + i},{2 * i}" for i in range(5)]
    plain, trailing = tmp_path / "plain.csv", tmp_path / "trailing.csv"
    plain.write_text("\n".join(rows) + "\n")
    trailing.write_text("\n".join(r + "," for r in rows[:1]) + "\n" + "\n".join(r + "," for r in rows[1:]) + "\n")
    a, b = read_measurement(plain).to_frame(), read_measurement(trailing).to_frame()
    pd.testing.assert_frame_equal(a, b)
    assert list(b.time_s) == [0.0, 0.1, 0.2, 0.3, 0.4] and list(b.pump_torque_nm) == [40, 41, 42, 43, 44]


def test_seconds_under_a_milliseconds_name_are_refused_or_warned_of(tmp_path):
    # fresh-eyes trial: a 3 s log under time_ms became 3 ms long and replayed with exit 0
    p = tmp_path / "m.csv"
    rows = [f"{0.01 * i:.2f},{40 + i},{i}" for i in range(300)]
    p.write_text("time_ms,pump_torque_nm,turbine_speed_rad_s\n" + "\n".join(rows) + "\n")
    with pytest.raises(InputError) as e:
        read_measurement(p)
    assert (e.value.field, e.value.value) == ("time_ms", "a record of 2.99 ms"), str(e.value)
    with pytest.warns(TcsimWarning, match="time_ms = a record of 2.99 ms: expected a record of at least 100 ms"):
        m = read_measurement(p, allow_implausible=True)
    assert m.time_s[-1] == pytest.approx(2.99e-3)
    p.write_text("time_ms,pump_torque_nm,turbine_speed_rad_s\n0,40,0\n50,41,1\n100,42,2\n")
    assert read_measurement(p).time_s[-1] == pytest.approx(0.1)  # 100 ms: no refusal


def test_a_mapped_column_with_its_unit_in_brackets_is_converted_by_it(tmp_path):
    # fresh-eyes trial: "turbine speed [rpm]" mapped with --channel was read as rad/s
    p = tmp_path / "m.csv"
    p.write_text("time [ms],EngTrq (Nm),turbine speed [rpm]\n0,40,0\n100,41,600\n200,42,1200\n")
    channels = {"time_s": "time [ms]", "pump_torque_nm": "EngTrq (Nm)", "turbine_speed_rad_s": "turbine speed [rpm]"}
    m = read_measurement(p, channels).to_frame()
    assert list(m.time_s) == pytest.approx([0.0, 0.1, 0.2])
    assert list(m.pump_torque_nm) == [40.0, 41.0, 42.0]
    assert list(m.turbine_speed_rad_s) == pytest.approx([0.0, 20 * math.pi, 40 * math.pi])


def test_a_gap_in_a_record_is_warned_of_once(tmp_path):
    # fresh-eyes trial: a second of dropped rows was bridged linearly without a word
    p = tmp_path / "m.csv"
    t = np.r_[np.arange(0.0, 2.0, 0.01), np.arange(3.0, 5.0, 0.01)]
    rows = "\n".join(f"{x:.2f},{40 + x:.3f},{x:.3f}" for x in t)
    p.write_text("time_s,pump_torque_nm,turbine_speed_rad_s\n" + rows + "\n")
    with pytest.warns(TcsimWarning, match=r"time_s: 1\.01 s between rows 200 and 201, 101 times the median step"):
        read_measurement(p)
    p.write_text("time_s,pump_torque_nm,turbine_speed_rad_s\n" + "\n".join(rows.splitlines()[:200]) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", TcsimWarning)
        read_measurement(p)  # no gap, no warning


def test_a_byte_that_is_not_utf8_far_into_a_csv_is_placed_in_the_whole_file(tmp_path):
    """pandas decodes a CSV in chunks and reports the offset within the chunk: the message gives
    the byte's line and offset in the file (it said offset 76 886 for a byte at 339 030)."""
    rows = ["time_s,pump_torque_nm,turbine_speed_rad_s"]
    rows += [f"{i / 1000:.3f},40.0000,{i / 100:.4f}" for i in range(20000)]
    rows[15000] = rows[15000].replace("40.0000", "40.00\xb0")
    data = "\n".join(rows).encode("latin-1")
    path = tmp_path / "m.csv"
    path.write_bytes(data)
    offset = data.index(b"\xb0")
    assert offset > 262144  # beyond pandas' first chunk
    refused(lambda: read_measurement(path), "(file)", f"byte 0xb0 on line 15001 (offset {offset})")


def _udds_below_69_km_h() -> tuple[np.ndarray, np.ndarray]:
    """The first 199 s of UDDS (up to 63 km/h: below the core's 250 km/h limit in either unit), km/h."""
    c = read_cycle(bundled_cycle_path("udds"), "udds")
    n = int(np.argmax(c.vehicle_speed_m_s * 3.6 > 65.0))
    return c.time_s[:n], c.vehicle_speed_m_s[:n] * 3.6


def test_a_cycle_in_km_h_under_the_m_s_name_is_warned_of_by_its_acceleration(tmp_path):
    """UDDS in km/h under ``vehicle_speed_m_s`` ran with exit 0 and only a speed-error warning: its
    1.48 m/s² reads as 5.3 m/s², beyond the plausible 5 (the range's own text names the mistake)."""
    time_s, km_h = _udds_below_69_km_h()
    wrong = tmp_path / "wrong.csv"
    pd.DataFrame({"time_s": time_s, "vehicle_speed_m_s": km_h}).to_csv(wrong, index=False)
    with pytest.warns(TcsimWarning) as record:
        warn_of_acceleration(read_cycle(wrong))
    (message,) = [str(w.message) for w in record]
    assert "vehicle_speed_m_s's change per second from row 164 (time_s 163) = 5.31" in message, message
    assert "km/h read as m/s" in message, message
    right = tmp_path / "right.csv"
    pd.DataFrame({"time_s": time_s, "vehicle_speed_km_h": km_h}).to_csv(right, index=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_of_acceleration(read_cycle(right))


def test_the_bundled_cycles_are_plausible_and_the_acceleration_spans_a_second():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in BUNDLED_CYCLES:
            warn_of_acceleration(read_cycle(bundled_cycle_path(name), name))
    # 10 Hz samples: the change over a second, not one sample's noise; 2 s apart: the next sample
    t = np.arange(0.0, 3.01, 0.1)
    v = 2.0 * t + np.where(np.arange(t.size) % 2 == 0, 0.05, -0.05)
    a = trace_acceleration(t, v)
    # (sample to sample the ±0.05 m/s noise alone is ±1 m/s²; over a second at most ±0.1), and none in
    # the last second, whose spans would shrink to one sample's
    assert np.abs(a - 2.0).max() <= 0.1 + 1e-9 and a.size in (20, 21), a.size
    np.testing.assert_allclose(trace_acceleration(np.array([0.0, 2.0, 4.0]), np.array([0.0, 4.0, 4.0])), [2.0, 0.0])
    # shorter than a second: its first-to-last change
    np.testing.assert_allclose(trace_acceleration(np.array([0.0, 0.5]), np.array([0.0, 3.0])), [6.0])


def test_noise_in_a_trace_s_last_second_is_not_an_acceleration():
    """A 100 Hz trace at a steady 20 m/s with 0.03 m/s of noise: the last second's changes were taken
    over ever shorter spans (one sample's at the end) and warned of as up to 9 m/s²."""
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 60.0, 0.01)
    v = np.concatenate([np.linspace(0.0, 20.0, 1000), np.full(t.size - 1000, 20.0)]) + 0.03 * rng.standard_normal(
        t.size
    )
    v[0] = 0.0
    a = trace_acceleration(t, v)
    # the 2 m/s² of the ramp and the noise over a second (σ 0.04 m/s²); the steady end stays small
    assert np.abs(a).max() < 2.3 and np.abs(a[-100:]).max() < 0.3, (np.abs(a).max(), np.abs(a[-100:]).max())
    assert t[a.size - 1] <= t[-1] - 1.0 + 1e-9, a.size
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_of_acceleration(Cycle("noisy", "noisy.csv", t, v))
