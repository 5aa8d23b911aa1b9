"""``tcsim export-fmu``: a converter model as an FMI 2.0 FMU (Model Exchange and Co-Simulation), with
no Python inside.

::

    tcsim export-fmu CONVERTER --model table|hrovat-tobler|quasi-dynamic -o FILE.fmu
                     [--causality pump-torque|speeds]

The FMU is a zip archive:

* ``modelDescription.xml`` (:func:`model_description_xml`): the signals with fixed value references
  (:data:`SIGNALS`), the converter's parameters as tunable parameters (value references from
  :data:`FIRST_PARAMETER_VR`), units, descriptions and the model structure;
* ``resources/model.json``: the model specification (:attr:`tcsim.transient.DynamicModel.spec`),
  the causality and the parameter list, read by the library at ``fmi2Instantiate``;
* ``binaries/linux64/tcsim_converter.so``: the Rust library ``crates/tcsim-fmu`` (a ``cdylib`` over
  ``tcsim-core``: diffsol's BDF solver inside ``fmi2DoStep``), found by :func:`find_libraries`
  (``binaries/win64/tcsim_converter.dll`` and ``binaries/darwin64/tcsim_converter.dylib`` as well
  when ``$TCSIM_FMU_LIBRARY`` lists them);
* ``sources/``: a README on rebuilding the binary for Windows and macOS, with the Rust sources of
  ``tcsim-core`` and ``tcsim-fmu`` and the workspace's ``Cargo.toml``/``Cargo.lock``.

Causality (thesis/VSIM choice by default): ``pump-torque`` has the inputs ``pump_torque_nm`` and
``turbine_speed_rad_s``; ``speeds`` has ``pump_speed_rad_s`` and ``turbine_speed_rad_s``. Every other
signal of the model is an output. The FMU starts from the steady state consistent with the inputs
set before ``fmi2ExitInitializationMode`` (as ``tcsim replay``).

Errors: a bad converter, model, causality or output file is an :class:`~tcsim.errors.InputError`
(exit 2); a library that cannot be found or built is a :class:`FmuLibraryError` (exit 1).
See ``docs/fmu.md``.
"""

from __future__ import annotations

import ctypes
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import uuid
import warnings
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlparse
from xml.sax.saxutils import quoteattr

from .. import _core
from ..errors import InputError, TcsimWarning
from ..models.converter import MODELS, Converter
from ..models.drives import Drive, PumpTorqueTurbineSpeed, Speeds
from ..models.dynamic import DynamicModel, resolve_model
from ..simulation.transient import SolverError, simulate

#: ``modelIdentifier`` of the FMU: the binary is ``binaries/<platform>/tcsim_converter.<ext>``.
MODEL_IDENTIFIER = "tcsim_converter"
#: Environment variable naming the library to package (overrides the source tree's build).
LIBRARY_ENV = "TCSIM_FMU_LIBRARY"
#: File name of the library that ``cargo build -p tcsim-fmu`` makes on Linux.
LIBRARY_FILE = "libtcsim_fmu.so"
#: The library's file name per platform (``cargo build`` output) and its FMI platform directory.
PLATFORM_LIBRARIES: dict[str, tuple[str, str]] = {
    "linux": ("libtcsim_fmu.so", "linux64"),
    "win32": ("tcsim_fmu.dll", "win64"),
    "darwin": ("libtcsim_fmu.dylib", "darwin64"),
}
#: FMI platform directory of a library by its suffix.
PLATFORM_OF_SUFFIX = {".so": "linux64", ".dll": "win64", ".dylib": "darwin64"}
#: Value reference of the first parameter; parameter i has ``FIRST_PARAMETER_VR + i``.
FIRST_PARAMETER_VR = 100
#: ``--causality`` choices: the two inputs of each.
CAUSALITIES: dict[str, tuple[str, str]] = {
    "pump-torque": ("pump_torque_nm", "turbine_speed_rad_s"),
    "speeds": ("pump_speed_rad_s", "turbine_speed_rad_s"),
}
#: Start values of the inputs (a part-load stall: 50 N·m at the pump, or the pump at 150 rad/s).
INPUT_START: dict[str, float] = {"pump_torque_nm": 50.0, "pump_speed_rad_s": 150.0, "turbine_speed_rad_s": 0.0}
#: Rates of the speed inputs (value references 12, 13), for Model Exchange: optional inputs, zero
#: when not connected. Co-Simulation takes the rates from fmi2SetRealInputDerivatives or from the
#: last communication interval instead.
RATE_INPUTS: dict[str, tuple[int, str, str]] = {
    "pump_speed_rad_s": (12, "pump_accel_rad_s2", "Rate of the pump speed input (Model Exchange; 0 if not connected)"),
    "turbine_speed_rad_s": (
        13,
        "turbine_accel_rad_s2",
        "Rate of the turbine speed input (Model Exchange; 0 if not connected)",
    ),
}
#: Value reference of the derivative of state coordinate c (0 pump speed, 2 stator speed, 3 flow).
FIRST_DERIVATIVE = 20
#: The models' continuous states in Model Exchange: signal name and coordinate.
_STATES = (("pump_speed_rad_s", 0), ("stator_speed_rad_s", 2), ("flow_m3_s", 3))
#: Event indicators in Model Exchange: the stator clutch and the flow direction (Hrovat & Tobler).
EVENT_INDICATORS = {"hrovat-tobler": 3}


