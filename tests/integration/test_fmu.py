"""FMI 2.0 Co-Simulation FMUs of the converter models (tcsim.fmu, crates/tcsim-fmu), run with FMPy.

The FMU's library is the one the build made (``cargo build --release --workspace``, in the README's
test command) or ``$TCSIM_FMU_LIBRARY``: the ``fmu_library`` fixture of ``conftest.py``.

The reference of the co-simulation is the transient engine driven by the same inputs, the run
``tcsim replay`` makes: ``transient.simulate(model, PumpTorqueTurbineSpeed(t, tp, wt))`` with the
pump torque and turbine speed of the table model's isolated take-off at 1 kHz.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
import tomli_w  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from tcsim import steady_state  # noqa: E402
from tcsim.errors import InputError  # noqa: E402
from tcsim.io import fmu as tfmu  # noqa: E402
from tcsim.models.converter import load_converter  # noqa: E402
from tcsim.transient import PumpTorqueTurbineSpeed, Speeds, dynamic_model, isolated_takeoff, simulate  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
CONVERTER = "li-sunden-2016"
MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
STOP_S = 2.0
STEP_S = 0.01  # the communication interval (FMPy's output_interval)
#: Acceptance tube: 0.5 % of the reference signal's range.
TUBE = 0.005
#: Signals of each model (value references), checked against the modelDescription.xml.
EXPECTED_SIGNALS = {
    "table": {0, 1, 2, 3, 4, 5, 8, 9, 10, 11},
    "hrovat-tobler": set(range(12)),
    "quasi-dynamic": {0, 1, 2, 3, 4, 5, 6, 8, 9, 10, 11},
}


# ---------------------------------------------------------------------------------------------
# fixtures


@pytest.fixture(scope="session")
def library_env(fmu_library):
    """$TCSIM_FMU_LIBRARY set to the session's library, for the exports and the CLI."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(tfmu.LIBRARY_ENV, str(fmu_library))
        yield fmu_library


@pytest.fixture(scope="session")
def fmus(library_env, tmp_path_factory) -> dict[tuple[str, str], Path]:
    """The FMU of each model and causality."""
    out = tmp_path_factory.mktemp("fmus")
    return {
        (m, c): tfmu.export_fmu(CONVERTER, m, out / f"{m}-{c}.fmu", causality=c)
        for m in MODELS
        for c in tfmu.CAUSALITIES
    }


@pytest.fixture(scope="session")
def takeoff() -> dict[str, np.ndarray]:
    """The table model's isolated take-off, 0–2 s at 1 kHz: the inputs of the co-simulations."""
    t = np.round(np.arange(0.0, STOP_S + 5e-4, 1e-3), 6)
    run = simulate(CONVERTER, isolated_takeoff(), model="table", times_s=t)
    return {"time": t, **{k: run[k] for k in ("pump_torque_nm", "pump_speed_rad_s", "turbine_speed_rad_s")}}


def _input(takeoff, names) -> np.ndarray:
    return np.array(
        list(zip(takeoff["time"], *(takeoff[n] for n in names))), dtype=[("time", float)] + [(n, float) for n in names]
    )


def _tube_excess(t_fmu, y_fmu, t_ref, y_ref, time_tolerance_s: float) -> np.ndarray:
    """How far (in units of the reference's range) each FMU sample lies outside the tube: the
    reference's envelope over ±time_tolerance_s, widened by TUBE × its range."""
    span = float(np.max(y_ref) - np.min(y_ref))
    out = np.empty(len(t_fmu))
    for i, (ti, yi) in enumerate(zip(t_fmu, y_fmu)):
        m = (t_ref >= ti - time_tolerance_s - 1e-9) & (t_ref <= ti + time_tolerance_s + 1e-9)
        lo, hi = np.min(y_ref[m]) - TUBE * span, np.max(y_ref[m]) + TUBE * span
        out[i] = max(lo - yi, yi - hi, 0.0) / span
    return out


def _model_description(path: Path) -> ElementTree.Element:
    with zipfile.ZipFile(path) as zf:
        return ElementTree.fromstring(zf.read("modelDescription.xml"))


