"""FMI 3.0 FMUs of the converter models (tcsim.io.fmu3, crates/tcsim-fmu/src/fmi3.rs), run with FMPy.

The same library as FMI 2.0 exports the ``fmi3*`` functions over the same instance: the FMI 3.0 FMU
must validate, simulate in both interfaces, match ``tcsim replay`` within 0.5 % of the range
(Co-Simulation: a ±1 communication step tube) and give the FMI 2.0 FMU's numbers.
"""

from __future__ import annotations

import ctypes
import json
import shutil
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy.fmi3 import FMU3Model, FMU3Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

import tcsim.fmu  # noqa: E402
from tcsim.errors import InputError  # noqa: E402
from tcsim.io import fmu as tfmu  # noqa: E402
from tcsim.io import fmu3  # noqa: E402
from tcsim.transient import PumpTorqueTurbineSpeed, Speeds, dynamic_model, isolated_takeoff, simulate  # noqa: E402

CONVERTER = "li-sunden-2016"
MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
STOP_S = 2.0
STEP_S = 0.01
#: Acceptance tube: 0.5 % of the reference signal's range.
TUBE = 0.005


@pytest.fixture(scope="module")
def library_env(fmu_library):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(tfmu.LIBRARY_ENV, str(fmu_library))
        yield fmu_library


@pytest.fixture(scope="module")
def fmus(library_env, tmp_path_factory) -> dict[tuple[str, str, int], Path]:
    """The FMI 3.0 FMU of each model and causality, and the FMI 2.0 FMU of the pump-torque ones."""
    out = tmp_path_factory.mktemp("fmus3")
    made = {
        (m, c, 3): fmu3.export_fmu(CONVERTER, m, out / f"{m}-{c}-3.fmu", c) for m in MODELS for c in tfmu.CAUSALITIES
    }
    made |= {(m, "pump-torque", 2): tfmu.export_fmu(CONVERTER, m, out / f"{m}-2.fmu") for m in MODELS}
    return made


@pytest.fixture(scope="module")
def takeoff() -> dict[str, np.ndarray]:
    t = np.round(np.arange(0.0, STOP_S + 5e-4, 1e-3), 6)
    run = simulate(CONVERTER, isolated_takeoff(), model="table", times_s=t)
    return {"time": t, **{k: run[k] for k in ("pump_torque_nm", "pump_speed_rad_s", "turbine_speed_rad_s")}}


def _input(takeoff, names) -> np.ndarray:
    cols = [takeoff["time"], *(takeoff[n] for n in names)]
    return np.array(list(zip(*cols)), dtype=[("time", float)] + [(n, float) for n in names])


def _tube_excess(t_fmu, y_fmu, t_ref, y_ref, time_tolerance_s: float) -> np.ndarray:
    """How far (in units of the reference's range) each FMU sample lies outside the reference's
    envelope over ±time_tolerance_s widened by TUBE × its range."""
    span = float(np.max(y_ref) - np.min(y_ref))
    out = np.empty(len(t_fmu))
    for i, (ti, yi) in enumerate(zip(t_fmu, y_fmu)):
        m = (t_ref >= ti - time_tolerance_s - 1e-9) & (t_ref <= ti + time_tolerance_s + 1e-9)
        lo, hi = np.min(y_ref[m]) - TUBE * span, np.max(y_ref[m]) + TUBE * span
        out[i] = max(lo - yi, yi - hi, 0.0) / span
    return out


def _root(path: Path) -> ElementTree.Element:
    with zipfile.ZipFile(path) as zf:
        return ElementTree.fromstring(zf.read("modelDescription.xml"))


