"""FMI 2.0 conformance of the FMU library, through its C API as the independent importers call it
(``fmusim`` of the Modelica Association, the FMU Compliance Checker on FMI Library): issue 13,
items 1–8, and the FMU state (``fmi2GetFMUstate`` and its serialisation).

The calls go through ctypes to the built library (the ``fmu_library`` fixture), with the
resources of FMUs exported by ``tcsim.io.fmu.export_fmu``; value references and dependencies are
read from each FMU's ``modelDescription.xml``.
"""

from __future__ import annotations

import ctypes
import json
import math
import shutil
import struct
import zipfile
from pathlib import Path
from urllib.parse import quote
from xml.etree import ElementTree

import pytest

from tcsim.io import fmu as tfmu

CONVERTER = "li-sunden-2016"
MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
OK, ERROR = 0, 3
ME, CS = 0, 1

LOGGER = ctypes.CFUNCTYPE(
    None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p
)


class Callbacks(ctypes.Structure):
    _fields_ = [
        ("logger", LOGGER),
        ("allocate", ctypes.c_void_p),
        ("free", ctypes.c_void_p),
        ("step_finished", ctypes.c_void_p),
        ("environment", ctypes.c_void_p),
    ]


class EventInfo(ctypes.Structure):
    _fields_ = [
        ("new_discrete_states_needed", ctypes.c_int),
        ("terminate_simulation", ctypes.c_int),
        ("nominals_changed", ctypes.c_int),
        ("values_changed", ctypes.c_int),
        ("next_event_time_defined", ctypes.c_int),
        ("next_event_time", ctypes.c_double),
    ]


class Unpacked:
    """An exported FMU, unpacked: its folder, GUID, variables and model structure."""

    def __init__(self, fmu: Path, folder: Path) -> None:
        with zipfile.ZipFile(fmu) as zf:
            zf.extractall(folder)
        self.folder = folder
        root = ElementTree.parse(folder / "modelDescription.xml").getroot()
        self.root = root
        self.guid = root.get("guid", "")
        self.variables = root.findall("ModelVariables/ScalarVariable")
        self.by_name = {v.get("name"): int(v.get("valueReference", "-1")) for v in self.variables}
        self.causality = {int(v.get("valueReference", "-1")): v.get("causality") for v in self.variables}
        self.states = len(root.findall("ModelStructure/Derivatives/Unknown"))
        self.indicators = int(root.get("numberOfEventIndicators", "0"))

    @property
    def uri(self) -> str:
        return (self.folder / "resources").as_uri()

    def vrs(self, causality: str | None = None) -> list[int]:
        return [vr for vr, c in self.causality.items() if causality is None or c == causality]

    def dependencies(self) -> dict[int, set[int]]:
        """Output value reference → the value references of the inputs it depends on directly."""
        vr_of_index = {i: int(v.get("valueReference", "-1")) for i, v in enumerate(self.variables, start=1)}
        out = {}
        for u in self.root.findall("ModelStructure/Outputs/Unknown"):
            deps = (u.get("dependencies") or "").split()
            out[vr_of_index[int(u.get("index", "0"))]] = {vr_of_index[int(d)] for d in deps}
        return out


