"""The FMU's ``torques`` causality and its lock-up clutch input, run with FMPy, against the
transient engine with the same drive.

* ``torques`` is drive (c) of :class:`tcsim.transient.PumpTorqueLoad`: pump torque and the turbine's
  load torque in, both speeds out; no input is differentiated, so the FMU follows the engine with
  no time tube, in Co-Simulation (at 1 ms communication steps) and in Model Exchange.
* ``lockup_capacity_nm`` (every causality) commands the lock-up clutch: the FMU locks and breaks
  away when the engine does with the same command.

The library is the session's (``fmu_library`` of ``conftest.py``).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy.fmi2 import FMU2Slave  # noqa: E402

from tcsim.io import fmu as tfmu  # noqa: E402
from tcsim.transient import PumpTorqueLoad, PumpTorqueTurbineSpeed, TransientResult, simulate  # noqa: E402

CONVERTER = "li-sunden-2016"
MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
#: Acceptance: 0.5 % of the reference signal's range, with no time tube.
TOLERANCE = 0.005
#: The load of the take-off (tcsim.transient.isolated_takeoff): inertia, torque and drag.
LOAD = {"load_inertia_kg_m2": 1.2, "load_drag_nm_s2": 0.002}
LOAD_TORQUE_NM = 10.0
#: Pump torque of the take-off: 40 N·m, ramped to 250 N·m over 0.1-0.3 s.
TORQUE_KNOTS = ([0.0, 0.1, 0.3], [40.0, 40.0, 250.0])
#: The clutch command: steps (FMPy input events) at 0.5 s (0 → 400 N·m: the clutch slips, then
#: locks), at 1.5 s (→ 60 N·m, below the locked torque: it breaks away), at 2.0 s (→ 0: open).
CAPACITY_STEPS = [(0.5, 400.0), (1.5, 60.0), (2.0, 0.0)]
#: A step of the engine's reference drive lasts 1 µs (its time resolution).
STEP_S = 1e-6


@pytest.fixture(scope="module")
def fmu_paths(fmu_library, tmp_path_factory) -> dict[tuple[str, str], Path]:
    """The FMU of each model under ``torques``, and Hrovat & Tobler's under ``pump-torque``."""
    out = tmp_path_factory.mktemp("fmus-causality")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(tfmu.LIBRARY_ENV, str(fmu_library))
        pairs = [(m, "torques") for m in MODELS] + [("hrovat-tobler", "pump-torque")]
        return {(m, c): tfmu.export_fmu(CONVERTER, m, out / f"{m}-{c}.fmu", causality=c) for m, c in pairs}


def _excess(res, ref: TransientResult, col: str) -> float:
    """Largest distance of the FMU's samples from the engine's (interpolated to the FMU's times), in
    units of the engine signal's range."""
    y = np.interp(res["time"], ref["time_s"], ref[col])
    return float(np.max(np.abs(res[col] - y)) / np.ptp(ref[col]))


def _step_knots(stop_s: float) -> tuple[list[float], list[float]]:
    """The command as the engine's signal: each step 1 µs long."""
    knots, values = [0.0], [0.0]
    for at, value in CAPACITY_STEPS:
        knots += [at, at + STEP_S]
        values += [values[-1], value]
    return [*knots, stop_s], [*values, values[-1]]


def _inputs(times: list[float], columns: dict[str, list[float]]) -> np.ndarray:
    names = list(columns)
    return np.array(list(zip(times, *columns.values())), dtype=[("time", float)] + [(n, float) for n in names])


@pytest.mark.parametrize("model", MODELS)
def test_torques_cosimulation_matches_drive_c(fmu_paths, model):
    """Co-Simulation at 1 ms communication steps (FMPy, inputs given at the communication points)
    against the engine under drive (c) with the same inputs: both speeds and the turbine torque
    within 0.5 % of their range at every communication point, with no time tube."""
    stop = 2.0
    t = np.round(np.arange(0.0, stop + 1e-9, 1e-3), 6)
    tp = np.interp(t, *TORQUE_KNOTS)
    ref = simulate(CONVERTER, PumpTorqueLoad(t, tp, load_torque_nm=LOAD_TORQUE_NM, **LOAD), model=model)
    inp = _inputs(list(t), {"pump_torque_nm": list(tp), "load_torque_nm": [LOAD_TORQUE_NM] * len(t)})
    res = fmpy.simulate_fmu(
        str(fmu_paths[(model, "torques")]),
        fmi_type="CoSimulation",
        input=inp,
        output_interval=1e-3,
        stop_time=stop,
        start_values=LOAD,
    )
    assert res["time"][-1] == pytest.approx(stop)
    assert res["turbine_speed_rad_s"][-1] > 50.0  # the take-off moved the load
    for col in ("pump_speed_rad_s", "turbine_speed_rad_s", "turbine_torque_nm", "effective_turbine_torque_nm"):
        assert _excess(res, ref, col) < TOLERANCE, col