# ---------------------------------------------------------------------------------------------
# the archive and its model description


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("causality", list(tfmu.CAUSALITIES))
def test_fmi3_fmu_validates(fmus, model, causality):
    path = fmus[(model, causality, 3)]
    assert validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(path))
    assert md.fmiVersion == "3.0" and md.modelExchange and md.coSimulation
    with zipfile.ZipFile(path) as zf:
        names = set(zf.namelist())
        config = json.loads(zf.read("resources/model.json"))
    assert "binaries/x86_64-linux/tcsim_converter.so" in names
    with zipfile.ZipFile(path) as zf:
        assert "binaries/x86_64-windows/tcsim_converter.dll" in zf.read("sources/README.md").decode()
    assert config[fmu3.TOKEN_KEY] == md.guid  # FMPy reads the instantiationToken as guid
    assert md.numberOfEventIndicators == (4 if model == "hrovat-tobler" else 1)  # stator and flow; the lock-up clutch


@pytest.mark.parametrize("model", MODELS)
def test_fmi3_variables_are_the_fmi2_variables(fmus, model):
    """Same names, value references, causalities, units and start values; FMI 3.0 adds ``time`` and
    the event indicators (Hrovat & Tobler), and the derivatives and dependencies agree."""
    md2 = fmpy.read_model_description(str(fmus[(model, "pump-torque", 2)]))
    md3 = fmpy.read_model_description(str(fmus[(model, "pump-torque", 3)]))

    def unit(v):  # FMI 3.0: the unit comes with the declared type (as in the Reference FMUs)
        return v.unit or (v.declaredType.unit if v.declaredType is not None else None)

    def table(md):
        return {
            v.valueReference: (v.name, v.causality, v.variability, unit(v), v.start, v.derivative and v.derivative.name)
            for v in md.modelVariables
        }

    t2, t3 = table(md2), table(md3)
    extra = {vr: row for vr, row in t3.items() if vr not in t2}
    assert {k: v for k, v in t3.items() if k in t2} == t2
    assert extra.pop(fmu3.TIME_VR)[:2] == ("time", "independent")
    stator_and_flow = {"stator_clutch_indicator", "flow_indicator", "reverse_flow_indicator"}
    assert {row[0] for row in extra.values()} == {"lockup_clutch_indicator"} | (
        stator_and_flow if model == "hrovat-tobler" else set()
    )
    assert [u.variable.valueReference for u in md3.eventIndicators] == sorted(extra)

    def deps(unknowns):
        return {u.variable.valueReference: sorted(d.valueReference for d in u.dependencies or []) for u in unknowns}

    assert deps(md3.outputs) == deps(md2.outputs)
    assert deps(md3.derivatives) == deps(md2.derivatives)


# ---------------------------------------------------------------------------------------------
# simulation against replay and against the FMI 2.0 FMU


@pytest.mark.parametrize("model", MODELS)
def test_fmi3_cosimulation_matches_replay_and_fmi2(fmus, takeoff, model):
    """FMPy's co-simulation of the take-off: within the 0.5 % tube of ±1 communication step around
    the replay run (after the start, as FMI 2.0: the first interval has no input rate yet), and
    the same numbers as the FMI 2.0 FMU (measured: bit for bit)."""
    t, tp, wt = takeoff["time"], takeoff["pump_torque_nm"], takeoff["turbine_speed_rad_s"]
    ref = simulate(dynamic_model(CONVERTER, model), PumpTorqueTurbineSpeed(t, tp, wt))
    runs = {
        v: fmpy.simulate_fmu(
            str(fmus[(model, "pump-torque", v)]),
            fmi_type="CoSimulation",
            input=_input(takeoff, ("pump_torque_nm", "turbine_speed_rad_s")),
            output_interval=STEP_S,
            stop_time=STOP_S,
        )
        for v in (2, 3)
    }
    res = runs[3]
    assert res["time"][-1] == pytest.approx(STOP_S)
    later = res["time"] > 1.5 * STEP_S
    for col in ("pump_speed_rad_s", "turbine_torque_nm", "effective_turbine_torque_nm"):
        excess = _tube_excess(res["time"][later], res[col][later], ref["time_s"], ref[col], STEP_S)
        assert excess.max() == 0.0, (col, res["time"][later][excess > 0][:5], excess.max())
        np.testing.assert_array_equal(res["time"], runs[2]["time"])
        span = np.ptp(ref[col])
        np.testing.assert_allclose(res[col], runs[2][col], rtol=0.0, atol=1e-9 * span, err_msg=col)