class Fmi2:
    """One instance of the library through ctypes, with the messages of its logger."""

    def __init__(self, lib: Path, uri: str, guid: str | None, kind: int) -> None:
        self.dll = ctypes.CDLL(str(lib))
        self.messages: list[tuple[int, str, str]] = []
        self._logger = LOGGER(self._log)
        self._callbacks = Callbacks(self._logger, None, None, None, None)
        f = self.dll.fmi2Instantiate
        f.restype = ctypes.c_void_p
        f.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_void_p]
        f.argtypes += [ctypes.c_int, ctypes.c_int]
        g = None if guid is None else guid.encode()
        self.c = f(b"conformance", kind, g, uri.encode(), ctypes.addressof(self._callbacks), 0, 0)

    def _log(self, _env, _name, status, category, _fmt, message) -> None:
        self.messages.append((status, (category or b"").decode(), (message or b"").decode()))

    def __call__(self, name: str, *args) -> int:
        return int(getattr(self.dll, name)(ctypes.c_void_p(self.c), *args))

    def free(self) -> None:
        if self.c:
            self.dll.fmi2FreeInstance(ctypes.c_void_p(self.c))
            self.c = None

    def setup(self, start: float = 0.0) -> int:
        return self("fmi2SetupExperiment", 0, ctypes.c_double(0.0), ctypes.c_double(start), 0, ctypes.c_double(0.0))

    def set(self, values: dict[int, float]) -> int:
        n = len(values)
        vr = (ctypes.c_uint * n)(*values)
        v = (ctypes.c_double * n)(*values.values())
        return self("fmi2SetReal", vr, ctypes.c_size_t(n), v)

    def get(self, vrs: list[int]) -> list[float]:
        n = len(vrs)
        out = (ctypes.c_double * n)()
        status = self("fmi2GetReal", (ctypes.c_uint * n)(*vrs), ctypes.c_size_t(n), out)
        assert status == OK, (status, self.messages)
        return list(out)

    def array(self, name: str, n: int) -> tuple[int, list[float]]:
        out = (ctypes.c_double * max(n, 1))()
        status = self(name, out, ctypes.c_size_t(n))
        return status, list(out)[:n]

    def step(self, t: float, h: float) -> int:
        return self("fmi2DoStep", ctypes.c_double(t), ctypes.c_double(h), 1)

    def start(self, inputs: dict[int, float]) -> None:
        """Set up at t = 0, set the inputs, initialise."""
        assert self.c, self.messages
        assert self.setup() == OK
        assert self("fmi2EnterInitializationMode") == OK
        assert self.set(inputs) == OK
        assert self("fmi2ExitInitializationMode") == OK, self.messages

    def me_step(self, t: float, h: float, n: int) -> None:
        """One explicit Euler step of Model Exchange from t (states read, derivatives, states set)."""
        status, x = self.array("fmi2GetContinuousStates", n)
        status2, dx = self.array("fmi2GetDerivatives", n)
        assert status == status2 == OK, self.messages
        assert self("fmi2SetTime", ctypes.c_double(t + h)) == OK
        new = (ctypes.c_double * n)(*[a + h * b for a, b in zip(x, dx)])
        assert self("fmi2SetContinuousStates", new, ctypes.c_size_t(n)) == OK
        assert self("fmi2CompletedIntegratorStep", 1, ctypes.byref(ctypes.c_int()), ctypes.byref(ctypes.c_int())) == OK


@pytest.fixture(scope="module")
def fmus(fmu_library, tmp_path_factory) -> dict[tuple[str, str], Unpacked]:
    """The six FMUs (3 models × 2 causalities), unpacked."""
    out = tmp_path_factory.mktemp("conformance")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(tfmu.LIBRARY_ENV, str(fmu_library))
        return {
            (m, c): Unpacked(tfmu.export_fmu(CONVERTER, m, out / f"{m}-{c}.fmu", causality=c), out / f"{m}-{c}")
            for m in MODELS
            for c in tfmu.CAUSALITIES
        }


@pytest.fixture
def instance(fmu_library):
    """Instances made by the test, freed at its end."""
    made: list[Fmi2] = []

    def make(fmu: Unpacked, kind: int, uri: str | None = None, guid: str | None = "") -> Fmi2:
        inst = Fmi2(fmu_library, uri or fmu.uri, fmu.guid if guid == "" else guid, kind)
        made.append(inst)
        return inst

    yield make
    for inst in made:
        inst.free()


def _inputs(fmu: Unpacked, causality: str) -> dict[int, float]:
    """A drive point off the steady state's trivial cases: 120 N·m or 180 rad/s at the pump, the
    turbine at 60 rad/s."""
    pump = {"pump-torque": ("pump_torque_nm", 120.0), "speeds": ("pump_speed_rad_s", 180.0)}[causality]
    return {fmu.by_name[pump[0]]: pump[1], fmu.by_name["turbine_speed_rad_s"]: 60.0}


# ---------------------------------------------------------------------------------------------
# 1. every declared variable can be read, in both interfaces