class FmuLibraryError(RuntimeError):
    """The FMU library could not be found or built (not the user's fault: exit code 1)."""


# ---------------------------------------------------------------------------------------------
# Units


@dataclass(frozen=True)
class Unit:
    name: str
    base: dict[str, int]
    display: tuple[tuple[str, float], ...] = ()


#: ``<UnitDefinitions>``: FMI unit names (``N.m``, ``rad/s``, ...) with their SI base-unit exponents.
UNITS: tuple[Unit, ...] = (
    Unit("N.m", {"kg": 1, "m": 2, "s": -2}),
    Unit("rad/s", {"s": -1, "rad": 1}, (("rpm", 30.0 / math.pi),)),
    Unit("m3/s", {"m": 3, "s": -1}),
    Unit("rad/s2", {"s": -2, "rad": 1}),
    Unit("m3/s2", {"m": 3, "s": -2}),
    Unit("kg.m2", {"kg": 1, "m": 2}),
    Unit("N.m.s2/rad2", {"kg": 1, "m": 2, "rad": -2}),
    Unit("m", {"m": 1}),
    Unit("m2", {"m": 2}),
    Unit("kg/m3", {"kg": 1, "m": -3}),
    Unit("rad", {"rad": 1}, (("deg", 180.0 / math.pi),)),
    Unit("s", {"s": 1}),
    Unit("1", {}),
)

# unit-suffix conventions (conventions.md) -> FMI unit; the longest suffix that matches wins
_SUFFIX_UNITS: tuple[tuple[str, str], ...] = (
    ("_nm_s2", "N.m.s2/rad2"),
    ("_kg_m2", "kg.m2"),
    ("_kg_m3", "kg/m3"),
    ("_m3_s", "m3/s"),
    ("_rad_s", "rad/s"),
    ("_nm", "N.m"),
    ("_m2", "m2"),
    ("_rad", "rad"),
    ("_m", "m"),
    ("_s", "s"),
)


def unit_of(name: str) -> str:
    """The FMI unit of a unit-suffixed name (``pump_exit_radius_m`` -> ``m``); ``1`` without suffix."""
    base = re.sub(r"\[\d+\]$", "", name)
    for suffix, unit in _SUFFIX_UNITS:
        if base.endswith(suffix):
            return unit
    return "1"


# ---------------------------------------------------------------------------------------------
# Signals


@dataclass(frozen=True)
class Signal:
    """A signal of the FMU: fixed value reference, name (conventions.md), unit, description and the
    models that have it."""

    vr: int
    name: str
    unit: str
    description: str
    models: tuple[str, ...] = MODELS
    #: True for a state of the model (no direct feedthrough from the inputs).
    state: bool = False


#: The signals in value-reference order; the same value reference whatever the causality.
SIGNALS: tuple[Signal, ...] = (
    Signal(0, "pump_torque_nm", "N.m", "Torque on the pump (engine torque at the converter input)"),
    Signal(1, "pump_speed_rad_s", "rad/s", "Pump (impeller) speed", state=True),
    Signal(2, "turbine_speed_rad_s", "rad/s", "Turbine speed (transmission input speed)"),
    Signal(3, "turbine_torque_nm", "N.m", "Torque delivered by the turbine to the transmission (positive in drive)"),
    Signal(4, "speed_ratio", "1", "Speed ratio SR = turbine speed / pump speed"),
    Signal(5, "torque_ratio", "1", "Torque ratio TR = turbine torque / pump torque"),
    Signal(6, "flow_m3_s", "m3/s", "Volume flow through the torus", ("hrovat-tobler", "quasi-dynamic"), state=True),
    Signal(
        7,
        "stator_speed_rad_s",
        "rad/s",
        "Stator speed (zero while the one-way clutch holds it)",
        ("hrovat-tobler",),
        state=True,
    ),
    Signal(8, "stator_torque_nm", "N.m", "Torque of the stator one-way clutch on the stator"),
    Signal(9, "effective_pump_torque_nm", "N.m", "Effective pump input torque T_p - I_p dw_p/dt (LS16 eq 3.3)"),
    Signal(10, "effective_turbine_torque_nm", "N.m", "Effective turbine output torque T_t + I_t dw_t/dt (LS16 eq 3.4)"),
    Signal(11, "effective_torque_ratio", "1", "Effective torque ratio: effective turbine / effective pump torque"),
)


