"""Converter definitions: TOML files validated by pydantic, bundled converters, tables alone.

A converter is a bundled name (``tcsim converters``), a TOML file, or a characteristic table
alone (CSV or VECTO ``.vtcc``, usable by the ``table`` model and as a fitting target). The
sections and keys are those of ``conventions.md``; each model needs only its own sections.
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from .. import _core
from ..errors import InputError, from_core, read_user_text
from .characteristic import CAPACITY_KEYS, Characteristic
from .plausibility import warn_implausible
from .tables import read_table

MODELS = ("table", "hrovat-tobler", "quasi-dynamic")


# --------------------------------------------------------------------------------------------
# TOML sections


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=True, frozen=True)


class CharacteristicSection(_Section):
    speed_ratio: list[float]
    torque_ratio: list[float]
    capacity_factor_nm_s2: list[float] | None = None
    k_factor_rpm_per_sqrt_nm: list[float] | None = None
    k_factor_rad_s_per_sqrt_nm: list[float] | None = None
    k_factor_rpm_per_sqrt_lbf_ft: list[float] | None = None
    capacity_nm_per_rpm2: list[float] | None = None
    mp1000_nm: list[float] | None = None
    #: How the table continues in overrun beyond its rows (checked by the core; docs/models.md).
    overrun: str | None = None
    #: The quantity interpolated in SR between rows (checked by the core; docs/models.md).
    interpolation: str | None = None
    #: First-order lag of the table model's pump torque, s (docs/lag.md); absent: no lag.
    lag_time_constant_s: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    #: The input (pump) torque the table was measured at, N·m: required in each table of an array
    #: ``[[characteristic]]`` (torque-dependent capacity, docs/torque_capacity.md).
    input_torque_nm: float | None = Field(default=None, gt=0, allow_inf_nan=False)

    @model_validator(mode="after")
    def _one_capacity(self):
        given = [k for k in CAPACITY_KEYS if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"exactly one capacity key of {', '.join(CAPACITY_KEYS)}; got {given or 'none'}")
        return self

    def capacity(self) -> tuple[str, list[float]]:
        key = next(k for k in CAPACITY_KEYS if getattr(self, k) is not None)
        return key, getattr(self, key)


def _positive():
    return Field(gt=0, allow_inf_nan=False)


class InertiaSection(_Section):
    """Rotating inertias including the fluid carried by each element, kg·m²."""

    pump_kg_m2: float = _positive()
    turbine_kg_m2: float = _positive()
    stator_kg_m2: float = _positive()


def _angle():
    return Field(gt=-90.0, lt=90.0, allow_inf_nan=False)


def _loss():
    return Field(ge=0.0, allow_inf_nan=False)


class GeometrySection(_Section):
    """Hrovat & Tobler parameters (Li & Sundén 2016, Table 2.2); angles in degrees."""

    flow_area_m2: float = _positive()
    fluid_density_kg_m3: float = _positive()
    pump_exit_radius_m: float = _positive()
    turbine_exit_radius_m: float = _positive()
    stator_exit_radius_m: float = _positive()
    pump_exit_angle_deg: float = _angle()
    turbine_exit_angle_deg: float = _angle()
    stator_exit_angle_deg: float = _angle()
    pump_inlet_angle_deg: float = _angle()
    turbine_inlet_angle_deg: float = _angle()
    stator_inlet_angle_deg: float = _angle()
    pump_shock_loss: float = _loss()
    turbine_shock_loss: float = _loss()
    stator_shock_loss: float = _loss()
    friction_loss: float = _loss()
    fluid_length_m: float = _positive()
    pump_shape_effect_m2: float = Field(allow_inf_nan=False)
    turbine_shape_effect_m2: float = Field(allow_inf_nan=False)
    stator_shape_effect_m2: float = Field(allow_inf_nan=False)

    def core_row(self) -> np.ndarray:
        """The fifteen steady-state parameters in the core's order, angles in radians."""
        return np.array([getattr(self, k) for k in STEADY_KEYS], dtype=float) * STEADY_SCALE


class QuasiDynamicSection(_Section):
    """tcsim's quasi-dynamic model (docs/physics.md §5, docs/transient.md). The density and pump
    radius set the Euler flow estimate; they default to the [geometry] values."""

    pump_shape_effect_m2: float = Field(allow_inf_nan=False)
    turbine_shape_effect_m2: float = Field(allow_inf_nan=False)
    flow_time_constant_s: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    fluid_density_kg_m3: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    pump_exit_radius_m: float | None = Field(default=None, gt=0, allow_inf_nan=False)