@pytest.mark.parametrize("kind", [ME, CS], ids=["ME", "CS"])
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("causality", ["pump-torque", "speeds"])
def test_every_declared_variable_reads_after_initialisation(fmus, instance, model, causality, kind):
    """fmusim reads every variable after initialisation: all of them, in one call, in both interfaces,
    after initialisation and after a step; the derivatives are those of the state (zero at the steady
    state, the rate of the pump speed after a torque step)."""
    fmu = fmus[(model, causality)]
    inst = instance(fmu, kind)
    inst.start(_inputs(fmu, causality))
    values = inst.get(fmu.vrs())
    assert all(math.isfinite(v) for v in values), dict(zip(fmu.vrs(), values))
    der = [fmu.by_name[n] for n in fmu.by_name if n.startswith("der(")]  # none: the table model's speeds
    assert len(der) == fmu.states and all(abs(d) < 1e-6 for d in inst.get(der))
    if kind == CS and causality == "pump-torque":
        pump, der_pump = fmu.by_name["pump_speed_rad_s"], fmu.by_name["der(pump_speed_rad_s)"]
        assert inst.set({fmu.by_name["pump_torque_nm"]: 200.0}) == OK
        assert inst.step(0.0, 1e-3) == OK
        w1, a1 = inst.get([pump, der_pump])
        assert inst.step(1e-3, 1e-4) == OK
        w2 = inst.get([pump])[0]
        assert a1 > 0.0 and (w2 - w1) / 1e-4 == pytest.approx(a1, rel=0.02)
    assert all(math.isfinite(v) for v in inst.get(fmu.vrs()))


# ---------------------------------------------------------------------------------------------
# 2. the resource URI


def _fmi_library_uri(path: Path) -> str:
    """The URI FMI Library makes: everything but letters, digits and -_.~/ percent-encoded (UTF-8)."""
    return "file://" + quote(path.as_posix(), safe="-_.~/")


def test_resource_uri_forms(fmus, instance, tmp_path):
    """A folder named with a space, '+', '(' and 'ö', as FMI Library encodes it, and the file:/,
    file:/// and file://localhost/ forms; another host is refused with a message."""
    fmu = fmus[("table", "pump-torque")]
    folder = tmp_path / "Jörg Müller+co (test)" / "fmu"
    shutil.copytree(fmu.folder, folder)
    resources = (folder / "resources").as_posix()
    encoded = quote(resources, safe="-_.~/")
    uris = [
        _fmi_library_uri(folder / "resources"),
        "file:" + encoded,
        "file:///" + encoded.lstrip("/"),
        "file://localhost" + encoded,
        "file://LOCALHOST" + encoded + "/",
        "file://" + resources,  # unencoded, as some importers pass it
    ]
    assert "%C3%B6" in uris[0] and "%2B" in uris[0] and "%28" in uris[0] and "%20" in uris[0]
    for uri in uris:
        inst = instance(fmu, CS, uri=uri)
        assert inst.c, (uri, inst.messages)
        inst.start(_inputs(fmu, "pump-torque"))
    refused = instance(fmu, CS, uri="file://fileserver" + encoded)
    assert not refused.c
    assert any('host "fileserver"' in m for _, _, m in refused.messages), refused.messages


# ---------------------------------------------------------------------------------------------
# 3. the direct feedthrough declared is the one measured


def _measured_dependencies(inst: Fmi2, fmu: Unpacked, point: dict[int, float]) -> dict[int, set[int]]:
    """Which outputs change when each input (speeds, torques and rates) moves, the states fixed
    (Model Exchange in continuous-time mode)."""
    outputs = fmu.vrs("output")
    base = dict(zip(outputs, inst.get(outputs)))
    measured: dict[int, set[int]] = {vr: set() for vr in outputs}
    for vr, value in point.items():
        assert inst.set({vr: value * 1.1 + 1.0}) == OK
        for out, v in zip(outputs, inst.get(outputs)):
            if abs(v - base[out]) > 1e-9 * max(1.0, abs(base[out])):
                measured[out].add(vr)
        assert inst.set({vr: value}) == OK
    return measured


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("causality", ["pump-torque", "speeds"])
def test_direct_feedthrough_declared_as_measured(fmus, instance, model, causality):
    fmu = fmus[(model, causality)]
    inst = instance(fmu, ME)
    point = _inputs(fmu, causality)
    point.update({vr: 40.0 for vr in fmu.vrs("input") if vr not in point})  # the rates
    inst.start(point)
    assert inst("fmi2EnterContinuousTimeMode") == OK
    measured, declared = _measured_dependencies(inst, fmu, point), fmu.dependencies()
    # the lock-up clutch's torque C·tanh(slip/0.2 rad/s) and state code (0 open, 1 slipping) are
    # declared by structure: at this point's large slip the tanh is flat in the speeds, and the state
    # changes only at C = 0; measured there, they depend on the command only
    for name in ("lockup_torque_nm", "lockup_state"):
        vr = fmu.by_name[name]
        assert measured.pop(vr) <= declared.pop(vr), name
    assert measured == declared