# ---------------------------------------------------------------------------------------------
# the archive and its model description


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("causality", list(tfmu.CAUSALITIES))
def test_fmu_validates_and_dumps(fmus, model, causality, capsys):
    path = fmus[(model, causality)]
    assert validate_fmu(str(path)) == []
    fmpy.dump(str(path))
    assert "Co-Simulation" in capsys.readouterr().out


@pytest.mark.parametrize("model", MODELS)
def test_fmu_contents(fmus, model):
    path = fmus[(model, "pump-torque")]
    with zipfile.ZipFile(path) as zf:
        names = set(zf.namelist())
        config = json.loads(zf.read("resources/model.json"))
        readme = zf.read("sources/README.md").decode()
    assert {
        "modelDescription.xml",
        "resources/model.json",
        "binaries/linux64/tcsim_converter.so",
        "sources/README.md",
        "sources/Cargo.toml",
        "sources/Cargo.lock",
        "sources/crates/tcsim-core/src/lib.rs",
        "sources/crates/tcsim-fmu/src/lib.rs",
    } <= names
    assert not any(n.endswith(".py") or n.endswith(".pyc") for n in names), "no Python inside"
    assert "win64" in readme and "darwin64" in readme and "cargo build --release -p tcsim-fmu" in readme

    # every numeric entry of the spec is a parameter, value reference 100 + i, start = spec value
    spec = dynamic_model(CONVERTER, model).spec
    assert config["causality"] == "pump-torque" and config["model"] == json.loads(json.dumps(spec))
    expected = [
        (k, i)
        for k, v in spec.items()
        if not isinstance(v, str)
        for i in (range(len(v)) if isinstance(v, list) else [0])
    ]
    assert [(p["key"], p["index"]) for p in config["parameters"]] == expected

    root = _model_description(path)
    assert root.get("fmiVersion") == "2.0" and root.find("ModelExchange").get("modelIdentifier") == "tcsim_converter"
    assert root.find("CoSimulation").get("modelIdentifier") == "tcsim_converter"
    variables = root.find("ModelVariables").findall("ScalarVariable")
    by_vr = {int(v.get("valueReference")): v for v in variables}
    assert {vr for vr in by_vr if vr < 12} == EXPECTED_SIGNALS[model]
    # Model Exchange: the rate of the turbine speed input, the lock-up clutch's input (15) and
    # outputs (16-18), and a derivative per continuous state (pump speed 20, stator speed 22,
    # flow 23); the clutch's friction ratio (37)
    states = {"table": {20}, "quasi-dynamic": {20, 23}, "hrovat-tobler": {20, 22, 23}}[model]
    starts = {"table": {30, 31}, "quasi-dynamic": {30, 31, 33}, "hrovat-tobler": {30, 31, 32, 33}}[model]
    assert {vr for vr in by_vr if 12 <= vr < 100} == {13, 15, 16, 17, 18, 37} | states | starts
    # the stator clutch and the flow direction (Hrovat & Tobler), and the lock-up clutch
    assert root.get("numberOfEventIndicators") == ("4" if model == "hrovat-tobler" else "1")
    for i, p in enumerate(config["parameters"]):
        v = by_vr[100 + i]
        assert v.get("name") == p["name"] and v.get("causality") == "parameter" and v.get("variability") == "tunable"
        value = spec[p["key"]][p["index"]] if isinstance(spec[p["key"]], list) else spec[p["key"]]
        assert float(v.find("Real").get("start")) == value
        assert v.find("Real").get("unit")
    names = [v.get("name") for v in variables]
    assert len(set(names)) == len(names)
    if model == "hrovat-tobler":
        assert {"pump_exit_angle_rad", "pump_shape_effect_m2", "fluid_length_m", "friction_loss"} <= set(names)
    else:
        assert {"table_speed_ratio[1]", "table_capacity_factor_nm_s2[13]", "pump_inertia_kg_m2"} <= set(names)
    causal = {v.get("name"): v.get("causality") for v in variables if int(v.get("valueReference")) < 12}
    assert causal.pop("pump_torque_nm") == "input" and causal.pop("turbine_speed_rad_s") == "input"
    assert set(causal.values()) == {"output"}


