"""``tcsim drive`` as a new user meets it (issue 14): the output-size guard of ``tcsim launch``
(the core's ``OutputSize``, docs/guarantees.md) refuses a trace too long for the memory before
anything runs, and every bad command line is one line, exit 2, nothing written."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from asammdf import MDF, Signal

from tcsim.analysis.drive import Cycle, run_drive
from tcsim.errors import InputError
from tcsim.io.cycle import read_cycle
from tcsim.models.dynamic import select_models
from tcsim.models.vehicle import load_vehicle


def standstill(hours: float, source: str = "standstill.csv") -> Cycle:
    """A trace that stands still for ``hours`` (two samples)."""
    return Cycle("standstill", source, np.array([0.0, hours * 3600.0]), np.zeros(2))


def test_a_drive_whose_output_exceeds_max_output_bytes_is_refused_before_running():
    # a small limit, so that a regression drives one hour instead of filling the memory
    v = load_vehicle()
    models = select_models(v.converter, ["table"])
    with pytest.raises(InputError) as e:
        run_drive(v, standstill(1.0), models, options={"max_output_bytes": 1e6})
    assert (e.value.source, e.value.core_source, e.value.field) == ("standstill.csv", "scenario", "output_samples")
    assert e.value.value == 36001.0 and "max_output_bytes = 1e6 bytes" in e.value.expected
    # a control step finer than the default makes the output: the options are at fault
    with pytest.raises(InputError) as e:
        run_drive(v, standstill(0.5), models, options={"max_output_bytes": 1e6, "driver_control_step_s": 0.01})
    assert (e.value.core_source, e.value.field) == ("options", "output_samples")


def test_a_trace_of_weeks_is_refused_in_one_line_by_the_cli(cli, tmp_path):
    trace = tmp_path / "weeks.csv"
    pd.DataFrame({"time_s": [0.0, 3e6], "vehicle_speed_m_s": [0.0, 0.0]}).to_csv(trace, index=False)
    before = trace.read_bytes()
    r = cli("drive", "--cycle", trace, "--out", tmp_path / "o")
    assert r.code == 2, (r.stdout, r.stderr)
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith(f"error: {trace}: output_samples = 3e+07: expected an output of at most"), line
    assert "max_output_bytes = 2e9 bytes" in line and "3 run(s)" in line
    assert not (tmp_path / "o").exists() and trace.read_bytes() == before


def _must_not_run(*args, **kwargs):
    raise AssertionError("the drive ran before its --out was checked")


@pytest.mark.parametrize("where", ["under a file", "under a file's missing folder"])
def test_an_out_that_cannot_be_created_is_refused_before_the_drive_runs(cli, tmp_path, monkeypatch, where):
    """Before: the whole drive ran (minutes for a long trace, its warnings printed) and then the
    output failed."""
    monkeypatch.setattr("tcsim.analysis.drive.drive", _must_not_run)
    blocker = tmp_path / "results.csv"
    blocker.write_text("a file\n")
    out = blocker / "run" if where == "under a file" else blocker / "a" / "run"
    r = cli("drive", "--cycle", "udds", "--out", out)
    assert r.code == 2, (r.stdout, r.stderr)
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("error: command line: --out = '"), line  # the value is shortened when long
    assert line.endswith(f": expected a directory that can be created ('{blocker}' is not a directory)"), line
    assert blocker.read_text() == "a file\n" and sorted(p.name for p in tmp_path.iterdir()) == ["results.csv"]


def test_a_directory_given_as_the_trace_is_named_a_directory(cli, tmp_path):
    """Before: ``(file) = 'not found'`` for a directory that exists."""
    folder = tmp_path / "traces.csv"
    folder.mkdir()
    r = cli("drive", "--cycle", folder, "--out", tmp_path / "o")
    assert r.code == 2
    expected = f"error: {folder}: (file) = 'a directory': expected an existing cycle file"
    assert r.stderr.strip().splitlines() == [expected]
    assert not (tmp_path / "o").exists()


def _mdf_trace(path, units: dict[str, str]):
    t = np.arange(0.0, 11.0)
    columns = {"vehicle_speed_m_s": np.interp(t, [0, 5, 10], [0, 10, 0]), "grade_percent": np.full(t.size, 2.0)}
    mdf = MDF(version="4.10")
    mdf.append([Signal(v, t, name=name, unit=units.get(name, "")) for name, v in columns.items()])
    mdf.save(path, overwrite=True)
    mdf.close()
    return path


@pytest.mark.parametrize(
    ("column", "unit"), [("vehicle_speed_m_s", "km/h"), ("vehicle_speed_m_s", "mph"), ("grade_percent", "deg")]
)
def test_a_unit_in_the_file_that_contradicts_the_column_name_is_refused(tmp_path, column, unit):
    """Before: an MDF4 channel ``vehicle_speed_m_s`` in km/h was read as m/s (3.6 times too fast)."""
    path = _mdf_trace(tmp_path / "trace.mf4", {column: unit})
    with pytest.raises(InputError) as e:
        read_cycle(path)
    assert (e.value.source, e.value.field, e.value.value) == (str(path), f"{column} (unit)", unit)
    assert "wrong units" in e.value.expected


def test_units_that_agree_with_the_column_names_are_read(tmp_path):
    path = _mdf_trace(tmp_path / "trace.mf4", {"vehicle_speed_m_s": "m/s", "grade_percent": "%"})
    c = read_cycle(path)
    assert c.vehicle_speed_m_s.max() == 10.0 and (c.grade_percent == 2.0).all()


@pytest.mark.parametrize(
    ("text", "field", "value"),
    [
        ("time_s,vehicle_speed_m_s\n100,0\n101,1\n102,-1\n103,0\n", "vehicle_speed_m_s", "-1 at row 3 (time_s 102)"),
        ("time_s,vehicle_speed_m_s\n100,0.5\n101,1\n", "vehicle_speed_m_s", "0.5 at row 1 (time_s 100)"),
        (
            "time_s,vehicle_speed_m_s,grade_percent\n0,0,0\n0.5,1,31\n",
            "grade_percent",
            "31 at row 2 (time_s 0.5)",
        ),
    ],
)
def test_a_value_out_of_range_is_located_like_every_other_trace_error(cli, tmp_path, text, field, value):
    """Before: ``vehicle_speed_m_s[2] = -1``, a 0-based sample index, where a NaN in the same file
    is ``row 3 (time_s 102)``: the file's data row (1-based) and its own time stamp."""
    path = tmp_path / "trace.csv"
    path.write_text(text)
    r = cli("drive", "--cycle", path, "--model", "table", "--out", tmp_path / "o")
    assert r.code == 2, r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith(f"error: {path}: {field} = '{value}': expected "), line
    assert not (tmp_path / "o").exists() and path.read_text() == text