# ---------------------------------------------------------------------------------------------
# 4. Model Exchange calls the calling sequence allows before initialisation ends


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("causality", ["pump-torque", "speeds"])
def test_model_exchange_arrays_in_initialisation_mode(fmus, instance, model, causality):
    fmu = fmus[(model, causality)]
    inst = instance(fmu, ME)
    n, m = fmu.states, fmu.indicators
    status, nominals = inst.array("fmi2GetNominalsOfContinuousStates", n)
    assert status == OK and len(nominals) == n and all(v > 0.0 for v in nominals), inst.messages
    assert inst.setup() == OK and inst("fmi2EnterInitializationMode") == OK
    assert inst.set(_inputs(fmu, causality)) == OK
    during = [inst.array(name, k) for name, k in [("fmi2GetContinuousStates", n), ("fmi2GetDerivatives", n)]]
    during.append(inst.array("fmi2GetEventIndicators", m))
    assert all(status == OK for status, _ in during), inst.messages
    assert inst("fmi2ExitInitializationMode") == OK
    after = [inst.array(name, k) for name, k in [("fmi2GetContinuousStates", n), ("fmi2GetDerivatives", n)]]
    after.append(inst.array("fmi2GetEventIndicators", m))
    assert during == after
    assert inst.array("fmi2GetDerivatives", n + 1)[0] == ERROR  # a wrong size is still refused


# ---------------------------------------------------------------------------------------------
# 5. start values set after a read in initialisation mode


@pytest.mark.parametrize("kind", [ME, CS], ids=["ME", "CS"])
def test_start_values_after_a_read_in_initialisation_mode(fmus, instance, kind):
    fmu = fmus[("hrovat-tobler", "pump-torque")]
    inst = instance(fmu, kind)
    pump = fmu.by_name["pump_speed_rad_s"]
    assert inst.setup() == OK and inst("fmi2EnterInitializationMode") == OK
    assert inst.set(_inputs(fmu, "pump-torque")) == OK
    steady = inst.get([pump])[0]
    assert inst.set({fmu.by_name["start_from_steady_state"]: 0.0}) == OK, inst.messages
    assert inst.set({fmu.by_name["initial_pump_speed_rad_s"]: 123.0}) == OK, inst.messages
    assert inst.get([pump])[0] == 123.0 != steady
    assert inst("fmi2ExitInitializationMode") == OK
    assert inst.get([pump])[0] == 123.0
    assert inst.set({fmu.by_name["initial_pump_speed_rad_s"]: 124.0}) == ERROR  # fixed from now on


# ---------------------------------------------------------------------------------------------
# 6. a refused value is not kept


@pytest.mark.parametrize("kind", [ME, CS], ids=["ME", "CS"])
def test_refused_parameter_value_is_not_kept(fmus, instance, kind):
    fmu = fmus[("hrovat-tobler", "speeds")]
    inst = instance(fmu, kind)
    inst.start(_inputs(fmu, "speeds"))
    shape, inertia = fmu.by_name["pump_shape_effect_m2"], fmu.by_name["pump_inertia_kg_m2"]
    before = inst.get([shape, inertia])
    assert inst.set({inertia: 0.2, shape: 0.5}) == ERROR  # beyond the mass-matrix bound: all refused
    assert any("shape_effect" in m for _, _, m in inst.messages), inst.messages
    assert inst.get([shape, inertia]) == before
    assert inst.set({shape: before[0] * 1.01}) == OK, inst.messages[-1:]
    assert inst.set({inertia: math.nan}) == ERROR
    assert inst.get([shape, inertia]) == [before[0] * 1.01, before[1]]


# ---------------------------------------------------------------------------------------------
# 7. bounded extrapolation of the inputs in Co-Simulation


def _steady_pump_speed(instance, fmu: Unpacked, torque: float) -> float:
    ref = instance(fmu, CS)
    ref.start({fmu.by_name["pump_torque_nm"]: torque, fmu.by_name["turbine_speed_rad_s"]: 0.0})
    return ref.get([fmu.by_name["pump_speed_rad_s"]])[0]