def test_speeds_causality_inputs(fmus):
    root = _model_description(fmus[("hrovat-tobler", "speeds")])
    causal = {v.get("name"): v.get("causality") for v in root.iter("ScalarVariable")}
    assert causal["pump_speed_rad_s"] == causal["turbine_speed_rad_s"] == "input"
    assert causal["pump_torque_nm"] == causal["turbine_torque_nm"] == "output"


# ---------------------------------------------------------------------------------------------
# co-simulation against the transient engine (tcsim replay)


@pytest.mark.parametrize("model", MODELS)
def test_cosimulation_matches_replay(fmus, takeoff, model):
    """FMPy's co-simulation (inputs given at the communication points only) against the replay run.

    FMPy does not pass the inputs' rates, so the FMU extrapolates them from the last interval and
    lags one interval behind a kink of an input (the start and end of the torque ramp): the tube is
    0.5 % of the range wide and one communication interval long. At the start the FMU cannot know
    the turbine speed's rate: its turbine torque then lacks the turbine's inertia torque I_t·ω̇_t
    (the replay run differentiates the whole record), so the first two samples are checked for that
    instead."""
    t, tp, wt = takeoff["time"], takeoff["pump_torque_nm"], takeoff["turbine_speed_rad_s"]
    dyn = dynamic_model(CONVERTER, model)
    ref = simulate(dyn, PumpTorqueTurbineSpeed(t, tp, wt))
    res = fmpy.simulate_fmu(
        str(fmus[(model, "pump-torque")]),
        fmi_type="CoSimulation",
        input=_input(takeoff, ("pump_torque_nm", "turbine_speed_rad_s")),
        output_interval=STEP_S,
        stop_time=STOP_S,
    )
    assert res["time"][-1] == pytest.approx(STOP_S)
    later = res["time"] > 1.5 * STEP_S
    for col in ("pump_speed_rad_s", "turbine_torque_nm", "effective_turbine_torque_nm"):
        excess = _tube_excess(res["time"][later], res[col][later], ref["time_s"], ref[col], STEP_S)
        assert excess.max() == 0.0, (col, res["time"][later][excess > 0][:5], excess.max())
    assert res["pump_speed_rad_s"][0] == pytest.approx(ref["pump_speed_rad_s"][0], rel=1e-9)
    # at t = 0 the FMU's turbine torque is the replay's without the torque of the turbine's rate:
    # its inertia torque and, in Hrovat & Tobler, the fluid term ρS_t·Q̇ that the rate causes
    # through the mass matrix (stator locked at stall): ∂Q̇/∂ω̇_t = −ρS_t·I_p/(I_p·ρL_f/A − ρ²S_p²)
    inertia = dyn.spec["inertia_kg_m2"][1] - _fluid_coupling_kg_m2(dyn.spec)
    rate_torque = inertia * ref["turbine_accel_rad_s2"][0]
    assert res["turbine_torque_nm"][0] == pytest.approx(ref["turbine_torque_nm"][0] + rate_torque, rel=1e-6)


def _fluid_coupling_kg_m2(spec: dict) -> float:
    """ρ²S_t²·I_p/(I_p·ρL_f/A − ρ²S_p²): the turbine torque per turbine acceleration the flow takes
    back in eqs 2.12–2.15 with the pump free and the stator locked (0 without a flow row)."""
    if spec["kind"] != "hrovat-tobler":
        return 0.0
    area, rho = spec["geometry"][0], spec["geometry"][1]
    (ip, _, _), (sp, st, _) = spec["inertia_kg_m2"], spec["shape_effect_m2"]
    return (rho * st) ** 2 * ip / (ip * rho * spec["fluid_length_m"] / area - (rho * sp) ** 2)


