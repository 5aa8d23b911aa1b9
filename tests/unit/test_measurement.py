"""tcsim.measurement: the five formats round-trip, units convert, channels map, bad files are InputErrors."""

from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
import scipy.io
from asammdf import MDF, Signal

from tcsim.errors import InputError
from tcsim.io.measurement import INPUT_CHANNELS, parse_channel_map, read_measurement
from tcsim.models.measurement import Measurement

N = 200  # samples of the synthetic measurement
TIME_S = np.linspace(0.0, 2.0, N)
ORIGINAL = {
    "pump_torque_nm": 150.0 + 40.0 * np.sin(3.0 * TIME_S),
    "turbine_speed_rad_s": 180.0 * TIME_S / 2.0,
    "pump_speed_rad_s": 120.0 + 60.0 * TIME_S,
    "turbine_torque_nm": 300.0 - 50.0 * TIME_S**2,
}
UNITS = {
    "time_s": "s",
    "pump_torque_nm": "Nm",
    "turbine_speed_rad_s": "rad/s",
    "pump_speed_rad_s": "rad/s",
    "turbine_torque_nm": "N m",
}


def write_csv(path: Path, columns: dict[str, np.ndarray]) -> Path:
    pd.DataFrame(columns).to_csv(path, index=False, float_format="%.17g")
    return path


def write_mat_v73(path: Path, columns: dict[str, np.ndarray]) -> Path:
    """An HDF5 file laid out like MATLAB v7.3: a 512-byte header, one 2-D double dataset per variable."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for k, (name, values) in enumerate(columns.items()):
            shape = (1, len(values)) if k % 2 else (len(values), 1)  # both orientations
            f.create_dataset(name, data=values.reshape(shape)).attrs["MATLAB_class"] = np.bytes_("double")
        f.create_dataset("label", data=np.frombuffer(b"a\0b\0", np.uint16).reshape(2, 1)).attrs["MATLAB_class"] = (
            np.bytes_("char")
        )
    with open(path, "r+b") as f:
        text = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
        f.write(text.ljust(116) + bytes(8) + b"\x00\x02IM")  # text, subsystem offset, version 0x0200, endian
    return path


def write_mdf(path: Path, columns: dict[str, np.ndarray], units: dict[str, str], time_s=TIME_S) -> Path:
    mdf = MDF(version="4.10")
    mdf.append([Signal(values, time_s, name=name, unit=units.get(name, "")) for name, values in columns.items()])
    mdf.save(path, overwrite=True)
    mdf.close()
    return path


def write(path: Path, columns: dict[str, np.ndarray], units: dict[str, str] | None = None) -> Path:
    """``columns`` (with time_s; MDF takes time from the timestamps) in the format of ``path``'s suffix."""
    suffix = path.suffix
    if suffix == ".csv":
        return write_csv(path, columns)
    if suffix == ".parquet":
        pd.DataFrame(columns).to_parquet(path)
        return path
    if path.name.endswith("v73.mat"):
        return write_mat_v73(path, columns)
    if suffix == ".mat":
        scipy.io.savemat(path, columns)
        return path
    data = {k: v for k, v in columns.items() if k != "time_s"}
    return write_mdf(path, data, units or {}, time_s=columns.get("time_s", TIME_S))


def assert_error(excinfo, path, *words) -> InputError:
    """The error names the file, the field and the value (and any other ``words``)."""
    err = excinfo.value
    text = str(err)
    assert str(path) in text and err.field in text and str(err.value)[:40] in text
    for word in words:
        assert word in text, (word, text)
    return err


# --------------------------------------------------------------------------------------------
# round trips