@pytest.mark.parametrize("model", MODELS)
def test_fmi3_model_exchange_matches_replay_and_fmi2(fmus, model):
    """FMPy's CVode drives the FMI 3.0 Model Exchange interface (states, derivatives, event
    indicators, the stator's release past the coupling point): within the 0.5 % tube of ±1 output
    interval around the engine run, and the FMI 2.0 FMU's run (to 1e-9 of the range: the same
    library and instance; measured: 9e-12)."""
    stop = 4.0
    t = np.round(np.arange(0.0, stop + 1e-9, 0.01), 6)
    tp = np.interp(t, [0.0, 0.1, 0.3, stop], [40.0, 40.0, 250.0, 250.0])
    wt = 80.0 * t  # passes the coupling point within the run: the stator releases (Hrovat & Tobler)
    names = ("pump_torque_nm", "turbine_speed_rad_s", "turbine_accel_rad_s2")
    inp = np.array(list(zip(t, tp, wt, np.full_like(t, 80.0))), dtype=[("time", float)] + [(n, float) for n in names])
    out = ["pump_speed_rad_s", "turbine_torque_nm"] + (["stator_speed_rad_s"] if model == "hrovat-tobler" else [])
    runs = {
        v: fmpy.simulate_fmu(
            str(fmus[(model, "pump-torque", v)]),
            fmi_type="ModelExchange",
            input=inp,
            output_interval=1e-3,
            stop_time=stop,
            output=out,
        )
        for v in (2, 3)
    }
    ref = simulate(
        CONVERTER,
        PumpTorqueTurbineSpeed(
            [0.0, 0.1, 0.3, stop], [40.0, 40.0, 250.0, 250.0], [0.0, 8.0, 24.0, 80.0 * stop], derivative_window_s=0.0
        ),
        model=model,
        times_s=np.round(np.arange(0.0, stop + 1e-9, 1e-3), 6),
    )
    res = runs[3]
    assert res["time"][-1] == pytest.approx(stop)
    for col in ("pump_speed_rad_s", "turbine_torque_nm"):
        excess = _tube_excess(res["time"], res[col], ref["time_s"], ref[col], 1e-3)
        assert excess.max() == 0.0, (col, excess.max())
        np.testing.assert_array_equal(res["time"], runs[2]["time"])
        np.testing.assert_allclose(res[col], runs[2][col], rtol=0.0, atol=1e-9 * np.ptp(ref[col]), err_msg=col)
    if model == "hrovat-tobler":
        stator = res["stator_speed_rad_s"]
        assert stator[0] == 0.0 and stator[-1] > 0.0  # locked at stall, released past the coupling point


@pytest.mark.parametrize("model", MODELS)
def test_fmi3_speeds_causality_simulates(fmus, takeoff, model):
    """Both speeds in, both interfaces: the turbine torque within the tube of the engine's drive (b)
    (Co-Simulation); Model Exchange runs to the end with finite torques."""
    t, wp, wt = takeoff["time"], takeoff["pump_speed_rad_s"], takeoff["turbine_speed_rad_s"]
    path = str(fmus[(model, "speeds", 3)])
    inputs = _input(takeoff, ("pump_speed_rad_s", "turbine_speed_rad_s"))
    res = fmpy.simulate_fmu(path, fmi_type="CoSimulation", input=inputs, output_interval=STEP_S, stop_time=STOP_S)
    ref = simulate(CONVERTER, Speeds(t, wp, wt), model=model)
    later = res["time"] > 1.5 * STEP_S
    excess = _tube_excess(
        res["time"][later], res["turbine_torque_nm"][later], ref["time_s"], ref["turbine_torque_nm"], STEP_S
    )
    assert excess.max() == 0.0, excess.max()
    me = fmpy.simulate_fmu(path, fmi_type="ModelExchange", input=inputs, output_interval=STEP_S, stop_time=0.5)
    assert me["time"][-1] == pytest.approx(0.5)
    assert np.all(np.isfinite(me["pump_torque_nm"])) and np.all(np.isfinite(me["turbine_torque_nm"]))