def _step_with_rates(path: Path, inputs: tuple[str, str], t, a, b, h: float = STEP_S) -> dict[str, np.ndarray]:
    """Co-simulate through FMU2Slave, giving each interval's inputs and their rates
    (``fmi2SetRealInputDerivatives``, canInterpolateInputs): the inputs are linear within each interval."""
    md = fmpy.read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    out_names = [v.name for v in md.modelVariables if v.causality == "output"]
    unzip = fmpy.extract(str(path))
    slave = FMU2Slave(
        guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="rates"
    )
    ins = [vr[n] for n in inputs]
    outs = [vr[n] for n in out_names]
    try:
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal(ins, [a[0], b[0]])
        slave.exitInitializationMode()
        times, rows = [0.0], [slave.getReal(outs)]
        for k in range(int(round(t[-1] / h))):
            t0, t1 = k * h, (k + 1) * h
            u0 = [float(np.interp(t0, t, a)), float(np.interp(t0, t, b))]
            u1 = [float(np.interp(t1, t, a)), float(np.interp(t1, t, b))]
            slave.setReal(ins, u0)
            slave.setRealInputDerivatives(ins, [1, 1], [(u1[0] - u0[0]) / h, (u1[1] - u0[1]) / h])
            slave.doStep(t0, h)
            times.append(t1)
            rows.append(slave.getReal(outs))
        slave.terminate()
    finally:
        slave.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)
    r = np.array(rows)
    return {"time": np.array(times), **{n: r[:, i] for i, n in enumerate(out_names)}}


@pytest.mark.parametrize("model", MODELS)
def test_cosimulation_with_input_rates_matches_replay(fmus, takeoff, model):
    """With the inputs' rates given (first-order hold), the FMU follows the replay run within the
    0.5 % tube at every communication point after the start, with no time tolerance."""
    t, tp, wt = takeoff["time"], takeoff["pump_torque_nm"], takeoff["turbine_speed_rad_s"]
    ref = simulate(CONVERTER, PumpTorqueTurbineSpeed(t, tp, wt), model=model)
    res = _step_with_rates(fmus[(model, "pump-torque")], ("pump_torque_nm", "turbine_speed_rad_s"), t, tp, wt)
    later = res["time"] > 0
    for col in ("pump_speed_rad_s", "turbine_torque_nm"):
        excess = _tube_excess(res["time"][later], res[col][later], ref["time_s"], ref[col], 0.0)
        assert excess.max() == 0.0, (col, res["time"][later][excess > 0][:5], excess.max())


@pytest.mark.parametrize("model", MODELS)
def test_speeds_causality_simulates(fmus, takeoff, model):
    """Both speeds in, the torques out, against the transient engine's drive (b).

    The pump torque carries I_p·ω̇_p of a prescribed speed, so it is as good as that rate: a
    communication interval sees the interval's mean rate (first-order hold), which at 10 ms
    intervals is percent of the range away from the instantaneous rate during the torque ramp, and
    the replay's default derivative smoothing (40 ms) differs as much. Checked: at 10 ms intervals
    (FMPy) the run completes and the turbine torque is in the tube; with the inputs' rates at the
    measurement's own 1 ms interval both torques follow ``tcsim replay --drive speeds --window 0``
    within the 0.5 % tube at every communication point."""
    t, wp, wt = takeoff["time"], takeoff["pump_speed_rad_s"], takeoff["turbine_speed_rad_s"]
    path = fmus[(model, "speeds")]
    res = fmpy.simulate_fmu(
        str(path),
        fmi_type="CoSimulation",
        input=_input(takeoff, ("pump_speed_rad_s", "turbine_speed_rad_s")),
        output_interval=STEP_S,
        stop_time=STOP_S,
    )
    assert res["time"][-1] == pytest.approx(STOP_S)
    for col in ("pump_torque_nm", "turbine_torque_nm", "speed_ratio", "effective_torque_ratio"):
        assert np.all(np.isfinite(res[col])), col
    ref = simulate(CONVERTER, Speeds(t, wp, wt), model=model)
    later = res["time"] > 1.5 * STEP_S
    excess = _tube_excess(
        res["time"][later], res["turbine_torque_nm"][later], ref["time_s"], ref["turbine_torque_nm"], STEP_S
    )
    assert excess.max() == 0.0, excess.max()

    ref = simulate(CONVERTER, Speeds(t, wp, wt, derivative_window_s=0.0), model=model)
    rated = _step_with_rates(path, ("pump_speed_rad_s", "turbine_speed_rad_s"), t, wp, wt, h=1e-3)
    later = rated["time"] > 0
    for col in ("pump_torque_nm", "turbine_torque_nm"):
        excess = _tube_excess(rated["time"][later], rated[col][later], ref["time_s"], ref[col], 0.0)
        assert excess.max() == 0.0, (col, rated["time"][later][excess > 0][:5], excess.max())


