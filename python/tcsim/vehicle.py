"""Vehicle definitions for ``tcsim launch``: TOML files validated by pydantic, bundled vehicles.

A vehicle is the car around a converter: engine, automatic gearbox with its shift schedule,
lock-up clutch, all-wheel-drive driveline with compliant shafts, tyres, body and service brake
(Li & Sundén 2016, §3.2.2, §3.5.2.2, §4.3.1). The converter itself is a converter file (or a
bundled converter) named by the vehicle file; its inertias are the converter's, not repeated here.

File layout (every quantity SI, its unit in its name)::

    name = "..."
    source = "..."
    description = "..."                  # optional
    converter = "li-sunden-2016"         # a bundled converter, or a .toml path relative to this file

    [engine]     inertia_kg_m2, idle_speed_rad_s, full_load_speed_rad_s (strictly increasing),
                 full_load_torque_nm, drag_torque_nm, drag_nm_s_per_rad, fast_time_constant_s,
                 boost_time_constant_s, boost_fraction (0..1), idle_governor_gain_nm_s_per_rad
    [gearbox]    ratios (strictly decreasing, gear 1 first), efficiencies (0 < η ≤ 1, per gear),
                 input_inertia_kg_m2 (per gear, at the gearbox input), output_inertia_kg_m2,
                 shift_clutch_capacity_nm (at the input), shift_handover_s,
                 upshift_speed_zero_pedal_m_s, upshift_speed_full_pedal_m_s (gears − 1 values,
                 upshift from gear k; strictly increasing), downshift_speed_zero_pedal_m_s,
                 downshift_speed_full_pedal_m_s (gears − 1 values, downshift from gear k + 1 to k;
                 strictly increasing, each below the upshift speed of the same pedal and index)
    [lockup]     capacity_nm (kinetic), static_to_kinetic (≥ 1), engage_time_s, min_gear,
                 engage_speed_zero_pedal_m_s, engage_speed_full_pedal_m_s
    [driveline]  final_drive_ratio, front/rear_shaft_stiffness_nm_per_rad and
                 front/rear_shaft_damping_nm_s_per_rad (each branch of the AWD split, at the
                 propshaft side: referred to the gearbox output, before the final drive),
                 front/rear_axle_inertia_kg_m2 (both wheels with hubs, brakes and half shafts)
    [tyres]      rolling_radius_m, friction_coefficient, slip_stiffness (dFx/dκ over Fz at zero
                 slip), front_load_fraction (0..1, exclusive)
    [body]       mass_kg, drag_area_m2 (Cd·A), rolling_resistance, air_density_kg_m3, grade_percent
    [brake]      capacity_nm (total wheel brake torque at full pedal), front_fraction (0..1)
    [sources]    "section.key" = "where the value comes from" ("assumed: why" where assumed)

Unknown keys, missing keys, non-finite numbers, values outside their range, arrays of the wrong
length or order are :class:`~tcsim.errors.InputError` naming the file, the field
(``[gearbox].ratios[3]``), the value and what was expected.
"""

from __future__ import annotations

import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import tomli_w
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from . import _core
from .converter import Converter, load_converter
from .converter import bundled_names as bundled_converter_names
from .errors import InputError, from_core

#: The bundled vehicle used when none is named.
DEFAULT_VEHICLE = "midsize-awd-8at"

SECTIONS: tuple[str, ...] = ("engine", "gearbox", "lockup", "driveline", "tyres", "body", "brake")


# --------------------------------------------------------------------------------------------
# TOML sections


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]
Fraction = Annotated[float, Field(gt=0, le=1)]


class EngineSection(_Section):
    """Engine: full-load curve, drag, torque build-up (fast + boost, thesis §3.3), idle governor."""

    inertia_kg_m2: float = Field(gt=0)
    idle_speed_rad_s: float = Field(gt=0)
    full_load_speed_rad_s: list[NonNegative] = Field(min_length=2)
    full_load_torque_nm: list[NonNegative] = Field(min_length=2)
    drag_torque_nm: float = Field(ge=0)
    drag_nm_s_per_rad: float = Field(ge=0)
    fast_time_constant_s: float = Field(gt=0)
    boost_time_constant_s: float = Field(gt=0)
    boost_fraction: float = Field(ge=0, le=1)
    idle_governor_gain_nm_s_per_rad: float = Field(gt=0)

    def full_load_torque_at(self, speed_rad_s: float) -> float:
        """Full-load torque at a speed (linear interpolation, end values held)."""
        return float(np.interp(speed_rad_s, self.full_load_speed_rad_s, self.full_load_torque_nm))

    def drag_at(self, speed_rad_s: float) -> float:
        return self.drag_torque_nm + self.drag_nm_s_per_rad * speed_rad_s