def test_long_step_extrapolates_one_interval_then_holds(fmus, instance):
    """fmi2DoStep(h = 1e6 s) after a 10 ms torque step 100 → 300 N·m: the torque's estimated rate
    (20 000 N·m/s) applies over one interval (10 ms), then the torque is held at 500 N·m: the pump
    ends at the stall steady state of 500 N·m, not at 2.6e6 rad/s. Given input derivatives apply over
    the whole step."""
    fmu = fmus[("table", "pump-torque")]
    torque, pump = fmu.by_name["pump_torque_nm"], fmu.by_name["pump_speed_rad_s"]
    inst = instance(fmu, CS)
    inst.start({torque: 100.0, fmu.by_name["turbine_speed_rad_s"]: 0.0})
    assert inst.step(0.0, 0.01) == OK
    assert inst.set({torque: 300.0}) == OK
    assert inst.step(0.01, 1e6) == OK, inst.messages
    assert inst.get([pump])[0] == pytest.approx(_steady_pump_speed(instance, fmu, 500.0), rel=1e-4)
    given = instance(fmu, CS)
    given.start({torque: 100.0, fmu.by_name["turbine_speed_rad_s"]: 0.0})
    assert given.step(0.0, 0.01) == OK and given.set({torque: 300.0}) == OK
    one = ctypes.c_int(1)
    assert (
        given(
            "fmi2SetRealInputDerivatives", (ctypes.c_uint * 1)(torque), 1, ctypes.byref(one), (ctypes.c_double * 1)(0.0)
        )
        == OK
    )
    assert given.step(0.01, 1e6) == OK
    assert given.get([pump])[0] == pytest.approx(_steady_pump_speed(instance, fmu, 300.0), rel=1e-4)


# ---------------------------------------------------------------------------------------------
# 8. call order, GUID, log categories, inputs, non-finite values


def test_call_order_is_enforced_in_co_simulation(fmus, instance):
    fmu = fmus[("quasi-dynamic", "pump-torque")]
    inst = instance(fmu, CS)
    assert inst.setup() == OK and inst("fmi2EnterInitializationMode") == OK
    assert inst.step(0.0, 0.01) == ERROR  # DoStep in initialisation mode
    assert inst.set(_inputs(fmu, "pump-torque")) == OK
    assert inst("fmi2ExitInitializationMode") == OK
    assert inst("fmi2ExitInitializationMode") == ERROR  # no silent restart
    assert inst.setup() == ERROR
    assert inst.step(0.0, 0.01) == OK
    assert inst.step(0.01, math.nan) == ERROR and inst.step(0.01, -1.0) == ERROR
    assert inst("fmi2SetTime", ctypes.c_double(0.02)) == ERROR  # a Model Exchange function
    assert inst("fmi2Terminate") == OK
    assert inst.step(0.01, 0.01) == ERROR  # after Terminate
    assert inst.set({fmu.by_name["pump_torque_nm"]: 1.0}) == ERROR
    assert all(math.isfinite(v) for v in inst.get(fmu.vrs()))  # still readable
    assert inst("fmi2Reset") == OK
    inst.start(_inputs(fmu, "pump-torque"))  # the whole sequence again after a reset
    assert inst.step(0.0, 0.01) == OK
    assert "not allowed in state" in " ".join(m for _, _, m in inst.messages)


def test_call_order_and_non_finite_values_in_model_exchange(fmus, instance):
    fmu = fmus[("hrovat-tobler", "pump-torque")]
    inst = instance(fmu, ME)
    assert inst("fmi2SetTime", ctypes.c_double(0.0)) == ERROR  # before initialisation
    inst.start(_inputs(fmu, "pump-torque"))
    assert inst("fmi2SetTime", ctypes.c_double(math.nan)) == ERROR
    assert inst("fmi2SetTime", ctypes.c_double(math.inf)) == ERROR
    assert inst("fmi2SetTime", ctypes.c_double(0.5)) == OK
    x = (ctypes.c_double * 3)(100.0, math.nan, 0.05)
    assert inst("fmi2SetContinuousStates", x, ctypes.c_size_t(3)) == ERROR
    assert inst.set({fmu.by_name["pump_torque_nm"]: math.inf}) == ERROR
    assert inst.step(0.0, 0.01) == ERROR  # a Co-Simulation function
    info = EventInfo()
    assert inst("fmi2EnterEventMode") == OK and inst("fmi2NewDiscreteStates", ctypes.byref(info)) == OK
    assert inst("fmi2Terminate") == OK
    assert inst("fmi2EnterEventMode") == ERROR
    assert inst("fmi2Reset") == OK  # still a Model Exchange instance after a reset
    inst.start(_inputs(fmu, "pump-torque"))
    assert inst.array("fmi2GetDerivatives", fmu.states)[0] == OK and inst.step(0.0, 0.01) == ERROR