# ---------------------------------------------------------------------------------------------
# errors and repeated use


def test_inadmissible_shape_effect_is_an_fmi_error(fmus, capfd):
    """A shape effect beyond the mass-matrix bound: fmi2Error with the reason through the logger,
    FMPy raises, the process lives on (and can simulate again)."""
    path = str(fmus[("hrovat-tobler", "pump-torque")])
    with pytest.raises(Exception, match="fmi2ExitInitializationMode failed"):
        fmpy.simulate_fmu(path, fmi_type="CoSimulation", start_values={"pump_shape_effect_m2": 0.5}, stop_time=0.1)
    assert "pump_shape_effect_m2" in capfd.readouterr().out
    res = fmpy.simulate_fmu(path, fmi_type="CoSimulation", stop_time=0.1)
    assert np.all(np.isfinite(res["pump_speed_rad_s"]))


def test_bad_input_value_is_an_fmi_error(fmus, capfd):
    path = fmus[("table", "pump-torque")]
    md = fmpy.read_model_description(str(path))
    unzip = fmpy.extract(str(path))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier="tcsim_converter", instanceName="bad")
    try:
        slave.instantiate()
        with pytest.raises(Exception, match="fmi2SetReal"):
            slave.setReal([0], [float("nan")])
        with pytest.raises(Exception, match="fmi2SetReal"):
            slave.setReal([3], [1.0])  # an output
    finally:
        slave.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB


@pytest.mark.parametrize("model", ["hrovat-tobler"])
def test_repeated_instantiate_reset_free_does_not_leak(fmus, model):
    """1000 cycles of load, instantiate, set up, initialise, step, terminate, reset, again, and free
    in one process: the peak RSS grows by less than 4 MB between cycle 100 and cycle 1000."""
    path = fmus[(model, "pump-torque")]
    md = fmpy.read_model_description(str(path))
    unzip = fmpy.extract(str(path))
    rss = {}
    try:
        for cycle in range(1, 1001):
            slave = FMU2Slave(
                guid=md.guid, unzipDirectory=unzip, modelIdentifier="tcsim_converter", instanceName=f"c{cycle}"
            )
            slave.instantiate()
            for _ in range(2):  # the second time after fmi2Reset
                slave.setupExperiment(startTime=0.0)
                slave.enterInitializationMode()
                slave.setReal([0, 2], [100.0, 0.0])
                slave.exitInitializationMode()
                for k in range(3):
                    slave.setReal([0, 2], [100.0 + 50.0 * k, 5.0 * k])
                    slave.doStep(0.01 * k, 0.01)
                assert np.isfinite(slave.getReal([1, 3])).all()
                slave.terminate()  # fmi2Terminate is allowed after a step, not after fmi2Reset
                slave.reset()
            slave.freeInstance()
            if cycle in (100, 1000):
                rss[cycle] = _rss_mb()
    finally:
        shutil.rmtree(unzip, ignore_errors=True)
    assert rss[1000] - rss[100] < 4.0, rss


# ---------------------------------------------------------------------------------------------
# the API's and the command line's errors


def test_export_api_input_errors(library_env, tmp_path):
    # errors of the API name its arguments (the command line shows them as its options)
    with pytest.raises(InputError, match="^argument: model = 'no-such-model'"):
        tfmu.export_fmu(CONVERTER, "no-such-model", tmp_path / "x.fmu")
    with pytest.raises(InputError, match="^argument: causality = 'turbine-torque'") as e:
        tfmu.export_fmu(CONVERTER, "table", tmp_path / "x.fmu", causality="turbine-torque")
    assert str(e.value.on_command_line()).startswith("command line: --causality = 'turbine-torque'")
    with pytest.raises(InputError, match=r"^argument: out_path = .*\.fmu") as e:
        tfmu.export_fmu(CONVERTER, "table", tmp_path / "x.zip")
    assert str(e.value.on_command_line()).startswith("command line: --out = ")
    with pytest.raises(InputError, match="shape_effect"):  # beyond the mass-matrix bound: refused at export
        tfmu.export_fmu(
            dynamic_model(CONVERTER, "hrovat-tobler").with_shape_effects(0.5, 0.5), None, tmp_path / "x.fmu"
        )
    assert list(tmp_path.iterdir()) == []