def test_the_console_summary_is_a_table_of_metrics_with_a_column_per_model(cli, tmp_path):
    """Before: ``summary.to_string()``, 15 columns that a terminal of 80 columns wrapped into an
    unreadable block of numbers."""
    path = tmp_path / "trace.csv"
    path.write_text("time_s,vehicle_speed_m_s\n0,0\n1,1\n2,2\n3,3\n4,2\n5,0\n6,0\n")
    r = cli("drive", "--cycle", path, "-m", "table", "-m", "hrovat-tobler", "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    summary = pd.read_csv(tmp_path / "o" / "summary.csv")
    lines = r.stdout.splitlines()
    header = next(line for line in lines if line.strip().startswith("metric"))
    assert header.split() == ["metric", "table", "hrovat-tobler"]
    rows = {line.split("[")[0].strip(): line.split("]")[-1].split() for line in lines if "] " in line}
    assert rows["RMS speed error"] == [f"{v:.2f}" for v in summary.rms_speed_error_km_h]
    assert rows["converter loss"] == [f"{v:.1f}" for v in summary.converter_loss_kj]
    assert rows["energy residual"] == [f"{v:.1e}" for v in summary.energy_residual]
    table = lines[lines.index(header) : lines.index(header) + 13]
    assert max(len(line.rstrip()) for line in table) <= 80


def test_a_trace_file_without_an_extension_is_named_as_a_file(cli, tmp_path):
    """Before: ``command line: --cycle = 'trace': expected one of us06, ... or a trace file`` for a
    trace file that exists; now the file and the extensions tcsim reads."""
    path = tmp_path / "trace"
    path.write_text("time_s,vehicle_speed_m_s\n0,0\n1,1\n")
    r = cli("drive", "--cycle", path, "--out", tmp_path / "o")
    assert r.code == 2
    expected = "a cycle file ending in one of .csv, .parquet, .mat, .mf4, .mdf"
    assert r.stderr.strip().splitlines() == [f"error: {path}: (extension) = '(none)': expected {expected}"]


@pytest.mark.parametrize("where", ["a read-only file system", "an existing file"])
def test_an_out_that_cannot_be_written_is_refused_before_the_drive_runs(cli, tmp_path, monkeypatch, where):
    """/proc refuses new directories even to root (before: after the whole drive); an existing file
    is never replaced by a directory."""
    if where == "a read-only file system" and not Path("/proc/self").is_dir():
        pytest.skip("needs Linux's /proc")
    monkeypatch.setattr("tcsim.analysis.drive.drive", _must_not_run)
    out = Path("/proc/tcsim-drive-out") if where == "a read-only file system" else tmp_path / "summary.csv"
    if where == "an existing file":
        out.write_text("kept\n")
    r = cli("drive", "--cycle", "us06", "--out", out)
    assert r.code == 2, r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith(f"error: command line: --out = '{out}': expected a "), line
    assert ("a writable directory (" if where == "a read-only file system" else "(a file of that name exists)") in line
    assert not out.exists() if where == "a read-only file system" else out.read_text() == "kept\n"


@pytest.mark.parametrize(
    ("options", "field"),
    [({"driver_kp": 1.0}, "driver_kp"), ({"driver_kp_per_s": "fast"}, "driver_kp_per_s"), ({"rtoll": 1e-6}, "rtoll")],
)
def test_a_misspelt_or_mistyped_driver_option_is_refused(options, field):
    """A misspelt option was ignored (the run used the default); a gain given as text was a bare
    ValueError of the binding."""
    v = load_vehicle()
    with pytest.raises(InputError) as e:
        run_drive(v, standstill(0.01), select_models(v.converter, ["table"]), options=options)
    assert (e.value.core_source, e.value.field) == ("options", field)
