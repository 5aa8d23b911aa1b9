"""tcsim launch: scenarios, scenario files, summary metrics on synthetic arrays, the core contract
(with a stand-in for ``_core.launch_runs``: unpacking, errors, files, plots, the sweep, the command
line) and, when the core has the vehicle plant, the take-off itself."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pandas as pd
import pytest

import tcsim
import tcsim.cli
from tcsim import _core
from tcsim.analysis.launch import (
    EVENT_COLUMNS,
    SUMMARY_COLUMNS,
    events_table,
    launch_summary,
    peak_value,
    time_to_speed,
    window_mean,
    window_min,
)
from tcsim.cli.launch import launch_files, write_launch
from tcsim.errors import InputError, TcsimWarning
from tcsim.io.scenario import read_scenario, scenario_from_option
from tcsim.models.dynamic import dynamic_model
from tcsim.models.shape_effects import THESIS_VALUES_M2, mass_matrix_bound
from tcsim.models.vehicle import load_vehicle
from tcsim.simulation.launch import LAUNCH_COLUMNS, SWEEP_SPAN_S, run_launch, select_models, sweep_cases, sweep_scenario
from tcsim.simulation.scenarios import Scenario, brake_release_time, flip_flop, part_pedal
from tcsim.simulation.transient import SolverError

# ---------------------------------------------------------------------------------------------
# scenarios


def test_flip_flop():
    s = flip_flop()
    assert s.name == "flip-flop" and s.end_time_s == 30.0 and s.brake_release_time_s == 5.0
    assert s.stop_speed_m_s == pytest.approx(27.7778, abs=1e-4)
    acc, brake = s.pedals_at([0.0, 4.99, 5.0, 5.025, 5.05, 10.0, 30.0])
    np.testing.assert_allclose(acc, [0, 0, 0, 0.5, 1, 1, 1])
    np.testing.assert_allclose(brake, [1, 1, 1, 0.5, 0, 0, 0])
    spec = s.core_spec()
    assert set(spec) == {"time_s", "accelerator_pedal", "brake_pedal", "end_time_s", "stop_speed_m_s"}
    json.dumps(spec)
    other = flip_flop(hold_s=2.0, end_time_s=8.0)
    assert other.brake_release_time_s == 2.0 and other.time_s.tolist() == [0.0, 2.0, 2.05, 8.0]


def test_part_pedal():
    s = part_pedal()
    assert s.name == "part-pedal" and s.end_time_s == 40.0 and s.brake_release_time_s == 5.0
    assert s.stop_speed_m_s == pytest.approx(50 / 3.6)
    acc, brake = s.pedals_at([4.0, 5.05, 20.0])
    np.testing.assert_allclose(acc, [0, 0.3, 0.3])
    np.testing.assert_allclose(brake, [1, 0, 0])
    assert part_pedal(pedal=0.6).accelerator_pedal.max() == 0.6
    assert part_pedal().core_spec()["stop_speed_m_s"] == pytest.approx(13.8889, abs=1e-4)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: flip_flop(hold_s=5.0, end_time_s=5.0), "end_time_s"),
        (lambda: flip_flop(hold_s=0.0), "hold_s"),
        (lambda: part_pedal(pedal=0.0), "pedal"),
        (lambda: part_pedal(pedal=1.5), "pedal"),
        (lambda: part_pedal(pedal=math.nan), "pedal"),
    ],
)
def test_bad_builtin_scenarios(make, field):
    with pytest.raises(InputError) as err:
        make()
    assert err.value.field == field


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(time_s=[0, 1, 1, 2]), "time_s[2]"),
        (dict(time_s=[0.5, 1, 2, 3]), "time_s[0]"),
        (dict(accelerator_pedal=[0, 0, 1.2, 1]), "accelerator_pedal[2]"),
        (dict(brake_pedal=[1, 1, -0.1, 0]), "brake_pedal[2]"),
        (dict(brake_pedal=[1, math.nan, 0, 0]), "brake_pedal[1]"),
        (dict(brake_pedal=[1, 0, 0]), "brake_pedal"),
        (dict(end_time_s=0.0), "end_time_s"),
        (dict(stop_speed_m_s=-1.0), "stop_speed_m_s"),
        (dict(brake_release_time_s=99.0), "brake_release_time_s"),
    ],
)
def test_scenario_validation(kwargs, field):
    args = dict(
        name="x",
        time_s=[0, 1, 2, 3],
        accelerator_pedal=[0, 0, 1, 1],
        brake_pedal=[1, 1, 0, 0],
        end_time_s=3.0,
        stop_speed_m_s=None,
        brake_release_time_s=1.0,
    )
    args.update(kwargs)
    with pytest.raises(InputError) as err:
        Scenario(**args)
    assert err.value.field == field and err.value.source == "scenario x"


def test_brake_release_time():
    assert brake_release_time([0, 5, 5.05, 10], [1, 1, 0, 0]) == 5.0
    assert brake_release_time([0, 1, 2, 3, 4], [0.5, 0.8, 0.4, 0.0, 0.0]) == 1.0  # start of the last fall
    assert brake_release_time([0, 1, 2], [0, 0, 0]) == 0.0  # never applied
    assert brake_release_time([0, 1, 2], [1, 1, 1]) == 2.0  # never released
    # applied, released, applied again: the first release counts
    assert brake_release_time([0, 1, 2, 3, 4], [1, 0, 0, 1, 0]) == 0.0


# ---------------------------------------------------------------------------------------------
# scenario files


def _scenario_frame() -> pd.DataFrame:
    t = np.round(np.arange(0, 8.0001, 0.01), 6)
    brake = np.interp(t, [0, 3, 3.2, 8], [1, 1, 0, 0])
    acc = np.interp(t, [0, 3, 3.2, 8], [0, 0, 0.8, 0.8])
    return pd.DataFrame({"time_s": t, "accelerator_pedal": acc, "brake_pedal": brake})


def test_read_scenario_csv(tmp_path):
    path = tmp_path / "take_off.csv"
    df = _scenario_frame()
    df.to_csv(path, index=False)
    s = read_scenario(path)
    assert s.name == "take_off" and s.source == str(path)
    np.testing.assert_allclose(s.time_s, df.time_s)
    np.testing.assert_allclose(s.accelerator_pedal, df.accelerator_pedal)
    assert s.end_time_s == 8.0 and s.stop_speed_m_s is None
    assert s.brake_release_time_s == pytest.approx(3.0)
    assert read_scenario(path, stop_speed_m_s=20.0, end_time_s=6.0).end_time_s == 6.0
    shifted = df.assign(time_s=df.time_s + 100.0)
    shifted.to_csv(path, index=False)
    s = read_scenario(path)  # the first sample becomes time 0
    assert s.time_s[0] == 0.0 and s.end_time_s == pytest.approx(8.0) and s.brake_release_time_s == pytest.approx(3.0)


def test_read_scenario_percent_ms_and_parquet(tmp_path):
    df = _scenario_frame()
    other = pd.DataFrame(
        {
            "time_ms": df.time_s * 1000,
            "accelerator_pedal_percent": df.accelerator_pedal * 100,
            "brake_pedal_percent": df.brake_pedal * 100,
            "engine_speed_rpm": 800.0,
        }
    )
    for suffix in (".csv", ".parquet"):
        path = tmp_path / f"scen{suffix}"
        (other.to_csv(path, index=False) if suffix == ".csv" else other.to_parquet(path))
        s = read_scenario(path)
        np.testing.assert_allclose(s.time_s, df.time_s, atol=1e-12)
        np.testing.assert_allclose(s.accelerator_pedal, df.accelerator_pedal, atol=1e-12)
        np.testing.assert_allclose(s.brake_pedal, df.brake_pedal, atol=1e-12)


def _bad(case: str) -> pd.DataFrame:
    df = _scenario_frame()
    if case == "missing":
        return df.drop(columns="brake_pedal")
    if case == "nan":
        df.loc[12, "accelerator_pedal"] = np.nan
    elif case == "backwards":
        df.loc[40, "time_s"] = df.loc[38, "time_s"]
    elif case == "above one":
        df.loc[500, "accelerator_pedal"] = 1.2
    elif case == "negative":
        df.loc[7, "brake_pedal"] = -0.1
    elif case == "text":
        df["brake_pedal"] = df["brake_pedal"].astype(object)
        df.loc[3, "brake_pedal"] = "on"
    elif case == "one row":
        return df.iloc[:1]
    return df


SCENARIO_CASES = {
    "missing": ["brake_pedal", "missing", "brake_pedal_percent"],
    "nan": ["accelerator_pedal", "NaN", "row 13"],
    "backwards": ["time_s", "row 41", "strictly increasing"],
    "above one": ["accelerator_pedal", "1.2", "row 501", "from 0 to 1"],
    "negative": ["brake_pedal", "-0.1", "row 8"],
    "text": ["brake_pedal", "'on'", "numbers only"],
    "one row": ["time_s", "1 rows", "at least 2"],
}


@pytest.mark.parametrize("case", sorted(SCENARIO_CASES))
def test_read_scenario_bad_files(tmp_path, case):
    path = tmp_path / "bad.csv"
    _bad(case).to_csv(path, index=False)
    with pytest.raises(InputError) as err:
        read_scenario(path)
    msg = str(err.value)
    assert msg.startswith(str(path)), msg
    for w in SCENARIO_CASES[case]:
        assert w in msg, (w, msg)


def test_read_scenario_percent_out_of_range_and_bad_paths(tmp_path):
    df = _scenario_frame()
    pct = pd.DataFrame(
        {"time_s": df.time_s, "accelerator_pedal_percent": df.accelerator_pedal * 100, "brake_pedal": df.brake_pedal}
    )
    pct.loc[100, "accelerator_pedal_percent"] = 120.0
    path = tmp_path / "pct.csv"
    pct.to_csv(path, index=False)
    with pytest.raises(InputError, match="accelerator_pedal_percent.*120.*from 0 to 100"):
        read_scenario(path)
    with pytest.raises(InputError, match="extension"):
        read_scenario(tmp_path / "scen.txt")
    with pytest.raises(InputError, match="not found"):
        read_scenario(tmp_path / "none.csv")
    with pytest.raises(InputError, match="--scenario"):
        scenario_from_option(str(tmp_path / "none.csv"))
    assert scenario_from_option("flip-flop").name == "flip-flop"
    assert scenario_from_option("part-pedal").name == "part-pedal"


# ---------------------------------------------------------------------------------------------
# summary metrics on synthetic arrays


def test_time_to_speed_constant_acceleration():
    t = np.arange(0, 20.0001, 0.01)
    release, a = 5.0, 4.0
    v = np.maximum(0.0, a * (t - release))
    assert time_to_speed(t, v, 100 / 3.6, release) == pytest.approx(100 / 3.6 / a, abs=1e-9)
    assert time_to_speed(t, v, 50 / 3.6, release) == pytest.approx(50 / 3.6 / a, abs=1e-9)
    assert math.isnan(time_to_speed(t, v, 100.0, release))  # never reached
    # coarse samples: linear interpolation between them
    assert time_to_speed([0, 5, 6, 7], [0, 0, 10, 30], 20.0, 5.0) == pytest.approx(1.5)
    # already above the target at the start
    assert time_to_speed([0, 1, 2], [30, 30, 30], 20.0, 0.5) == 0.0


def test_peak_and_window_metrics():
    t = np.arange(0, 10.0001, 0.001)
    release = 5.0
    accel = np.where(t < release, 0.0, 6.0 * (t - release))  # ramp 6 m/s³ after release
    accel = np.minimum(accel, 5.0)
    assert peak_value(t, accel, release) == pytest.approx(5.0)
    # mean of 6 τ over the first 0.5 s (τ up to 0.5 s: 3 m/s² max, below the 5 m/s² cap) = 1.5
    assert window_mean(t, accel, release, 0.5) == pytest.approx(1.5, abs=1e-9)
    # a V-shaped effective TR with its minimum between samples: edges and samples
    t2 = np.array([4.0, 5.0, 5.2, 5.45, 5.7, 6.0])
    etr = np.array([2.1, 2.1, 1.6, 1.4, 1.8, 2.0])
    assert window_min(t2, etr, 5.0, 0.5) == pytest.approx(1.4)
    # window edge interpolated: the window ends at 5.5 between 5.45 and 5.7
    step = np.array([2.0, 2.0, 2.0, 2.0, 1.0, 1.0])
    assert window_min(t2, step, 5.0, 0.5) == pytest.approx(2 - (0.05 / 0.25) * 1.0)
    # the run ends before the window does
    assert math.isnan(window_mean(t2, etr, 5.8, 0.5)) and math.isnan(window_min(t2, etr, 5.8, 0.5))
    # NaN samples ignored by the minimum
    assert window_min([0, 0.25, 0.5], [np.nan, 1.0, 2.0], 0.0, 0.5) == 1.0


def test_launch_summary_columns_and_values():
    t = np.arange(0, 15.0001, 0.01)
    frames = {}
    for name, a in (("table", 5.0), ("quasi-dynamic", 4.0)):
        accel = np.where(t < 5.0, 0.0, a)
        v = np.maximum(0.0, a * (t - 5.0))
        frames[name] = pd.DataFrame(
            {
                "time_s": t,
                "vehicle_speed_m_s": v,
                "vehicle_accel_m_s2": accel,
                "effective_torque_ratio": np.where(t < 5.0, 2.14, 2.14 - a / 10),
            }
        )
    s = launch_summary(frames, 5.0)
    assert list(s.columns) == list(SUMMARY_COLUMNS) and list(s.model) == ["table", "quasi-dynamic"]
    row = s.set_index("model").loc["quasi-dynamic"]
    assert row.time_0_100_km_h_s == pytest.approx(100 / 3.6 / 4.0, abs=1e-9)
    assert row.time_0_50_km_h_s == pytest.approx(50 / 3.6 / 4.0, abs=1e-9)
    assert row.peak_accel_m_s2 == 4.0 and row.mean_accel_first_0_5_s_m_s2 == pytest.approx(4.0)
    assert row.min_effective_torque_ratio_first_0_5_s == pytest.approx(1.74)
    assert math.isnan(launch_summary({"x": frames["table"].iloc[:700]}, 5.0).time_0_100_km_h_s[0])


# ---------------------------------------------------------------------------------------------
# the core contract, with a stand-in for _core.launch_runs


def fake_launch_runs(models, vehicle, scenario, options, threads):
    """Results like the core's (``_core.LaunchRun``): a first-order acceleration whose lag grows with
    the shape effect; ``fail_input`` in a model spec is the (source, field) of an input error;
    ``fail_solver`` in a model spec, or shape effects above 0.5 m² in all in a sweep (a scenario
    shorter than 10 s: the bundled quasi-dynamic model's own 0.4 + 0.3 m² runs), a solver failure."""
    assert {"engine", "gearbox", "lockup", "driveline", "tyres", "body", "brake"} <= set(vehicle.to_dict())
    t = np.round(np.arange(0.0, scenario["end_time_s"] + 1e-9, 0.01), 9)
    acc_pedal = np.interp(t, scenario["time_s"], scenario["accelerator_pedal"])
    brake = np.interp(t, scenario["time_s"], scenario["brake_pedal"])
    release = t[np.argmax(brake < 1.0)]
    out = []
    for m in models:
        shape = sum(abs(s) for s in m.get("shape_effect_m2", []))
        if m.get("fail_solver") or (shape > 0.5 and scenario["end_time_s"] < 10.0):
            out.append(_core.LaunchRun(error=_core.RunError("solver", "step size too small at t = 5.12 s")))
            continue
        if m.get("fail_input"):
            source, fld = m["fail_input"]
            out.append(_core.LaunchRun(error=_core.RunError("input", "bad", source, fld, "-1", "a positive value")))
            continue
        tau = 0.05 + (0.1 if m["kind"] != "table" else 0.0) + shape
        a = np.where(t < release, 0.0, 6.0 * acc_pedal * (1 - np.exp(-(t - release) / tau)))
        v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t))])
        stop = scenario["stop_speed_m_s"]
        n = int(np.argmax(v >= stop)) + 1 if stop is not None and (v >= stop).any() else len(t)
        etr = np.where(t < release, 2.14, 2.14 - (0.3 + shape) * np.exp(-(t - release) / 0.3))
        cols = {
            "time_s": t,
            "vehicle_speed_m_s": v,
            "vehicle_accel_m_s2": a,
            "pump_speed_rad_s": 80 + 200 * acc_pedal,
            "turbine_speed_rad_s": v * 50,
            "speed_ratio": np.clip(v * 50 / (80 + 200 * acc_pedal), 0, 1),
            "torque_ratio": etr + 0.05,
            "effective_torque_ratio": etr,
            "gear": np.where(v < 12.5, 1.0, 2.0),
            "lockup_state": np.zeros_like(t),
            "engine_torque_nm": 100 + 300 * acc_pedal,
            "pump_torque_nm": 90 + 250 * acc_pedal,
            "turbine_torque_nm": 200 + 300 * acc_pedal,
            "stator_speed_rad_s": np.full_like(t, np.nan),
        }
        cols = {k: np.asarray(c)[:n] for k, c in cols.items()}
        events = [_core.LaunchEvent(float(t[np.argmax(v >= 12.5)]), "upshift", 2)] if (v[:n] >= 12.5).any() else []
        out.append(_core.LaunchRun(cols, events))
    return out