class GearboxSection(_Section):
    """Automatic gearbox: ratios, efficiency and inertia per gear, shift clutches and schedule."""

    ratios: list[Positive] = Field(min_length=1)
    efficiencies: list[Fraction]
    input_inertia_kg_m2: list[Positive]
    output_inertia_kg_m2: float = Field(gt=0)
    shift_clutch_capacity_nm: float = Field(gt=0)
    shift_handover_s: float = Field(gt=0)
    upshift_speed_zero_pedal_m_s: list[Positive]
    upshift_speed_full_pedal_m_s: list[Positive]
    downshift_speed_zero_pedal_m_s: list[Positive]
    downshift_speed_full_pedal_m_s: list[Positive]

    @property
    def gears(self) -> int:
        return len(self.ratios)


class LockupSection(_Section):
    """Lock-up clutch: friction capacity, engagement ramp and schedule (by gear and speed)."""

    capacity_nm: float = Field(gt=0)
    static_to_kinetic: float = Field(ge=1)
    engage_time_s: float = Field(gt=0)
    min_gear: int = Field(ge=1)
    engage_speed_zero_pedal_m_s: float = Field(gt=0)
    engage_speed_full_pedal_m_s: float = Field(gt=0)


class DrivelineSection(_Section):
    """Final drive and the front/rear branches of the AWD driveline (thesis §4.3.1)."""

    final_drive_ratio: float = Field(gt=0)
    front_shaft_stiffness_nm_per_rad: float = Field(gt=0)
    rear_shaft_stiffness_nm_per_rad: float = Field(gt=0)
    front_shaft_damping_nm_s_per_rad: float = Field(ge=0)
    rear_shaft_damping_nm_s_per_rad: float = Field(ge=0)
    front_axle_inertia_kg_m2: float = Field(gt=0)
    rear_axle_inertia_kg_m2: float = Field(gt=0)


class TyresSection(_Section):
    """Longitudinal tyre: rolling radius and a saturating force curve in slip."""

    rolling_radius_m: float = Field(gt=0)
    friction_coefficient: float = Field(gt=0)
    slip_stiffness: float = Field(gt=0)
    front_load_fraction: float = Field(gt=0, lt=1)


class BodySection(_Section):
    """Vehicle body: mass, aerodynamic drag, rolling resistance, road grade."""

    mass_kg: float = Field(gt=0)
    drag_area_m2: float = Field(ge=0)
    rolling_resistance: float = Field(ge=0)
    air_density_kg_m3: float = Field(gt=0)
    grade_percent: float = Field(gt=-100, lt=100)


class BrakeSection(_Section):
    """Service brake: total wheel torque at full pedal and its front share."""

    capacity_nm: float = Field(gt=0)
    front_fraction: float = Field(ge=0, le=1)


class VehicleFile(_Section):
    name: str
    source: str
    description: str | None = None
    converter: str
    engine: EngineSection
    gearbox: GearboxSection
    lockup: LockupSection
    driveline: DrivelineSection
    tyres: TyresSection
    body: BodySection
    brake: BrakeSection
    #: Where each value comes from: "section.key" -> text ("assumed: ..." where assumed).
    sources: dict[str, str] = {}


# --------------------------------------------------------------------------------------------
# the vehicle


@dataclass(frozen=True)
class Vehicle:
    """A validated vehicle definition. ``path`` is where it was read from (for messages);
    ``converter`` is the converter it names, loaded and validated."""

    name: str
    source: str
    path: str
    converter: Converter
    engine: EngineSection
    gearbox: GearboxSection
    lockup: LockupSection
    driveline: DrivelineSection
    tyres: TyresSection
    body: BodySection
    brake: BrakeSection
    description: str | None = None
    converter_spec: str = ""
    sources: dict[str, str] = field(default_factory=dict)
    #: The vehicle as the core read and validated it (what ``_core.launch_runs`` takes).
    core: Any = None

    @property
    def sections(self) -> dict[str, _Section]:
        """The sections by name, in file order."""
        return {s: getattr(self, s) for s in SECTIONS}

    def core_spec(self) -> dict[str, dict[str, Any]]:
        """The nested dict the core takes: ``{"engine": {...}, "gearbox": {...}, ...}``, the keys of
        the TOML file, arrays as lists."""
        return {name: section.model_dump() for name, section in self.sections.items()}

    def to_toml_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "source": self.source}
        if self.description:
            out["description"] = self.description
        out["converter"] = self.converter_spec or self.converter.name
        out.update(self.core_spec())
        if self.sources:
            out["sources"] = dict(self.sources)
        return out

    # a few derived numbers for summaries and plots
    def overall_ratio(self, gear: int) -> float:
        """Gearbox ratio of ``gear`` (1-based) times the final drive."""
        return self.gearbox.ratios[gear - 1] * self.driveline.final_drive_ratio


