"""Core input errors carry the input they are about as data (issue 10, defect 7): a bad first sample of
a measurement names the measurement, a bad ``--initial`` names the command line, a bad scenario names
the scenario file; never the converter file."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from tcsim import transient as tr
from tcsim.cli import main
from tcsim.errors import InputError

T = np.arange(0.0, 2.0, 0.01)


def _csv(path, **columns):
    pd.DataFrame({"time_s": T, **{k: np.full(len(T), v) for k, v in columns.items()}}).to_csv(path, index=False)
    return str(path)


def _error_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_a_negative_first_turbine_speed_names_the_measurement(tmp_path, capsys):
    meas = _csv(tmp_path / "log.csv", pump_torque_nm=40.0, turbine_speed_rad_s=-100.0)
    assert main(["replay", "li-sunden-2016", meas, "--out", str(tmp_path / "o")]) == 2
    line = _error_line(capsys)
    assert line.startswith(f"error: {meas}: initial turbine_speed_rad_s = -100: expected a turbine speed of zero")
    assert not (tmp_path / "o").exists()


def test_a_first_sample_in_overrun_replays_with_hrovat_tobler(tmp_path):
    # before issue 11: exit 2, "initial speed_ratio = 2: expected a speed ratio from 0 to 1"; now the
    # H&T steady state covers overrun (reverse flow), so the replay starts from it
    meas = _csv(tmp_path / "log.csv", pump_speed_rad_s=100.0, turbine_speed_rad_s=200.0)
    args = ["replay", "li-sunden-2016", meas, "--drive", "speeds", "-m", "hrovat-tobler", "--out", str(tmp_path / "o")]
    assert main(args) == 0


def test_a_bad_initial_value_names_the_command_line(tmp_path, capsys):
    meas = _csv(tmp_path / "log.csv", pump_torque_nm=40.0, turbine_speed_rad_s=50.0)
    args = ["replay", "li-sunden-2016", meas, "-m", "hrovat-tobler", "--out", str(tmp_path / "o")]
    assert main([*args, "--initial", "stator_speed_rad_s=-1"]) == 2
    assert _error_line(capsys).startswith(
        "error: command line: --initial stator_speed_rad_s = -1: expected zero or more"
    )


def test_api_errors_carry_the_source_and_the_file_given():
    drive = tr.PumpTorqueTurbineSpeed(T, np.full(len(T), 40.0), np.full(len(T), -100.0))
    with pytest.raises(InputError) as e:
        tr.simulate("li-sunden-2016", drive, model="hrovat-tobler", files={"drive": "log.csv"})
    assert (e.value.source, e.value.core_source, e.value.field, e.value.value) == (
        "log.csv",
        "drive",
        "initial turbine_speed_rad_s",
        -100.0,
    )
    with pytest.raises(InputError) as e:
        tr.simulate("li-sunden-2016", drive, model="table")
    assert (e.value.source, e.value.field) == ("drive", "initial turbine_speed_rad_s")
    # drive (c): the turbine speed comes from the initial state
    load = tr.PumpTorqueLoad(T, np.full(len(T), 40.0), 0.5)
    with pytest.raises(InputError) as e:
        tr.simulate("li-sunden-2016", load, model="hrovat-tobler", initial={"turbine_speed_rad_s": -100.0})
    assert (e.value.core_source, e.value.field, e.value.value) == ("initial", "initial turbine_speed_rad_s", -100.0)


def test_a_scenario_that_makes_the_output_too_large_names_the_scenario_file(tmp_path, capsys):
    scenario = tmp_path / "long.csv"
    pd.DataFrame({"time_s": [0.0, 1e5], "accelerator_pedal": [0.0, 1.0], "brake_pedal": [1.0, 0.0]}).to_csv(
        scenario, index=False
    )
    args = ["launch", "--scenario", str(scenario), "--model", "table", "--out", str(tmp_path / "o")]
    assert main([*args, "--allow-implausible"]) == 2  # a 1e5 s scenario is implausible: past that, too big
    warning, line = capsys.readouterr().err.strip().splitlines()  # the override's warning, then the error
    assert warning.startswith(f"warning: {scenario}: time_s (time span, s) = 100000 is outside"), warning
    assert line.startswith(f"error: {scenario}: output_samples = 1e+07: expected an output of at most"), line
    assert "max_output_bytes" in line and not (tmp_path / "o").exists()
