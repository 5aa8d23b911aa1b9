"""``tcsim export-fmu``: a converter model as an FMI 2.0 FMU (Model Exchange and Co-Simulation), with
no Python inside.

::

    tcsim export-fmu CONVERTER --model table|hrovat-tobler|quasi-dynamic -o FILE.fmu
                     [--causality pump-torque|speeds|torques] [--fmi-version 2|3]

The FMU is a zip archive:

* ``modelDescription.xml`` (:func:`model_description_xml`), written from the FMU's variable table
  (``crates/tcsim-fmu/src/variables.rs``, read through :func:`fmu_variables`): the signals with
  fixed value references (:data:`SIGNALS`), the converter's parameters as tunable parameters
  (value references from :data:`FIRST_PARAMETER_VR`), units, descriptions and the model structure;
* ``resources/model.json``: the model specification (:attr:`tcsim.transient.DynamicModel.spec`),
  the causality and the parameter list, read by the library at ``fmi2Instantiate``;
* ``binaries/linux64/tcsim_converter.so``: the Rust library ``crates/tcsim-fmu`` (a ``cdylib`` over
  ``tcsim-core``: tcsim's BDF solver inside ``fmi2DoStep``), found by :func:`find_libraries`
  (``binaries/win64/tcsim_converter.dll`` and ``binaries/darwin64/tcsim_converter.dylib`` as well
  when ``$TCSIM_FMU_LIBRARY`` lists them);
* ``sources/``: a README on rebuilding the binary for Windows and macOS, with the Rust sources of
  ``tcsim-core`` and ``tcsim-fmu`` and the workspace's ``Cargo.toml``/``Cargo.lock``.

Causality (thesis/VSIM choice by default): ``pump-torque`` has the inputs ``pump_torque_nm`` and
``turbine_speed_rad_s``; ``speeds`` has ``pump_speed_rad_s`` and ``turbine_speed_rad_s``; ``torques``
has ``pump_torque_nm`` and ``load_torque_nm`` (drive (c) of :class:`tcsim.transient.PumpTorqueLoad`:
both speeds are states and outputs, no input is differentiated; parameters ``load_inertia_kg_m2`` and
``load_drag_nm_s2``, default 0). Every causality has the input ``lockup_capacity_nm`` (N·m ≥ 0,
default 0) of the lock-up clutch, with the outputs ``lockup_torque_nm``, ``lockup_state`` and
``lockup_slip_rad_s``. Every other signal of the model is an output. The FMU starts from the steady
state consistent with the inputs set before ``fmi2ExitInitializationMode`` (as ``tcsim replay``).

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
from collections.abc import Callable, Sequence
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
from ..models.drives import Drive, PumpTorqueLoad, PumpTorqueTurbineSpeed, Speeds
from ..models.dynamic import DynamicModel, resolve_model
from ..simulation.transient import SolverError, simulate
from .fmu_sources import PACKAGED_DIR, SOURCES_DIR, copy_rust_sources, is_source_tree
from .outputs import output_file

#: ``modelIdentifier`` of the FMU: the binary is ``binaries/<platform>/tcsim_converter.<ext>``
#: (owned by the FMU crate's variable table).
MODEL_IDENTIFIER: str = _core.FMU_MODEL_IDENTIFIER
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
FIRST_PARAMETER_VR: int = _core.FMU_FIRST_PARAMETER_VR
#: ``--causality`` choices: the two inputs of each.
CAUSALITIES: dict[str, tuple[str, str]] = {name: (a, b) for name, (a, b) in _core.fmu_causalities()}
#: The inputs of every causality besides its two: the lock-up clutch's capacity.
COMMON_INPUTS: tuple[str, ...] = tuple(_core.fmu_common_inputs())


class FmuLibraryError(RuntimeError):
    """The FMU library could not be found or built (not the user's fault: exit code 1)."""


# ---------------------------------------------------------------------------------------------
# The variable table (crates/tcsim-fmu/src/variables.rs, through tcsim._core)


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
SIGNALS: tuple[Signal, ...] = tuple(
    Signal(s["vr"], s["name"], s["unit"], s["description"], tuple(s["models"]), s["state"]) for s in _core.fmu_signals()
)


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


def _check_causality(causality: str) -> tuple[str, str]:
    if causality not in CAUSALITIES:
        raise InputError.argument("causality", causality, f"one of {', '.join(CAUSALITIES)}")
    return CAUSALITIES[causality]


def fmu_variables(model: DynamicModel, causality: str = "pump-torque") -> list[dict[str, Any]]:
    """The FMU's variables (:func:`tcsim._core.fmu_variables`) in ``<ModelVariables>`` order; a
    parameter that is not a finite number is an :class:`~tcsim.errors.InputError`."""
    _check_causality(causality)
    variables = _core.fmu_variables(model.spec, causality)
    for v in variables:
        if v["key"] is not None and not math.isfinite(v["start"]):
            raise InputError(model.source, v["name"], v["start"], "a finite number")
    return variables


def fmu_parameters(model: DynamicModel) -> list[Parameter]:
    """Every numeric entry of the model's spec (scalars, and each element of the arrays) as a
    parameter, in the spec's key order, with value references from :data:`FIRST_PARAMETER_VR`."""
    return [
        Parameter(v["vr"], v["name"], v["key"], v["index"], v["start"], v["unit"], v["description"])
        for v in fmu_variables(model)
        if v["key"] is not None
    ]


# ---------------------------------------------------------------------------------------------
# modelDescription.xml, written from the variable table only


#: Characters XML 1.0 does not allow, even as character references (C0 controls but tab, newline and
#: carriage return; surrogates, which a non-UTF-8 file name decodes to; U+FFFE and U+FFFF).
_XML_FORBIDDEN = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def xml_text(text: str) -> str:
    """``text`` with every character XML 1.0 forbids shown as its escape (``\\x01``, ``\\udcff``):
    every user string that reaches ``modelDescription.xml`` goes through here, then
    :func:`xml_attr` or an element's escaping."""
    return _XML_FORBIDDEN.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


def xml_attr(text: str) -> str:
    """``text`` as a quoted XML attribute value (:func:`xml_text`, then ``&``, ``<``, ``"`` and
    whitespace escaped)."""
    return quoteattr(xml_text(text))


def _version() -> str:
    try:
        return metadata.version("tcsim")
    except Exception:
        return "0+unknown"


def _header(
    model: DynamicModel, causality: str, variables: list[dict[str, Any]], name: str, guid: str, stamp: str
) -> list[str]:
    """``<fmiModelDescription ...>`` with the Model Exchange and Co-Simulation capabilities."""
    a, version, stem = xml_attr, _version(), Path(model.source).stem
    inputs, outputs = (", ".join(v["name"] for v in variables if v["causality"] == c) for c in ("input", "output"))
    description = (
        f"Torque converter {stem}, {model.name} model (tcsim {version}). Inputs {inputs}; outputs {outputs}. "
        "Starts from the steady state consistent with the inputs."
    )
    return [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<fmiModelDescription fmiVersion="2.0" modelName={a(name)} guid={a(guid)}',
        f"  description={a(description)}",
        f'  generationTool={a("tcsim " + version)} generationDateAndTime="{stamp}" license="MIT"',
        f'  variableNamingConvention="flat" numberOfEventIndicators="{_core.fmu_event_indicators(model.name)}">',
        f'  <ModelExchange modelIdentifier="{MODEL_IDENTIFIER}" completedIntegratorStepNotNeeded="true"'
        ' canGetAndSetFMUstate="true" canSerializeFMUstate="true" providesDirectionalDerivative="false"/>',
        f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"'
        ' canInterpolateInputs="true" maxOutputDerivativeOrder="0" canGetAndSetFMUstate="true"'
        ' canSerializeFMUstate="true" providesDirectionalDerivative="false"/>',
    ]


def _log_categories() -> list[str]:
    """``<LogCategories>``: the categories the library logs with (:data:`tcsim._core.FMU_LOG_CATEGORIES`)."""
    lines = ["  <LogCategories>"]
    lines += [f"    <Category name={xml_attr(n)} description={xml_attr(d)}/>" for n, d in _core.FMU_LOG_CATEGORIES]
    return [*lines, "  </LogCategories>"]


def _unit_definitions() -> list[str]:
    """``<UnitDefinitions>`` of :func:`tcsim._core.fmu_units`."""
    lines = ["  <UnitDefinitions>"]
    for name, base, display in _core.fmu_units():
        exponents = " ".join(f'{k}="{v}"' for k, v in base)
        lines.append(f"    <Unit name={xml_attr(name)}>")
        lines.append(f"      <BaseUnit {exponents}/>" if exponents else "      <BaseUnit/>")
        lines += [f'      <DisplayUnit name={xml_attr(d)} factor="{factor}"/>' for d, factor in display]
        lines.append("    </Unit>")
    return [*lines, "  </UnitDefinitions>"]


def _model_variables(variables: list[dict[str, Any]], index: dict[int, int]) -> list[str]:
    """``<ModelVariables>``: one ``<ScalarVariable>`` per row of the table (``index``: the 1-based
    index of each value reference)."""
    a = xml_attr
    lines = ["  <ModelVariables>"]
    for v in variables:
        attrs = f'causality="{v["causality"]}" variability="{v["variability"]}"'
        attrs += f' initial="{v["initial"]}"' if v["initial"] else ""
        real = f"unit={a(v['unit'])}"
        real += f" displayUnit={a(v['display_unit'])}" if v["display_unit"] else ""
        real += f' start="{v["start_text"]}"' if v["start_text"] is not None else ""
        real += f' derivative="{index[v["derivative_of"]]}"' if v["derivative_of"] is not None else ""
        lines.append(f"    <!-- index {index[v['vr']]} -->")
        head = f'name={a(v["name"])} valueReference="{v["vr"]}" description={a(v["description"])}'
        lines.append(f"    <ScalarVariable {head} {attrs}>")
        lines += [f"      <Real {real}/>", "    </ScalarVariable>"]
    return [*lines, "  </ModelVariables>"]


def _model_structure(variables: list[dict[str, Any]], index: dict[int, int]) -> list[str]:
    """``<ModelStructure>``: the outputs with their direct dependencies, the derivatives, and the
    initial unknowns (every variable the FMU calculates)."""
    lines = ["  <ModelStructure>", "    <Outputs>"]
    for v in variables:
        if v["causality"] == "output":
            depends = " ".join(str(index[vr]) for vr in v["dependencies"])
            lines.append(f'      <Unknown index="{index[v["vr"]]}" dependencies="{depends}"/>')
    lines.append("    </Outputs>")
    derivatives = [v for v in variables if v["derivative_of"] is not None]
    if derivatives:
        lines.append("    <Derivatives>")
        lines += [f'      <Unknown index="{index[v["vr"]]}"/>' for v in derivatives]
        lines.append("    </Derivatives>")
    lines.append("    <InitialUnknowns>")
    lines += [f'      <Unknown index="{index[v["vr"]]}"/>' for v in variables if v["initial"] == "calculated"]
    return [*lines, "    </InitialUnknowns>", "  </ModelStructure>"]


def model_description_xml(
    model: DynamicModel,
    causality: str = "pump-torque",
    model_name: str | None = None,
    guid: str | None = None,
    generation_time: datetime | None = None,
) -> str:
    """The ``modelDescription.xml`` (FMI 2.0, Co-Simulation and Model Exchange) of a model under a
    causality, written from the FMU's variable table (:func:`fmu_variables`)."""
    variables = fmu_variables(model, causality)
    index = {v["vr"]: i for i, v in enumerate(variables, start=1)}
    name = model_name or f"tcsim {Path(model.source).stem} {model.name}"
    guid = guid or "{" + str(uuid.uuid4()) + "}"
    stamp = (generation_time or datetime.now(UTC)).strftime("%Y-%m-%dT%H:%M:%SZ")
    return "\n".join(
        [
            *_header(model, causality, variables, name, guid, stamp),
            *_unit_definitions(),
            *_log_categories(),
            '  <DefaultExperiment startTime="0.0" stopTime="10.0" tolerance="1e-06" stepSize="0.001"/>',
            *_model_variables(variables, index),
            *_model_structure(variables, index),
            "</fmiModelDescription>",
            "",
        ]
    )


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
    return next((root for root in candidates if is_source_tree(root)), None)


def packaged_dir() -> Path:
    """``tcsim/_fmu/`` of this copy of tcsim: where an installed wheel carries the FMU library it was
    built with and that library's Rust sources (``sources/``); absent in a source checkout."""
    return Path(__file__).resolve().parents[1] / PACKAGED_DIR


def packaged_library() -> Path | None:
    """The FMU library installed with this copy of tcsim (``tcsim/_fmu/libtcsim_fmu.so`` on Linux),
    or None in a source checkout (``maturin develop``) or a copy built without it."""
    lib = packaged_dir() / _local_library_file()
    return lib if lib.is_file() else None


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
    """The FMU libraries to package, the first found of:

    1. ``$TCSIM_FMU_LIBRARY`` (one file, or several separated by ``os.pathsep``, one per platform:
       ``.so`` linux64, ``.dll`` win64, ``.dylib`` darwin64);
    2. the library installed with the package (:func:`packaged_library`): built by ``pip install``
       together with ``tcsim._core``, so it matches the variable table the XML is written from;
    3. ``target/release/``, then ``target/debug/`` of the source tree (``libtcsim_fmu.so`` on
       Linux), with a :class:`~tcsim.errors.TcsimWarning` when it is older than the Rust sources;
    4. with ``build`` and a source tree, the library built now with cargo (a warning says so first).

    Raises :class:`FmuLibraryError` when there is none."""
    env = os.environ.get(LIBRARY_ENV)
    if env:
        return _env_libraries(env)
    installed = packaged_library()
    if installed is not None:
        return [installed]
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
            warnings.warn(
                f"the FMU library {name} is not built: running 'cargo build --release -p tcsim-fmu' in {root} "
                "(minutes the first time)",
                TcsimWarning,
                stacklevel=2,
            )
            return [build_library(root)]
    raise FmuLibraryError(
        f"the FMU library {name} was not found: set {LIBRARY_ENV} to it, reinstall tcsim with "
        "'pip install' (which builds it into the package), or run 'cargo build --release -p tcsim-fmu' in the "
        "tcsim source tree" + ("" if root is None else f" ({root})")
    )


def _env_libraries(env: str) -> list[Path]:
    """The libraries ``$TCSIM_FMU_LIBRARY`` lists: files, ``.so``/``.dll``/``.dylib``, one a platform."""
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


def _check_library(
    lib: Path, needed: Sequence[str] = ("fmi2GetVersion", "fmi2Instantiate", "fmi2DoStep", "fmi2FreeInstance")
) -> None:
    """The library exports the ``needed`` functions (by default FMI 2.0's; and, if it is for this
    platform, it loads)."""
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
one binary serves every converter, model and causality of this tcsim version.

## Rebuilding the binary for another platform

The library needs Rust 1.89 or newer (https://rustup.rs) and nothing else: no Python, no FMI SDK.
Build it for the target: cargo writes `target/<target>/release/tcsim_fmu.dll` (Windows) or
`target/<target>/release/libtcsim_fmu.dylib` (macOS). Copy it into the FMU under the
`modelIdentifier`, `{mi}`:

| target | FMI 2.0 | FMI 3.0 |
|---|---|---|
| `x86_64-pc-windows-msvc` or `-gnu` | `binaries/win64/{mi}.dll` | `binaries/x86_64-windows/{mi}.dll` |
| `x86_64-apple-darwin` | `binaries/darwin64/{mi}.dylib` (universal) | `binaries/x86_64-darwin/{mi}.dylib` |
| `aarch64-apple-darwin` | `binaries/darwin64/{mi}.dylib` (universal) | `binaries/aarch64-darwin/{mi}.dylib` |
| `x86_64-unknown-linux-gnu` | `binaries/linux64/{mi}.so` | `binaries/x86_64-linux/{mi}.so` |

Windows, MSVC (PowerShell, with the Visual Studio C++ build tools), in the folder of `converter.fmu`:

    rustup target add x86_64-pc-windows-msvc
    python -m zipfile -e converter.fmu fmu
    cd fmu\\sources
    $env:RUSTFLAGS = "-C target-feature=+crt-static"
    cargo build --release -p tcsim-fmu --target x86_64-pc-windows-msvc
    mkdir ..\\binaries\\win64
    copy target\\x86_64-pc-windows-msvc\\release\\tcsim_fmu.dll ..\\binaries\\win64\\{mi}.dll
    Remove-Item -Recurse target; cd ..
    python -m zipfile -c ..\\converter-win.fmu modelDescription.xml binaries resources sources

Windows, GNU, cross-compiled on Linux (`apt-get install gcc-mingw-w64-x86-64`):

    rustup target add x86_64-pc-windows-gnu
    python3 -m zipfile -e converter.fmu fmu && cd fmu/sources
    cargo build --release -p tcsim-fmu --target x86_64-pc-windows-gnu
    mkdir -p ../binaries/win64 && cp target/x86_64-pc-windows-gnu/release/tcsim_fmu.dll ../binaries/win64/{mi}.dll
    rm -rf target && cd .. && python3 -m zipfile -c ../converter-win.fmu modelDescription.xml binaries resources sources

macOS, one universal library for Intel and Apple silicon (Xcode command-line tools):

    rustup target add x86_64-apple-darwin aarch64-apple-darwin
    python3 -m zipfile -e converter.fmu fmu && cd fmu/sources
    cargo build --release -p tcsim-fmu --target x86_64-apple-darwin
    cargo build --release -p tcsim-fmu --target aarch64-apple-darwin
    mkdir -p ../binaries/darwin64
    lipo -create -output ../binaries/darwin64/{mi}.dylib target/x86_64-apple-darwin/release/libtcsim_fmu.dylib \\
        target/aarch64-apple-darwin/release/libtcsim_fmu.dylib
    rm -rf target && cd .. && python3 -m zipfile -c ../converter-mac.fmu modelDescription.xml binaries resources sources

An FMI 3.0 FMU takes the FMI 3.0 folders (one library per architecture, no `lipo`). Keep
`modelDescription.xml` and `resources/` as they are: they do not depend on the platform. Zip with
Python's `zipfile` (paths with `/`, files at the root). Do not add `<SourceFiles>`: the sources are
Rust, not the C an importing tool would compile.

## Contents

* `Cargo.toml`, `Cargo.lock`: the workspace (members `tcsim-core` and `tcsim-fmu` only) and the
  exact dependency versions tcsim was built with;
* `crates/tcsim-core/`: the converter models and the transient engine (pure Rust);
* `crates/tcsim-fmu/`: the FMI C API (Model Exchange and Co-Simulation).
{missing}
License: MIT (`LICENSE`).
"""


def _write_sources(root: Path | None, dest: Path) -> None:
    """``sources/``: the README and the Rust sources, those installed with the package
    (``tcsim/_fmu/sources/``, the sources of :func:`packaged_library`) else those of the source tree
    ``root``; with neither, the README alone and a warning."""
    dest.mkdir(parents=True, exist_ok=True)
    missing = ""
    installed = packaged_dir() / SOURCES_DIR
    if installed.is_dir():
        shutil.copytree(installed, dest, dirs_exist_ok=True)
    elif root is not None:
        copy_rust_sources(root, dest)
    else:
        missing = (
            "\n**This FMU carries no Rust sources**: it was exported without the tcsim source tree. "
            "Get them from the tcsim repository (the same version) and build there.\n"
        )
        warnings.warn(
            "the tcsim source tree was not found: the FMU's sources/ holds the rebuild instructions only",
            TcsimWarning,
            stacklevel=3,
        )
    (dest / "README.md").write_text(SOURCES_README.format(version=_version(), mi=MODEL_IDENTIFIER, missing=missing))


# ---------------------------------------------------------------------------------------------
# Export


def _check_model(model: DynamicModel, causality: str) -> None:
    """A short run from the default inputs' steady state, so that an inadmissible model (a shape
    effect beyond the mass-matrix bound, ...) is an input error now, not an fmi2Error later."""
    t = [0.0, 1e-3]
    variables = fmu_variables(model, causality)
    start = {v["name"]: [v["start"]] * 2 for v in variables if v["causality"] in ("input", "parameter")}
    first, second = (start[name] for name in CAUSALITIES[causality])  # the table's start values
    drive: Drive
    if causality == "torques":
        drive = PumpTorqueLoad(
            t,
            first,
            load_inertia_kg_m2=start["load_inertia_kg_m2"][0],
            load_torque_nm=second,
            load_drag_nm_s2=start["load_drag_nm_s2"][0],
        )
    else:
        drive = (Speeds if causality == "speeds" else PumpTorqueTurbineSpeed)(t, first, second)
    try:
        simulate(model, drive)
    except SolverError:
        pass  # the inputs of a real run differ; not a reason to refuse the export


def _output_path(out_path: str | Path) -> Path:
    """``out_path`` if it names a ``.fmu`` file that is missing or an FMU (a zip archive with a
    ``modelDescription.xml``), which is then replaced; the rest of the rule is
    :func:`tcsim.io.outputs.output_file`'s."""
    out = Path(out_path)
    if out.suffix.lower() != ".fmu":
        raise InputError.argument("out_path", str(out), "a file name ending in .fmu")
    if out.is_dir():
        raise InputError.argument("out_path", str(out), "a .fmu file (a directory of that name exists)")
    if out.is_file() and not _is_fmu(out):
        expected = "a new .fmu file or an FMU to replace (the file is not an FMU)"
        raise InputError.argument("out_path", str(out), expected)
    return out


def _is_fmu(path: Path) -> bool:
    try:
        with zipfile.ZipFile(path) as zf:
            return "modelDescription.xml" in zf.namelist()
    except (OSError, zipfile.BadZipFile):
        return False


@dataclass(frozen=True)
class FmiVersion:
    """What differs between the FMI versions an FMU is written for (the library, the model and the
    variables are the same)."""

    #: ``fmiVersion`` of the model description (``2.0``).
    name: str
    #: ``modelDescription.xml`` of a model under a causality with a GUID/instantiation token.
    model_description: Callable[[DynamicModel, str, str], str]
    #: Entries ``resources/model.json`` adds for the version, given the token.
    resources: Callable[[str], dict[str, Any]]
    #: The ``binaries/`` directories of a library file.
    platforms: Callable[[Path], list[str]]
    #: Functions the library must export.
    functions: tuple[str, ...]
    #: What ``sources/README.md`` adds for the version (markdown; none for FMI 2.0).
    sources_note: str = ""


#: FMI 2.0: ``binaries/linux64``, ``win64``, ``darwin64``; the GUID in ``model.json``.
FMI2 = FmiVersion(
    "2.0",
    lambda model, causality, token: model_description_xml(model, causality, guid=token),
    lambda token: {"guid": token},  # checked by fmi2Instantiate
    lambda lib: [PLATFORM_OF_SUFFIX[lib.suffix.lower()]],
    ("fmi2GetVersion", "fmi2Instantiate", "fmi2DoStep", "fmi2FreeInstance"),
)


def export_fmu(
    converter: Converter | str | Path | DynamicModel | None,
    model: str | DynamicModel,
    out_path: str | Path,
    causality: str = "pump-torque",
    fmi: FmiVersion = FMI2,
) -> Path:
    """Write the FMU of ``model`` (a name of :data:`tcsim.models.converter.MODELS`, or a
    :class:`~tcsim.transient.DynamicModel`, with ``converter`` then ignored) of ``converter`` (a
    :class:`~tcsim.models.converter.Converter`, bundled name or file) to ``out_path`` (``*.fmu``), written
    atomically by the rule of :func:`tcsim.io.outputs.output_file` (an input of the run or a
    directory of that name is refused, an existing file replaced), for FMI 2.0 or, with
    ``fmi=tcsim.io.fmu3.FMI3``, 3.0. Returns the path."""
    _check_causality(causality)
    out = _output_path(out_path)
    dyn = resolve_model(converter if isinstance(converter, (Converter, DynamicModel)) else str(converter), model)
    _check_model(dyn, causality)
    token = "{" + str(uuid.uuid4()) + "}"
    xml = fmi.model_description(dyn, causality, token)
    config = {**model_json(dyn, causality), **fmi.resources(token)}
    libs = find_libraries()
    for lib in libs:
        _check_library(lib, fmi.functions)
    root = source_root()

    inputs = [str(p) for p in (converter, dyn.source) if isinstance(p, (str, Path))]
    with output_file(out, inputs) as tmp, tempfile.TemporaryDirectory(prefix="tcsim-fmu-") as stage_dir:
        stage = Path(stage_dir)
        (stage / "modelDescription.xml").write_text(xml, encoding="utf-8")
        (stage / "resources").mkdir()
        (stage / "resources" / "model.json").write_text(json.dumps(config, indent=1) + "\n")
        for lib in libs:
            for platform in fmi.platforms(lib):
                (stage / "binaries" / platform).mkdir(parents=True)
                shutil.copyfile(lib, stage / "binaries" / platform / f"{MODEL_IDENTIFIER}{lib.suffix.lower()}")
        _write_sources(root, stage / "sources")
        if fmi.sources_note:
            with (stage / "sources" / "README.md").open("a") as readme:
                readme.write(fmi.sources_note)
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zf:
            for item in sorted(stage.rglob("*")):
                if item.is_file():
                    zf.write(item, item.relative_to(stage).as_posix())
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
    "COMMON_INPUTS",
)
