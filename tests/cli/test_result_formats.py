"""Result tables as CSV, Parquet or MATLAB ``.mat`` (``--format``) with angular speeds in rad/s or rpm
(``--speed-unit``), one writer per format (tcsim.io.tables, issue 17 item 3): the same columns and
values in every format, the unit in the column name, bad option values refused before anything runs,
nothing left by a run that fails or is interrupted while writing."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.io

from interrupts import interrupt
from tcsim import transient
from tcsim.errors import InputError, TcsimWarning
from tcsim.io import tables
from tcsim.io.measurement import read_measurement
from tcsim.io.results import write_frames
from tcsim.io.tables import FORMATS, SPEED_UNITS, TableFormat, mat_variables, matlab_name, to_speed_unit
from tcsim.units import RAD_S_PER_RPM

CHARACTERISE = ("characterise", "li-sunden-2016")
LAUNCH = ("launch", "--model", "table", "--model", "quasi-dynamic")


@pytest.fixture(scope="module")
def measurement(tmp_path_factory) -> Path:
    """Hrovat & Tobler under the isolated take-off, 0–2 s at 200 Hz, as a measurement to replay."""
    t = np.round(np.arange(401) * 5e-3, 12)
    f = transient.simulate("li-sunden-2016", transient.isolated_takeoff(), "hrovat-tobler", times_s=t).frame()
    path = tmp_path_factory.mktemp("meas") / "takeoff.csv"
    columns = ["time_s", "pump_torque_nm", "turbine_speed_rad_s", "pump_speed_rad_s", "turbine_torque_nm"]
    f[columns].to_csv(path, index=False, float_format="%.17g")
    return path


def run_ok(cli, cwd: Path, *args: str) -> Path:
    out = cwd / args[args.index("--out") + 1]
    r = cli(*args, cwd=cwd)
    assert r.code == 0, (r.code, r.stdout, r.stderr)
    assert "Traceback" not in r.stdout + r.stderr
    return out


def tables_of(out: Path, suffix: str) -> dict[str, Path]:
    return {p.stem: p for p in sorted(out.glob(f"*.{suffix}"))}


def loadmat_columns(path: Path) -> dict[str, np.ndarray]:
    """The variables of a ``.mat`` file in their order, each as a 1-D array (text cells as str)."""
    variables = scipy.io.loadmat(path)
    out = {}
    for name, v in variables.items():
        if name.startswith("__"):
            continue
        if v.dtype == object:
            out[name] = np.array([str(c[0]) if c.size else "" for c in v.ravel()], dtype=object)
        else:
            out[name] = v.ravel()
    return out


def assert_same_table(path: Path, csv: Path) -> None:
    """The ``.mat`` or ``.parquet`` file ``path`` holds the CSV file's columns, in its order, with its
    values (numbers bit for bit, NaN where the CSV is empty; text as the CSV's text)."""
    text = pd.read_csv(csv, dtype=str, keep_default_na=False)
    numbers = pd.read_csv(csv)
    got = loadmat_columns(path) if path.suffix == ".mat" else dict(pd.read_parquet(path).items())
    assert list(got) == list(text.columns), path
    for name, values in got.items():
        values = np.asarray(values)
        assert len(values) == len(text), (path, name)
        if values.dtype == object or pd.api.types.is_string_dtype(values):
            expected = text[name].to_numpy()
            shown = np.array(["" if v is None or v != v else str(v) for v in values], dtype=object)
            np.testing.assert_array_equal(shown, expected, err_msg=f"{path.name}: {name}")
        else:
            np.testing.assert_array_equal(values.astype(float), numbers[name].to_numpy(dtype=float), f"{name}")


# ---------------------------------------------------------------------------------------------
# every format holds the CSV's columns and values


@pytest.mark.parametrize("file_format", ["mat", "parquet"])
@pytest.mark.parametrize("command", ["characterise", "launch", "replay"])
def test_every_format_holds_the_csv_columns_and_values(cli, tmp_path, measurement, command, file_format):
    args = {"characterise": CHARACTERISE, "launch": LAUNCH, "replay": ("replay", "li-sunden-2016", str(measurement))}
    csv = run_ok(cli, tmp_path, *args[command], "--out", "csv")
    other = run_ok(cli, tmp_path, *args[command], "--out", "other", "--format", file_format)
    csv_tables, other_tables = tables_of(csv, "csv"), tables_of(other, file_format)
    assert list(other_tables) == list(csv_tables) and csv_tables
    assert not list(other.glob("*.csv"))
    for name, path in other_tables.items():
        assert_same_table(path, csv_tables[name])
    assert {p.name for p in other.glob("*.png")} == {p.name for p in csv.glob("*.png")}


def test_the_commands_name_the_files_they_wrote(cli, tmp_path):
    r = cli(*CHARACTERISE, "--out", "o", "--format", "mat", cwd=tmp_path)
    assert r.code == 0 and "o/characteristic.mat" in r.stdout, r.stdout
    r = cli(*LAUNCH, "--out", "l", "--format", "parquet", cwd=tmp_path)
    assert r.code == 0 and "summary.parquet" in r.stdout and ".csv" not in r.stdout, r.stdout


def test_a_mat_file_of_every_kind_of_column():
    df = pd.DataFrame(
        {
            "time_s": [0.0, 0.5, np.nan],
            "gear": np.array([1, 2, 3], dtype=np.int64),
            "valid": [True, False, True],
            "model": pd.array(["table", "quasi-dynamic", None], dtype="string"),
            "detail": pd.Series([1, "two", None], dtype=object),
        }
    )
    variables = mat_variables(df)
    assert list(variables) == list(df.columns)
    assert variables["valid"].dtype == bool and variables["gear"].dtype == np.int64
    assert list(variables["model"]) == ["table", "quasi-dynamic", ""]
    assert list(variables["detail"]) == ["1", "two", ""]


def test_a_mixed_text_column_is_written_to_parquet_as_text(tmp_path):
    df = pd.DataFrame({"detail": pd.Series([1, "two", None], dtype=object), "x": [1.0, 2.0, 3.0]})
    tables.write_parquet(df, tmp_path / "t.parquet")
    back = pd.read_parquet(tmp_path / "t.parquet")
    assert back["detail"].tolist()[:2] == ["1", "two"] and pd.isna(back["detail"].iloc[2])


@pytest.mark.parametrize(
    ("column", "name"),
    [
        ("pump_speed_rad_s", "pump_speed_rad_s"),
        ("0_100_km_h_s", "x0_100_km_h_s"),
        ("a-b c", "a_b_c"),
        ("end", "end_"),
        ("_x", "x_x"),
        ("é", "x_"),
        ("a" * 70, "a" * 63),
    ],
)
def test_matlab_names(column, name):
    assert matlab_name(column) == name


def test_two_columns_of_one_matlab_name_are_a_failure_not_a_silent_loss():
    with pytest.raises(ValueError, match="both become the MATLAB variable 'a_b'"):
        mat_variables(pd.DataFrame({"a-b": [1.0], "a b": [2.0]}))


# ---------------------------------------------------------------------------------------------
# speeds in rpm


def test_rpm_names_the_unit_and_converts_speeds_and_accelerations_only():
    df = pd.DataFrame(
        {
            "time_s": [0.0, 1.0],
            "pump_speed_rad_s": [0.0, 100.0],
            "pump_accel_rad_s2": [10.0, 0.0],
            "k_factor_rpm_per_sqrt_nm": [150.0, np.inf],
            "pump_torque_nm": [50.0, 60.0],
        }
    )
    rpm = to_speed_unit(df, "rpm")
    assert list(rpm.columns) == [
        "time_s",
        "pump_speed_rpm",
        "pump_accel_rpm_per_s",
        "k_factor_rpm_per_sqrt_nm",
        "pump_torque_nm",
    ]
    np.testing.assert_array_equal(rpm.pump_speed_rpm * RAD_S_PER_RPM, df.pump_speed_rad_s)
    np.testing.assert_array_equal(rpm.pump_accel_rpm_per_s * RAD_S_PER_RPM, df.pump_accel_rad_s2)
    for same in ("time_s", "k_factor_rpm_per_sqrt_nm", "pump_torque_nm"):
        np.testing.assert_array_equal(rpm[same], df[same])
    assert to_speed_unit(df, "rad/s") is df
    assert list(df.columns)[1] == "pump_speed_rad_s"  # the frame given is not changed


def test_an_rpm_column_beside_its_rad_s_column_is_a_failure():
    with pytest.raises(ValueError, match="exist already"):
        to_speed_unit(pd.DataFrame({"w_rad_s": [1.0], "w_rpm": [9.5]}), "rpm")


@pytest.mark.parametrize("file_format", FORMATS)
def test_rpm_results_round_trip_to_rad_s(cli, tmp_path, measurement, file_format):
    """Replay written in rpm: every speed column is the rad/s run's ÷ RAD_S_PER_RPM, and tcsim reads
    the rpm file back as a measurement in rad/s (its unit suffix says rpm)."""
    args = ("replay", "li-sunden-2016", str(measurement), "--model", "hrovat-tobler")
    base = run_ok(cli, tmp_path, *args, "--out", "base")
    rpm = run_ok(cli, tmp_path, *args, "--out", "rpm", "--format", file_format, "--speed-unit", "rpm")
    ref = pd.read_csv(base / "hrovat-tobler.csv")
    run = rpm / f"hrovat-tobler.{file_format}"
    got = pd.read_csv(run) if file_format == "csv" else pd.read_parquet(run) if file_format == "parquet" else None
    if got is None:
        got = pd.DataFrame(loadmat_columns(run))
    converted = [c for c in ref.columns if c.endswith(("_rad_s", "_rad_s2"))]
    assert {"pump_speed_rad_s", "turbine_speed_rad_s", "pump_accel_rad_s2"} <= set(converted)
    assert list(got.columns) == [tables.column_in_unit(c, "rpm") for c in ref.columns]
    assert not any(c.endswith(("_rad_s", "_rad_s2")) for c in got.columns)
    for c in ref.columns:
        factor = RAD_S_PER_RPM if c in converted else 1.0
        np.testing.assert_allclose(got[tables.column_in_unit(c, "rpm")] * factor, ref[c], rtol=1e-14, atol=0)
    back = read_measurement(run, {}, required=("pump_speed_rad_s", "turbine_speed_rad_s"), optional=())
    np.testing.assert_allclose(back.channels["turbine_speed_rad_s"], ref["turbine_speed_rad_s"], rtol=1e-14)


def test_the_warning_of_non_finite_values_names_the_column_as_written(tmp_path):
    df = pd.DataFrame({"time_s": [0.0, 1.0], "pump_speed_rad_s": [1.0, np.inf]})
    with pytest.warns(TcsimWarning, match=r"^run\.mat: .* in pump_speed_rpm \(1\)"):
        paths = write_frames({"run.csv": df}, tmp_path, TableFormat("mat", "rpm"))
    assert [p.name for p in paths] == ["run.mat"]
    assert np.isinf(loadmat_columns(tmp_path / "run.mat")["pump_speed_rpm"][1])


# ---------------------------------------------------------------------------------------------
# the options on the command line


COMMANDS_WITH_TABLES = [
    "characterise",
    "operating-point",
    "study",
    "replay",
    "fit-shapes",
    "launch",
    "drive",
    "torque-estimate",
    "design",
    "design-study",
]


@pytest.mark.parametrize("command", COMMANDS_WITH_TABLES)
def test_every_command_with_result_tables_offers_both_options(cli, command):
    r = cli(command, "--help")
    assert r.code == 0, r.stderr
    help_text = " ".join(r.stdout.split())
    assert "--format" in help_text and "--speed-unit" in help_text
    for choice in (*FORMATS, *SPEED_UNITS):
        assert choice in help_text, (command, choice)


@pytest.mark.parametrize(
    ("option", "value", "expected"),
    [("--format", "xlsx", "one of csv, parquet, mat"), ("--speed-unit", "deg/s", "one of rad/s, rpm")],
)
@pytest.mark.parametrize("command", [CHARACTERISE, LAUNCH, ("design", "li-sunden-2016-design")])
def test_a_bad_option_value_is_refused_before_anything_runs(cli, tmp_path, command, option, value, expected):
    r = cli(*command, "--out", "o", option, value, cwd=tmp_path)
    assert r.code == 2, (r.code, r.stderr)
    assert r.stderr.strip().splitlines() == [f"error: command line: {option} = '{value}': expected {expected}"]
    assert os.listdir(tmp_path) == []


def test_table_format_refuses_what_the_options_refuse():
    assert TableFormat().file_name("summary.csv") == "summary.csv"
    assert TableFormat("mat", "rpm").file_name("hrovat-tobler.csv") == "hrovat-tobler.mat"
    with pytest.raises(InputError, match="^argument: format = 'MAT'"):
        TableFormat("MAT")
    with pytest.raises(InputError, match="^argument: speed_unit = 'deg/s'"):
        TableFormat("csv", "deg/s")


# ---------------------------------------------------------------------------------------------
# nothing half-written


@pytest.mark.parametrize("file_format", ["parquet", "mat"])
def test_a_run_that_fails_while_writing_leaves_nothing(cli, tmp_path, monkeypatch, file_format):
    def half_then_fail(df, path):
        Path(path).write_bytes(b"PAR1 half")
        raise OSError(28, "No space left on device")

    monkeypatch.setitem(tables.WRITERS, file_format, half_then_fail)
    r = cli(*CHARACTERISE, "--out", "o", "--format", file_format, cwd=tmp_path)
    assert r.code == 1 and "No space left on device" in r.stderr, (r.code, r.stderr)
    assert os.listdir(tmp_path) == []


@pytest.mark.subprocess
@pytest.mark.parametrize("file_format", ["parquet", "mat"])
def test_an_interrupt_while_writing_a_format_leaves_nothing(tmp_path, file_format):
    r = interrupt([*LAUNCH, "--out", "o", "--format", file_format], signal.SIGTERM, "writing", tmp_path)
    assert r.returncode == 128 + signal.SIGTERM, (r.returncode, r.stderr)
    assert r.stderr.strip().splitlines() == ["interrupted (SIGTERM): nothing written"], r.stderr
    assert os.listdir(tmp_path) == []