def test_fmi3_cosimulation_takes_the_speed_rates_as_inputs(fmus, takeoff):
    """FMI 3.0 has no fmi2SetRealInputDerivatives: in Co-Simulation the rate inputs
    ``pump_accel_rad_s2``/``turbine_accel_rad_s2`` set before fmi3DoStep are the speeds' rates over
    the step (first-order hold). With them at the measurement's 1 ms interval both torques follow
    ``tcsim replay --drive speeds --window 0`` within 0.5 % of the range at every communication
    point, with no time tolerance, as FMI 2.0 with input derivatives does."""
    t, wp, wt = takeoff["time"], takeoff["pump_speed_rad_s"], takeoff["turbine_speed_rad_s"]
    h, log = 1e-3, _Log()
    md, unzip, inst = _instance(fmus[("hrovat-tobler", "speeds", 3)], FMU3Slave, log)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    ins = [vr[n] for n in ("pump_speed_rad_s", "turbine_speed_rad_s", "pump_accel_rad_s2", "turbine_accel_rad_s2")]
    outs = [vr["pump_torque_nm"], vr["turbine_torque_nm"]]
    rows = []
    try:
        inst.instantiate(logMessage=log)
        inst.enterInitializationMode(startTime=0.0)
        inst.setFloat64(ins[:2], [wp[0], wt[0]])
        inst.exitInitializationMode()
        for k in range(len(t) - 1):
            rates = [(wp[k + 1] - wp[k]) / h, (wt[k + 1] - wt[k]) / h]
            inst.setFloat64(ins, [wp[k], wt[k], *rates])
            inst.doStep(k * h, h)
            rows.append(inst.getFloat64(outs))
        inst.terminate()
    finally:
        inst.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)
    res = np.array(rows)
    ref = simulate(CONVERTER, Speeds(t, wp, wt, derivative_window_s=0.0), model="hrovat-tobler")
    for i, col in enumerate(("pump_torque_nm", "turbine_torque_nm")):
        excess = _tube_excess(t[1:], res[:, i], ref["time_s"], ref[col], 0.0)
        assert excess.max() == 0.0, (col, t[1:][excess > 0][:5], excess.max())


# ---------------------------------------------------------------------------------------------
# the C API: every variable, the token, the calling sequence, what is not supported


class _Log:
    """Collects the FMU's log messages (the logMessage callback)."""

    def __init__(self) -> None:
        self.messages: list[str] = []

    def __call__(self, env, status, category, message) -> None:
        self.messages.append(message.decode())


def _array(getter, n: int) -> list[float]:
    """Call one of FMU3Model's array getters (``getContinuousStates``, ...) for ``n`` values."""
    values = (ctypes.c_double * n)()
    getter(values, n)
    return list(values)


def _instance(path: Path, cls, log: _Log, token: str | None = None):
    md = fmpy.read_model_description(str(path))
    unzip = fmpy.extract(str(path))
    inst = cls(guid=token or md.guid, unzipDirectory=unzip, modelIdentifier="tcsim_converter", instanceName="test")
    return md, unzip, inst