#: Geometry keys of the steady state, in the core's parameter order (degrees in files).
STEADY_KEYS = tuple(k.removesuffix("_rad") + "_deg" if k.endswith("_rad") else k for k in _core.ht_parameter_names())
STEADY_SCALE = np.array([math.pi / 180.0 if k.endswith("_deg") else 1.0 for k in STEADY_KEYS])


class ConverterFile(_Section):
    name: str
    source: str
    description: str | None = None
    characteristic: CharacteristicSection | None = None
    inertia: InertiaSection | None = None
    geometry: GeometrySection | None = None
    quasi_dynamic: QuasiDynamicSection | None = None
    #: Where each value comes from: "section.key" -> text ("assumed: ..." where assumed).
    sources: dict[str, str] = {}


_SECTIONS = ("characteristic", "inertia", "geometry", "quasi_dynamic")
_REQUIRED = {
    "table": ("characteristic",),
    "hrovat-tobler": ("geometry",),
    "quasi-dynamic": ("characteristic",),
}


# --------------------------------------------------------------------------------------------
# the converter


@dataclass(frozen=True)
class Converter:
    """A validated converter definition. ``path`` is where it was read from (for messages)."""

    name: str
    source: str
    path: str
    characteristic: Characteristic | None = None
    inertia: InertiaSection | None = None
    geometry: GeometrySection | None = None
    quasi_dynamic: QuasiDynamicSection | None = None
    description: str | None = None
    sources: dict[str, str] = field(default_factory=dict)
    #: ``[characteristic] lag_time_constant_s``: the table model's first-order lag, s (docs/lag.md).
    lag_time_constant_s: float | None = None

    @property
    def models(self) -> tuple[str, ...]:
        """The models whose sections this converter has."""
        return tuple(m for m in MODELS if all(getattr(self, s) is not None for s in _REQUIRED[m]))

    def require(self, model: str) -> None:
        """Raise an InputError unless the converter has the sections ``model`` needs."""
        if model not in MODELS:
            raise InputError.argument("model", model, f"one of {', '.join(MODELS)}")
        for section in _REQUIRED[model]:
            if getattr(self, section) is None:
                raise InputError(self.path, f"[{section}]", "missing", f"a [{section}] section for the {model} model")

    def core_geometry(self) -> np.ndarray:
        """The geometry as a (1, 15) array for the core."""
        self.require("hrovat-tobler")
        assert self.geometry is not None  # require() checked it
        return self.geometry.core_row()[None, :]

    def to_toml_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "source": self.source}
        if self.description:
            out["description"] = self.description
        if self.characteristic is not None:
            out["characteristic"] = _characteristic_toml(self.characteristic)
            if self.lag_time_constant_s is not None:
                first = out["characteristic"]
                (first[0] if isinstance(first, list) else first)["lag_time_constant_s"] = self.lag_time_constant_s
        for section in ("inertia", "geometry", "quasi_dynamic"):
            model = getattr(self, section)
            if model is not None:
                out[section] = model.model_dump(exclude_none=True)
        if self.sources:
            out["sources"] = dict(self.sources)
        return out


def _characteristic_toml(c: Characteristic) -> dict[str, Any] | list[dict[str, Any]]:
    """``[characteristic]``, or for several tables ``[[characteristic]]`` with the converter-wide
    rules written in the first table."""

    def one(t: Characteristic, rules: bool) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if t.input_torque_nm is not None:
            out["input_torque_nm"] = float(t.input_torque_nm)
        out |= {
            "speed_ratio": t.speed_ratio.tolist(),
            "torque_ratio": t.torque_ratio.tolist(),
            "capacity_factor_nm_s2": t.capacity_factor_nm_s2.tolist(),
        }
        return out | (dict(t.core_rules()) if rules else {})

    if not c.by_torque:
        return one(c, True)
    return [one(t, i == 0) for i, t in enumerate(c.by_torque)]


#: The keys of ``[characteristic]`` that apply to the whole converter: in ``[[characteristic]]`` each
#: may be given in any of the tables, with the same value wherever it is given more than once.
CONVERTER_WIDE_KEYS = ("overrun", "interpolation", "lag_time_constant_s")