def test_guid_is_checked(fmus, instance):
    fmu = fmus[("table", "speeds")]
    assert not instance(fmu, CS, guid="{00000000-0000-0000-0000-000000000000}").c
    wrong = instance(fmu, ME, guid=None)
    assert not wrong.c and "GUID null" in wrong.messages[-1][2]
    assert instance(fmu, ME).c and instance(fmu, CS).c
    assert json.loads((fmu.folder / "resources" / "model.json").read_text())["guid"] == fmu.guid


def test_log_categories_are_declared(fmus, instance):
    """Every category the library logs with is in <LogCategories>; fmi2SetDebugLogging takes the
    declared ones and refuses another."""
    fmu = fmus[("hrovat-tobler", "speeds")]
    declared = [c.get("name") for c in fmu.root.findall("LogCategories/Category")]
    inst = instance(fmu, CS)
    names = (ctypes.c_char_p * len(declared))(*[d.encode() for d in declared])
    assert inst("fmi2SetDebugLogging", 1, ctypes.c_size_t(len(declared)), names) == OK
    assert inst.step(0.0, 0.01) == ERROR and inst.set({0: math.nan}) == ERROR
    bad = (ctypes.c_char_p * 1)(b"logEverything")
    assert inst("fmi2SetDebugLogging", 1, ctypes.c_size_t(1), bad) == ERROR
    assert inst.messages and {c for _, c, _ in inst.messages} <= set(declared)
    assert "logStatusError" in declared


def test_co_simulation_keeps_its_rate_input(fmus, instance):
    """turbine_accel_rad_s2 is an input in both interfaces: Co-Simulation never writes it."""
    fmu = fmus[("hrovat-tobler", "pump-torque")]
    accel = fmu.by_name["turbine_accel_rad_s2"]
    inst = instance(fmu, CS)
    inst.start({**_inputs(fmu, "pump-torque"), accel: 7.0})
    for k in range(3):
        assert inst.set({fmu.by_name["turbine_speed_rad_s"]: 60.0 + 5.0 * k}) == OK
        assert inst.step(0.01 * k, 0.01) == OK
        assert inst.get([accel]) == [7.0]


def test_co_simulation_rate_input_is_the_input_derivative(fmus, instance):
    """In Co-Simulation a rate input set before fmi2DoStep is its speed's rate over that step: the
    same run, bit for bit, as fmi2SetRealInputDerivatives with that value; the next step without it
    takes the last interval's rate. (FMI 2.0 ignored the rate inputs in Co-Simulation until they
    were found connected in fmi-sim: the same step with and without them was equal.)"""
    fmu = fmus[("hrovat-tobler", "speeds")]
    pump, turbine = fmu.by_name["pump_speed_rad_s"], fmu.by_name["turbine_speed_rad_s"]
    accel, torque = fmu.by_name["pump_accel_rad_s2"], fmu.by_name["pump_torque_nm"]
    one = ctypes.c_int(1)

    def run(how: str) -> list[float]:
        inst = instance(fmu, CS)
        inst.start(_inputs(fmu, "speeds"))
        assert inst.step(0.0, 0.01) == OK and inst.set({pump: 185.0, turbine: 61.0}) == OK
        if how == "input":
            assert inst.set({accel: 900.0}) == OK
        elif how == "derivative":
            derivative = (ctypes.c_double * 1)(900.0)
            refs = (ctypes.c_uint * 1)(pump)
            assert inst("fmi2SetRealInputDerivatives", refs, 1, ctypes.byref(one), derivative) == OK
        assert inst.step(0.01, 0.01) == OK and inst.set({pump: 190.0, turbine: 62.0}) == OK
        first = inst.get([torque])[0]
        assert inst.step(0.02, 0.01) == OK  # no rate given: the last interval's, 500 rad/s² for all three
        return [first, inst.get([torque])[0]]

    given, derivative, estimated = run("input"), run("derivative"), run("none")
    assert given == derivative
    # I_p·(900 − 500 rad/s²) ≈ 40 N·m more pump torque over the step with the given rate
    assert given[0] - estimated[0] > 10.0
    assert given[1] == pytest.approx(estimated[1], abs=1.0)