@pytest.fixture
def fake_core(monkeypatch):
    monkeypatch.setattr(tcsim._core, "launch_runs", fake_launch_runs, raising=False)
    return fake_launch_runs


@pytest.fixture(scope="module")
def vehicle():
    return load_vehicle()


def test_run_launch_unpacks_columns_and_events(fake_core, vehicle):
    models = select_models(vehicle, [])
    assert [m.name for m in models] == ["table", "hrovat-tobler", "quasi-dynamic"]
    runs = run_launch(vehicle, flip_flop(), models)
    assert list(runs) == ["table", "hrovat-tobler", "quasi-dynamic"]
    for run in runs.values():
        f = run.frame
        assert set(LAUNCH_COLUMNS) <= set(f.columns) and "stator_speed_rad_s" not in f.columns  # all-NaN dropped
        assert f.vehicle_speed_m_s.iloc[-1] >= 100 / 3.6 and run.events[0][1] == "upshift"
    ev = events_table(runs)
    assert list(ev.columns) == list(EVENT_COLUMNS) and len(ev) == 3 and ev.detail[0] == "2"


def test_run_launch_errors(fake_core, vehicle, monkeypatch):
    table = dynamic_model(vehicle.converter, "table")
    scen = flip_flop()
    bad_vehicle = type(table)("table", {**table.spec, "fail_input": ("vehicle", "engine.inertia_kg_m2")}, table.source)
    with pytest.raises(InputError) as err:
        run_launch(vehicle, scen, [bad_vehicle])
    assert err.value.source == vehicle.path and err.value.field == "engine.inertia_kg_m2" and err.value.value == -1.0
    bad_scen = type(table)("table", {**table.spec, "fail_input": ("scenario", "time_s")}, table.source)
    with pytest.raises(InputError) as err:
        run_launch(vehicle, scen, [bad_scen])
    assert err.value.source == "scenario flip-flop"
    bad_model = type(table)("table", {**table.spec, "fail_input": ("converter", "capacity_factor_nm_s2")}, table.source)
    with pytest.raises(InputError) as err:
        run_launch(vehicle, scen, [bad_model])
    assert err.value.source == table.source
    qd = dynamic_model(vehicle.converter, "quasi-dynamic")
    qd = type(qd)(qd.name, {**qd.spec, "fail_solver": True}, qd.source)
    with pytest.raises(SolverError, match="t = 5.12 s"):
        run_launch(vehicle, scen, [table, qd])
    with pytest.warns(TcsimWarning, match="left out"):
        frames = run_launch(vehicle, scen, [table, qd], labels=["a", "b"], on_error="warn")
    assert list(frames) == ["a"]

    def core_error(*args):
        raise tcsim._core.CoreInputError("bad", "[gearbox].ratios", "-1", "positive", "vehicle")

    monkeypatch.setattr(tcsim._core, "launch_runs", core_error)
    with pytest.raises(InputError) as err:
        run_launch(vehicle, scen, [table, qd])
    assert err.value.source == vehicle.path


