"""The transient Python API: tiers, batch, GIL, errors. The physics is tested in the Rust core
(crates/tcsim-core/tests/transient.rs); here, what the Python layer adds."""

from __future__ import annotations

import threading
import time
from dataclasses import replace

import numpy as np
import pytest

import tcsim
from tcsim import transient as tr
from tcsim.errors import InputError

T = np.linspace(0.0, 3.0, 301)


@pytest.mark.parametrize(
    "model, extra, absent",
    [
        ("table", set(), {"flow_m3_s", "stator_speed_rad_s"}),
        ("quasi-dynamic", {"flow_m3_s"}, {"stator_speed_rad_s"}),
        ("hrovat-tobler", {"flow_m3_s", "stator_speed_rad_s", "stator_mode", "flow_direction"}, set()),
    ],
)
def test_one_line_simulate_has_the_model_columns(model, extra, absent):
    r = tcsim.simulate("li-sunden-2016", tr.isolated_takeoff(), model=model, times_s=T)
    df = r.frame()
    base = {
        "time_s",
        "pump_speed_rad_s",
        "turbine_speed_rad_s",
        "pump_torque_nm",
        "turbine_torque_nm",
        "speed_ratio",
        "torque_ratio",
        "effective_pump_torque_nm",
        "effective_turbine_torque_nm",
        "effective_torque_ratio",
    }
    assert base | extra <= set(df.columns)
    assert not absent & set(df.columns)
    assert len(df) == len(T) and df["time_s"].tolist() == T.tolist()
    # eq 3.1 holds column-wise: T_p = inertia + fluid + transferred
    np.testing.assert_allclose(
        df["pump_torque_nm"],
        df["pump_inertia_torque_nm"] + df.get("pump_fluid_torque_nm", 0) + df["pump_transferred_torque_nm"],
        rtol=1e-9,
        atol=1e-9,
    )


def test_batch_equals_single_runs_and_broadcasts():
    base = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    models = [base.with_shape_effects(s, s) for s in (0.0, 0.01, 0.02)]
    batch = tr.simulate_batch(models, [tr.isolated_takeoff()], times_s=T)
    for m, b in zip(models, batch):
        single = tr.simulate(m, tr.isolated_takeoff(), times_s=T)
        np.testing.assert_array_equal(single["pump_speed_rad_s"], b["pump_speed_rad_s"])
    # one model, several drives
    drives = [tr.isolated_takeoff(), tr.isolated_takeoff(tip_out=True)]
    runs = tr.simulate_batch([base], drives, times_s=np.linspace(0, 10, 101))
    assert [e.kind for e in runs[1].events].count("flow-zero") == 2
    assert runs[0]["flow_m3_s"].min() > 0 and runs[1]["flow_m3_s"].min() < 0


def test_batch_releases_the_gil():
    """A Python thread keeps running while the core integrates a batch (no clock involved: the
    other thread counts how often it ran Python code while the batch call was in progress)."""
    base = tr.dynamic_model("li-sunden-2016", "hrovat-tobler")
    models = [base.with_shape_effects(0.01 * (i % 3), 0.0) for i in range(400)]
    in_call = threading.Event()
    done = threading.Event()
    ticks = 0

    def count():
        nonlocal ticks
        in_call.wait()
        while not done.is_set():
            ticks += 1
            time.sleep(0.001)

    th = threading.Thread(target=count)
    th.start()
    in_call.set()
    tr.simulate_batch(models, [tr.isolated_takeoff()], times_s=np.linspace(0, 10, 11), threads=1)
    done.set()
    th.join()
    # with the GIL held for the call the counter could move at most once or twice (switch interval)
    assert ticks >= 5, ticks


def test_inadmissible_shape_effect_names_the_bound():
    m = tr.dynamic_model("li-sunden-2016", "hrovat-tobler").with_shape_effects(0.2, 0.0)
    with pytest.raises(InputError) as e:
        tr.simulate(m, tr.isolated_takeoff(), times_s=T)
    assert e.value.field == "geometry.pump_shape_effect_m2"
    assert "|S| < 0.0612283" in str(e.value)  # √(I_p(ρL_f/A − ρ²S_s²/I_s))/ρ: S_t = 0 here, the bundled S_s


def test_bad_signals_and_initial_states_are_input_errors():
    drive = tr.PumpTorqueTurbineSpeed(np.array([0.0, 1.0, 2.0]), np.array([50.0, np.nan, 50.0]), np.zeros(3))
    with pytest.raises(InputError, match=r"pump_torque_nm\[1\]"):
        tr.simulate("li-sunden-2016", drive, model="table")
    drive = tr.PumpTorqueTurbineSpeed(np.array([0.0, 1.0]), np.array([-20.0, -20.0]), np.zeros(2))
    with pytest.raises(InputError, match="initial pump_torque_nm"):
        tr.simulate("li-sunden-2016", drive, model="hrovat-tobler")
    with pytest.raises(InputError, match="one of"):
        tr.simulate("li-sunden-2016", tr.isolated_takeoff(), initial={"pump_speed_rpm": 1000.0})


def test_initial_state_override():
    r = tr.simulate(
        "li-sunden-2016",
        tr.isolated_takeoff(),
        model="hrovat-tobler",
        times_s=T,
        initial={"pump_speed_rad_s": 150.0, "turbine_speed_rad_s": 20.0},
    )
    assert r["pump_speed_rad_s"][0] == 150.0 and r["turbine_speed_rad_s"][0] == 20.0
    default = tr.simulate("li-sunden-2016", tr.isolated_takeoff(), model="hrovat-tobler", times_s=T)
    # default: the steady state with the first pump torque (40 N·m) at stall
    assert default["pump_torque_nm"][0] == pytest.approx(40.0, rel=1e-9)
    assert default["flow_rate_of_change_m3_s2"][0] == pytest.approx(0.0, abs=0.1)


def test_quasi_dynamic_needs_its_section():
    conv = tcsim.load_converter("li-sunden-2016")
    with pytest.raises(InputError, match=r"\[quasi_dynamic\]"):
        tr.dynamic_model(replace(conv, quasi_dynamic=None), "quasi-dynamic")
    assert tr.default_flow_time_constant_s(conv) == pytest.approx(2.93e-3, rel=1e-2)


@pytest.mark.parametrize("model", ["table", "hrovat-tobler", "quasi-dynamic"])
def test_sample_times_from_linspace_ending_an_ulp_after_a_drive_time_stamp(model):
    # 37–80 % of a 3 s record: np.linspace(0.37 * 3.0, 0.8 * 3.0, 33) ends at 2.4000000000000004;
    # with a drive time stamp at 2.4 s the run failed ("the step 4.4e-16 s fell below the smallest
    # step"; found by a before/after comparison of the core, issue 16)
    times = np.linspace(0.37 * 3.0, 0.8 * 3.0, 33)
    assert times[-1] > 2.4
    drive = tr.PumpTorqueLoad(
        np.array([0.0, 0.1, 0.3, 2.4, 10.0]), np.array([40.0, 40.0, 250.0, 250.0, 250.0]), 1.2, 10.0, 0.002
    )
    r = tr.simulate("li-sunden-2016", drive, model, times_s=times)
    at = tr.simulate("li-sunden-2016", drive, model, times_s=np.append(times[:-1], 2.4))
    for c in ("pump_speed_rad_s", "turbine_speed_rad_s", "turbine_torque_nm"):
        assert r[c][-1] == pytest.approx(at[c][-1], rel=1e-9), c
