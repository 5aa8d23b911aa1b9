"""Every FMU ``tcsim export-fmu`` writes, simulated in an FMU importer this project did not write.

The importer is ``fmi-sim`` (crates.io, the rust-fmi project: a pure-Rust FMI 2.0/3.0 simulator of
Model Exchange and Co-Simulation whose algorithms follow the Modelica Association's ``fmusim``),
pinned and installed by ``tools/install_importers.sh`` (CI runs it; the script owns the version and
the path). Without it these tests fail with the command that installs it: they never skip.

Each FMU (model × causality × FMI version) runs in both interfaces, driven by the recorded take-off
``tests/golden/data/takeoff_measurement.csv`` (3 s at 1 kHz), and is compared with the run
``tcsim replay`` makes of the same record (:func:`tcsim.transient.simulate` with the drive of the
causality, default derivative window):

* Model Exchange: fmi-sim integrates with explicit Euler, one step per output interval
  (:data:`ME_STEP_S`); its inputs include the rates (``*_accel_rad_s2``), given as the replay's own
  smoothed derivatives, so FMU and engine see the same input. Every output is within
  :data:`TOLERANCE` of the replay's range at every sample.
* Co-Simulation: fmi-sim sets the inputs at each communication point (:data:`CS_STEP_S`) and gives
  no rates, as most masters do; every output lies in the tube of ±1 communication interval and
  ±:data:`TOLERANCE` of the range around the replay, after the first interval (at the start the
  FMU cannot know the inputs' rates). The speeds causality is the exception
  (:data:`RATES_IN_COSIMULATION`): its pump torque holds ``I_p·dω_p/dt`` of the prescribed pump
  speed, which a master must give (the rate inputs, as in Model Exchange), at a step short enough
  for that acceleration (:data:`STEPS_S`).

What the speeds causality does without the rates is shown by a strict xfail
(:data:`WITHOUT_RATES`). A new FMI version or causality joins by extending :data:`FMI_VERSIONS`
or :data:`REPLAY_DRIVES`.
The last tests unpack an FMU into folders whose names hold a space, ``+``, ``(`` and ``ö``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from collections.abc import Callable
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pandas as pd
import pytest

from tcsim.cli import main
from tcsim.io import fmu as tfmu
from tcsim.transient import PumpTorqueLoad, PumpTorqueTurbineSpeed, Speeds, TransientResult, simulate

REPO = Path(__file__).resolve().parents[2]
INSTALL = REPO / "tools" / "install_importers.sh"
MEASUREMENT = REPO / "tests" / "golden" / "data" / "takeoff_measurement.csv"
CONVERTER = "li-sunden-2016"
MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
#: ``tcsim export-fmu --fmi-version`` values to test (FMI 3.0 joins as "3"); "2" is the default
#: and is exported without the flag.
FMI_VERSIONS = ("2", "3")
#: The replay drive of each ``--causality``, made from the measurement's columns (SI, conventions.md).
REPLAY_DRIVES: dict[str, Callable[[pd.DataFrame], PumpTorqueTurbineSpeed | Speeds | PumpTorqueLoad]] = {
    "pump-torque": lambda m: PumpTorqueTurbineSpeed(m["time_s"], m["pump_torque_nm"], m["turbine_speed_rad_s"]),
    "speeds": lambda m: Speeds(m["time_s"], m["pump_speed_rad_s"], m["turbine_speed_rad_s"]),
    # drive (c) with the FMU's defaults (no load inertia, no drag): the measured pump torque and a load
    # of half the measured turbine torque, so that the turbine accelerates as in the take-off
    "torques": lambda m: PumpTorqueLoad(m["time_s"], m["pump_torque_nm"], 0.0, load_torque_nm=m["load_torque_nm"]),
}
INTERFACES = ("model-exchange", "co-simulation")
#: Acceptance: 0.5 % of the replay signal's range (issue 13).
TOLERANCE = 0.005
#: fmi-sim's explicit Euler step in Model Exchange (its step is the output interval), s.
ME_STEP_S = 1e-3
#: Communication interval of the Co-Simulation runs, s.
CS_STEP_S = 1e-2
#: Steps of the torques causality (both speeds are states, the turbine with only its own inertia):
#: fmi-sim's explicit Euler needs 0.1 ms for Hrovat & Tobler's fast flow mode (at 1 ms it diverges:
#: measured), and the communication interval is 1 ms as in the FMPy test of that causality.
#: The speeds causality in Co-Simulation: 1 ms. A step's outputs combine the pump speed at its end
#: with the rate given at its start, an error of ``I_p·h·d²ω_p/dt²`` where the replay's terms cancel
#: (the measured pump torque is constant after its ramp): measured 0.38-0.45 % of the range at 1 ms,
#: 0.75-0.90 % at 2 ms, 3.5-4.6 % at 10 ms (first order in the step).
STEPS_S: dict[tuple[str, str], float] = {
    ("torques", "model-exchange"): 1e-4,
    ("torques", "co-simulation"): 1e-3,
    ("speeds", "co-simulation"): 1e-3,
}
#: Causalities whose Co-Simulation inputs include the rates (the rate inputs ``*_accel_rad_s2``, set
#: at each communication point): the speeds causality, whose pump torque holds ``I_p·dω_p/dt``.
RATES_IN_COSIMULATION = frozenset({"speeds"})
#: Hang guard of one importer run (a subprocess), s.
RUN_TIMEOUT_S = 300


# ---------------------------------------------------------------------------------------------
# the importer


def _pinned_version() -> str:
    """The fmi-sim version that tools/install_importers.sh pins (its FMI_SIM_VERSION= line)."""
    for line in INSTALL.read_text().splitlines():
        if line.startswith("FMI_SIM_VERSION="):
            return line.split("=", 1)[1].strip()
    raise AssertionError(f"{INSTALL}: no FMI_SIM_VERSION= line")


@pytest.fixture(scope="session")
def fmi_sim() -> Path:
    """The pinned fmi-sim binary where tools/install_importers.sh puts it; a missing or other
    version fails the test with the command that installs it."""
    where = subprocess.run(["bash", str(INSTALL), "--where"], capture_output=True, text=True, check=True, timeout=60)
    binary = Path(where.stdout.strip())
    how = f"run `bash {INSTALL.relative_to(REPO)}` (CI does)"
    if not binary.is_file():
        pytest.fail(f"the FMU importer fmi-sim {_pinned_version()} is not installed ({binary}): {how}", pytrace=False)
    said = subprocess.run([binary, "--version"], capture_output=True, text=True, timeout=60)
    version = (said.stdout + said.stderr).strip().removeprefix("Error: ").splitlines()[0]  # 0.7.0 says it on stderr
    if version != f"fmi-sim {_pinned_version()}":
        pytest.fail(f"{binary}: {version!r}, expected fmi-sim {_pinned_version()}: {how}", pytrace=False)
    return binary


def _run_importer(
    fmi_sim: Path,
    fmu: Path,
    interface: str,
    inputs: pd.DataFrame,
    step_s: float,
    stop_s: float,
    workdir: Path,
    env: dict[str, str] | None = None,
) -> pd.DataFrame:
    """Simulate ``fmu`` in fmi-sim (``interface``: model-exchange or co-simulation) from t = 0 to
    ``stop_s`` (s) with outputs every ``step_s`` (s) and ``inputs`` (a ``time`` column in s and one
    column per FMU input, linearly interpolated by fmi-sim); the output table, or AssertionError
    with the importer's message."""
    workdir.mkdir(parents=True, exist_ok=True)
    inp, out = workdir / f"{interface}-input.csv", workdir / f"{interface}-output.csv"
    # every value with a decimal point: fmi-sim infers each column's type from its first rows
    inputs.to_csv(inp, index=False, float_format="%.17e")
    args = [fmi_sim, "--model", fmu, "-i", inp, "-o", out, interface]
    args += ["--output-interval", repr(step_s), "-s", "0", "-f", repr(stop_s)]
    env = dict(os.environ if env is None else env, RUST_BACKTRACE="0")  # its error in one line
    p = subprocess.run(list(map(str, args)), capture_output=True, text=True, env=env, timeout=RUN_TIMEOUT_S)
    if p.returncode != 0 or not out.is_file():
        raise AssertionError(f"fmi-sim {interface} of {fmu.name} failed (exit {p.returncode}): {p.stderr.strip()}")
    return pd.read_csv(out)