def _table_sections(items: Any, path: str) -> list[CharacteristicSection]:
    """The tables of ``[[characteristic]]``, validated one by one (fields ``[characteristic][i].key``),
    each with its ``input_torque_nm``."""
    if not items:
        raise InputError(path, "[characteristic]", "[]", "at least one [[characteristic]] table")
    sections = []
    for i, item in enumerate(items):
        try:
            section = CharacteristicSection.model_validate(item)
        except ValidationError as err:
            raise _pydantic_to_input_error(err, path, ("characteristic", i)) from None
        if section.input_torque_nm is None:
            raise InputError(
                path,
                f"[characteristic][{i}].input_torque_nm",
                "missing",
                "the input torque in N·m the table was measured at, in each [[characteristic]] table",
            )
        sections.append(section)
    for key in CONVERTER_WIDE_KEYS:
        given = [(i, getattr(t, key)) for i, t in enumerate(sections) if getattr(t, key) is not None]
        for i, value in given[1:]:
            if value != given[0][1]:
                raise InputError(
                    path,
                    f"[characteristic][{i}].{key}",
                    value,
                    f"{given[0][1]!r} as in [characteristic][{given[0][0]}] ({key} applies to the whole converter)",
                )
    return sections


def _rule(sections: list[CharacteristicSection], key: str) -> str | None:
    return next((getattr(t, key) for t in sections if getattr(t, key) is not None), None)


def _lag(doc: ConverterFile, tables: list[CharacteristicSection] | None) -> float | None:
    """``lag_time_constant_s`` of ``[characteristic]`` or of any ``[[characteristic]]`` table (the same
    in each table that gives it: :data:`CONVERTER_WIDE_KEYS`)."""
    sections = tables if tables is not None else [doc.characteristic] if doc.characteristic is not None else []
    return next((t.lag_time_constant_s for t in sections if t.lag_time_constant_s is not None), None)


def _characteristic(doc: ConverterFile, tables: list[CharacteristicSection] | None, path: str) -> Characteristic | None:
    """The validated characteristic of ``[characteristic]``, or of the ``[[characteristic]]`` ``tables``."""
    sections = tables if tables is not None else ([doc.characteristic] if doc.characteristic is not None else [])
    if not sections:
        return None
    overrun, interpolation = _rule(sections, "overrun"), _rule(sections, "interpolation")
    prefixes = ["[characteristic]."] if tables is None else [f"[characteristic][{i}]." for i in range(len(sections))]
    out = []
    for section, where in zip(sections, prefixes, strict=True):
        key, values = section.capacity()
        out.append(
            Characteristic.from_columns(
                section.speed_ratio,
                section.torque_ratio,
                values,
                key,
                path,
                where,
                overrun=overrun,
                interpolation=interpolation,
                input_torque_nm=section.input_torque_nm,
            )
        )
    if len(out) == 1:  # [characteristic], or an array of one table: that table alone
        return out[0]
    return Characteristic.torque_dependent(out, path, prefixes)


def _unknown_beside(err: ValidationError, loc: tuple[Any, ...]) -> str:
    """For a missing key, the unknown keys beside it (a misspelt key was reported as missing
    without naming what was typed: a fresh-eyes trial)."""
    typed = [x["loc"][-1] for x in err.errors() if x["type"] == "extra_forbidden" and x["loc"][:-1] == loc[:-1]]
    return f" (the section has the unknown key {', '.join(map(repr, typed))}: misspelt?)" if typed else ""


def _pydantic_to_input_error(err: ValidationError, path: str, prefix: tuple[Any, ...] = ()) -> InputError:
    e = err.errors()[0]
    loc = [str(x) for x in (*prefix, *e["loc"])]
    if loc and loc[0] in _SECTIONS + ("sources",):
        head = f"[{loc[0]}]"
        rest = "".join(f"[{x}]" if x.isdigit() else f".{x}" for x in loc[1:])
        field_name = head + rest
    else:
        field_name = ".".join(loc) or "(file)"
    value = e.get("input", "")
    msg = e["msg"].removeprefix("Input should be ")
    if e["type"] == "extra_forbidden":
        section = f"[{loc[0]}]" if len(loc) > 1 else "the top level"
        msg = f"a known key of {section} (this key is unknown; conventions.md lists the keys)"
    elif e["type"] == "missing":
        value, msg = "missing", "this required key" + _unknown_beside(err, e["loc"])
    elif e["type"] == "value_error":
        msg = msg.removeprefix("Value error, ")
        value = "" if isinstance(value, dict) else value
    if isinstance(value, (dict, list)) and len(str(value)) > 60:
        value = f"{type(value).__name__} of {len(value)}"
    return InputError(path, field_name, value, msg)


