"""tcsim replay: metrics on known arrays, the smoothed derivative, a synthetic measurement replayed
through the command line (all formats, channel mapping, initial state, both drives), bad inputs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from asammdf import MDF, Signal

import tcsim.cli
from tcsim import transient
from tcsim.analysis.effective import smoothed_rate
from tcsim.analysis.replay import error_metrics, metric_windows, parse_initial
from tcsim.errors import InputError
from tcsim.simulation import transient as runs

BUNDLED_TOML = Path(__file__).resolve().parents[2] / "python" / "tcsim" / "data" / "converters" / "li-sunden-2016.toml"
STATOR_RELEASE_S = 2.37  # Hrovat & Tobler, isolated take-off of transient.isolated_takeoff()
MODEL_COLUMNS = [
    "time_s",
    "pump_speed_rad_s",
    "turbine_speed_rad_s",
    "pump_torque_nm",
    "turbine_torque_nm",
    "speed_ratio",
    "torque_ratio",
    "effective_pump_torque_nm",
    "effective_turbine_torque_nm",
]
PLOTS = ["inputs.png", "turbine_torque.png", "effective_pump_torque.png", "effective_turbine_torque.png"]
# Replay accuracy of the Hrovat & Tobler pump speed against the run that made the measurement
# (drive (a) instead of (c); the prescribed turbine speed's derivative is smoothed over 40 ms).
# Measured: relative RMS 6e-7, max 1.1e-3 rad/s; the bounds leave two orders of magnitude for
# solver tolerance, while a wrong drive or initial state gives errors of percent.
PUMP_SPEED_REL_RMS = 1e-4
PUMP_SPEED_MAX_ABS_RAD_S = 0.05
TURBINE_TORQUE_NRMSE = 1e-3  # measured 3.5e-5


# ---------------------------------------------------------------------------------------------
# the synthetic measurement


@pytest.fixture(scope="module")
def synthetic() -> pd.DataFrame:
    """Hrovat & Tobler under the isolated take-off (drive c), 0–3 s at 1 kHz."""
    t = np.round(np.arange(3001) * 1e-3, 12)
    run = transient.simulate("li-sunden-2016", transient.isolated_takeoff(), "hrovat-tobler", times_s=t)
    assert any(e.kind == "stator-release" and e.time_s < t[-1] for e in run.events), "record too short"
    f = run.frame()
    return f[["time_s", "pump_torque_nm", "turbine_speed_rad_s", "pump_speed_rad_s", "turbine_torque_nm"]].copy()


@pytest.fixture
def meas_csv(tmp_path, synthetic) -> Path:
    path = tmp_path / "takeoff.csv"
    synthetic.to_csv(path, index=False, float_format="%.17g")
    return path


def replay_ok(cli, *args) -> Path:
    out = Path(args[args.index("--out") + 1])
    r = cli("replay", *args)
    assert r.code == 0, (r.code, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr + r.stdout
    return out


# ---------------------------------------------------------------------------------------------
# pure functions


def test_error_metrics_constant_offset():
    t = np.linspace(0.0, 2.5, 251)
    measured = 10.0 + 4.0 * np.sin(2.0 * t)
    df = error_metrics(t, measured, measured + 0.3, window_s=1.0)
    assert list(df["window"]) == ["all", "1", "2", "3"]
    np.testing.assert_allclose(df["window_start_s"], [0.0, 0.0, 1.0, 2.0])
    np.testing.assert_allclose(df["window_end_s"], [2.5, 1.0, 2.0, 2.5])
    assert list(df["n"]) == [251, 100, 100, 51]
    np.testing.assert_allclose(df["rmse"], 0.3, rtol=1e-12)
    np.testing.assert_allclose(df["max_abs_error"], 0.3, rtol=1e-12)
    whole = df.iloc[0]
    assert whole["nrmse"] == pytest.approx(0.3 / np.ptp(measured), rel=1e-12)
    assert df.iloc[2]["nrmse"] == pytest.approx(0.3 / np.ptp(measured[100:200]), rel=1e-12)


def test_error_metrics_known_errors_and_flat_channel():
    t = np.array([0.0, 0.1, 0.2, 0.3])
    measured = np.full(4, 5.0)
    df = error_metrics(t, measured, measured + [0.0, 0.0, -3.0, 4.0], window_s=None)
    assert len(df) == 1
    row = df.iloc[0]
    assert row["rmse"] == pytest.approx(2.5)  # sqrt((9 + 16) / 4)
    assert row["max_abs_error"] == 4.0 and row["max_abs_error_time_s"] == pytest.approx(0.3)
    assert math.isnan(row["nrmse"])  # a flat measured channel has no range
    with pytest.raises(ValueError):
        error_metrics(t, measured, measured[:3])


def test_metric_windows_cover_every_sample_once():
    t = np.cumsum(np.full(1234, 0.0037))
    windows = metric_windows(t, 0.5)
    masks = np.zeros((len(windows) - 1, len(t)), dtype=bool)
    for row, (*_, samples) in zip(masks, windows[1:], strict=True):
        row[samples] = True
    assert (masks.sum(axis=0) == 1).all()
    assert windows[-1][2] == pytest.approx(t[-1])


def test_smoothed_rate_is_exact_on_polynomials_and_matches_the_core(synthetic):
    t = np.linspace(0.0, 1.0, 1001)
    np.testing.assert_allclose(smoothed_rate(t, 3.0 * t + 1.0, 0.04), 3.0, rtol=1e-9)
    # symmetric windows (edges between samples): the slope of a parabola is its derivative
    inner = slice(30, -30)
    np.testing.assert_allclose(smoothed_rate(t, t**2, 0.04)[inner], 2.0 * t[inner], rtol=1e-9, atol=1e-12)
    # the same slope as the core applies to a prescribed speed (drive (a): turbine acceleration)
    time, speed = synthetic["time_s"].to_numpy(), synthetic["turbine_speed_rad_s"].to_numpy()
    drive = transient.PumpTorqueTurbineSpeed(time, synthetic["pump_torque_nm"].to_numpy(), speed)
    core = transient.simulate("li-sunden-2016", drive, "table")["turbine_accel_rad_s2"]
    np.testing.assert_allclose(smoothed_rate(time, speed, transient.DERIVATIVE_WINDOW_S), core, rtol=1e-9, atol=1e-9)


def test_parse_initial():
    assert parse_initial(["pump_speed_rad_s=150", "flow_m3_s = 0.05"]) == {"pump_speed_rad_s": 150.0, "flow_m3_s": 0.05}
    for bad in (
        ["pump_speed_rad_s"],
        ["pump_speed=150"],
        ["pump_speed_rad_s=fast"],
        ["pump_speed_rad_s=nan"],
        ["flow_m3_s=1", "flow_m3_s=2"],
    ):
        with pytest.raises(InputError, match="--initial"):
            parse_initial(bad)


# ---------------------------------------------------------------------------------------------
# the command on the synthetic measurement


def test_replay_reproduces_the_run_that_made_the_measurement(cli, tmp_path, meas_csv, synthetic):
    out = replay_ok(cli, "li-sunden-2016", meas_csv, "--model", "hrovat-tobler", "--out", tmp_path / "r")
    sim = pd.read_csv(out / "hrovat-tobler.csv")
    assert len(sim) == len(synthetic)
    assert set(MODEL_COLUMNS + ["flow_m3_s", "stator_speed_rad_s"]) <= set(sim.columns)
    np.testing.assert_allclose(sim["time_s"], synthetic["time_s"], rtol=0, atol=1e-12)
    err = sim["pump_speed_rad_s"] - synthetic["pump_speed_rad_s"]
    rel_rms = np.sqrt(np.mean(err**2) / np.mean(synthetic["pump_speed_rad_s"] ** 2))
    assert rel_rms < PUMP_SPEED_REL_RMS and np.abs(err).max() < PUMP_SPEED_MAX_ABS_RAD_S, (rel_rms, np.abs(err).max())

    metrics = pd.read_csv(out / "metrics.csv")
    whole = metrics[metrics["window"] == "all"].set_index("channel")
    assert set(whole.index) == {
        "pump_speed_rad_s",
        "turbine_torque_nm",
        "effective_pump_torque_nm",
        "effective_turbine_torque_nm",
    }
    assert whole.loc["turbine_torque_nm", "nrmse"] < TURBINE_TORQUE_NRMSE
    assert whole.loc["pump_speed_rad_s", "rmse"] == pytest.approx(np.sqrt(np.mean(err**2)), rel=1e-6)
    assert (whole["n"] == len(synthetic)).all()
    # drive (a) prescribes ω_t and its smoothed derivative, so eq 3.4's error is the turbine torque's
    assert whole.loc["effective_turbine_torque_nm", "rmse"] == pytest.approx(
        whole.loc["turbine_torque_nm", "rmse"], rel=1e-6
    )
    assert len(metrics) == 4 * (1 + 3)  # four channels × (all + three 1 s windows)

    events = pd.read_csv(out / "events.csv")
    assert list(events.columns) == ["model", "time_s", "kind", "stator_locked", "flow_direction"]
    release = events[events["kind"] == "stator-release"]
    assert list(release["model"]) == ["hrovat-tobler"] and release["time_s"].iloc[0] == pytest.approx(
        STATOR_RELEASE_S, abs=0.01
    )
    for name in PLOTS + ["pump_speed.png", "measurement.csv"]:
        assert (out / name).stat().st_size > 0, name


def test_default_models_and_metrics_for_each(cli, tmp_path, meas_csv, synthetic):
    r = cli("replay", "li-sunden-2016", meas_csv, "--out", tmp_path / "r", "--metrics-window", "2")
    assert r.code == 0, r.stderr
    out = tmp_path / "r"
    for model in ("table", "hrovat-tobler", "quasi-dynamic"):
        assert model in r.stdout
        frame = pd.read_csv(out / f"{model}.csv")
        assert len(frame) == len(synthetic) and set(MODEL_COLUMNS) <= set(frame.columns)
        assert ("flow_m3_s" in frame.columns) == (model != "table")
        assert ("stator_speed_rad_s" in frame.columns) == (model == "hrovat-tobler")
    metrics = pd.read_csv(out / "metrics.csv")
    counts = metrics.groupby(["model", "channel"]).size()
    assert len(counts) == 3 * 4 and (counts == 1 + 2).all()  # all + windows [0, 2) and [2, 3]
    assert "turbine torque RMSE" in r.stdout and str(out) in r.stdout


@pytest.mark.parametrize("fmt", ["parquet", "mf4"])
def test_parquet_and_mdf4(cli, tmp_path, synthetic, fmt):
    path = tmp_path / f"takeoff.{fmt}"
    if fmt == "parquet":
        synthetic.to_parquet(path)
    else:
        units = {"pump_torque_nm": "Nm", "turbine_torque_nm": "Nm"}
        with MDF(version="4.10") as mdf:
            mdf.append(
                [
                    Signal(synthetic[c].to_numpy(), synthetic["time_s"].to_numpy(), name=c, unit=units.get(c, "rad/s"))
                    for c in synthetic.columns
                    if c != "time_s"
                ]
            )
            mdf.save(path, overwrite=True)
    out = replay_ok(cli, "li-sunden-2016", path, "--model", "hrovat-tobler", "--out", tmp_path / "r")
    assert len(pd.read_csv(out / "hrovat-tobler.csv")) == len(synthetic)
    whole = pd.read_csv(out / "metrics.csv").query("window == 'all'").set_index("channel")
    assert whole.loc["pump_speed_rad_s", "nrmse"] < PUMP_SPEED_REL_RMS


def test_channel_mapping_with_renamed_columns(cli, tmp_path, synthetic):
    renamed = synthetic.rename(
        columns={
            "time_s": "t",
            "pump_torque_nm": "EngTrq",
            "turbine_speed_rad_s": "GbxInSpd",
            "pump_speed_rad_s": "EngSpd",
            "turbine_torque_nm": "TurbTrq",
        }
    )
    renamed["GbxInSpd_rpm"] = renamed.pop("GbxInSpd") * 30.0 / math.pi  # mapped and converted by its suffix
    path = tmp_path / "logger.csv"
    renamed.to_csv(path, index=False, float_format="%.17g")
    maps = [
        "time_s=t",
        "pump_torque_nm=EngTrq",
        "turbine_speed_rad_s=GbxInSpd_rpm",
        "pump_speed_rad_s=EngSpd",
        "turbine_torque_nm=TurbTrq",
    ]
    out = replay_ok(
        cli,
        "li-sunden-2016",
        path,
        "--model",
        "hrovat-tobler",
        "--out",
        tmp_path / "r",
        *[a for m in maps for a in ("--channel", m)],
    )
    whole = pd.read_csv(out / "metrics.csv").query("window == 'all'").set_index("channel")
    assert whole.loc["pump_speed_rad_s", "nrmse"] < PUMP_SPEED_REL_RMS
    assert whole.loc["turbine_torque_nm", "nrmse"] < TURBINE_TORQUE_NRMSE


def test_initial_pump_speed_override(cli, tmp_path, meas_csv):
    out = replay_ok(
        cli,
        "li-sunden-2016",
        meas_csv,
        "--model",
        "hrovat-tobler",
        "--model",
        "table",
        "--initial",
        "pump_speed_rad_s=150",
        "--out",
        tmp_path / "r",
    )
    for model in ("hrovat-tobler", "table"):
        first = pd.read_csv(out / f"{model}.csv").iloc[0]
        assert first["pump_speed_rad_s"] == pytest.approx(150.0, rel=1e-9)
        assert first["turbine_speed_rad_s"] == 0.0


def test_drive_speeds_and_inputs_only(cli, tmp_path, synthetic):
    path = tmp_path / "speeds.csv"
    synthetic.to_csv(path, index=False, float_format="%.17g")
    out = replay_ok(
        cli, "li-sunden-2016", path, "--drive", "speeds", "--model", "hrovat-tobler", "--out", tmp_path / "b"
    )
    whole = pd.read_csv(out / "metrics.csv").query("window == 'all'").set_index("channel")
    assert set(whole.index) == {
        "pump_torque_nm",
        "turbine_torque_nm",
        "effective_pump_torque_nm",
        "effective_turbine_torque_nm",
    }
    # the prescribed pump speed's smoothed derivative rounds the corners of the torque ramp (0.1 s,
    # 0.3 s): measured NRMSE 1.2e-3 with the 40 ms window
    assert (
        whole.loc["pump_torque_nm", "nrmse"] < 5e-3 and whole.loc["turbine_torque_nm", "nrmse"] < TURBINE_TORQUE_NRMSE
    )
    assert (out / "pump_torque.png").exists()

    bare = tmp_path / "inputs_only.csv"
    synthetic[["time_s", "pump_torque_nm", "turbine_speed_rad_s"]].to_csv(bare, index=False)
    out = replay_ok(cli, "li-sunden-2016", bare, "--model", "table", "--out", tmp_path / "a")
    assert not (out / "metrics.csv").exists() and (out / "table.csv").exists()
    assert all((out / p).exists() for p in PLOTS)


# ---------------------------------------------------------------------------------------------
# bad inputs: exit 2, one line naming the file, the field and the value, nothing written


def _bad_csv(synthetic: pd.DataFrame, case: str) -> pd.DataFrame:
    df = synthetic.copy()
    if case == "missing channel":
        return df.drop(columns="pump_torque_nm")
    if case == "non-monotonic time":
        df.loc[500, "time_s"] = 0.4
    elif case == "nan":
        df.loc[700, "turbine_torque_nm"] = np.nan
    elif case == "wrong units":
        df["turbine_speed_rad_s"] = df["turbine_speed_rad_s"] * 30.0 / math.pi + 100.0  # rpm, up to ~3300
    return df


CSV_CASES = {  # case: (extra args, words of the message)
    "missing channel": ([], ["pump_torque_nm", "missing"]),
    "non-monotonic time": ([], ["time_s", "0.4", "row 501", "strictly increasing"]),
    "nan": ([], ["turbine_torque_nm", "NaN", "row 701"]),
    "wrong units": ([], ["turbine_speed_rad_s", "rpm"]),
}
ARG_CASES = {  # case: (converter TOML edit or None, extra args, words)
    "unknown model": (None, ["--model", "lookup"], ["command line", "--model", "lookup"]),
    "unknown drive": (None, ["--drive", "torques"], ["command line", "--drive", "torques"]),
    "malformed initial": (
        None,
        ["--initial", "pump_speed_rad_s:150"],
        ["command line", "--initial", "pump_speed_rad_s:150"],
    ),
    "unknown initial key": (
        None,
        ["--initial", "pump_speed_rpm=1500"],
        ["command line", "--initial", "pump_speed_rpm"],
    ),
    "negative window": (None, ["--window", "-0.1"], ["command line", "--window", "-0.1"]),
    "bad channel map": (None, ["--channel", "pump_torque=EngTrq"], ["--channel", "pump_torque=EngTrq"]),
    "no inertia, dynamic model": (
        "characteristic only",
        ["--model", "quasi-dynamic"],
        ["[inertia]", "missing", "quasi-dynamic"],
    ),
    "no inertia, default models": ("characteristic only", [], ["[inertia]", "missing"]),
    "inadmissible shape effect": (
        "big shape effect",
        ["--model", "hrovat-tobler"],
        ["geometry.pump_shape_effect_m2", "|S| <"],
    ),
}


def _converter(tmp_path: Path, edit: str | None) -> str | Path:
    if edit is None:
        return "li-sunden-2016"
    text = BUNDLED_TOML.read_text()
    path = tmp_path / "conv.toml"
    if edit == "characteristic only":
        text = text[: text.index("[inertia]")]
    else:
        old = "pump_shape_effect_m2 = 0.001310"
        assert old in text
        text = text.replace(old, "pump_shape_effect_m2 = 0.2", 1)
    path.write_text(text)
    return path


def assert_exit_2(r, tmp_path: Path, out: Path, *words: str) -> str:
    assert r.code == 2, (r.code, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr + r.stdout
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, lines
    msg = lines[0]
    assert msg.startswith("error: ") and "expected" in msg
    for w in words:
        assert str(w) in msg, f"{w!r} not in {msg!r}"
    assert not out.exists(), "no output may be written on bad input"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(f".{out.name}.")], "staging directory left behind"
    return msg


@pytest.mark.parametrize("case", sorted(CSV_CASES))
def test_bad_measurement(cli, tmp_path, synthetic, case):
    extra, words = CSV_CASES[case]
    path = tmp_path / "bad.csv"
    _bad_csv(synthetic, case).to_csv(path, index=False, float_format="%.17g")
    out = tmp_path / "out"
    r = cli("replay", "li-sunden-2016", path, "--out", out, *extra)
    assert_exit_2(r, tmp_path, out, str(path), *words)


@pytest.mark.parametrize("case", sorted(ARG_CASES))
def test_bad_arguments_and_converters(cli, tmp_path, meas_csv, case):
    edit, extra, words = ARG_CASES[case]
    converter = _converter(tmp_path, edit)
    out = tmp_path / "out"
    r = cli("replay", converter, meas_csv, "--out", out, *extra)
    msg = assert_exit_2(r, tmp_path, out, *words)
    if edit is not None:
        assert str(converter) in msg


def test_solver_failure_is_exit_1_with_the_message(monkeypatch, capsys, tmp_path, meas_csv):
    def fail(*args, **kwargs):
        raise transient.SolverError("hrovat-tobler: step size too small at t = 1.234 s, state [1, 2, 3, 4]")

    monkeypatch.setattr(runs, "simulate", fail)
    out = tmp_path / "out"
    assert (
        tcsim.cli.main(["replay", "li-sunden-2016", str(meas_csv), "--model", "hrovat-tobler", "--out", str(out)]) == 1
    )
    err = capsys.readouterr().err
    assert "SolverError" in err and "t = 1.234 s" in err and "Traceback" not in err
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".out.")]


def test_ignored_initial_state_warns(cli, tmp_path, meas_csv):
    r = cli(
        "replay",
        "li-sunden-2016",
        meas_csv,
        "--model",
        "table",
        "--initial",
        "turbine_speed_rad_s=3",
        "--initial",
        "flow_m3_s=0.05",
        "--out",
        tmp_path / "r",
    )
    assert r.code == 0, r.stderr
    assert "turbine_speed_rad_s is ignored" in r.stderr and "flow_m3_s is ignored by the table model" in r.stderr


def test_a_window_constant_to_round_off_has_no_nrmse():
    # fresh-eyes trial: a replayed launch's braked windows, constant to rounding (a range of 1e-13),
    # gave NRMSE 5.7e12 next to windows of the same data with NaN
    t = np.linspace(0.0, 3.0, 301)
    measured = np.where(t < 2.0, 74.8 + 1e-13 * np.sin(40.0 * t), 74.8 + 10.0 * (t - 2.0))
    df = error_metrics(t, measured, measured + 0.3, window_s=1.0)
    assert np.isnan(df.iloc[1]["nrmse"]) and np.isnan(df.iloc[2]["nrmse"]), df
    assert df.iloc[3]["nrmse"] == pytest.approx(0.3 / np.ptp(measured[200:]), rel=1e-12)
    assert df.iloc[0]["nrmse"] == pytest.approx(0.3 / np.ptp(measured), rel=1e-12)