def model_signals(model: str) -> list[Signal]:
    """The signals of a model, in value-reference order."""
    return [s for s in SIGNALS if model in s.models]


# ---------------------------------------------------------------------------------------------
# Parameters

_TRIPLE = ("pump", "turbine", "stator")
_GEOMETRY_DESCRIPTIONS = {
    "flow_area_m2": "Flow area A of the torus",
    "fluid_density_kg_m3": "Fluid density",
    "pump_exit_radius_m": "Pump exit radius",
    "turbine_exit_radius_m": "Turbine exit radius",
    "stator_exit_radius_m": "Stator exit radius",
    "pump_shock_loss": "Shock loss coefficient at the pump inlet",
    "turbine_shock_loss": "Shock loss coefficient at the turbine inlet",
    "stator_shock_loss": "Shock loss coefficient at the stator inlet",
    "friction_loss": "Friction loss coefficient",
}
_TABLE_KEYS = {
    "speed_ratio": "speed ratio SR",
    "torque_ratio": "torque ratio TR",
    "capacity_factor_nm_s2": "capacity factor CF = pump torque / pump speed^2",
}


@dataclass(frozen=True)
class Parameter:
    """A tunable parameter: the spec value ``model[key]`` (scalar, ``index`` 0) or ``model[key][index]``."""

    vr: int
    name: str
    key: str
    index: int
    value: float
    unit: str
    description: str

    def entry(self) -> dict[str, Any]:
        """The parameter's entry in ``resources/model.json``."""
        return {"name": self.name, "key": self.key, "index": self.index}


def _name_and_description(key: str, index: int | None, size: int) -> tuple[str, str]:
    if key == "inertia_kg_m2" and index is not None and size == 3:
        return f"{_TRIPLE[index]}_inertia_kg_m2", f"Moment of inertia of the {_TRIPLE[index]}"
    if key == "shape_effect_m2" and index is not None and size <= 3:
        return (
            f"{_TRIPLE[index]}_shape_effect_m2",
            f"Shape effect S of the {_TRIPLE[index]} (signed, LS16 eqs 2.16-2.18)",
        )
    if key == "geometry" and index is not None:
        names = _core.ht_parameter_names()
        if size == len(names):
            name = names[index]
            if name.endswith("_angle_rad"):
                blade, where = name.removesuffix("_angle_rad").split("_")
                return name, f"Blade angle at the {blade} {where}"
            return name, _GEOMETRY_DESCRIPTIONS.get(name, name.replace("_", " "))
    if key in _TABLE_KEYS and index is not None:
        return f"table_{key}[{index + 1}]", f"Characteristic table, row {index + 1}: {_TABLE_KEYS[key]}"
    described = {
        "fluid_length_m": "Mean length L_f of the fluid path around the torus",
        "fluid_density_kg_m3": "Fluid density (flow estimate of the quasi-dynamic model)",
        "pump_exit_radius_m": "Pump exit radius (flow estimate of the quasi-dynamic model)",
        "flow_time_constant_s": "Time constant tau_Q of the flow lag (quasi-dynamic model)",
    }
    if index is None:
        return key, described.get(key, key.replace("_", " "))
    return f"{key}[{index + 1}]", f"{key.replace('_', ' ')}, element {index + 1}"


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def fmu_parameters(model: DynamicModel) -> list[Parameter]:
    """Every numeric entry of the model's spec (scalars, and each element of the arrays) as a
    parameter, in the spec's key order, with value references from :data:`FIRST_PARAMETER_VR`."""
    out: list[Parameter] = []
    for key, value in model.spec.items():
        if _number(value):
            items: list[tuple[int | None, Any]] = [(None, value)]
        elif isinstance(value, (list, tuple)) and value and all(_number(v) for v in value):
            items = list(enumerate(value))
        else:
            continue  # "kind" and anything else that is not a number
        for index, v in items:
            name, description = _name_and_description(key, index, len(items))
            if not math.isfinite(float(v)):
                raise InputError(model.source, name, float(v), "a finite number")
            out.append(
                Parameter(FIRST_PARAMETER_VR + len(out), name, key, index or 0, float(v), unit_of(name), description)
            )
    names = [p.name for p in out]
    if len(set(names)) != len(names):
        raise ValueError(f"parameter names are not unique: {names}")
    return out


