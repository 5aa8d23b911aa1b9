"""Vehicle definitions for ``tcsim launch``: vehicle files read and validated by the core, bundled vehicles.

A vehicle is the car around a converter: engine, automatic gearbox with its shift schedule,
lock-up clutch, all-wheel-drive driveline with compliant shafts, tyres, body and service brake
(Li & Sundén 2016, §3.2.2, §3.5.2.2, §4.3.1). The converter itself is a converter file (or a
bundled converter) named by the vehicle file; its inertias are the converter's, not repeated here.

The file format (every key, its unit and range) is described in ``docs/vehicle.md``. The core owns
the schema and checks a file once (``tcsim._core.read_vehicle``); this module finds the file,
hands its text to the core and loads the converter it names. Unknown keys, missing keys, wrong
types, non-finite numbers, values outside their range, arrays of the wrong length or order are
:class:`~tcsim.errors.InputError` naming the file, the field as the file writes it
(``[gearbox].ratios[3]``), the value and what was expected.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from functools import cached_property
from importlib import resources
from pathlib import Path
from typing import Any

import tomli_w

from .. import _core
from ..errors import InputError, from_core, read_user_text
from .converter import Converter, load_converter
from .converter import bundled_names as bundled_converter_names

#: The bundled vehicle used when none is named.
DEFAULT_VEHICLE = "midsize-awd-8at"

#: The sections of a vehicle file that hold the vehicle's values, in file order (the core's).
SECTIONS: tuple[str, ...] = tuple(_core.vehicle_sections())


class Section(Mapping[str, Any]):
    """One section of a validated vehicle file: its values by key (``body["mass_kg"]``) or as
    attributes (``body.mass_kg``); arrays are lists."""

    def __init__(self, name: str, values: Mapping[str, Any]):
        self._name = name
        self._values = dict(values)

    def __getitem__(self, key: str) -> Any:
        return self._values[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __getattr__(self, key: str) -> Any:
        try:
            return self.__dict__["_values"][key]
        except KeyError:
            raise AttributeError(f"[{self._name}] has no key {key!r}") from None

    @property
    def gears(self) -> int:
        """Number of gears (of ``[gearbox]``)."""
        return len(self._values["ratios"])

    def __repr__(self) -> str:
        return f"Section([{self._name}], {self._values!r})"


@dataclass(frozen=True)
class Vehicle:
    """A vehicle file as the core read and validated it (``core``, what ``_core.launch_runs``
    takes). ``path`` is where it was read from (for messages); ``converter`` is the converter it
    names, loaded and validated."""

    core: _core.Vehicle
    path: str
    converter: Converter

    @property
    def name(self) -> str:
        return self.core.name

    @property
    def source(self) -> str:
        return self.core.source

    @property
    def description(self) -> str | None:
        return self.core.description

    @property
    def converter_spec(self) -> str:
        """The ``converter`` reference as the file writes it."""
        return self.core.converter

    @cached_property
    def sources(self) -> dict[str, str]:
        """``[sources]``: where each value comes from, ``{"section.key": text}``."""
        return dict(self.core.sources)

    @cached_property
    def sections(self) -> dict[str, Section]:
        """The sections by name, in file order."""
        values = self.core.to_dict()
        return {s: Section(s, values[s]) for s in SECTIONS}

    def __getattr__(self, name: str) -> Section:
        # the sections as attributes: vehicle.engine, vehicle.gearbox, ...
        if name in SECTIONS:
            return self.sections[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def core_spec(self) -> dict[str, dict[str, Any]]:
        """The validated sections as plain dicts: ``{"engine": {...}, "gearbox": {...}, ...}``, the
        keys of the TOML file, arrays as lists."""
        values = self.core.to_dict()
        return {s: values[s] for s in SECTIONS}

    def to_toml_dict(self) -> dict[str, Any]:
        """The whole validated file as a TOML-ready dict (top level, sections, ``[sources]``)."""
        return self.core.to_dict()

    def overall_ratio(self, gear: int) -> float:
        """Gearbox ratio of ``gear`` (1-based) times the final drive."""
        return self.gearbox.ratios[gear - 1] * self.driveline.final_drive_ratio


def _load_named_converter(spec: str, path: str) -> Converter:
    if spec in bundled_converter_names():
        return load_converter(spec)
    base = Path(path).parent
    candidate = Path(spec) if Path(spec).is_absolute() else base / spec
    if not candidate.is_file() or candidate.suffix.lower() != ".toml":
        raise InputError(
            path,
            "converter",
            spec,
            f"a bundled converter ({', '.join(bundled_converter_names())}) or a converter .toml file "
            f"relative to the vehicle file ({candidate} does not exist or is not .toml)",
        )
    return load_converter(candidate)


def read_vehicle_text(text: str, path: str) -> Vehicle:
    """A vehicle file's text, validated once by the core (``path`` names it in messages and
    anchors the converter reference)."""
    try:
        core = _core.read_vehicle(text, path)
    except _core.CoreInputError as e:
        raise from_core(e, path) from None
    return Vehicle(core, path, _load_named_converter(core.converter, path))


def parse_vehicle(data: dict[str, Any], path: str) -> Vehicle:
    """A parsed TOML document (written back as TOML and read by the core)."""
    try:
        text = tomli_w.dumps(data)
    except TypeError as e:  # a value TOML cannot hold (None, an object)
        raise InputError(path, "(file)", type(e).__name__, f"a TOML document ({e})") from None
    return read_vehicle_text(text, path)


def read_vehicle_toml(path: Path) -> Vehicle:
    return read_vehicle_text(read_user_text(path, "a readable UTF-8 TOML file"), str(path))


def _bundled_dir():
    return resources.files("tcsim") / "data" / "vehicles"


def bundled_vehicle_names() -> list[str]:
    """Names of the bundled vehicles (``data/vehicles/*.toml``)."""
    return sorted(p.name.removesuffix(".toml") for p in _bundled_dir().iterdir() if p.name.endswith(".toml"))


def load_vehicle(spec: str | Path | None = None) -> Vehicle:
    """A bundled vehicle name (default :data:`DEFAULT_VEHICLE`) or a vehicle ``.toml`` file."""
    if spec is None:
        spec = DEFAULT_VEHICLE
    text = str(spec)
    if isinstance(spec, str) and text in bundled_vehicle_names():
        with resources.as_file(_bundled_dir() / f"{text}.toml") as p:
            return read_vehicle_toml(Path(p))
    path = Path(spec)
    if path.suffix.lower() != ".toml" or not path.is_file():
        raise InputError(
            text,
            "vehicle",
            text,
            f"a bundled vehicle ({', '.join(bundled_vehicle_names())}) or an existing vehicle .toml file",
        )
    return read_vehicle_toml(path)