@pytest.mark.parametrize("cls", [FMU3Slave, FMU3Model])
def test_fmi3_every_declared_variable_can_be_read_after_initialisation(fmus, cls):
    """Reading every variable of modelDescription.xml after initialisation (what fmusim does) works
    in both interfaces, and the event indicators are those of fmi3GetEventIndicators."""
    log = _Log()
    md, unzip, inst = _instance(fmus[("hrovat-tobler", "pump-torque", 3)], cls, log)
    try:
        inst.instantiate(logMessage=log)
        inst.enterInitializationMode(startTime=0.5)
        inst.setFloat64([0, 2], [150.0, 20.0])
        inst.exitInitializationMode()
        vrs = [v.valueReference for v in md.modelVariables]
        values = dict(zip(vrs, inst.getFloat64(vrs)))
        assert all(np.isfinite(list(values.values()))), log.messages
        assert values[fmu3.TIME_VR] == 0.5
        indicators = [u.variable.valueReference for u in md.eventIndicators]
        if cls is FMU3Model:
            # stator, flow, reverse flow and the lock-up clutch
            assert inst.getNumberOfContinuousStates() == 3 and inst.getNumberOfEventIndicators() == 4
            assert [values[vr] for vr in indicators] == _array(inst.getEventIndicators, 4)
            assert [values[20], values[22], values[23]] == _array(inst.getContinuousStateDerivatives, 3)
        assert all(values[vr] > 0.0 for vr in indicators)  # stall: the stator locked, flow forward
        inst.terminate()
    finally:
        inst.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


def test_fmi3_model_exchange_answers_in_initialisation_mode(fmus):
    """The number of states and indicators and the nominals from instantiation on; the states,
    derivatives and indicators in initialisation mode are the steady state of the inputs so far."""
    log = _Log()
    _, unzip, inst = _instance(fmus[("hrovat-tobler", "pump-torque", 3)], FMU3Model, log)
    try:
        inst.instantiate(logMessage=log)
        assert inst.getNumberOfContinuousStates() == 3
        nominals = _array(inst.getNominalsOfContinuousStates, 3)
        inst.enterInitializationMode(startTime=0.0)
        inst.setFloat64([0, 2], [120.0, 50.0])
        during = _array(inst.getContinuousStates, 3)
        assert np.allclose(_array(inst.getContinuousStateDerivatives, 3), 0.0, atol=1e-6)
        inst.exitInitializationMode()
        assert _array(inst.getContinuousStates, 3) == during
        assert _array(inst.getNominalsOfContinuousStates, 3) == nominals
        steady = simulate(
            CONVERTER,
            PumpTorqueTurbineSpeed([0.0, 1.0], [120.0, 120.0], [50.0, 50.0]),
            model="hrovat-tobler",
            times_s=[0.0, 1e-6],
        )
        assert during[0] == pytest.approx(steady["pump_speed_rad_s"][0], rel=1e-9)
    finally:
        inst.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


def test_fmi3_wrong_instantiation_token_is_refused(fmus):
    log = _Log()
    _, unzip, inst = _instance(fmus[("table", "pump-torque", 3)], FMU3Slave, log, token="{not-the-token}")
    try:
        with pytest.raises(Exception, match="Failed to instantiate"):
            inst.instantiate(logMessage=log)
        assert any("instantiationToken" in m and "{not-the-token}" in m for m in log.messages), log.messages
    finally:
        shutil.rmtree(unzip, ignore_errors=True)


