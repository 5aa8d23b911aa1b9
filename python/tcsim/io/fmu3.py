"""``tcsim export-fmu --fmi-version 3``: a converter model as an FMI 3.0 FMU (Model Exchange and
Co-Simulation), beside FMI 2.0 (:mod:`tcsim.io.fmu`) and from the same library, model and variable
table.

The FMU differs from the FMI 2.0 one only in what FMI 3.0 asks:

* ``modelDescription.xml`` (:func:`model_description_xml`): ``fmiVersion="3.0"``, an
  ``instantiationToken``, the variables as ``<Float64>`` with the same names, units and value
  references, plus ``time`` (the independent variable, value reference :data:`TIME_VR`) and the event
  indicators of the Hrovat & Tobler model as variables (:func:`tcsim._core.fmu_event_indicator_variables`);
  ``<ModelStructure>`` with ``<Output>``, ``<ContinuousStateDerivative>``, ``<InitialUnknown>`` and
  ``<EventIndicator>`` (dependencies as value references);
* ``resources/model.json`` carries the ``instantiationToken``, which ``fmi3Instantiate*`` checks;
* ``binaries/x86_64-linux/tcsim_converter.so`` (``x86_64-windows``, ``x86_64-darwin`` and
  ``aarch64-darwin`` for the other platforms' libraries, :func:`platforms`).

The binary exports both ``fmi2*`` and ``fmi3*`` functions (``crates/tcsim-fmu/src/fmi3.rs``).
See ``docs/fmu.md``.
"""

from __future__ import annotations

import uuid
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from .. import _core
from ..errors import InputError
from ..models.converter import Converter
from ..models.dynamic import DynamicModel
from . import fmu
from .fmu import MODEL_IDENTIFIER, FmiVersion, fmu_variables, xml_attr

#: Value reference of ``time``, the independent variable (the variable table's).
TIME_VR: int = _core.FMU_TIME_VR
#: The key of ``resources/model.json`` holding the ``instantiationToken`` (the library's).
TOKEN_KEY: str = _core.FMU_INSTANTIATION_TOKEN_KEY
#: FMI 3.0 platform directory of a library by its suffix (a macOS library by its architecture,
#: :func:`platforms`).
PLATFORM_OF_SUFFIX = {".so": "x86_64-linux", ".dll": "x86_64-windows"}
#: Mach-O CPU types: x86-64 and arm64.
_MACHO_CPUS = {0x01000007: "x86_64-darwin", 0x0100000C: "aarch64-darwin"}
#: The FMI 3.0 functions the library must export to be packaged.
FUNCTIONS = ("fmi3GetVersion", "fmi3InstantiateModelExchange", "fmi3InstantiateCoSimulation", "fmi3DoStep")


def platforms(lib: Path) -> list[str]:
    """The ``binaries/`` directories of a library: by suffix, and for a macOS ``.dylib`` by the
    architectures in its Mach-O header (both for a universal library)."""
    suffix = lib.suffix.lower()
    if suffix != ".dylib":
        return [PLATFORM_OF_SUFFIX[suffix]]
    head = lib.read_bytes()[:4096]
    if head[:4] == b"\xcf\xfa\xed\xfe":  # a thin 64-bit library, little-endian
        cpu = int.from_bytes(head[4:8], "little")
        return [_MACHO_CPUS[cpu]] if cpu in _MACHO_CPUS else ["x86_64-darwin"]
    if head[:4] == b"\xca\xfe\xba\xbe":  # universal: the architectures' CPU types, big-endian
        n = int.from_bytes(head[4:8], "big")
        cpus = [int.from_bytes(head[8 + 20 * i : 12 + 20 * i], "big") for i in range(min(n, 8))]
        found = sorted({_MACHO_CPUS[c] for c in cpus if c in _MACHO_CPUS})
        return found or ["x86_64-darwin"]
    return ["x86_64-darwin"]