@pytest.mark.parametrize("name", ["m.csv", "m.parquet", "m_v5.mat", "m_v73.mat", "m.mf4"])
def test_round_trip(tmp_path, name):
    path = write(tmp_path / name, {"time_s": TIME_S, **ORIGINAL}, UNITS)
    m = read_measurement(path)
    assert isinstance(m, Measurement) and m.source == str(path)
    assert m.time_s.dtype == np.float64
    np.testing.assert_allclose(m.time_s, TIME_S, rtol=1e-12, atol=0)
    assert list(m.channels) == ["pump_torque_nm", "turbine_speed_rad_s", "pump_speed_rad_s", "turbine_torque_nm"]
    for key, values in ORIGINAL.items():
        np.testing.assert_allclose(m.channels[key], values, rtol=1e-12, atol=0)
    frame = m.to_frame()
    assert list(frame.columns)[0] == "time_s" and len(frame) == N
    assert m.has("pump_speed_rad_s") and not m.has("flow_m3_s")


def test_optional_channels_absent_and_comments(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text(
        "# logged on the test bench\ntime_s,pump_torque_nm,turbine_speed_rad_s\n"
        "0,100,0\n# a comment line\n0.1,101,2\n0.2,102,4\n"
    )
    m = read_measurement(path)
    assert set(m.channels) == {"pump_torque_nm", "turbine_speed_rad_s"}
    np.testing.assert_array_equal(m.channels["pump_torque_nm"], [100, 101, 102])


def test_mdf_channels_resampled_onto_first_required(tmp_path):
    path = tmp_path / "m.mf4"
    mdf = MDF(version="4.10")
    mdf.append(
        [
            Signal(ORIGINAL["pump_torque_nm"], TIME_S, name="pump_torque_nm", unit="Nm"),
            Signal(ORIGINAL["turbine_speed_rad_s"], TIME_S, name="turbine_speed_rad_s", unit="rad/s"),
        ]
    )
    coarse = TIME_S[::4]
    mdf.append([Signal(120.0 + 60.0 * coarse, coarse, name="pump_speed_rad_s", unit="rad/s")])
    mdf.save(path, overwrite=True)
    mdf.close()
    m = read_measurement(path)
    np.testing.assert_allclose(m.time_s, TIME_S, rtol=1e-12)
    np.testing.assert_allclose(
        m.channels["pump_speed_rad_s"][: len(TIME_S) - 3], ORIGINAL["pump_speed_rad_s"][:-3], rtol=1e-9
    )


# --------------------------------------------------------------------------------------------
# units


def test_rpm_and_time_ms_columns_are_converted(tmp_path):
    path = write_csv(
        tmp_path / "m.csv",
        {
            "time_ms": TIME_S * 1000.0,
            "pump_torque_knm": ORIGINAL["pump_torque_nm"] / 1e3,
            "turbine_speed_rpm": ORIGINAL["turbine_speed_rad_s"] * 30.0 / math.pi,
            "turbine_torque_lbf_ft": ORIGINAL["turbine_torque_nm"] / 1.3558179483314004,
        },
    )
    m = read_measurement(path)
    np.testing.assert_allclose(m.time_s, TIME_S, rtol=1e-12)
    for key in ("pump_torque_nm", "turbine_speed_rad_s", "turbine_torque_nm"):
        np.testing.assert_allclose(m.channels[key], ORIGINAL[key], rtol=1e-12)


def test_mdf_unit_metadata_decides(tmp_path):
    path = write_mdf(
        tmp_path / "m.mf4",
        {
            "EngTrq": ORIGINAL["pump_torque_nm"] / 1e3,
            "TurbSpd": ORIGINAL["turbine_speed_rad_s"] * 30.0 / math.pi,
            "EngSpd": ORIGINAL["pump_speed_rad_s"] * 180.0 / math.pi,
        },
        {"EngTrq": "kNm", "TurbSpd": "rpm", "EngSpd": "deg/s"},
    )
    mapping = parse_channel_map(["pump_torque_nm=EngTrq", "turbine_speed_rad_s = TurbSpd", "pump_speed_rad_s=EngSpd"])
    m = read_measurement(path, mapping)
    for key in ("pump_torque_nm", "turbine_speed_rad_s", "pump_speed_rad_s"):
        np.testing.assert_allclose(m.channels[key], ORIGINAL[key], rtol=1e-12)


# --------------------------------------------------------------------------------------------
# channel map


def test_channel_map(tmp_path):
    path = write_csv(
        tmp_path / "m.csv",
        {
            "t": TIME_S,
            "EngTrq": ORIGINAL["pump_torque_nm"],
            "TurbSpd_rpm": ORIGINAL["turbine_speed_rad_s"] * 30.0 / math.pi,
            "turbine_torque_nm": ORIGINAL["turbine_torque_nm"],
        },
    )
    mapping = parse_channel_map(["time_s=t", "pump_torque_nm=EngTrq", "turbine_speed_rad_s=TurbSpd_rpm"])
    assert mapping == {"time_s": "t", "pump_torque_nm": "EngTrq", "turbine_speed_rad_s": "TurbSpd_rpm"}
    m = read_measurement(path, mapping)
    np.testing.assert_allclose(m.time_s, TIME_S, rtol=1e-12)
    for key in ("pump_torque_nm", "turbine_speed_rad_s", "turbine_torque_nm"):
        np.testing.assert_allclose(m.channels[key], ORIGINAL[key], rtol=1e-12)
    assert not m.has("pump_speed_rad_s")
    assert "flow_m3_s" in INPUT_CHANNELS and INPUT_CHANNELS[0] == "time_s"


@pytest.mark.parametrize("item", ["pump_torque_nm", "speed=EngSpd", "pump_torque_nm=", "=EngTrq"])
def test_malformed_channel_item(item):
    with pytest.raises(InputError) as excinfo:
        parse_channel_map([item])
    err = assert_error(excinfo, "--channel", "TARGET=SOURCE", "pump_torque_nm")
    assert err.field == "--channel" and err.value == item


def test_mapped_column_missing(tmp_path):
    path = write_csv(tmp_path / "m.csv", {"time_s": TIME_S, **ORIGINAL})
    with pytest.raises(InputError) as excinfo:
        read_measurement(path, {"pump_torque_nm": "EngTrq"})
    assert_error(excinfo, path, "EngTrq", "missing", "turbine_speed_rad_s")


# --------------------------------------------------------------------------------------------
# bad files


def _csv(tmp_path, **changes) -> Path:
    columns = {"time_s": TIME_S.copy(), **{k: v.copy() for k, v in ORIGINAL.items()}}
    for key, value in changes.items():
        if value is None:
            columns.pop(key)
        else:
            columns[key] = value
    return write_csv(tmp_path / "bad.csv", columns)


def _with(values: np.ndarray, row: int, value) -> np.ndarray:
    out = values.astype(object if isinstance(value, str) else float)
    out[row] = value
    return out


BAD_CSV = {
    # name: (column changes, field, words in the message)
    "missing channel": (
        {"pump_torque_nm": None},
        "pump_torque_nm",
        ["missing", "pump_torque_knm", "--channel pump_torque_nm=COLUMN", "turbine_speed_rad_s"],
    ),
    "missing time": ({"time_s": None}, "time_s", ["missing", "time_ms"]),
    "time not increasing": ({"time_s": _with(TIME_S, 50, TIME_S[48])}, "time_s", ["row 51", "strictly increasing"]),
    "NaN": ({"pump_torque_nm": _with(ORIGINAL["pump_torque_nm"], 9, np.nan)}, "pump_torque_nm", ["NaN at row 10"]),
    "inf": (
        {"turbine_speed_rad_s": _with(ORIGINAL["turbine_speed_rad_s"], 0, np.inf)},
        "turbine_speed_rad_s",
        ["inf at row 1"],
    ),
    "non-numeric": (
        {"pump_torque_nm": _with(ORIGINAL["pump_torque_nm"], 4, "12,5 Nm")},
        "pump_torque_nm",
        ["'12,5 Nm' at row 5", "numbers only"],
    ),
    "rad/s that look like rpm": (
        {"pump_speed_rad_s": ORIGINAL["pump_speed_rad_s"] * 30.0 / math.pi * 8},
        "pump_speed_rad_s",
        ["plausible", "rad/s", "allow_implausible=True runs it anyway"],
    ),
    "torque too large": (
        {"turbine_torque_nm": ORIGINAL["turbine_torque_nm"] * 1000},
        "turbine_torque_nm",
        ["N·m", "10000", "allow_implausible=True runs it anyway"],
    ),
    "time in ms named _s": ({"time_s": TIME_S * 1e6}, "time_s", ["time in seconds"]),
    "one row": ({k: v[:1] for k, v in {"time_s": TIME_S, **ORIGINAL}.items()}, "time_s", ["1 rows", "at least 2"]),
}


@pytest.mark.parametrize("case", list(BAD_CSV))
def test_bad_csv(tmp_path, case):
    changes, field, words = BAD_CSV[case]
    path = _csv(tmp_path, **changes)
    with pytest.raises(InputError) as excinfo:
        read_measurement(path)
    err = assert_error(excinfo, path, *words)
    assert err.field == field


def test_mdf_unconvertible_unit(tmp_path):
    path = write_mdf(
        tmp_path / "m.mf4",
        {"pump_torque_nm": ORIGINAL["pump_torque_nm"], "VehSpd": ORIGINAL["turbine_speed_rad_s"]},
        {"VehSpd": "km/h"},
    )
    with pytest.raises(InputError) as excinfo:
        read_measurement(path, {"turbine_speed_rad_s": "VehSpd"})
    assert_error(excinfo, path, "VehSpd", "km/h", "wrong units", "rpm")


def test_mdf_torque_in_bar(tmp_path):
    path = write_mdf(
        tmp_path / "m.mf4",
        {"pump_torque_nm": ORIGINAL["pump_torque_nm"], "turbine_speed_rad_s": ORIGINAL["turbine_speed_rad_s"]},
        {"pump_torque_nm": "bar"},
    )
    with pytest.raises(InputError) as excinfo:
        read_measurement(path)
    assert_error(excinfo, path, "pump_torque_nm", "bar", "wrong units")


def test_unknown_extension(tmp_path):
    path = tmp_path / "m.xlsx"
    path.write_bytes(b"PK")
    with pytest.raises(InputError) as excinfo:
        read_measurement(path)
    assert_error(excinfo, path, ".xlsx", ".csv", ".parquet", ".mat", ".mf4")


@pytest.mark.parametrize("name", ["bad.parquet", "bad.mat", "bad_v73.mat", "bad.mf4", "bad.csv"])
def test_corrupt_file(tmp_path, name):
    path = tmp_path / name
    if name == "bad_v73.mat":  # an HDF5 signature followed by garbage
        path.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 4)
    elif name == "bad.csv":
        path.write_bytes(b'time_s,pump_torque_nm\n0,"1\n')
    else:
        path.write_bytes(bytes(range(256)) * 8)
    with pytest.raises(InputError) as excinfo:
        read_measurement(path)
    err = assert_error(excinfo, path, "readable")
    assert err.field == "(file)"


@pytest.mark.parametrize("content", ["", "# only a comment\n", "time_s,pump_torque_nm,turbine_speed_rad_s\n"])
def test_empty_csv(tmp_path, content):
    path = tmp_path / "empty.csv"
    path.write_text(content)
    with pytest.raises(InputError) as excinfo:
        read_measurement(path)
    assert_error(excinfo, path)


def test_missing_file(tmp_path):
    path = tmp_path / "nowhere.mf4"
    with pytest.raises(InputError) as excinfo:
        read_measurement(path)
    assert_error(excinfo, path, "not found")