# ---------------------------------------------------------------------------------------------
# the FMUs and the reference


@pytest.fixture(scope="module")
def fmus(fmu_library, tmp_path_factory) -> dict[tuple[str, str, str], Path]:
    """Every FMU, written by ``tcsim export-fmu`` (in-process) with the build's library."""
    out = tmp_path_factory.mktemp("fmus")
    written = {}
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(tfmu.LIBRARY_ENV, str(fmu_library))
        for version in FMI_VERSIONS:
            for model in MODELS:
                for causality in tfmu.CAUSALITIES:
                    path = out / f"{model}-{causality}-fmi{version}.fmu"
                    flag = [] if version == "2" else ["--fmi-version", version]
                    args = ["export-fmu", CONVERTER, "--model", model, "--causality", causality, "-o", str(path)]
                    assert main(args + flag) == 0, args + flag
                    written[(model, causality, version)] = path
    return written


@pytest.fixture(scope="module")
def measurement() -> pd.DataFrame:
    m = pd.read_csv(MEASUREMENT)
    return m.assign(load_torque_nm=0.5 * m["turbine_torque_nm"])  # the torques causality's load input


_REPLAYS: dict[tuple[str, str], TransientResult] = {}


def _replay(measurement: pd.DataFrame, model: str, causality: str) -> TransientResult:
    """The run ``tcsim replay --drive <causality>`` makes of the measurement (cached per module run)."""
    if causality not in REPLAY_DRIVES:
        pytest.fail(f"causality {causality!r} has no replay drive: add it to REPLAY_DRIVES", pytrace=False)
    if (model, causality) not in _REPLAYS:
        _REPLAYS[(model, causality)] = simulate(CONVERTER, REPLAY_DRIVES[causality](measurement), model=model)
    return _REPLAYS[(model, causality)]


