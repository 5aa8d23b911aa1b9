"""Issue 12, item 4: the table model's first-order lag ``[characteristic] lag_time_constant_s``
(docs/lag.md): the step response of the pump torque, passivity and the energy identity over runs
with reversals, no lag key = today's model, the launch, the FMU and the file key."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
import tomllib
import warnings
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tcsim.errors import TcsimWarning
from tcsim.models.converter import Converter, load_converter, parse_converter
from tcsim.models.dynamic import dynamic_model
from tcsim.models.vehicle import read_vehicle_text
from tcsim.simulation.launch import run_launch
from tcsim.simulation.scenarios import Scenario
from tcsim.transient import Speeds, isolated_takeoff, simulate

#: The lag time constant of the tests, s.
T_C = 0.05
#: When the steps happen, s, and how long they take (a ramp 1/500 of t_c: its own effect on the
#: response at t_c is below 1e-5 of the step).
T_STEP, RAMP = 0.1, 1e-4


def lagged(tc: float | None = T_C, name: str = "li-sunden-2016") -> Converter:
    return dataclasses.replace(load_converter(name), lag_time_constant_s=tc)


def step_drive(wp: tuple[float, float], wt: tuple[float, float]) -> Speeds:
    t = np.array([0.0, T_STEP, T_STEP + RAMP, T_STEP + 10 * T_C])
    return Speeds(t, np.array([wp[0], wp[0], wp[1], wp[1]]), np.array([wt[0], wt[0], wt[1], wt[1]]))


STEPS = {
    "turbine-speed-step": ((200.0, 200.0), (20.0, 170.0)),
    "pump-speed-step": ((150.0, 220.0), (80.0, 80.0)),
    "turbine-speed-drop": ((200.0, 200.0), (150.0, 20.0)),
}


@pytest.mark.parametrize("case", STEPS)
def test_the_pump_torque_step_response_is_first_order_with_the_time_constant(case):
    """Both speeds given (drive b), a step in one of them: the transferred pump torque follows
    ``T_new + (T_old − T_new)·e^(−t/t_c)`` from the middle of the ramp: 63.2 % of the step at t_c
    to 1 % of the step, and a log-linear fit of the decay gives t_c to 1 %."""
    wp, wt = STEPS[case]
    t = np.concatenate([np.linspace(0.0, T_STEP, 11), T_STEP + RAMP + np.linspace(0.0, 8 * T_C, 801)])
    f = simulate(lagged(), step_drive(wp, wt), model="table", times_s=t).frame()
    plain = simulate(lagged(None), step_drive(wp, wt), model="table", times_s=t).frame()
    tp = f["pump_transferred_torque_nm"].to_numpy()
    old, new = plain["pump_transferred_torque_nm"].iloc[0], plain["pump_transferred_torque_nm"].iloc[-1]
    assert abs(new - old) > 20.0  # a real step
    assert tp[0] == pytest.approx(old, rel=1e-12)  # the lag starts at its steady value
    tau = f["time_s"].to_numpy() - (T_STEP + RAMP / 2)
    at_tc = np.interp(T_C, tau, (tp - old) / (new - old))
    assert abs(at_tc - (1.0 - math.exp(-1.0))) < 0.01, at_tc
    window = (tau > 0.2 * T_C) & (tau < 3.0 * T_C)
    slope = np.polyfit(tau[window], np.log(np.abs(tp[window] - new)), 1)[0]
    assert abs(-1.0 / slope - T_C) < 0.01 * T_C, -1.0 / slope
    # the Simscape form: the delivered torque is the table's TR at the current speeds times the
    # lagged pump torque (the passivity rule is inactive in drive)
    tr = plain["turbine_transferred_torque_nm"] / plain["pump_transferred_torque_nm"]
    assert np.allclose(f["turbine_transferred_torque_nm"], tr * f["pump_transferred_torque_nm"], rtol=1e-12)
    # without the lag the torque steps at once
    assert plain["pump_transferred_torque_nm"].iloc[11] == pytest.approx(new, rel=1e-12)


def test_no_lag_key_is_the_model_without_lag_exactly():
    """A file without the key runs today's model, bit for bit (the golden tests pin today's
    numbers); the spec carries the key only when it is given."""
    plain = load_converter("li-sunden-2016")
    assert plain.lag_time_constant_s is None
    assert "lag_time_constant_s" not in dynamic_model(plain, "table").spec
    assert dynamic_model(lagged(), "table").spec["lag_time_constant_s"] == T_C
    drive = step_drive((200.0, 200.0), (60.0, 130.0))
    a = simulate(plain, drive, model="table").frame()
    b = simulate(dataclasses.replace(plain, name="copy"), drive, model="table").frame()
    assert a.equals(b)
    # the flow columns of the table model stay empty with the lag: its state is no flow
    f = simulate(lagged(), drive, model="table").frame()
    flows = ("flow_m3_s", "flow_rate_of_change_m3_s2", "flow_direction")
    assert all(np.isnan(simulate(lagged(), drive, model="table").columns[c]).all() for c in flows)
    assert not any(c in f.columns for c in flows)
    assert not f["pump_torque_nm"].equals(a["pump_torque_nm"])


@pytest.mark.parametrize("tc", [0.02, 0.3])
def test_the_isolated_tip_out_with_the_lag_never_creates_energy(tc):
    """The isolated take-off with its tip-out visits every quadrant (overrun, a reversed pump):
    with the lag the converter never delivers power (the passivity rule acts where the lagged torque
    keeps its sign through a reversal), and the energy identity closes to 1e-6 of the energy
    through the pump with the lag storing nothing."""
    t = np.linspace(0.0, 10.0, 100_001)
    with pytest.warns(TcsimWarning, match='overrun = "mirror"'):
        f = simulate(lagged(tc), isolated_takeoff(tip_out=True), model="table", times_s=t).frame()
    assert f["speed_ratio"].max() > 3.0 and f["pump_speed_rad_s"].min() < -50.0  # every quadrant visited
    absorbed = (
        f["pump_transferred_torque_nm"] * f["pump_speed_rad_s"]
        - f["turbine_transferred_torque_nm"] * f["turbine_speed_rad_s"]
    )
    scale = (f["pump_torque_nm"].abs() * f["pump_speed_rad_s"].abs()).max()
    assert absorbed.min() >= -1e-12 * scale
    assert np.allclose(absorbed, f["fluid_loss_power_w"], rtol=0.0, atol=1e-12 * scale)
    loss = np.trapezoid(f["fluid_loss_power_w"], f["time_s"])
    net = np.trapezoid(f["converter_input_power_w"], f["time_s"]) - loss
    stored = f["stored_energy_j"].iloc[-1] - f["stored_energy_j"].iloc[0]
    through = np.trapezoid((f["pump_torque_nm"] * f["pump_speed_rad_s"]).abs(), f["time_s"])
    assert abs(stored - net) < 1e-6 * through, (stored, net, through)
    kinetic = 0.5 * (0.109 * f["pump_speed_rad_s"] ** 2 + 0.056 * f["turbine_speed_rad_s"] ** 2)
    assert np.allclose(f["stored_energy_j"], kinetic, rtol=1e-12)


def test_a_reversing_pump_under_the_lag_is_held_passive_by_the_rule():
    """Both speeds given, the pump reversed faster than t_c (the steady pump torque changes sign,
    the lagged one keeps its sign): the candidate pair would deliver power, the rule projects it
    onto zero power; the absorbed power is never negative."""
    t = np.linspace(0.0, 0.6, 601)
    wp = np.where(t < 0.1, 200.0, np.where(t < 0.15, 200.0 - (t - 0.1) * 6000.0, -100.0))
    drive = Speeds(t, wp, np.full_like(t, 50.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)
        f = simulate(lagged(0.2), drive, model="table").frame()
    p_tr = f["pump_transferred_torque_nm"]
    absorbed = p_tr * f["pump_speed_rad_s"] - f["turbine_transferred_torque_nm"] * f["turbine_speed_rad_s"]
    scale = (p_tr.abs() * f["pump_speed_rad_s"].abs()).max()
    assert absorbed.min() >= -1e-12 * scale
    rule = (f["pump_speed_rad_s"] < 0) & (absorbed.abs() <= 1e-9 * scale)
    assert rule.sum() > 10  # the rule acted (zero power while the lag catches up)
    assert absorbed.iloc[-1] > 0  # and let go once the lagged torque turned


SPEEDS = st.integers(-300, 300).map(float)


@settings(max_examples=25, deadline=None)
@given(
    tc=st.sampled_from([0.01, 0.05, 0.3]),
    # whole rad/s: subnormal speeds (1e-311 rad/s) overflow the speed ratio with or without the lag
    knots=st.lists(st.tuples(SPEEDS, SPEEDS), min_size=3, max_size=8),
)
def test_random_speed_histories_with_reversals_never_get_power_from_the_lag(tc, knots):
    """Both speeds given, random piecewise-linear histories through every quadrant (reversals of
    either shaft faster or slower than t_c): the lagged converter absorbs power at every sample."""
    t = np.linspace(0.0, 0.1 * (len(knots) - 1), len(knots))
    wp, wt = (np.array(v) for v in zip(*knots, strict=True))
    times = np.linspace(t[0], t[-1], 40 * len(knots))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)
        f = simulate(lagged(tc), Speeds(t, wp, wt), model="table", times_s=times).frame()
    p_tr, t_tr = f["pump_transferred_torque_nm"], f["turbine_transferred_torque_nm"]
    absorbed = p_tr * f["pump_speed_rad_s"] - t_tr * f["turbine_speed_rad_s"]
    scale = ((p_tr.abs() + t_tr.abs()) * (f["pump_speed_rad_s"].abs() + f["turbine_speed_rad_s"].abs())).max()
    assert absorbed.min() >= -1e-12 * scale, absorbed.min()
    assert np.allclose(f["fluid_loss_power_w"], absorbed, rtol=0.0, atol=1e-12 * scale)


def _vehicle():
    text = (resources.files("tcsim") / "data" / "vehicles" / "midsize-awd-8at.toml").read_text(encoding="utf-8")
    return read_vehicle_text(text, "midsize-awd-8at.toml")


def test_a_launch_with_the_lag_runs_and_differs_from_without():
    vehicle = _vehicle()
    pedal = Scenario("wot", np.array([0.0, 8.0]), np.array([1.0, 1.0]), np.zeros(2), 8.0)
    conv = dataclasses.replace(vehicle.converter, lag_time_constant_s=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)
        runs = run_launch(vehicle, pedal, [dynamic_model(conv, "table")])
        plain = run_launch(vehicle, pedal, [dynamic_model(vehicle.converter, "table")])
    (f,), (g,) = (r.frame for r in runs.values()), (r.frame for r in plain.values())
    assert f["vehicle_speed_m_s"].iloc[-1] > 10.0
    diff = (f["pump_speed_rad_s"] - g["pump_speed_rad_s"]).abs().max()
    assert diff > 1.0, diff


def _launch_cli(folder: Path, lag: str) -> pd.DataFrame:
    """``tcsim launch`` of the bundled vehicle with its converter file given the ``lag`` line."""
    data = resources.files("tcsim") / "data"
    conv = (data / "converters" / "li-sunden-2016-fitted.toml").read_text(encoding="utf-8")
    (folder / "conv.toml").write_text(conv.replace("[characteristic]\n", f"[characteristic]\n{lag}\n", 1))
    vehicle = (data / "vehicles" / "midsize-awd-8at.toml").read_text(encoding="utf-8")
    assert 'converter = "li-sunden-2016-fitted"' in vehicle
    (folder / "car.toml").write_text(vehicle.replace('converter = "li-sunden-2016-fitted"', 'converter = "conv.toml"'))
    args = [sys.executable, "-m", "tcsim", "launch", "car.toml", "--model", "table", "--out", "out"]
    p = subprocess.run(args, cwd=folder, capture_output=True, text=True, timeout=300)  # hang guard only
    assert p.returncode == 0, p.stderr
    return pd.read_csv(folder / "out" / "table.csv")


def test_the_launch_command_runs_the_lag(tmp_path):
    """``tcsim launch`` with a converter file that has the key: the run differs from the same file
    without it (the vehicle uses the table model's lag)."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    with_lag, without = _launch_cli(tmp_path / "a", "lag_time_constant_s = 0.1"), _launch_cli(tmp_path / "b", "")
    # the rows differ in number (events are rows): compare at the run without the lag's times
    pump = np.interp(without["time_s"], with_lag["time_s"], with_lag["pump_speed_rad_s"])
    diff = np.abs(pump - without["pump_speed_rad_s"]).max()
    assert diff > 1.0, diff
    assert with_lag["vehicle_speed_m_s"].iloc[-1] > 10.0


def test_the_lag_key_round_trips_through_the_file():
    conv = lagged(0.08)
    back = parse_converter(conv.to_toml_dict(), "again.toml")
    assert back.lag_time_constant_s == 0.08
    doc = tomllib.loads(
        (resources.files("tcsim") / "data" / "converters" / "li-sunden-2016.toml").read_text(encoding="utf-8")
    )
    doc["characteristic"]["lag_time_constant_s"] = 0.08
    parsed = parse_converter(doc, "conv.toml")
    assert parsed.lag_time_constant_s == 0.08
    # the quasi-dynamic and Hrovat & Tobler models have their own dynamics and ignore the key
    assert "lag_time_constant_s" not in dynamic_model(parsed, "quasi-dynamic").spec
    assert "lag_time_constant_s" not in dynamic_model(parsed, "hrovat-tobler").spec


@pytest.mark.fmu
def test_the_fmu_carries_the_lag(fmu_library, tmp_path, monkeypatch):
    """Co-simulation of the exported FMU with the lag: the pump torque step response (turbine
    speed step, pump speed given) has the time constant, as in the engine."""
    fmpy = pytest.importorskip("fmpy")
    from tcsim.io import fmu as tfmu  # noqa: PLC0415  after the importorskip of fmpy above

    monkeypatch.setenv(tfmu.LIBRARY_ENV, str(fmu_library))
    path = tfmu.export_fmu(lagged(), "table", tmp_path / "lag.fmu", causality="speeds")
    inp = np.array(
        [(0.0, 200.0, 60.0), (T_STEP, 200.0, 60.0), (T_STEP + RAMP, 200.0, 130.0), (0.6, 200.0, 130.0)],
        dtype=[("time", float), ("pump_speed_rad_s", float), ("turbine_speed_rad_s", float)],
    )
    res = fmpy.simulate_fmu(str(path), fmi_type="CoSimulation", input=inp, output_interval=1e-3, stop_time=0.6)
    plain = simulate(lagged(None), step_drive((200.0, 200.0), (60.0, 130.0)), model="table").frame()
    old, new = plain["pump_transferred_torque_nm"].iloc[0], plain["pump_transferred_torque_nm"].iloc[-1]
    frac = (res["pump_torque_nm"] - old) / (new - old)
    at_tc = np.interp(T_STEP + RAMP / 2 + T_C, res["time"], frac)
    assert abs(at_tc - (1.0 - math.exp(-1.0))) < 0.01, at_tc


@pytest.mark.fmu
def test_the_fmu_runs_the_lag_in_model_exchange(fmu_library, tmp_path, monkeypatch):
    """Model Exchange declares the lag state of a lagged table model (``lagged_pump_torque_nm``, a
    continuous state with ``der(lagged_pump_torque_nm)``): FMPy's CVode integrates it. The
    take-off under the ``torques`` causality (a pump torque step 40 → 250 N·m at 0.1 s, given as an
    input event) follows the engine's drive (c) within 0.5 % of the range, and the pump torque step
    response of the ``speeds`` causality has the time constant."""
    fmpy = pytest.importorskip("fmpy")
    from tcsim.io import fmu as tfmu  # noqa: PLC0415  after the importorskip of fmpy above
    from tcsim.transient import PumpTorqueLoad  # noqa: PLC0415  next to its only use

    monkeypatch.setenv(tfmu.LIBRARY_ENV, str(fmu_library))
    path = tfmu.export_fmu(lagged(), "table", tmp_path / "lag.fmu", causality="torques")
    md = fmpy.read_model_description(str(path))
    assert md.numberOfContinuousStates == 3  # pump and turbine speed, and the lag
    stop, load = 2.0, {"load_inertia_kg_m2": 1.2, "load_drag_nm_s2": 0.002}
    inp = np.array(
        [(0.0, 40.0, 10.0), (0.1, 40.0, 10.0), (0.1, 250.0, 10.0), (stop, 250.0, 10.0)],
        dtype=[("time", float), ("pump_torque_nm", float), ("load_torque_nm", float)],
    )
    res = fmpy.simulate_fmu(
        str(path),
        fmi_type="ModelExchange",
        input=inp,
        output_interval=1e-3,
        stop_time=stop,
        start_values=load,
        relative_tolerance=1e-6,
    )
    ref = simulate(
        lagged(),
        PumpTorqueLoad([0.0, 0.1, 0.1 + 1e-6, stop], [40.0, 40.0, 250.0, 250.0], load_torque_nm=10.0, **load),
        model="table",
        times_s=np.round(np.arange(0.0, stop + 1e-9, 1e-3), 6),
    )
    for col in ("pump_speed_rad_s", "turbine_speed_rad_s", "turbine_torque_nm"):
        y = np.interp(res["time"], ref["time_s"], ref[col])
        assert np.max(np.abs(res[col] - y)) < 0.005 * np.ptp(ref[col]), col
    # in drive the passivity rule does not act: the declared lag state is the torque the pump absorbs
    np.testing.assert_allclose(res["lagged_pump_torque_nm"], res["effective_pump_torque_nm"], rtol=1e-9)

    speeds = tfmu.export_fmu(lagged(), "table", tmp_path / "lag-speeds.fmu", causality="speeds")
    step = np.array(
        [(0.0, 200.0, 60.0), (T_STEP, 200.0, 60.0), (T_STEP, 200.0, 130.0), (0.6, 200.0, 130.0)],
        dtype=[("time", float), ("pump_speed_rad_s", float), ("turbine_speed_rad_s", float)],
    )
    res = fmpy.simulate_fmu(
        str(speeds), fmi_type="ModelExchange", input=step, output_interval=1e-3, stop_time=0.6, relative_tolerance=1e-6
    )
    plain = simulate(lagged(None), step_drive((200.0, 200.0), (60.0, 130.0)), model="table").frame()
    old, new = plain["pump_transferred_torque_nm"].iloc[0], plain["pump_transferred_torque_nm"].iloc[-1]
    frac = (res["pump_torque_nm"] - old) / (new - old)
    at_tc = np.interp(T_STEP + T_C, res["time"], frac)
    assert abs(at_tc - (1.0 - math.exp(-1.0))) < 0.01, at_tc