#: The plausibility range (``tcsim._core.plausibility_ranges()``) of each design value of a converter
#: file, by section and key suffix.
DESIGN_QUANTITIES: tuple[tuple[str, str], ...] = (
    ("_radius_m", "radius_m"),
    ("_angle_deg", "blade_angle_deg"),
    ("fluid_density_kg_m3", "fluid_density_kg_m3"),
    ("flow_area_m2", "flow_area_m2"),
    ("fluid_length_m", "fluid_length_m"),
    ("_kg_m2", "inertia_kg_m2"),
    ("_loss", "loss_coefficient"),
)


def warn_implausible_design(doc: ConverterFile, path: str) -> None:
    """A :class:`~tcsim.errors.TcsimWarning` for each design value of ``[inertia]``, ``[geometry]``
    and ``[quasi_dynamic]`` outside its plausible range (a radius of 1e6 m, an angle of 89.99°): the
    file runs, but the value is most likely a unit mistake or a typo."""
    for section in ("inertia", "geometry", "quasi_dynamic"):
        values = getattr(doc, section)
        if values is None:
            continue
        for key, value in values.model_dump().items():
            quantity = next((q for suffix, q in DESIGN_QUANTITIES if key.endswith(suffix)), None)
            if quantity is not None and value is not None:
                warn_implausible(quantity, value, path, f"[{section}].{key}")


def parse_converter(data: dict[str, Any], path: str) -> Converter:
    """Validate a parsed TOML document."""
    if "distributions" in data and "source" not in data:  # a trial passed one to `tcsim study`
        raise InputError(
            path,
            "[distributions]",
            "a Monte Carlo study file",
            "a converter file (run a Monte Carlo study file with: tcsim monte-carlo FILE)",
        )
    tables = None
    if isinstance(data.get("characteristic"), list):  # [[characteristic]]: torque-dependent capacity
        tables = _table_sections(data["characteristic"], path)
        data = {k: v for k, v in data.items() if k != "characteristic"}
    try:
        doc = ConverterFile.model_validate(data)
    except ValidationError as err:
        raise _pydantic_to_input_error(err, path) from None
    for key in doc.sources:
        section, _, name = key.partition(".")
        model = getattr(doc, section, None) if section in _SECTIONS else None
        if section == "characteristic" and tables is not None:
            model = tables[0]
        if model is None or name not in type(model).model_fields:
            raise InputError(path, "[sources]", key, "a key 'section.name' naming a value of this converter")
    characteristic = _characteristic(doc, tables, path)
    if doc.geometry is not None:
        try:
            _core.ht_check_geometry(doc.geometry.core_row())
        except _core.CoreInputError as e:
            raise from_core(e, path, "[geometry].") from None
    warn_implausible_design(doc, path)
    return Converter(
        doc.name,
        doc.source,
        path,
        characteristic,
        doc.inertia,
        doc.geometry,
        doc.quasi_dynamic,
        doc.description,
        dict(doc.sources),
        _lag(doc, tables),
    )


def read_converter_toml(path: Path) -> Converter:
    text = read_user_text(path, "a readable UTF-8 TOML file")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(str(path), "(syntax)", str(e), "valid TOML") from None
    conv = parse_converter(data, str(path))
    if conv.characteristic is not None:
        conv.characteristic.warn_if_implausible()
    return conv


def _bundled_dir():
    return resources.files("tcsim") / "data" / "converters"


def bundled_names() -> list[str]:
    return sorted(p.name.removesuffix(".toml") for p in _bundled_dir().iterdir() if p.name.endswith(".toml"))


def bundled_converters() -> list[Converter]:
    return [load_converter(n) for n in bundled_names()]


def load_converter(spec: str | Path) -> Converter:
    """A bundled name, a converter TOML, or a characteristic table (.csv, .vtcc)."""
    if not isinstance(spec, str | os.PathLike):
        expected = "a bundled converter's name (tcsim.bundled_names()) or a file path"
        raise InputError.argument("converter", type(spec).__name__, expected)
    text = str(spec)
    if isinstance(spec, str) and text in bundled_names():
        with resources.as_file(_bundled_dir() / f"{text}.toml") as p:
            return read_converter_toml(Path(p))
    path = Path(spec)
    if not path.exists():
        raise InputError(
            text,
            "converter",
            text,
            f"a bundled converter ({', '.join(bundled_names())}) or an existing .toml, .csv or .vtcc file",
        )
    suffix = path.suffix.lower()
    if suffix == ".toml":
        return read_converter_toml(path)
    if suffix in (".csv", ".vtcc"):
        table = read_table(path)
        return Converter(path.stem, f"characteristic table {path.name}", str(path), characteristic=table)
    raise InputError(text, "file type", suffix or "(none)", "a .toml converter or a .csv/.vtcc characteristic table")