def test_libraries_of_several_platforms(library_env, tmp_path, monkeypatch):
    """$TCSIM_FMU_LIBRARY may list one library per platform; each goes to its binaries/ directory."""
    dll = tmp_path / "tcsim_fmu.dll"  # stands in for a Windows build: same exports
    shutil.copyfile(library_env, dll)
    monkeypatch.setenv(tfmu.LIBRARY_ENV, os.pathsep.join([str(library_env), str(dll)]))
    path = tfmu.export_fmu(CONVERTER, "table", tmp_path / "two.fmu")
    names = zipfile.ZipFile(path).namelist()
    assert "binaries/linux64/tcsim_converter.so" in names and "binaries/win64/tcsim_converter.dll" in names
    monkeypatch.setenv(tfmu.LIBRARY_ENV, str(tmp_path / "two.fmu"))
    with pytest.raises(tfmu.FmuLibraryError, match=r"\.so, \.dll or \.dylib"):
        tfmu.export_fmu(CONVERTER, "table", tmp_path / "three.fmu")


def test_missing_library_is_a_clear_failure(monkeypatch, tmp_path):
    monkeypatch.setenv(tfmu.LIBRARY_ENV, str(tmp_path / "nowhere.so"))
    with pytest.raises(tfmu.FmuLibraryError, match="nowhere.so"):
        tfmu.export_fmu(CONVERTER, "table", tmp_path / "x.fmu")
    assert list(tmp_path.iterdir()) == []


def test_cli_export_fmu(cli, library_env, tmp_path):
    out = tmp_path / "sub" / "ht.fmu"
    r = cli("export-fmu", CONVERTER, "--model", "hrovat-tobler", "-o", out, "--causality", "speeds")
    assert r.code == 0, (r.stdout, r.stderr)
    assert out.is_file() and validate_fmu(str(out)) == []
    assert json.loads(zipfile.ZipFile(out).read("resources/model.json"))["causality"] == "speeds"
    assert [p.name for p in out.parent.iterdir()] == ["ht.fmu"], "no temporary file left"
    # the summary names every input the FMU declares (it left out turbine_accel_rad_s2: a trial)
    declared = [
        v.get("name")
        for v in ElementTree.fromstring(zipfile.ZipFile(out).read("modelDescription.xml")).iter("ScalarVariable")
        if v.get("causality") == "input"
    ]
    assert "turbine_accel_rad_s2" in declared and f"inputs {', '.join(declared)};" in " ".join(r.stdout.split())


@pytest.mark.parametrize(
    "args, field",
    [
        (("--model", "nonsense"), "--model"),
        (("--model", "table", "--causality", "turbine-torque"), "--causality"),
    ],
)
def test_cli_export_fmu_bad_input_is_exit_2(cli, library_env, tmp_path, args, field):
    out = tmp_path / "x.fmu"
    r = cli("export-fmu", CONVERTER, *args, "-o", out)
    assert r.code == 2, (r.code, r.stdout, r.stderr)
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and field in lines[0] and "Traceback" not in r.stderr
    assert not out.exists()


def test_cli_export_fmu_missing_library_is_exit_1(cli, tmp_path, monkeypatch):
    monkeypatch.setenv(tfmu.LIBRARY_ENV, str(tmp_path / "nowhere.so"))
    r = cli("export-fmu", CONVERTER, "--model", "table", "-o", tmp_path / "x.fmu")
    assert r.code == 1 and "nowhere.so" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "x.fmu").exists()


def test_outputs_in_initialisation_mode_are_the_steady_state(fmus):
    """FMI 2.0 lets an importer read outputs in initialisation mode (Simulink and Dymola do): they
    are the steady state for the inputs set so far, as after fmi2ExitInitializationMode."""
    path = fmus[("hrovat-tobler", "pump-torque")]
    md = fmpy.read_model_description(str(path))
    unzip = fmpy.extract(str(path))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier="tcsim_converter", instanceName="init")
    try:
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal([0, 2], [120.0, 50.0])
        during = slave.getReal([1, 3])
        slave.exitInitializationMode()
        after = slave.getReal([1, 3])
        assert during == pytest.approx(after, rel=1e-12)
        steady = simulate(
            CONVERTER,
            PumpTorqueTurbineSpeed([0.0, 1.0], [120.0, 120.0], [50.0, 50.0]),
            model="hrovat-tobler",
            times_s=[0.0, 1e-6],
        )
        assert after[0] == pytest.approx(steady["pump_speed_rad_s"][0], rel=1e-9)
        slave.terminate()
    finally:
        slave.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