# ---------------------------------------------------------------------------------------------
# modelDescription.xml


def _version() -> str:
    try:
        return metadata.version("tcsim")
    except Exception:
        return "0+unknown"


def _xml_real(value: float) -> str:
    """A real as modelDescription.xml writes it (Python's shortest round-trip form)."""
    return repr(float(value))


def _check_causality(causality: str) -> tuple[str, str]:
    if causality not in CAUSALITIES:
        raise InputError("command line", "--causality", causality, f"one of {', '.join(CAUSALITIES)}")
    return CAUSALITIES[causality]


class _Variables:
    """``<ModelVariables>`` being written: the lines, and each variable's 1-based index by name."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.index: dict[str, int] = {}

    def add(self, name: str, vr: int, description: str, attrs: str, real: str) -> None:
        self.index[name] = len(self.index) + 1
        q = quoteattr
        self.lines.append(f"    <!-- index {self.index[name]} -->")
        self.lines.append(
            f'    <ScalarVariable name={q(name)} valueReference="{vr}" description={q(description)} {attrs}>'
        )
        self.lines.append(f"      <Real {real}/>")
        self.lines.append("    </ScalarVariable>")


def _header_lines(
    model: DynamicModel, inputs: tuple[str, str], outputs: list[Signal], name: str, guid: str, stamp: str
):
    """From the XML declaration to the capabilities of Model Exchange and Co-Simulation."""
    version = _version()
    description = (
        f"Torque converter {Path(model.source).stem}, {model.name} model (tcsim {version}). Inputs "
        f"{', '.join(inputs)}; outputs {', '.join(s.name for s in outputs)}. Starts from the steady "
        "state consistent with the inputs."
    )
    a = quoteattr
    return [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<fmiModelDescription fmiVersion="2.0" modelName={a(name)} guid={a(guid)}',
        f"  description={a(description)}",
        f'  generationTool={a("tcsim " + version)} generationDateAndTime="{stamp}" license="MIT"',
        f'  variableNamingConvention="flat" numberOfEventIndicators="{EVENT_INDICATORS.get(model.name, 0)}">',
        f'  <ModelExchange modelIdentifier="{MODEL_IDENTIFIER}" completedIntegratorStepNotNeeded="true"'
        ' canGetAndSetFMUstate="false" canSerializeFMUstate="false" providesDirectionalDerivative="false"/>',
        f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"'
        ' canInterpolateInputs="true" maxOutputDerivativeOrder="0" canGetAndSetFMUstate="false"'
        ' canSerializeFMUstate="false" providesDirectionalDerivative="false"/>',
    ]


def _unit_lines() -> list[str]:
    """``<UnitDefinitions>`` of :data:`UNITS`."""
    lines = ["  <UnitDefinitions>"]
    for u in UNITS:
        base = " ".join(f'{k}="{v}"' for k, v in u.base.items())
        lines.append(f"    <Unit name={quoteattr(u.name)}>")
        lines.append(f"      <BaseUnit {base}/>" if base else "      <BaseUnit/>")
        for name, factor in u.display:
            lines.append(f'      <DisplayUnit name={quoteattr(name)} factor="{_xml_real(factor)}"/>')
        lines.append("    </Unit>")
    lines.append("  </UnitDefinitions>")
    return lines


def _signal_variables(v: _Variables, signals: list[Signal], inputs: tuple[str, str]) -> None:
    """The signals (inputs with their start values, outputs), then the rates of the speed inputs."""
    for s in signals:
        if s.name in inputs:
            v.add(
                s.name,
                s.vr,
                s.description,
                'causality="input" variability="continuous"',
                f'unit="{s.unit}" start="{_xml_real(INPUT_START[s.name])}"',
            )
        else:
            v.add(
                s.name,
                s.vr,
                s.description,
                'causality="output" variability="continuous" initial="calculated"',
                f'unit="{s.unit}"',
            )
    for name in inputs:
        if name in RATE_INPUTS:
            vr, rate, text = RATE_INPUTS[name]
            v.add(rate, vr, text, 'causality="input" variability="continuous"', 'unit="rad/s2" start="0"')


def _start_variables(v: _Variables, inputs: tuple[str, str]) -> None:
    """``start_from_steady_state`` and the ``initial_*`` values of the states that are not inputs."""
    v.add(
        "start_from_steady_state",
        30,
        "1: start at the steady state consistent with the inputs (as tcsim replay); 0: at the initial_* values",
        'causality="parameter" variability="fixed" initial="exact"',
        'unit="1" start="1"',
    )
    for name, vr, unit, start in (
        ("pump_speed_rad_s", 31, "rad/s", 150.0),
        ("stator_speed_rad_s", 32, "rad/s", 0.0),
        ("flow_m3_s", 33, "m3/s", 0.05),
    ):
        if name in v.index and name not in inputs:
            v.add(
                f"initial_{name}",
                vr,
                f"Initial {name.replace('_', ' ').rsplit(' ', 2)[0]} when start_from_steady_state = 0",
                'causality="parameter" variability="fixed" initial="exact"',
                f'unit="{unit}" start="{_xml_real(start)}"',
            )


def _derivative_variables(v: _Variables, inputs: tuple[str, str]) -> list[str]:
    """``der(x)`` of each continuous state that is not an input (Model Exchange); their names."""
    derivatives = []
    for name, c in [(name, c) for name, c in _STATES if name in v.index and name not in inputs]:
        der = f"der({name})"
        unit = "m3/s2" if c == 3 else "rad/s2"
        v.add(
            der,
            FIRST_DERIVATIVE + c,
            f"Time derivative of {name}",
            'causality="local" variability="continuous" initial="calculated"',
            f'unit="{unit}" derivative="{v.index[name]}"',
        )
        derivatives.append(der)
    return derivatives


def _structure_lines(
    index: dict[str, int], inputs: tuple[str, str], outputs: list[Signal], derivatives: list[str]
) -> list[str]:
    """``<ModelStructure>``: outputs with their dependencies, derivatives, initial unknowns."""
    both = " ".join(str(index[n]) for n in inputs)
    lines = ["  <ModelStructure>", "    <Outputs>"]
    for s in outputs:
        # a state (pump speed, flow, stator speed) does not depend directly on the inputs
        lines.append(f'      <Unknown index="{index[s.name]}" dependencies="{"" if s.state else both}"/>')
    lines.append("    </Outputs>")
    if derivatives:
        lines.append("    <Derivatives>")
        lines += [f'      <Unknown index="{index[der]}"/>' for der in derivatives]
        lines.append("    </Derivatives>")
    lines.append("    <InitialUnknowns>")
    for name in sorted([s.name for s in outputs] + derivatives, key=lambda n: index[n]):
        lines.append(f'      <Unknown index="{index[name]}"/>')
    lines += ["    </InitialUnknowns>", "  </ModelStructure>"]
    return lines


def model_description_xml(
    model: DynamicModel,
    causality: str = "pump-torque",
    model_name: str | None = None,
    guid: str | None = None,
    generation_time: datetime | None = None,
) -> str:
    """The ``modelDescription.xml`` (FMI 2.0, Co-Simulation and Model Exchange) of a model under a
    causality."""
    inputs = _check_causality(causality)
    signals = model_signals(model.name)
    outputs = [s for s in signals if s.name not in inputs]
    name = model_name or f"tcsim {Path(model.source).stem} {model.name}"
    stamp = (generation_time or datetime.now(UTC)).strftime("%Y-%m-%dT%H:%M:%SZ")
    lines = _header_lines(model, inputs, outputs, name, guid or "{" + str(uuid.uuid4()) + "}", stamp)
    lines += _unit_lines()
    lines.append('  <DefaultExperiment startTime="0.0" stopTime="10.0" tolerance="1e-06" stepSize="0.001"/>')
    v = _Variables()
    _signal_variables(v, signals, inputs)
    _start_variables(v, inputs)
    derivatives = _derivative_variables(v, inputs)
    for p in fmu_parameters(model):
        display = ' displayUnit="deg"' if p.unit == "rad" else ""
        v.add(
            p.name,
            p.vr,
            p.description,
            'causality="parameter" variability="tunable"',
            f'unit="{p.unit}"{display} start="{_xml_real(p.value)}"',
        )
    lines += ["  <ModelVariables>", *v.lines, "  </ModelVariables>"]
    lines += _structure_lines(v.index, inputs, outputs, derivatives)
    lines += ["</fmiModelDescription>", ""]
    return "\n".join(lines)


def model_json(model: DynamicModel, causality: str = "pump-torque") -> dict[str, Any]:
    """The content of ``resources/model.json`` read by the library at ``fmi2Instantiate``."""
    _check_causality(causality)
    spec = json.loads(json.dumps(model.spec, default=float))  # plain JSON types
    return {"causality": causality, "model": spec, "parameters": [p.entry() for p in fmu_parameters(model)]}


# ---------------------------------------------------------------------------------------------
# The library and the sources


def source_root() -> Path | None:
    """The tcsim source tree (with ``Cargo.toml`` and ``crates/tcsim-fmu``): the tree this module
    is in, else the local directory tcsim was installed from (``pip install /path/to/tcsim``)."""
    candidates = [Path(__file__).resolve().parents[3]]  # python/tcsim/io/fmu.py -> the tree
    try:
        text = metadata.distribution("tcsim").read_text("direct_url.json")
        url = json.loads(text or "{}").get("url", "")
        if url.startswith("file://"):
            candidates.append(Path(unquote(urlparse(url).path)))
    except Exception:
        pass
    for root in candidates:
        if (root / "Cargo.toml").is_file() and (root / "crates" / "tcsim-fmu" / "Cargo.toml").is_file():
            return root
    return None


def _newest_source_mtime(root: Path) -> float:
    paths = [root / "Cargo.lock"]
    for crate in ("tcsim-core", "tcsim-fmu"):
        paths.append(root / "crates" / crate / "Cargo.toml")
        paths.extend((root / "crates" / crate / "src").rglob("*.rs"))
    return max((p.stat().st_mtime for p in paths if p.is_file()), default=0.0)


def _local_library_file() -> str:
    for prefix, (name, _) in PLATFORM_LIBRARIES.items():
        if sys.platform.startswith(prefix):
            return name
    return LIBRARY_FILE


def build_library(root: Path, timeout_s: float = 1800.0) -> Path:
    """``cargo build --release -p tcsim-fmu`` in the source tree; the library it made."""
    cargo = shutil.which("cargo")
    name = _local_library_file()
    if cargo is None:
        raise FmuLibraryError(
            f"the FMU library {name} is not built and cargo is not on PATH: install Rust "
            f"(https://rustup.rs) and run 'cargo build --release -p tcsim-fmu' in {root}, or set "
            f"{LIBRARY_ENV}"
        )
    try:
        p = subprocess.run(
            [cargo, "build", "--release", "-p", "tcsim-fmu"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=timeout_s,
        )
    except subprocess.TimeoutExpired:
        raise FmuLibraryError(
            f"'cargo build --release -p tcsim-fmu' in {root} took more than {timeout_s:g} s"
        ) from None
    lib = root / "target" / "release" / name
    if p.returncode != 0 or not lib.is_file():
        tail = "\n".join(p.stderr.strip().splitlines()[-15:])
        raise FmuLibraryError(f"'cargo build --release -p tcsim-fmu' in {root} failed (exit {p.returncode}):\n{tail}")
    return lib


def find_libraries(build: bool = True) -> list[Path]:
    """The FMU libraries to package: ``$TCSIM_FMU_LIBRARY`` (one file, or several separated by
    ``os.pathsep``, one per platform: ``.so`` linux64, ``.dll`` win64, ``.dylib`` darwin64), else
    ``target/release/``, else ``target/debug/`` of the source tree (``libtcsim_fmu.so`` on Linux);
    else, with ``build`` and a source tree, the library is built with cargo. Raises
    :class:`FmuLibraryError` when there is none."""
    env = os.environ.get(LIBRARY_ENV)
    if env:
        libs = [Path(part).expanduser() for part in env.split(os.pathsep) if part.strip()]
        for lib in libs:
            if not lib.is_file():
                raise FmuLibraryError(f"{LIBRARY_ENV}={env}: {lib}: no such file")
            if lib.suffix.lower() not in PLATFORM_OF_SUFFIX:
                raise FmuLibraryError(f"{LIBRARY_ENV}={env}: {lib}: expected a .so, .dll or .dylib library")
        platforms = [PLATFORM_OF_SUFFIX[lib.suffix.lower()] for lib in libs]
        if len(set(platforms)) != len(platforms):
            raise FmuLibraryError(f"{LIBRARY_ENV}={env}: one library per platform")
        return libs
    root = source_root()
    name = _local_library_file()
    if root is not None:
        for profile in ("release", "debug"):
            lib = root / "target" / profile / name
            if lib.is_file():
                if lib.stat().st_mtime < _newest_source_mtime(root):
                    warnings.warn(
                        f"{lib} is older than the Rust sources; run 'cargo build --release -p tcsim-fmu' "
                        f"in {root} to package the current code",
                        TcsimWarning,
                        stacklevel=2,
                    )
                return [lib]
        if build:
            return [build_library(root)]
    raise FmuLibraryError(
        f"the FMU library {name} was not found: set {LIBRARY_ENV} to it, or run "
        "'cargo build --release -p tcsim-fmu' in the tcsim source tree" + ("" if root is None else f" ({root})")
    )


def _check_library(lib: Path) -> None:
    """The library exports the FMI 2.0 Co-Simulation functions (and, if it is for this platform,
    it loads)."""
    needed = ("fmi2GetVersion", "fmi2Instantiate", "fmi2DoStep", "fmi2FreeInstance")
    if lib.suffix.lower() != Path(_local_library_file()).suffix:
        data = lib.read_bytes()
        missing = [f for f in needed if f.encode() not in data]
    else:
        try:
            dll = ctypes.CDLL(str(lib.resolve()))
        except OSError as e:
            raise FmuLibraryError(f"{lib} cannot be loaded: {e}") from None
        missing = [f for f in needed if not hasattr(dll, f)]
    if missing:
        raise FmuLibraryError(f"{lib} is not the tcsim FMU library: it does not export {', '.join(missing)}")


SOURCES_README = """\
# Sources of the tcsim converter FMU