def _type_name(v: dict[str, Any]) -> str:
    """The ``<Float64Type>`` of a variable's unit and display unit (the variables carry their units
    through ``declaredType``, as the Modelica Association's Reference FMUs do: importers that read
    only type definitions, such as fmi-sim 0.7.0, accept no ``unit`` on a variable)."""
    return v["unit"] + (f" in {v['display_unit']}" if v["display_unit"] else "")


def _type_definitions(variables: list[dict[str, Any]]) -> list[str]:
    """``<TypeDefinitions>``: one ``<Float64Type>`` per unit and display unit used (``time``: s)."""
    a, seen, lines = xml_attr, {"s": ("s", None)}, []
    for v in variables:
        if v["unit"]:
            seen[_type_name(v)] = (v["unit"], v["display_unit"])
    for name, (unit, display) in seen.items():
        shown = f" displayUnit={a(display)}" if display else ""
        lines.append(f"    <Float64Type name={a(name)} unit={a(unit)}{shown}/>")
    return ["  <TypeDefinitions>", *lines, "  </TypeDefinitions>"]


def _float64(v: dict[str, Any]) -> str:
    """One ``<Float64>`` of a row of the variable table."""
    a = xml_attr
    attrs = f'name={a(v["name"])} valueReference="{v["vr"]}"'
    attrs += f" description={a(v['description'])}" if v["description"] else ""
    attrs += f' causality="{v["causality"]}" variability="{v["variability"]}"'
    attrs += f' initial="{v["initial"]}"' if v["initial"] else ""
    attrs += f" declaredType={a(_type_name(v))}" if v["unit"] else ""
    attrs += f' start="{v["start_text"]}"' if v["start_text"] is not None else ""
    attrs += f' derivative="{v["derivative_of"]}"' if v["derivative_of"] is not None else ""
    return f"    <Float64 {attrs}/>"


def _header(model: DynamicModel, variables: list[dict[str, Any]], name: str, token: str, stamp: str) -> list[str]:
    """``<fmiModelDescription ...>`` with the Model Exchange and Co-Simulation capabilities."""
    a, version, stem = xml_attr, fmu._version(), Path(model.source).stem
    inputs = ", ".join(v["name"] for v in variables if v["causality"] == "input")
    description = (
        f"Torque converter {stem}, {model.name} model (tcsim {version}), FMI 3.0. Inputs {inputs}. Starts from "
        "the steady state consistent with the inputs."
    )
    caps = 'canGetAndSetFMUState="true" canSerializeFMUState="true" providesDirectionalDerivatives="false"'
    return [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<fmiModelDescription fmiVersion="3.0" modelName={a(name)} instantiationToken={a(token)}',
        f"  description={a(description)}",
        f'  generationTool={a("tcsim " + version)} generationDateAndTime="{stamp}" license="MIT"',
        '  variableNamingConvention="flat">',
        f'  <ModelExchange modelIdentifier="{MODEL_IDENTIFIER}" needsCompletedIntegratorStep="false" {caps}/>',
        f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"'
        f' maxOutputDerivativeOrder="0" providesIntermediateUpdate="false" hasEventMode="false" {caps}/>',
    ]


def _model_structure(variables: list[dict[str, Any]], indicators: list[dict[str, Any]]) -> list[str]:
    """``<ModelStructure>``: the outputs with their direct dependencies (value references), the
    state derivatives, the initial unknowns (outputs and derivatives) and the event indicators."""
    lines = ["  <ModelStructure>"]
    for v in variables:
        if v["causality"] == "output":
            depends = " ".join(str(vr) for vr in v["dependencies"])
            lines.append(f'    <Output valueReference="{v["vr"]}" dependencies="{depends}"/>')
    lines += [
        f'    <ContinuousStateDerivative valueReference="{v["vr"]}"/>'
        for v in variables
        if v["derivative_of"] is not None
    ]
    lines += [f'    <InitialUnknown valueReference="{v["vr"]}"/>' for v in variables if v["initial"] == "calculated"]
    lines += [f'    <EventIndicator valueReference="{v["vr"]}"/>' for v in indicators]
    return [*lines, "  </ModelStructure>"]