@pytest.mark.parametrize("model", MODELS)
def test_model_exchange_with_cvode_matches_the_engine(fmus, model):
    """Model Exchange: FMPy integrates the FMU's states with CVode, handling the stator-clutch
    events through the event indicators; the result stays within the 0.5 % tube of the engine run
    with the same inputs (the turbine speed's rate connected to turbine_accel_rad_s2).

    FMPy's Model Exchange driver sets the inputs once per output interval and holds them, so the
    FMU sees the torque ramp as a staircase: at 10 ms intervals that alone puts the table model's
    pump speed 2 % of its range behind the ramp. The run uses 1 ms intervals, and the tube allows
    one interval in time, as for Co-Simulation."""
    path = str(fmus[(model, "pump-torque")])
    t = np.round(np.arange(0.0, 10.0 + 1e-9, 0.01), 6)
    tp = np.interp(t, [0.0, 0.1, 0.3, 10.0], [40.0, 40.0, 250.0, 250.0])
    wt = 32.0 * t  # passes the coupling point: the stator releases (Hrovat & Tobler)
    inp = np.array(
        list(zip(t, tp, wt, np.full_like(t, 32.0))),
        dtype=[
            ("time", float),
            ("pump_torque_nm", float),
            ("turbine_speed_rad_s", float),
            ("turbine_accel_rad_s2", float),
        ],
    )
    res = fmpy.simulate_fmu(
        path,
        fmi_type="ModelExchange",
        input=inp,
        output_interval=1e-3,
        stop_time=10.0,
        output=["pump_speed_rad_s", "turbine_torque_nm"],
    )
    ref = simulate(
        CONVERTER,
        PumpTorqueTurbineSpeed(
            [0.0, 0.1, 0.3, 10.0], [40.0, 40.0, 250.0, 250.0], [0.0, 3.2, 9.6, 320.0], derivative_window_s=0.0
        ),
        model=model,
        times_s=np.round(np.arange(0.0, 10.0 + 1e-9, 1e-3), 6),
    )
    for col in ("pump_speed_rad_s", "turbine_torque_nm"):
        excess = _tube_excess(res["time"], res[col], ref["time_s"], ref[col], 1e-3)
        assert excess.max() == 0.0, (col, excess.max())
    if model == "hrovat-tobler":
        stator = fmpy.simulate_fmu(
            path,
            fmi_type="ModelExchange",
            input=inp,
            output_interval=0.01,
            stop_time=10.0,
            output=["stator_speed_rad_s"],
        )["stator_speed_rad_s"]
        assert stator[0] == 0.0 and stator[-1] > 0.0  # locked at stall, released past the coupling point


def test_start_values_override_the_steady_state(fmus):
    """Initialisation matches tcsim replay (the steady state consistent with the inputs) unless the
    start values are set: start_from_steady_state = 0 and initial_*."""
    path = str(fmus[("hrovat-tobler", "pump-torque")])
    inp = np.array(
        [(0.0, 100.0, 0.0), (0.1, 100.0, 0.0)],
        dtype=[("time", float), ("pump_torque_nm", float), ("turbine_speed_rad_s", float)],
    )
    steady = fmpy.simulate_fmu(path, fmi_type="CoSimulation", input=inp, output_interval=0.01, stop_time=0.1)
    replay = simulate(CONVERTER, PumpTorqueTurbineSpeed([0.0, 0.1], [100.0, 100.0], [0.0, 0.0]), model="hrovat-tobler")
    assert steady["pump_speed_rad_s"][0] == pytest.approx(replay["pump_speed_rad_s"][0], rel=1e-9)
    for fmi_type in ("CoSimulation", "ModelExchange"):
        given = fmpy.simulate_fmu(
            path,
            fmi_type=fmi_type,
            input=inp,
            output_interval=0.01,
            stop_time=0.1,
            start_values={"start_from_steady_state": 0.0, "initial_pump_speed_rad_s": 200.0, "initial_flow_m3_s": 0.02},
        )
        assert given["pump_speed_rad_s"][0] == pytest.approx(200.0) and given["flow_m3_s"][0] == pytest.approx(0.02)