def test_fmi3_calling_sequence_and_unsupported_functions_are_errors(fmus):
    """DoStep before initialisation, SetFloat64 of an output or of time, other types, clocks,
    directional derivatives and a second ExitInitializationMode return fmi3Error with a message;
    the instance goes on afterwards."""
    log = _Log()
    _, unzip, inst = _instance(fmus[("table", "pump-torque", 3)], FMU3Slave, log)
    try:
        inst.instantiate(logMessage=log)
        calls = [
            ("fmi3DoStep", lambda: inst.doStep(0.0, 0.01)),
            ("fmi3GetFloat64", lambda: inst.getFloat64([20])),  # calculated: no value yet
            ("fmi3GetFloat64", lambda: inst.getFloat64([1])),  # an output: the same
            ("fmi3SetFloat64", lambda: inst.setFloat64([fmu3.TIME_VR], [1.0])),
            ("fmi3SetFloat64", lambda: inst.setFloat64([3], [1.0])),  # an output
            ("fmi3GetInt32", lambda: inst.getInt32([0])),
            ("fmi3GetClock", lambda: inst.getClock([0])),
            ("fmi3GetDirectionalDerivative", lambda: inst.getDirectionalDerivative([1], [0], [1.0])),
            ("fmi3ExitInitializationMode", lambda: inst.exitInitializationMode()),
        ]
        for name, call in calls:
            with pytest.raises(Exception, match=name):
                call()
        assert any("not supported" in m for m in log.messages) and any("fmi3DoStep in state" in m for m in log.messages)
        inst.enterInitializationMode(startTime=0.0)
        inst.setFloat64([0, 2], [100.0, 0.0])
        inst.exitInitializationMode()
        with pytest.raises(Exception, match="fmi3ExitInitializationMode"):
            inst.exitInitializationMode()
        assert inst.doStep(0.0, 0.01)[3] == pytest.approx(0.01)  # lastSuccessfulTime
        with pytest.raises(Exception, match="fmi3DoStep"):
            inst.doStep(0.02, 0.01)  # not the end of the last step
        inst.terminate()
        with pytest.raises(Exception, match="fmi3DoStep"):
            inst.doStep(0.01, 0.01)
        inst.reset()
        inst.enterInitializationMode(startTime=0.0)
        inst.exitInitializationMode()
        assert np.isfinite(inst.getFloat64([1])[0])
    finally:
        inst.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


def _steps(inst, first: int, last: int) -> list[list[float]]:
    """Co-simulation steps ``first``..``last`` (10 ms) of a torque ramp at a rising turbine speed;
    the outputs after each."""
    rows = []
    for k in range(first, last):
        inst.setFloat64([0, 2], [100.0 + 20.0 * k, 4.0 * k])
        inst.doStep(0.01 * k, 0.01)
        rows.append(inst.getFloat64([1, 3, 6, 7, 20, 23]))
    return rows


def test_fmi3_fmu_state_continues_bit_for_bit(fmus):
    """fmi3GetFMUState at 0.2 s, on to 0.5 s; fmi3SetFMUState and the same inputs give the same
    numbers bit for bit, also in a fresh instance from the serialised state; a damaged serialised
    state is refused."""
    log = _Log()
    path = fmus[("hrovat-tobler", "pump-torque", 3)]
    _, unzip, inst = _instance(path, FMU3Slave, log)
    _, unzip2, fresh = _instance(path, FMU3Slave, log)
    try:
        inst.instantiate(logMessage=log)
        inst.enterInitializationMode(startTime=0.0)
        inst.setFloat64([0, 2], [100.0, 0.0])
        inst.exitInitializationMode()
        _steps(inst, 0, 20)
        state = inst.getFMUState()
        first = _steps(inst, 20, 50)
        inst.setFMUState(state)
        assert _steps(inst, 20, 50) == first
        data = inst.serializeFMUState(state)
        inst.freeFMUState(state)
        fresh.instantiate(logMessage=log)
        restored = fresh.deserializeFMUState(data)
        fresh.setFMUState(restored)
        assert _steps(fresh, 20, 50) == first
        with pytest.raises(Exception, match="fmi3DeserializeFMUState"):
            fresh.deserializeFMUState(data[:-1])
        fresh.freeFMUState(restored)
    finally:
        inst.freeInstance()
        fresh.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)
        shutil.rmtree(unzip2, ignore_errors=True)


def test_fmi3_fmu_state_in_model_exchange(fmus):
    """Model Exchange: a state taken in continuous-time mode restores the states, the time and the
    mode (fmi3CompletedIntegratorStep is allowed again)."""
    log = _Log()
    _, unzip, inst = _instance(fmus[("hrovat-tobler", "pump-torque", 3)], FMU3Model, log)
    try:
        inst.instantiate(logMessage=log)
        inst.enterInitializationMode(startTime=0.0)
        inst.setFloat64([0, 2], [150.0, 20.0])
        inst.exitInitializationMode()
        inst.updateDiscreteStates()
        inst.enterContinuousTimeMode()
        saved_x, state = _array(inst.getContinuousStates, 3), inst.getFMUState()
        inst.setTime(0.3)
        inst.setContinuousStates((ctypes.c_double * 3)(*[1.1 * x for x in saved_x]), 3)
        inst.enterEventMode()
        inst.setFMUState(state)
        assert _array(inst.getContinuousStates, 3) == saved_x and inst.getFloat64([fmu3.TIME_VR]) == [0.0]
        inst.completedIntegratorStep()
        inst.freeFMUState(state)
    finally:
        inst.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