def model_description_xml(
    model: DynamicModel,
    causality: str = "pump-torque",
    token: str | None = None,
    model_name: str | None = None,
    generation_time: datetime | None = None,
) -> str:
    """The ``modelDescription.xml`` (FMI 3.0, Model Exchange and Co-Simulation) of a model under a
    causality, from the FMU's variable table (:func:`tcsim.io.fmu.fmu_variables`) and its FMI 3.0
    additions (``time``, the event indicators)."""
    variables = fmu_variables(model, causality)
    indicators = _core.fmu_event_indicator_variables(model.name)
    name = model_name or f"tcsim {Path(model.source).stem} {model.name}"
    token = token or "{" + str(uuid.uuid4()) + "}"
    stamp = (generation_time or datetime.now(UTC)).strftime("%Y-%m-%dT%H:%M:%SZ")
    time = (
        f'    <Float64 name="time" valueReference="{TIME_VR}" description="Simulation time"'
        ' causality="independent" variability="continuous" declaredType="s"/>'
    )
    return "\n".join(
        [
            *_header(model, variables, name, token, stamp),
            *fmu._unit_definitions(),
            *_type_definitions(variables + indicators),
            "  <LogCategories>",
            '    <Category name="logStatusError" description="Errors, with the reason (always logged)"/>',
            "  </LogCategories>",
            '  <DefaultExperiment startTime="0.0" stopTime="10.0" tolerance="1e-06" stepSize="0.001"/>',
            "  <ModelVariables>",
            time,
            *(_float64(v) for v in variables + indicators),
            "  </ModelVariables>",
            *_model_structure(variables, indicators),
            "</fmiModelDescription>",
            "",
        ]
    )


#: What ``sources/README.md`` of an FMI 3.0 FMU adds: its platform directories.
SOURCES_NOTE = f"""
## This is an FMI 3.0 FMU

FMI 3.0 names the binary directories by platform tuple: put the library into
`binaries/x86_64-windows/{MODEL_IDENTIFIER}.dll` (Windows x86-64),
`binaries/x86_64-darwin/{MODEL_IDENTIFIER}.dylib` (macOS Intel) or
`binaries/aarch64-darwin/{MODEL_IDENTIFIER}.dylib` (macOS Apple silicon; a universal library goes into
both), and on Linux x86-64 `binaries/x86_64-linux/{MODEL_IDENTIFIER}.so`, instead of `win64`, `darwin64`
and `linux64` above. The library is the same for FMI 2.0 and 3.0.
"""

#: FMI 3.0: ``binaries/x86_64-linux`` (...), the ``instantiationToken`` in ``model.json``.
FMI3 = FmiVersion(
    "3.0",
    lambda model, causality, token: model_description_xml(model, causality, token=token),
    lambda token: {TOKEN_KEY: token},
    platforms,
    FUNCTIONS,
    SOURCES_NOTE,
)


#: The FMI versions by their ``--fmi-version`` name.
FMI_VERSIONS: dict[str, FmiVersion] = {"2": fmu.FMI2, "3": FMI3}


def fmi_version(value: int | str) -> FmiVersion:
    """The FMI version of a ``--fmi-version`` value (``2`` or ``3``); anything else is an
    :class:`~tcsim.errors.InputError`."""
    if str(value) not in FMI_VERSIONS:
        raise InputError.argument("fmi_version", value, " or ".join(FMI_VERSIONS))
    return FMI_VERSIONS[str(value)]


def export_fmu(
    converter: Converter | str | Path | DynamicModel | None,
    model: str | DynamicModel,
    out_path: str | Path,
    causality: str = "pump-torque",
) -> Path:
    """Write the FMI 3.0 FMU of ``model`` of ``converter`` to ``out_path``: as
    :func:`tcsim.io.fmu.export_fmu` (the same arguments, checks and errors). Returns the path."""
    return fmu.export_fmu(converter, model, out_path, causality, fmi=FMI3)


__all__: Sequence[str] = ("export_fmu", "model_description_xml", "platforms", "fmi_version", "FMI3", "TIME_VR")