@pytest.mark.parametrize("fmi_type", ["ModelExchange", "CoSimulation"])
def test_tip_out_flow_events_in_both_interfaces(fmus, fmi_type):
    """A tip-out (pump torque 250 → −30 N·m at 5 s) with the turbine still driven: the stator
    releases, the flow reaches zero and reverses at once (the reverse-flow form of issue 11: with
    unit shock coefficients F_Q(0⁺) = F_Q(0⁻), so it is not held); both interfaces follow the
    engine run within the 0.5 % tube."""
    path = str(fmus[("hrovat-tobler", "pump-torque")])
    knots, torque = [0.0, 0.1, 0.3, 5.0, 5.1, 8.0], [40.0, 40.0, 250.0, 250.0, -30.0, -30.0]
    t = np.round(np.arange(0.0, 8.0 + 1e-9, 1e-3), 6)
    inp = np.array(
        list(zip(t, np.interp(t, knots, torque), 32.0 * t, np.full_like(t, 32.0))),
        dtype=[
            ("time", float),
            ("pump_torque_nm", float),
            ("turbine_speed_rad_s", float),
            ("turbine_accel_rad_s2", float),
        ],
    )
    res = fmpy.simulate_fmu(
        path,
        fmi_type=fmi_type,
        input=inp,
        output_interval=1e-3,
        stop_time=8.0,
        output=["pump_speed_rad_s", "turbine_torque_nm", "flow_m3_s"],
    )
    ref = simulate(
        CONVERTER,
        PumpTorqueTurbineSpeed(knots, torque, [32.0 * k for k in knots], derivative_window_s=0.0),
        model="hrovat-tobler",
        times_s=t,
    )
    assert [(e.kind, e.flow_direction) for e in ref.events] == [("stator-release", 1.0), ("flow-zero", -1.0)]
    reversed_ = (res["time"] > 5.3) & (res["time"] < 6.4)
    assert (res["flow_m3_s"][reversed_] < 0.0).all()  # reverse flow after the event
    for col in ("pump_speed_rad_s", "turbine_torque_nm"):
        excess = _tube_excess(res["time"], res[col], ref["time_s"], ref[col], 1e-3)
        assert excess.max() == 0.0, (col, excess.max())


def test_a_torque_dependent_converter_runs_in_the_fmu(library_env, tmp_path):
    """Issue 12: the FMU's model.json carries the tables of a torque-dependent converter and the FMU
    solves the pump torque's fixed point as the engine does (speeds given, held constant)."""
    doc = load_converter(CONVERTER).to_toml_dict()
    c1 = doc.pop("characteristic")
    heavy = {**c1, "capacity_factor_nm_s2": [0.8 * c for c in c1["capacity_factor_nm_s2"]]}
    doc["characteristic"] = [{"input_torque_nm": 100.0, **c1}, {"input_torque_nm": 300.0, **heavy}]
    conv = tmp_path / "two.toml"
    conv.write_text(tomli_w.dumps(doc))
    path = tfmu.export_fmu(str(conv), "table", tmp_path / "two.fmu", causality="speeds")
    spec = json.loads(zipfile.ZipFile(path).read("resources/model.json"))
    assert "input_torque_nm" in json.dumps(spec)
    inp = np.array(
        [(0.0, 250.0, 50.0), (1.0, 250.0, 50.0)],
        dtype=[("time", float), ("pump_speed_rad_s", float), ("turbine_speed_rad_s", float)],
    )
    res = fmpy.simulate_fmu(str(path), fmi_type="CoSimulation", input=inp, output_interval=0.1, stop_time=1.0)
    ref = steady_state(str(conv), "table", 250.0, 50.0)["pump_torque_nm"][0]
    assert 163.6 < ref < 204.5  # between the two tables' torques at these speeds
    np.testing.assert_allclose(res["pump_torque_nm"][1:], ref, rtol=1e-9)