def _variables(fmu: Path, causality: str) -> list[str]:
    """Names of the FMU's variables of ``causality`` (input, output), FMI 2.0 or 3.0 alike."""
    with zipfile.ZipFile(fmu) as zf:
        root = ElementTree.fromstring(zf.read("modelDescription.xml"))
    variables = root.find("ModelVariables")
    assert variables is not None, fmu
    return [v.get("name", "") for v in variables if v.get("causality") == causality]


def _importer_inputs(
    fmu: Path, rates: bool, causality: str, ref: TransientResult | None, meas: pd.DataFrame
) -> pd.DataFrame:
    """The input table of a run: the causality's two inputs from the measurement; with ``rates``
    also the FMU's rate inputs, the replay's derivatives of the same record."""
    columns = {"time": meas["time_s"].to_numpy()}
    for name in tfmu.CAUSALITIES[causality]:
        columns[name] = meas[name].to_numpy()
    if rates:
        for name in _variables(fmu, "input"):
            if name not in columns and name not in tfmu.COMMON_INPUTS:  # the clutch's command: its start, 0
                assert ref is not None and name in ref.columns, f"the replay has no column {name!r} for the FMU's input"
                columns[name] = ref[name]
    return pd.DataFrame(columns)


def _deviation(t, y, t_ref, y_ref, window_s: float) -> float:
    """Largest distance of the samples (t, y) from the reference (t_ref, y_ref) in units of its
    range: from its envelope over [t − window_s, t + window_s] (0: its value at t)."""
    span = float(np.max(y_ref) - np.min(y_ref))
    lo = np.array([np.min(y_ref[(t_ref >= ti - window_s - 1e-9) & (t_ref <= ti + window_s + 1e-9)]) for ti in t])
    hi = np.array([np.max(y_ref[(t_ref >= ti - window_s - 1e-9) & (t_ref <= ti + window_s + 1e-9)]) for ti in t])
    return float(np.max(np.maximum(np.maximum(lo - y, y - hi), 0.0)) / span)