# ---------------------------------------------------------------------------------------------
# 9. FMU state


def _fmu_state(inst: Fmi2) -> ctypes.c_void_p:
    state = ctypes.c_void_p()
    assert inst("fmi2GetFMUstate", ctypes.byref(state)) == OK and state.value, inst.messages
    return state


def _serialise(inst: Fmi2, state: ctypes.c_void_p) -> bytes:
    size = ctypes.c_size_t()
    assert inst("fmi2SerializedFMUstateSize", state, ctypes.byref(size)) == OK
    buffer = ctypes.create_string_buffer(size.value)
    assert inst("fmi2SerializeFMUstate", state, buffer, size) == OK
    return buffer.raw


def _deserialise(inst: Fmi2, data: bytes) -> tuple[int, ctypes.c_void_p]:
    state = ctypes.c_void_p()
    status = inst("fmi2DeSerializeFMUstate", ctypes.c_char_p(data), ctypes.c_size_t(len(data)), ctypes.byref(state))
    return status, state


def _continue(inst: Fmi2, fmu: Unpacked, kind: int, t0: float, n: int) -> list[list[float]]:
    """n steps of 10 ms from t0 with a torque ramp, the outputs after each (bit patterns)."""
    torque = fmu.by_name["pump_torque_nm"]
    rows = []
    for k in range(n):
        t = t0 + 0.01 * k
        assert inst.set({torque: 120.0 + 800.0 * t}) == OK
        if kind == CS:
            assert inst.step(t, 0.01) == OK, inst.messages
        else:
            inst.me_step(t, 0.01, fmu.states)
        rows.append([struct.pack("<d", v) for v in inst.get(fmu.vrs())])
    return rows


@pytest.mark.parametrize("kind", [ME, CS], ids=["ME", "CS"])
def test_restored_state_continues_bit_for_bit(fmus, instance, kind):
    fmu = fmus[("hrovat-tobler", "pump-torque")]
    inst = instance(fmu, kind)
    inst.start(_inputs(fmu, "pump-torque"))
    _continue(inst, fmu, kind, 0.0, 5)
    state = _fmu_state(inst)
    first = _continue(inst, fmu, kind, 0.05, 5)
    assert inst("fmi2SetFMUstate", state) == OK, inst.messages
    assert _continue(inst, fmu, kind, 0.05, 5) == first
    data = _serialise(inst, state)
    assert inst("fmi2FreeFMUstate", ctypes.byref(state)) == OK and state.value is None
    fresh = instance(fmu, kind)  # instantiated only
    status, restored = _deserialise(fresh, data)
    assert status == OK and fresh("fmi2SetFMUstate", restored) == OK, fresh.messages
    assert _continue(fresh, fmu, kind, 0.05, 5) == first
    assert fresh("fmi2FreeFMUstate", ctypes.byref(restored)) == OK


def test_foreign_or_damaged_states_are_refused(fmus, instance):
    fmu = fmus[("hrovat-tobler", "pump-torque")]
    inst = instance(fmu, CS)
    inst.start(_inputs(fmu, "pump-torque"))
    data = _serialise(inst, _fmu_state(inst))
    other_model = instance(fmus[("table", "pump-torque")], CS)
    other_causality = instance(fmus[("hrovat-tobler", "speeds")], CS)
    other_interface = instance(fmu, ME)
    flag_at = 24 + 8  # the second word: the phase
    damaged = [data[:-1], data[:10], data + b"\0" * 8, b"x" * len(data), b"", data[:flag_at] + b"\xff" * 8 + data[40:]]
    for target, payload in [(other_model, data), (other_causality, data), (other_interface, data)] + [
        (inst, d) for d in damaged
    ]:
        status, state = _deserialise(target, payload)
        assert status == ERROR and not state.value
    assert "refused" in inst.messages[-1][2]
    status, state = _deserialise(inst, data)  # the intact one is accepted
    assert status == OK and inst("fmi2SetFMUstate", state) == OK
    assert inst("fmi2FreeFMUstate", ctypes.byref(state)) == OK