# --------------------------------------------------------------------------------------------
# validation


def _name(section: str, key: str, index: int | None = None) -> str:
    return f"[{section}].{key}" + (f"[{index}]" if index is not None else "")


def _expected(e: dict[str, Any]) -> str:
    ctx = e.get("ctx") or {}
    kind = e["type"]
    if kind == "greater_than":
        return f"a number greater than {ctx.get('gt'):g}"
    if kind == "greater_than_equal":
        return f"a number of at least {ctx.get('ge'):g}"
    if kind == "less_than":
        return f"a number less than {ctx.get('lt'):g}"
    if kind == "less_than_equal":
        return f"a number of at most {ctx.get('le'):g}"
    if kind == "finite_number":
        return "a finite number"
    if kind in ("float_type", "float_parsing"):
        return "a number"
    if kind in ("int_type", "int_parsing", "int_from_float"):
        return "an integer"
    if kind == "list_type":
        return "an array of numbers"
    if kind == "string_type":
        return "a string"
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        return "a table (section)"
    if kind == "too_short":
        return f"at least {ctx.get('min_length')} values"
    return e["msg"].removeprefix("Input should be ")


_KIND = {"float": "a float", "int": "an integer", "str": "a string", "bool": "a boolean"}


def _pydantic_to_input_error(err: ValidationError, path: str) -> InputError:
    e = err.errors()[0]
    loc = [str(x) for x in e["loc"]]
    if loc and (loc[0] in SECTIONS or loc[0] == "sources") and len(loc) > 1:
        field_name = f"[{loc[0]}]" + "".join(f"[{x}]" if x.isdigit() else f".{x}" for x in loc[1:])
    elif loc and loc[0] in SECTIONS:
        field_name = f"[{loc[0]}]"
    else:
        field_name = ".".join(loc) or "(file)"
    value = e.get("input", "")
    expected = _expected(e)
    if e["type"] == "extra_forbidden":
        if len(loc) > 1 and loc[0] in SECTIONS:
            where, known = f"[{loc[0]}]", VehicleFile.model_fields[loc[0]].annotation.model_fields
        else:
            where, known = "the top level", VehicleFile.model_fields
        expected = f"a known key of {where}: {', '.join(known)} (this key is unknown)"
    elif e["type"] == "missing":
        value = "missing"
        expected = f"this required {'section' if len(loc) == 1 and loc[0] in SECTIONS else 'key'}"
    if e["type"].endswith("_type") and not isinstance(value, (dict, list)):
        expected += f", not {_KIND.get(type(value).__name__, 'a ' + type(value).__name__)} ({value!r})"
    if isinstance(value, dict):
        value = f"table of {len(value)} keys"
    elif isinstance(value, list) and len(str(value)) > 60:
        value = f"list of {len(value)}"
    return InputError(path, field_name, value, expected)


def _strictly(path: str, section: str, key: str, values: Sequence[float], increasing: bool) -> None:
    v = np.asarray(values, dtype=float)
    bad = np.flatnonzero(np.diff(v) <= 0) if increasing else np.flatnonzero(np.diff(v) >= 0)
    if bad.size:
        i = int(bad[0]) + 1
        word = "increasing" if increasing else "decreasing"
        raise InputError(
            path, _name(section, key, i), float(v[i]), f"strictly {word} values (previous value {v[i - 1]:g})"
        )


def _length(path: str, section: str, key: str, values: Sequence[float], n: int, what: str) -> None:
    if len(values) != n:
        raise InputError(path, _name(section, key), f"{len(values)} values", f"{n} values ({what})")