# ---------------------------------------------------------------------------------------------
# every FMU in both interfaces


#: The speeds causality in Co-Simulation without the rates (a master that does not give them): the
#: outputs that leave the band and why (test_speeds_cosimulation_without_rates; strict, so a change
#: is noticed).
WITHOUT_RATES = (
    frozenset({"pump_torque_nm", "torque_ratio"}),
    "without the rates the FMU estimates the pump speed's rate from the last interval of the sampled "
    "record (a backward difference, 1.5 intervals before the outputs and unsmoothed): at 1 ms "
    "pump_torque_nm 1.8-2.2 % and torque_ratio 15 % of the range outside the tube (docs/fmu.md)",
)


def _deviations(
    fmi_sim, fmus, measurement, tmp_path, case: tuple[str, str, str], interface: str, rates: bool | None = None
) -> dict[str, float]:
    """Run one FMU in fmi-sim; each output's distance from the replay in units of its range (Model
    Exchange: pointwise; Co-Simulation: from the ±1 interval tube, after the first interval).
    ``rates``: whether the inputs include the rates (default: Model Exchange and
    :data:`RATES_IN_COSIMULATION`)."""
    model, causality, version = case
    fmu = fmus[case]
    ref = _replay(measurement, model, causality)
    stop_s = float(measurement["time_s"].iloc[-1])
    step_s = STEPS_S.get((causality, interface), ME_STEP_S if interface == "model-exchange" else CS_STEP_S)
    if rates is None:
        rates = interface == "model-exchange" or causality in RATES_IN_COSIMULATION
    inputs = _importer_inputs(fmu, rates, causality, ref, measurement)
    res = _run_importer(fmi_sim, fmu, interface, inputs, step_s, stop_s, tmp_path)

    t = res["time"].to_numpy()
    grid = np.round(np.arange(0.0, stop_s + step_s / 2, step_s), 9)
    # every output point, and in Model Exchange each event's time once more (fmi-sim records before the event)
    assert t[-1] == pytest.approx(stop_s) and np.all(np.diff(t) >= 0.0) and set(grid) <= set(np.round(t, 9))
    outputs = _variables(fmu, "output")
    assert set(outputs) == set(res.columns) - {"time"}, "fmi-sim records every output"
    compared = [name for name in outputs if not np.isnan(ref[name]).all()]
    assert set(tfmu.CAUSALITIES[causality]).isdisjoint(compared) and len(compared) >= 4, compared
    later = t > (0.0 if interface == "model-exchange" else 1.5 * step_s)
    if interface == "model-exchange":  # pointwise: at the replay's samples (a finer Euler step has more)
        later &= np.isin(np.round(t, 9), np.round(np.asarray(ref["time_s"]), 9))
    window_s = 0.0 if interface == "model-exchange" else step_s
    return {
        name: _deviation(t[later], res[name].to_numpy()[later], ref["time_s"], ref[name], window_s) for name in compared
    }


def _percent(deviations: dict[str, float]) -> dict[str, str]:
    return {k: f"{100 * v:.3f} % of range" for k, v in deviations.items()}


@pytest.mark.parametrize("interface", INTERFACES)
@pytest.mark.parametrize("version", FMI_VERSIONS)
@pytest.mark.parametrize("causality", list(tfmu.CAUSALITIES))
@pytest.mark.parametrize("model", MODELS)
def test_importer_matches_replay(fmi_sim, fmus, measurement, tmp_path, model, causality, version, interface):
    """Every output within the band."""
    deviations = _deviations(fmi_sim, fmus, measurement, tmp_path, (model, causality, version), interface)
    assert max(deviations.values()) <= TOLERANCE, str(_percent(deviations))


@pytest.mark.parametrize("version", FMI_VERSIONS)
@pytest.mark.parametrize("model", MODELS)
def test_speeds_cosimulation_without_rates(fmi_sim, fmus, measurement, tmp_path, model, version):
    """Without the rates, the outputs that do not hold the pump speed's rate stay within the band;
    those of :data:`WITHOUT_RATES` are checked by the strict xfail below."""
    deviations = _deviations(fmi_sim, fmus, measurement, tmp_path, (model, "speeds", version), "co-simulation", False)
    checked = {k: v for k, v in deviations.items() if k not in WITHOUT_RATES[0]}
    assert checked and max(checked.values()) <= TOLERANCE, _percent(checked)