def test_sweep_cases_use_admissible_values(vehicle):
    models = select_models(vehicle, [])
    cases = sweep_cases(models)
    qd = [(c.pump_shape_effect_m2, c.turbine_shape_effect_m2) for c in cases if c.model == "quasi-dynamic"]
    assert qd == [(v, v) for v in THESIS_VALUES_M2] + [(0.4, 0.3)]
    ht = [c for c in cases if c.model == "hrovat-tobler"]
    bound = mass_matrix_bound(models[1])
    assert len(ht) == 4 and all(bound.admissible(c.pump_shape_effect_m2, c.turbine_shape_effect_m2) for c in ht)
    assert all(c.dynamic.shape_effect_m2[:2] == (c.pump_shape_effect_m2, c.turbine_shape_effect_m2) for c in cases)
    assert not [c for c in cases if c.model == "table"]
    assert len({c.label for c in cases if c.model == "quasi-dynamic"}) == 5


def test_launch_writes_files_and_plots(fake_core, vehicle, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)  # the fake fails the (0.4, 0.3) pair
        result = launch_files(vehicle, "flip-flop", sweep=True)
    assert list(result.summary.model) == ["table", "hrovat-tobler", "quasi-dynamic"]
    s = result.summary.set_index("model")
    assert s.time_0_100_km_h_s.notna().all() and (
        s.loc["table"].mean_accel_first_0_5_s_m_s2 > s.loc["quasi-dynamic"].mean_accel_first_0_5_s_m_s2
    )
    paths = write_launch(result, tmp_path)
    names = {p.name for p in paths}
    assert {
        "summary.csv",
        "table.csv",
        "hrovat-tobler.csv",
        "quasi-dynamic.csv",
        "timeseries.csv",
        "events.csv",
        "scenario.csv",
        "shape_sweep.csv",
        "shape_sweep_summary.csv",
        "torque_speed_ratio.png",
        "effective_torque_ratio.png",
        "vehicle_accel_release.png",
        "vehicle_accel.png",
        "vehicle_speed.png",
        "speeds.png",
        "shape_sweep_quasi-dynamic_effective_torque_ratio.png",
        "shape_sweep_quasi-dynamic_vehicle_accel.png",
        "shape_sweep_hrovat-tobler_effective_torque_ratio.png",
        "shape_sweep_hrovat-tobler_vehicle_accel.png",
    } <= names
    assert all(p.exists() and p.stat().st_size > 0 for p in paths)
    summary = pd.read_csv(tmp_path / "summary.csv")
    assert list(summary.columns) == list(SUMMARY_COLUMNS)
    ts = pd.read_csv(tmp_path / "quasi-dynamic.csv")
    assert set(LAUNCH_COLUMNS) <= set(ts.columns) and ts.time_s.iloc[0] == 0.0
    sweep = pd.read_csv(tmp_path / "shape_sweep_summary.csv")
    assert (~sweep.finished).sum() == 1  # the pair the fake refuses
    assert pd.read_csv(tmp_path / "timeseries.csv").model.unique().tolist() == list(result.frames)