def test_fmi2_fmu_is_not_instantiated_as_fmi3(fmus):
    """An FMI 2.0 FMU's model.json has no instantiationToken: fmi3Instantiate* refuses it."""
    log = _Log()
    md = fmpy.read_model_description(str(fmus[("table", "pump-torque", 2)]))
    unzip = fmpy.extract(str(fmus[("table", "pump-torque", 2)]))
    shutil.copytree(Path(unzip) / "binaries" / "linux64", Path(unzip) / "binaries" / "x86_64-linux")
    inst = FMU3Model(guid=md.guid, unzipDirectory=unzip, modelIdentifier="tcsim_converter", instanceName="two")
    try:
        with pytest.raises(Exception, match="Failed to instantiate"):
            inst.instantiate(logMessage=log)
        assert any("--fmi-version 3" in m for m in log.messages), log.messages
    finally:
        shutil.rmtree(unzip, ignore_errors=True)


# ---------------------------------------------------------------------------------------------
# the command line and the platforms


def test_cli_export_fmu_fmi_version(cli, library_env, tmp_path):
    out = tmp_path / "ht3.fmu"
    r = cli("export-fmu", CONVERTER, "--model", "hrovat-tobler", "-o", out, "--fmi-version", "3")
    assert r.code == 0, (r.stdout, r.stderr)
    assert "FMI 3.0" in r.stdout and "x86_64-linux" in r.stdout
    assert _root(out).get("fmiVersion") == "3.0" and validate_fmu(str(out)) == []
    bad = tmp_path / "x.fmu"
    r = cli("export-fmu", CONVERTER, "--model", "table", "-o", bad, "--fmi-version", "2.1")
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.code == 2 and lines == ["error: command line: --fmi-version = '2.1': expected 2 or 3"], r.stderr
    assert not bad.exists()


def test_api_fmi_versions(library_env, tmp_path):
    """``tcsim.fmu.export_fmu(..., fmi=tcsim.fmu.FMI3)``; ``fmi_version`` knows 2 and 3 only."""
    assert tcsim.fmu.fmi_version(3) is tcsim.fmu.FMI3 and tcsim.fmu.fmi_version("2") is tcsim.fmu.FMI2
    with pytest.raises(InputError, match="^argument: fmi_version = 4"):
        tcsim.fmu.fmi_version(4)
    path = tcsim.fmu.export_fmu(CONVERTER, "table", tmp_path / "t.fmu", "speeds", fmi=tcsim.fmu.FMI3)
    assert _root(path).get("fmiVersion") == "3.0"


def test_macos_libraries_go_to_their_architectures(tmp_path):
    """A thin Mach-O library goes to its architecture's directory, a universal one to both."""
    thin = tmp_path / "arm.dylib"
    thin.write_bytes(b"\xcf\xfa\xed\xfe" + (0x0100000C).to_bytes(4, "little") + bytes(24))
    fat = tmp_path / "universal.dylib"
    arch = [c.to_bytes(4, "big") + bytes(16) for c in (0x01000007, 0x0100000C)]
    fat.write_bytes(b"\xca\xfe\xba\xbe" + (2).to_bytes(4, "big") + b"".join(arch))
    assert fmu3.platforms(thin) == ["aarch64-darwin"]
    assert fmu3.platforms(fat) == ["aarch64-darwin", "x86_64-darwin"]
    assert fmu3.platforms(Path("tcsim_fmu.dll")) == ["x86_64-windows"]