def _check_engine(e: EngineSection, path: str) -> None:
    _strictly(path, "engine", "full_load_speed_rad_s", e.full_load_speed_rad_s, increasing=True)
    _length(
        path,
        "engine",
        "full_load_torque_nm",
        e.full_load_torque_nm,
        len(e.full_load_speed_rad_s),
        "one per full_load_speed_rad_s",
    )
    lo, hi = e.full_load_speed_rad_s[0], e.full_load_speed_rad_s[-1]
    if not lo <= e.idle_speed_rad_s < hi:
        raise InputError(
            path,
            _name("engine", "idle_speed_rad_s"),
            e.idle_speed_rad_s,
            f"a speed within the full-load curve's speeds [{lo:g}, {hi:g}) rad/s",
        )
    available, drag = e.full_load_torque_at(e.idle_speed_rad_s), e.drag_at(e.idle_speed_rad_s)
    if available <= drag:
        raise InputError(
            path,
            _name("engine", "full_load_torque_nm"),
            f"{available:g} N·m at idle",
            f"more than the drag torque at idle ({drag:g} N·m), or the engine cannot hold idle",
        )


def _check_gearbox(g: GearboxSection, path: str) -> None:
    n = g.gears
    _strictly(path, "gearbox", "ratios", g.ratios, increasing=False)
    for key in ("efficiencies", "input_inertia_kg_m2"):
        _length(path, "gearbox", key, getattr(g, key), n, f"one per gear: ratios has {n}")
    pairs = (
        ("upshift_speed_zero_pedal_m_s", "downshift_speed_zero_pedal_m_s"),
        ("upshift_speed_full_pedal_m_s", "downshift_speed_full_pedal_m_s"),
    )
    for up_key, down_key in pairs:
        for key in (up_key, down_key):
            what = (
                f"gears − 1 = {n - 1}: {'upshift from' if key.startswith('up') else 'downshift into'} gears 1..{n - 1}"
            )
            _length(path, "gearbox", key, getattr(g, key), n - 1, what)
            _strictly(path, "gearbox", key, getattr(g, key), increasing=True)
        up, down = getattr(g, up_key), getattr(g, down_key)
        for k, (u, d) in enumerate(zip(up, down)):
            if d >= u:
                raise InputError(
                    path,
                    _name("gearbox", down_key, k),
                    d,
                    f"a speed below {up_key}[{k}] = {u:g} m/s (downshift {k + 2}→{k + 1} below "
                    f"upshift {k + 1}→{k + 2}, or the gearbox hunts)",
                )


def _check_lockup(lu: LockupSection, gears: int, path: str) -> None:
    if lu.min_gear > gears:
        raise InputError(path, _name("lockup", "min_gear"), lu.min_gear, f"a gear from 1 to {gears} ([gearbox].ratios)")


def _check_sources(doc: VehicleFile, path: str) -> None:
    for key in doc.sources:
        section, _, name = key.partition(".")
        if section not in SECTIONS or name not in type(getattr(doc, section)).model_fields:
            raise InputError(path, "[sources]", key, "a key 'section.name' naming a value of this vehicle")


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


def _core_vehicle(text: str, path: str) -> Any:
    try:
        return _core.read_vehicle(text, path)
    except _core.CoreInputError as e:
        raise from_core(e, path) from None


def parse_vehicle(data: dict[str, Any], path: str) -> Vehicle:
    """Validate a parsed TOML document (``path`` names it in messages and anchors the converter)."""
    return _build(data, path, _core_vehicle(tomli_w.dumps(data), path))


def _build(data: dict[str, Any], path: str, core: Any) -> Vehicle:
    try:
        doc = VehicleFile.model_validate(data)
    except ValidationError as err:
        raise _pydantic_to_input_error(err, path) from None
    _check_engine(doc.engine, path)
    _check_gearbox(doc.gearbox, path)
    _check_lockup(doc.lockup, doc.gearbox.gears, path)
    _check_sources(doc, path)
    conv = _load_named_converter(doc.converter, path)
    return Vehicle(
        doc.name,
        doc.source,
        path,
        conv,
        doc.engine,
        doc.gearbox,
        doc.lockup,
        doc.driveline,
        doc.tyres,
        doc.body,
        doc.brake,
        doc.description,
        doc.converter,
        dict(doc.sources),
        core,
    )


def read_vehicle_toml(path: Path) -> Vehicle:
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(str(path), "(file)", type(e).__name__, f"a readable UTF-8 TOML file ({e})") from None
    core = _core_vehicle(text, str(path))
    return _build(tomllib.loads(text), str(path), core)


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