def test_cli_launch_with_the_stand_in(fake_core, tmp_path, capsys):
    out = tmp_path / "out"
    assert (
        tcsim.cli.main(
            ["launch", "--out", str(out), "--scenario", "part-pedal", "--model", "table", "--model", "quasi-dynamic"]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "part-pedal" in printed and "quasi-dynamic" in printed
    s = pd.read_csv(out / "summary.csv")
    assert list(s.model) == ["table", "quasi-dynamic"] and s.time_0_100_km_h_s.isna().all()  # stops at 50 km/h
    assert s.time_0_50_km_h_s.notna().all()


@pytest.mark.parametrize(
    "args, words",
    [
        (["--model", "nonsense"], ["--model", "nonsense"]),
        (["--scenario", "moon-landing"], ["--scenario", "moon-landing", "flip-flop"]),
        (["--model", "table", "--sweep-shape-effects"], ["--sweep-shape-effects", "hrovat-tobler"]),
    ],
)
def test_cli_bad_options_exit_2(fake_core, tmp_path, capsys, args, words):
    out = tmp_path / "out"
    assert tcsim.cli.main(["launch", "--out", str(out), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not out.exists()


def test_cli_bad_scenario_file_exit_2(fake_core, tmp_path, capsys):
    path = tmp_path / "scen.csv"
    _bad("above one").to_csv(path, index=False)
    out = tmp_path / "out"
    assert tcsim.cli.main(["launch", "--out", str(out), "--scenario", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "accelerator_pedal" in err and not out.exists()


def test_cli_solver_failure_exit_1_nothing_written(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(
        tcsim._core,
        "launch_runs",
        lambda *a: [_core.LaunchRun(error=_core.RunError("solver", "step size too small at t = 5.3 s"))] * 3,
        raising=False,
    )
    out = tmp_path / "out"
    assert tcsim.cli.main(["launch", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "SolverError" in err and "t = 5.3 s" in err and not out.exists()


# ---------------------------------------------------------------------------------------------
# the take-off on the core's vehicle plant


@pytest.fixture(scope="module")
def flip_flop_runs():
    veh = load_vehicle()
    return {name: run.frame for name, run in run_launch(veh, flip_flop(), select_models(veh, [])).items()}


def test_vehicle_stands_still_while_braked(flip_flop_runs):
    for name, f in flip_flop_runs.items():
        braked = f[f.time_s < 5.0]
        assert braked.vehicle_speed_m_s.abs().max() < 1e-3, name
        assert (f.gear[f.time_s < 5.0] == 1).all()


def test_stall_phase_table_and_quasi_dynamic_agree_then_dynamic_models_start_lower(flip_flop_runs):
    table, qd = flip_flop_runs["table"], flip_flop_runs["quasi-dynamic"]
    t = np.linspace(1.0, 4.9, 40)
    np.testing.assert_allclose(
        np.interp(t, qd.time_s, qd.torque_ratio), np.interp(t, table.time_s, table.torque_ratio), rtol=1e-4
    )
    s = launch_summary(flip_flop_runs, 5.0).set_index("model")
    for dyn in ("hrovat-tobler", "quasi-dynamic"):
        assert s.loc[dyn].mean_accel_first_0_5_s_m_s2 < s.loc["table"].mean_accel_first_0_5_s_m_s2
    assert s.time_0_100_km_h_s.notna().all()


def test_sweep_scenario_ends_after_the_release():
    s = sweep_scenario(flip_flop())
    assert s.end_time_s == 5.0 + SWEEP_SPAN_S and s.brake_release_time_s == 5.0
    np.testing.assert_array_equal(s.accelerator_pedal, flip_flop().accelerator_pedal)
    assert sweep_scenario(flip_flop(hold_s=1.0, end_time_s=2.0)).end_time_s == 2.0


def test_larger_shape_effects_lower_the_initial_acceleration(tmp_path):
    """Thesis §4.1, figs 4.3–4.6: a larger S deepens the effective-TR dip and lowers the acceleration."""
    result = launch_files(None, "flip-flop", ["table", "quasi-dynamic", "hrovat-tobler"], sweep=True)
    s = result.sweep_summary
    assert s.finished.all()
    for model in ("quasi-dynamic", "hrovat-tobler"):
        equal = s[(s.model == model) & (s.pump_shape_effect_m2 == s.turbine_shape_effect_m2)]
        equal = equal.sort_values("pump_shape_effect_m2")
        assert (np.diff(equal.mean_accel_first_0_5_s_m_s2) < 0).all(), equal
        assert (np.diff(equal.min_effective_torque_ratio_first_0_5_s) < 0).all(), equal
    assert result.sweep.time_s.max() <= 5.0 + SWEEP_SPAN_S + 1e-9
    names = {p.name for p in write_launch(result, tmp_path)}
    assert "shape_sweep_quasi-dynamic_vehicle_accel.png" in names


def test_cli_launch_end_to_end(cli, tmp_path):
    out = tmp_path / "out"
    r = cli("launch", "--out", out)
    assert r.code == 0, (r.stdout, r.stderr)
    assert "Traceback" not in r.stderr and "flip-flop" in r.stdout
    names = {p.name for p in out.iterdir()}
    assert {
        "summary.csv",
        "table.csv",
        "hrovat-tobler.csv",
        "quasi-dynamic.csv",
        "timeseries.csv",
        "events.csv",
        "torque_speed_ratio.png",
        "vehicle_accel_release.png",
        "vehicle_accel.png",
    } <= names
    s = pd.read_csv(out / "summary.csv")
    assert list(s.model) == ["table", "hrovat-tobler", "quasi-dynamic"]
    assert s.time_0_100_km_h_s.between(3.0, 15.0).all() and (s.time_0_50_km_h_s < s.time_0_100_km_h_s).all()
    events = pd.read_csv(out / "events.csv")
    assert {"upshift-start", "shift-end", "lockup-engage"} <= set(events.kind)


def test_cli_launch_scenario_file(cli, tmp_path):
    path = tmp_path / "creep.csv"
    t = np.round(np.arange(0, 6.0001, 0.05), 6)
    pd.DataFrame(
        {"time_s": t, "accelerator_pedal": 0.0, "brake_pedal": np.interp(t, [0, 1, 1.5, 6], [1, 1, 0, 0])}
    ).to_csv(path, index=False)
    out = tmp_path / "out"
    r = cli("launch", "--out", out, "--scenario", path, "--model", "table")
    assert r.code == 0, (r.stdout, r.stderr)
    f = pd.read_csv(out / "table.csv")
    assert f.time_s.iloc[-1] == pytest.approx(6.0) and f.vehicle_speed_m_s.iloc[-1] > 0.1  # idle creep
    assert f.vehicle_speed_m_s[f.time_s < 1.0].abs().max() < 1e-3


def test_models_rejoin_in_torque_ratio(flip_flop_runs):
    """Thesis §3.2.2: after the dip the three models come within 5 % in TR within about 1 s."""
    release = 5.0
    for dt in (1.0, 1.2, 1.5):
        tr = [np.interp(release + dt, f.time_s, f.effective_torque_ratio) for f in flip_flop_runs.values()]
        assert (max(tr) - min(tr)) / abs(tr[0]) < 0.05, (dt, tr)


def test_energy_balances(flip_flop_runs):
    """The engine's work is the kinetic and spring energy plus every modelled loss (1e-3)."""
    for name, f in flip_flop_runs.items():
        t = f.time_s.to_numpy()
        engine = np.trapezoid(f.engine_power_w, t)
        losses = np.trapezoid(f.vehicle_loss_power_w, t) + f.event_energy_loss_j.iloc[-1]
        stored = f.vehicle_stored_energy_j.iloc[-1] - f.vehicle_stored_energy_j.iloc[0]
        assert abs(engine - stored - losses) < 1e-3 * engine, name


def test_part_pedal_launch_is_gentler(flip_flop_runs):
    veh = load_vehicle()
    part = run_launch(veh, part_pedal(), select_models(veh, ["table"]))["table"].frame
    full = flip_flop_runs["table"]
    assert part.vehicle_speed_m_s[part.time_s < 5.0].abs().max() == 0.0

    def window(f):
        return f[(f.time_s > 5.0) & (f.time_s <= 6.0)].vehicle_accel_m_s2.mean()

    assert 0.0 < window(part) < window(full)


def test_logged_engine_torque_is_replayed(tmp_path, cli, flip_flop_runs):
    """Thesis §3.5.2.2: the engine model replaced by a logged engine torque. Replaying the engine
    torque of the table model's own run reproduces its launch."""
    f = flip_flop_runs["table"]
    sc = flip_flop()
    path = tmp_path / "logged.csv"
    pedal, brake = sc.pedals_at(f.time_s)
    pd.DataFrame(
        {"time_s": f.time_s, "accelerator_pedal": pedal, "brake_pedal": brake, "engine_torque_nm": f.engine_torque_nm}
    ).to_csv(path, index=False)
    out = tmp_path / "out"
    r = cli("launch", "--out", out, "--scenario", path, "--model", "table")
    assert r.code == 0, r.stderr
    g = pd.read_csv(out / "table.csv")
    assert g.engine_torque_nm.to_numpy() == pytest.approx(np.interp(g.time_s, f.time_s, f.engine_torque_nm), abs=1e-9)
    v = np.interp(f.time_s, g.time_s, g.vehicle_speed_m_s)
    assert np.max(np.abs(v - f.vehicle_speed_m_s)) < 0.05