@pytest.mark.parametrize("model", MODELS)
def test_torques_model_exchange_matches_drive_c(fmu_paths, model):
    """Model Exchange (FMPy's CVode): both speeds are continuous states. The pump torque steps
    40 → 250 N·m at 0.1 s (an input event: FMPy's Model Exchange driver holds an input between its
    samples, so a ramp would lag by CVode's step) and the load moves off; the run, with Hrovat &
    Tobler's stator release, stays within 0.5 % of the engine's range with no time tube."""
    stop = 3.0
    ref = simulate(
        CONVERTER,
        PumpTorqueLoad([0.0, 0.1, 0.1 + STEP_S, stop], [40.0, 40.0, 250.0, 250.0], load_torque_nm=10.0, **LOAD),
        model=model,
        times_s=np.round(np.arange(0.0, stop + 1e-9, 1e-3), 6),
    )
    inp = _inputs([0.0, 0.1, 0.1, stop], {"pump_torque_nm": [40.0, 40.0, 250.0, 250.0], "load_torque_nm": [10.0] * 4})
    res = fmpy.simulate_fmu(
        str(fmu_paths[(model, "torques")]),
        fmi_type="ModelExchange",
        input=inp,
        output_interval=1e-3,
        stop_time=stop,
        start_values=LOAD,
        relative_tolerance=1e-6,
    )
    if model == "hrovat-tobler":
        assert [e.kind for e in ref.events] == ["stator-release"]
    for col in ("pump_speed_rad_s", "turbine_speed_rad_s", "turbine_torque_nm"):
        assert _excess(res, ref, col) < TOLERANCE, col


def test_torques_start_at_the_initial_turbine_speed(fmu_paths):
    """Drive (c)'s start: the steady state at the given turbine speed (initial_turbine_speed_rad_s,
    default 0: a vehicle at rest), as the engine's ``initial={"turbine_speed_rad_s": ...}``."""
    path = str(fmu_paths[("hrovat-tobler", "torques")])
    inp = _inputs([0.0, 0.05], {"pump_torque_nm": [150.0, 150.0], "load_torque_nm": [20.0, 20.0]})
    for wt in (0.0, 80.0):
        ref = simulate(
            CONVERTER,
            PumpTorqueLoad([0.0, 0.05], [150.0, 150.0], load_torque_nm=20.0, **LOAD),
            model="hrovat-tobler",
            times_s=[0.0, 0.05],
            initial={"turbine_speed_rad_s": wt},
        )
        for fmi_type in ("CoSimulation", "ModelExchange"):
            res = fmpy.simulate_fmu(
                path,
                fmi_type=fmi_type,
                input=inp,
                output_interval=0.05,
                stop_time=0.05,
                start_values={**LOAD, "initial_turbine_speed_rad_s": wt},
            )
            assert res["turbine_speed_rad_s"][0] == wt
            assert res["pump_speed_rad_s"][0] == pytest.approx(ref["pump_speed_rad_s"][0], rel=1e-9)
            assert res["pump_speed_rad_s"][-1] == pytest.approx(ref["pump_speed_rad_s"][-1], rel=1e-3)