@pytest.mark.xfail(strict=True, reason=WITHOUT_RATES[1])
@pytest.mark.parametrize("model", MODELS)
def test_speeds_cosimulation_without_rates_lags(fmi_sim, fmus, measurement, tmp_path, model):
    """The outputs of :data:`WITHOUT_RATES` within the band (they are not: the estimate lags)."""
    deviations = _deviations(fmi_sim, fmus, measurement, tmp_path, (model, "speeds", "2"), "co-simulation", False)
    lagging = {k: v for k, v in deviations.items() if k in WITHOUT_RATES[0]}
    assert lagging and max(lagging.values()) <= TOLERANCE, _percent(lagging)


# ---------------------------------------------------------------------------------------------
# unpacked into folders with awkward names (the resource URI, issue 13 item 2)

#: Folder names. fmi-sim (the url crate's path set) percent-encodes the space and ö in the resource
#: URI it passes, FMPy (pathlib's as_uri) all but letters, digits and ``-_.~/``; the FMU decodes
#: them all (issue 13 item 2; these cases failed before, shown by strict xfails until the fix).
FOLDERS = ("plain", "with space", "with+plus", "with(paren", "with-ö", "unpack dir +(ö)")


SHORT_STOP_S = 0.1


@pytest.fixture(scope="module")
def plain_run(fmi_sim, fmus, measurement, tmp_path_factory) -> pd.DataFrame:
    """The Co-Simulation run of the short case from the plain temporary folder."""
    fmu = fmus[("hrovat-tobler", "pump-torque", "2")]
    inputs = _importer_inputs(fmu, False, "pump-torque", None, measurement)
    workdir = tmp_path_factory.mktemp("plain")
    return _run_importer(fmi_sim, fmu, "co-simulation", inputs, CS_STEP_S, SHORT_STOP_S, workdir)


@pytest.mark.parametrize("folder", FOLDERS)
def test_importer_unpacks_into_an_awkward_folder(fmi_sim, fmus, measurement, plain_run, tmp_path, folder):
    """fmi-sim unpacks the FMU into a temporary folder under $TMPDIR: named ``folder`` here, with
    the FMU file in it too. The run is the run from the plain temporary folder."""
    where = tmp_path / folder
    where.mkdir()
    fmu = Path(shutil.copy(fmus[("hrovat-tobler", "pump-torque", "2")], where / "converter.fmu"))
    inputs = _importer_inputs(fmu, False, "pump-torque", None, measurement)
    env = dict(os.environ, TMPDIR=str(where))
    res = _run_importer(fmi_sim, fmu, "co-simulation", inputs, CS_STEP_S, SHORT_STOP_S, where, env=env)
    pd.testing.assert_frame_equal(res, plain_run, check_exact=True)
    assert [p.name for p in where.iterdir() if p.name.startswith("fmi-rs")] == [], "fmi-sim removed what it unpacked"


@pytest.mark.parametrize("folder", FOLDERS)
def test_fmpy_runs_from_an_awkward_folder(fmus, tmp_path, folder):
    """FMPy, from the FMU unpacked into a folder named ``folder``: the same run as from the archive."""
    fmpy = pytest.importorskip("fmpy")
    archive = fmus[("hrovat-tobler", "pump-torque", "2")]
    unpacked = tmp_path / folder / "converter"
    fmpy.extract(str(archive), unzipdir=str(unpacked))
    options = {"fmi_type": "CoSimulation", "output_interval": CS_STEP_S, "stop_time": SHORT_STOP_S}
    try:
        res = fmpy.simulate_fmu(str(unpacked), **options)
    except Exception as e:  # FMPy raises Exception for an fmi2Error
        raise AssertionError(f"FMPy from {unpacked}: {e}") from e
    np.testing.assert_array_equal(res, fmpy.simulate_fmu(str(archive), **options))