This FMU was exported by `tcsim export-fmu` (tcsim {version}). Its binary, `binaries/linux64/{mi}.so`,
is the Rust library `crates/tcsim-fmu` of tcsim, built from the sources in this directory. The
model itself (the converter's parameters and the causality) is data, in `resources/model.json`, so
one binary serves every converter, model and causality.

## Rebuilding the binary for another platform

The library has no dependency but Rust crates (diffsol, nalgebra, serde_json); no Python, no
FMI SDK. With a Rust toolchain (https://rustup.rs, Rust 1.89 or newer) on the target platform:

    cd sources            # this directory, extracted from the .fmu (a zip archive)
    cargo build --release -p tcsim-fmu

(or the same command in a checkout of the tcsim source tree). Then put the library into the FMU
under the name the `modelIdentifier` requires, `{mi}`:

| platform | cargo makes | copy it into the FMU as |
|---|---|---|
| Linux x86-64 | `target/release/libtcsim_fmu.so` | `binaries/linux64/{mi}.so` |
| Windows x86-64 (MSVC) | `target\\release\\tcsim_fmu.dll` | `binaries/win64/{mi}.dll` |
| macOS (x86-64 or arm64) | `target/release/libtcsim_fmu.dylib` | `binaries/darwin64/{mi}.dylib` |

For example on Windows (PowerShell):

    Expand-Archive converter.fmu fmu; cd fmu\\sources
    cargo build --release -p tcsim-fmu
    mkdir ..\\binaries\\win64; copy target\\release\\tcsim_fmu.dll ..\\binaries\\win64\\{mi}.dll
    cd ..; Remove-Item -Recurse sources\\target
    Compress-Archive -Path * -DestinationPath ..\\converter.fmu -Force

and on macOS:

    mkdir fmu && cd fmu && unzip ../converter.fmu && cd sources
    cargo build --release -p tcsim-fmu
    mkdir -p ../binaries/darwin64 && cp target/release/libtcsim_fmu.dylib ../binaries/darwin64/{mi}.dylib
    rm -rf target && cd .. && zip -r ../converter.fmu . -x 'sources/target/*'

A universal macOS library: build both `--target x86_64-apple-darwin` and `--target aarch64-apple-darwin`
and join them with `lipo -create -output {mi}.dylib <x86_64 lib> <arm64 lib>`.

Keep `modelDescription.xml` and `resources/` as they are: they do not depend on the platform.
Do not add `<SourceFiles>`: the sources are Rust, not the C an importing tool would compile.

## Contents

* `Cargo.toml`, `Cargo.lock`: the workspace (members `tcsim-core` and `tcsim-fmu` only) and the
  exact dependency versions tcsim was built with;
* `crates/tcsim-core/`: the converter models and the transient engine (pure Rust);
* `crates/tcsim-fmu/`: the FMI 2.0 C API (Model Exchange and Co-Simulation).
{missing}
License: MIT (`LICENSE`).
"""

_CRATE_FILES = ("Cargo.toml", "build.rs", "README.md", "LICENSE")
_CRATE_DIRS = ("src", "include")


def _write_sources(root: Path | None, dest: Path) -> None:
    """``sources/``: the README and, when the source tree is known, the Rust sources."""
    dest.mkdir(parents=True, exist_ok=True)
    missing = ""
    if root is None:
        missing = (
            "\n**This FMU carries no Rust sources**: it was exported without the tcsim source tree. "
            "Get them from the tcsim repository (the same version) and build there.\n"
        )
        warnings.warn(
            "the tcsim source tree was not found: the FMU's sources/ holds the rebuild instructions only",
            TcsimWarning,
            stacklevel=3,
        )
    else:
        ws = (root / "Cargo.toml").read_text()
        ws = re.sub(r"(?ms)^members\s*=\s*\[.*?\]", 'members = ["crates/tcsim-core", "crates/tcsim-fmu"]', ws, count=1)
        (dest / "Cargo.toml").write_text(ws)
        for name in ("Cargo.lock", "LICENSE"):
            if (root / name).is_file():
                shutil.copy2(root / name, dest / name)
        for crate in ("tcsim-core", "tcsim-fmu"):
            src, out = root / "crates" / crate, dest / "crates" / crate
            out.mkdir(parents=True)
            for name in _CRATE_FILES:
                if (src / name).is_file():
                    shutil.copy2(src / name, out / name)
            for d in _CRATE_DIRS:
                if (src / d).is_dir():
                    shutil.copytree(src / d, out / d, ignore=shutil.ignore_patterns("target", "*.orig", "*.rej", ".*"))
    (dest / "README.md").write_text(SOURCES_README.format(version=_version(), mi=MODEL_IDENTIFIER, missing=missing))


# ---------------------------------------------------------------------------------------------
# Export


def _check_model(model: DynamicModel, causality: str) -> None:
    """A short run from the default inputs' steady state, so that an inadmissible model (a shape
    effect beyond the mass-matrix bound, ...) is an input error now, not an fmi2Error later."""
    t = [0.0, 1e-3]
    drive: Drive
    if causality == "speeds":
        drive = Speeds(t, [INPUT_START["pump_speed_rad_s"]] * 2, [INPUT_START["turbine_speed_rad_s"]] * 2)
    else:
        drive = PumpTorqueTurbineSpeed(t, [INPUT_START["pump_torque_nm"]] * 2, [INPUT_START["turbine_speed_rad_s"]] * 2)
    try:
        simulate(model, drive)
    except SolverError:
        pass  # the inputs of a real run differ; not a reason to refuse the export


def _output_path(out_path: str | Path) -> Path:
    out = Path(out_path)
    if out.suffix.lower() != ".fmu":
        raise InputError("command line", "--out", str(out), "a file name ending in .fmu")
    if out.is_dir():
        raise InputError("command line", "--out", str(out), "a .fmu file (a directory of that name exists)")
    return out


def export_fmu(
    converter: Converter | str | Path | DynamicModel | None,
    model: str | DynamicModel,
    out_path: str | Path,
    causality: str = "pump-torque",
) -> Path:
    """Write the FMU of ``model`` (a name of :data:`tcsim.models.converter.MODELS`, or a
    :class:`~tcsim.transient.DynamicModel`, with ``converter`` then ignored) of ``converter`` (a
    :class:`~tcsim.models.converter.Converter`, bundled name or file) to ``out_path`` (``*.fmu``), written
    atomically. Returns the path."""
    _check_causality(causality)
    out = _output_path(out_path)
    dyn = resolve_model(converter if isinstance(converter, (Converter, DynamicModel)) else str(converter), model)
    _check_model(dyn, causality)
    xml = model_description_xml(dyn, causality)
    config = model_json(dyn, causality)
    libs = find_libraries()
    for lib in libs:
        _check_library(lib)
    root = source_root()

    parent = out.resolve().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".partial", dir=parent)
        os.close(fd)
    except OSError as e:
        raise InputError("command line", "--out", str(out), f"a writable location ({e.strerror})") from None
    tmp = Path(tmp_name)
    try:
        with tempfile.TemporaryDirectory(prefix="tcsim-fmu-") as stage_dir:
            stage = Path(stage_dir)
            (stage / "modelDescription.xml").write_text(xml, encoding="utf-8")
            (stage / "resources").mkdir()
            (stage / "resources" / "model.json").write_text(json.dumps(config, indent=1) + "\n")
            for lib in libs:
                platform = PLATFORM_OF_SUFFIX[lib.suffix.lower()]
                (stage / "binaries" / platform).mkdir(parents=True)
                shutil.copyfile(lib, stage / "binaries" / platform / f"{MODEL_IDENTIFIER}{lib.suffix.lower()}")
            _write_sources(root, stage / "sources")
            with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zf:
                for item in sorted(stage.rglob("*")):
                    if item.is_file():
                        zf.write(item, item.relative_to(stage).as_posix())
        os.chmod(tmp, 0o644)
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)
    return out


__all__: Sequence[str] = (
    "export_fmu",
    "model_description_xml",
    "model_json",
    "fmu_parameters",
    "find_libraries",
    "FmuLibraryError",
    "SIGNALS",
    "CAUSALITIES",
)