def _lockup_reference(causality: str, stop: float) -> tuple[TransientResult, np.ndarray, dict[str, list[float]]]:
    """The engine's run with the clutch command, and the FMU's input table (steps as FMPy input
    events: the time repeats)."""
    knots, capacity = _step_knots(stop)
    grid = sorted({*knots, *TORQUE_KNOTS[0]})
    tp = np.interp(grid, *TORQUE_KNOTS)
    cap = np.interp(grid, knots, capacity)
    # the FMU's table: the torque ramp's knots, and each command step as two rows at its time
    rows = [(0.0, 0.0), (0.1, 0.0), (0.3, 0.0)]
    for at, value in CAPACITY_STEPS:
        rows += [(at, rows[-1][1]), (at, value)]
    rows.append((stop, rows[-1][1]))
    times = [r[0] for r in rows]
    columns = {"pump_torque_nm": list(np.interp(times, *TORQUE_KNOTS))}
    if causality == "torques":
        drive = PumpTorqueLoad(grid, tp, load_torque_nm=LOAD_TORQUE_NM, lockup_capacity_nm=cap, **LOAD)
        columns["load_torque_nm"] = [LOAD_TORQUE_NM] * len(times)
    else:
        # the turbine follows a vehicle at 20 rad/s², its rate given (Model Exchange)
        drive = PumpTorqueTurbineSpeed(grid, tp, 20.0 * np.array(grid), lockup_capacity_nm=cap, derivative_window_s=0.0)
        columns["turbine_speed_rad_s"] = [20.0 * x for x in times]
        columns["turbine_accel_rad_s2"] = [20.0] * len(times)
    t = np.round(np.arange(0.0, stop + 1e-9, 1e-3), 6)
    ref = simulate(CONVERTER, drive, model="hrovat-tobler", times_s=t)
    columns["lockup_capacity_nm"] = [r[1] for r in rows]
    return ref, np.asarray(times), columns


def _transitions(res) -> list[tuple[float, float]]:
    """(time, new state) of each change of the FMU's ``lockup_state``."""
    state = res["lockup_state"]
    return [(float(res["time"][i + 1]), float(state[i + 1])) for i in np.flatnonzero(np.diff(state) != 0)]


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
@pytest.mark.parametrize("causality", ["pump-torque", "torques"])
def test_lockup_capacity_locks_and_breaks_away_as_the_engine(fmu_paths, causality, fmi_type):
    """The clutch command 0 → 400 N·m at 0.5 s, → 60 N·m at 1.5 s, → 0 at 2.0 s: the clutch slips,
    locks, breaks away and opens as in the engine's run with the same command (lock and breakaway
    within one 1 ms communication step in Co-Simulation, within 1e-3 s in Model Exchange, whose
    events FMPy records at their time), and the pump speed follows the engine's within 0.5 % of
    its range."""
    stop = 2.5
    ref, times, columns = _lockup_reference(causality, stop)
    kinds = [(e.kind, round(e.time_s, 6)) for e in ref.events if e.kind.startswith("lockup-")]
    lock = next(t for k, t in kinds if k == "lockup-lock")
    breakaway = next(t for k, t in kinds if k == "lockup-slip")
    assert 0.5 < lock < 1.5 and breakaway == pytest.approx(1.5, abs=1e-5)
    res = fmpy.simulate_fmu(
        str(fmu_paths[("hrovat-tobler", causality)]),
        fmi_type=fmi_type,
        input=_inputs(list(times), columns),
        output_interval=1e-3,
        stop_time=stop,
        start_values=LOAD if causality == "torques" else {},
        relative_tolerance=1e-6,
    )
    changes = _transitions(res)
    assert [s for _, s in changes] == [1.0, 2.0, 1.0, 0.0], changes  # slipping, locked, slipping, open
    tolerance = 1e-3 + 1e-9
    assert changes[1][0] == pytest.approx(lock, abs=tolerance)
    assert changes[2][0] == pytest.approx(breakaway, abs=tolerance)
    assert changes[3][0] == pytest.approx(2.0, abs=tolerance)
    locked = (res["time"] > lock + 2e-3) & (res["time"] < 1.5)
    assert np.all(res["lockup_slip_rad_s"][locked] == 0.0) and np.all(res["lockup_torque_nm"][locked] > 0.0)
    assert _excess(res, ref, "pump_speed_rad_s") < TOLERANCE


@pytest.mark.parametrize("value", [-1.0, float("nan"), float("inf")])
def test_a_negative_or_non_finite_capacity_is_refused(fmu_paths, capfd, value):
    """fmi2SetReal of a capacity below zero or not finite: fmi2Error, the logged message names the
    variable and the value, and the capacity keeps its value."""
    path = fmu_paths[("hrovat-tobler", "torques")]
    md = fmpy.read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}["lockup_capacity_nm"]
    unzip = fmpy.extract(str(path))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier="tcsim_converter", instanceName="cap")
    try:
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal([vr], [100.0])
        with pytest.raises(Exception, match="fmi2SetReal"):
            slave.setReal([vr], [value])
        assert f"lockup_capacity_nm = {value:g}".replace("nan", "NaN").replace("inf", "inf") in capfd.readouterr().out
        assert slave.getReal([vr]) == [100.0]
    finally:
        slave.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)
