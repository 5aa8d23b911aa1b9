"""Starting files for ``tcsim init``: a commented, valid converter, vehicle, scenario, study, Monte Carlo
study or design file.

Every value of a template is read from the bundled data (the converter ``li-sunden-2016``, the vehicle
``midsize-awd-8at``, the built-in flip-flop scenario, the design ``li-sunden-2016-design``) or, with
``--from TABLE``, from the user's characteristic table; none is typed here. The comment above each
key gives its unit (from the key's name), the bounds the schema enforces, the plausible range of
:mod:`tcsim.models.plausibility`, the measured range of :mod:`tcsim.models.design_ranges`, for a
study the range of Table D.1's parameter study, and the bundled file's source for the value.

``init converter --from TABLE`` writes the table as ``[characteristic]`` in its own capacity
convention (the values as read, to 15 significant digits) and the sections the other models need
(``[inertia]``, ``[geometry]``, ``[quasi_dynamic]``) commented out, with the bundled converter's values
as placeholders and a ``# TODO`` line that names them: the file runs the ``table`` model at once and
every other model refuses it with one line naming the missing section.

Templates are written atomically (:func:`tcsim.io.outputs.output_file`); an existing file is refused
unless ``force``.
"""

from __future__ import annotations

import shlex
import textwrap
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import MISSING, dataclass, fields
from pathlib import Path
from typing import Any

import annotated_types
import numpy as np
import tomli_w
from pydantic import BaseModel

from .. import _core
from ..analysis.study import TABLE_D1
from ..errors import InputError
from ..models.characteristic import Characteristic
from ..models.converter import (
    DESIGN_QUANTITIES,
    CharacteristicSection,
    GeometrySection,
    InertiaSection,
    QuasiDynamicSection,
    load_converter,
)
from ..models.design import TorusDesign
from ..models.design_file import load_design_file
from ..models.design_ranges import DESIGN_RANGES
from ..models.plausibility import RANGES
from ..models.vehicle import DEFAULT_VEHICLE, load_vehicle
from ..simulation.scenarios import flip_flop
from .outputs import check_output_file, output_file

#: What ``tcsim init`` writes.
KINDS = ("converter", "vehicle", "scenario", "study", "monte-carlo", "design")
#: The file ``tcsim init KIND`` writes without ``--out``.
DEFAULT_FILES = {
    "converter": "converter.toml",
    "vehicle": "vehicle.toml",
    "scenario": "scenario.csv",
    "study": "study.toml",
    "monte-carlo": "monte-carlo.toml",
    "design": "design.toml",
}
#: The bundled converter whose values fill the converter and study templates.
TEMPLATE_CONVERTER = "li-sunden-2016"
#: The bundled design whose values fill the design template.
TEMPLATE_DESIGN = "li-sunden-2016-design"
#: Sections a converter made from a table alone lacks, with the models that need them.
TODO_SECTIONS = {
    "inertia": "every transient model (launch, drive, replay, export-fmu)",
    "geometry": "the hrovat-tobler model (and study, fit's start values)",
    "quasi_dynamic": "the quasi-dynamic model's transient runs",
}
_WIDTH = 118

#: Unit of a key by the suffix of its name (docs/conventions.md: names carry their units), longest first.
_UNIT_SUFFIXES = (
    ("_nm_s_per_rad", "N·m·s/rad"),
    ("_nm_per_rad", "N·m/rad"),
    ("_rad_s_per_sqrt_nm", "(rad/s)/√(N·m)"),
    ("_rpm_per_sqrt_lbf_ft", "rpm/√(lbf·ft)"),
    ("_rpm_per_sqrt_nm", "rpm/√(N·m)"),
    ("_nm_per_rpm2", "N·m/rpm²"),
    ("_nm_s2", "N·m/(rad/s)²"),
    ("_kg_m2", "kg·m²"),
    ("_kg_m3", "kg/m³"),
    ("_rad_s", "rad/s"),
    ("_m_s", "m/s"),
    ("_m2", "m²"),
    ("_deg", "°"),
    ("_nm", "N·m"),
    ("_kg", "kg"),
    ("_percent", "%"),
    ("_m", "m"),
    ("_s", "s"),
)
_CONVERTER_SCHEMA: dict[str, type[BaseModel]] = {
    "characteristic": CharacteristicSection,
    "inertia": InertiaSection,
    "geometry": GeometrySection,
    "quasi_dynamic": QuasiDynamicSection,
}
_CONVERTER_SECTIONS = {
    "characteristic": "the steady characteristic against speed ratio (table and quasi-dynamic models)",
    "inertia": "rotating inertias including the fluid each element carries (every transient run)",
    "geometry": "Hrovat & Tobler parameters, Li & Sundén (2016) Table 2.2 (hrovat-tobler model, study)",
    "quasi_dynamic": "the quasi-dynamic model's shape effects (docs/transient.md)",
    "sources": "where each value comes from: 'section.key' = text ('assumed: ...' where assumed)",
}


@dataclass(frozen=True)
class Template:
    """A template's text, the sections still to fill (``init converter --from``) and the command that
    takes the file as written."""

    kind: str
    text: str
    todo: tuple[str, ...]
    command: str


# --------------------------------------------------------------------------------------------
# notes on one key


def unit_of(key: str) -> str:
    """The unit a key's name carries (``pump_kg_m2`` → ``kg·m²``), or ``""``."""
    return next((unit for suffix, unit in _UNIT_SUFFIXES if key.endswith(suffix)), "")


def _schema_bounds(model: type[BaseModel] | None, key: str) -> str:
    """The bounds the pydantic schema enforces on ``key`` (``> 0``, ``> -90 and < 90``), or ``""``."""
    if model is None or key not in model.model_fields:
        return ""
    ops = {"gt": ">", "ge": "≥", "lt": "<", "le": "≤"}
    parts = []
    for meta in model.model_fields[key].metadata:
        for name, op in ops.items():
            if isinstance(meta, annotated_types.BaseMetadata) and getattr(meta, name, None) is not None:
                parts.append(f"{op} {getattr(meta, name):g}")
    return f"required {' and '.join(parts)}" if parts else ""


def _ranges(key: str) -> list[str]:
    """The plausible range and the measured range (automotive converters) of a design value."""
    out = []
    quantity = next((q for suffix, q in DESIGN_QUANTITIES if key.endswith(suffix)), None)
    if quantity is not None:
        out.append(f"plausible {RANGES[quantity].describe()}")
    if key in DESIGN_RANGES:
        out.append(f"measured range {DESIGN_RANGES[key].describe()}")
    return out


def _study_range(key: str, value: Any) -> str:
    """The range ``tcsim study`` sweeps ``key`` over (Table D.1), or ``""``."""
    rng = next((p for p in TABLE_D1 if p.key == key), None)
    if rng is None:
        return ""
    low, high = (value * (1 + rng.low), value * (1 + rng.high)) if rng.relative else (rng.low, rng.high)
    return f"tcsim study sweeps {low:.4g} to {high:.4g} (Table D.1: {rng.label})"


def _note(
    key: str, value: Any, schema: type[BaseModel] | None, source: str | None, study: bool = False, ranges: bool = True
) -> str:
    """The comment above a key: unit, schema bounds, plausible and measured ranges (of a converter's
    design values, with ``ranges``), the study's range (with ``study``) and the source."""
    unit = unit_of(key)
    parts = [unit] if unit else []
    parts += [p for p in (_schema_bounds(schema, key), *(_ranges(key) if ranges else ())) if p]
    if study:
        parts += [p for p in (_study_range(key, value),) if p]
    if source:
        parts.append(f"source: {source}")
    return "; ".join(parts)


# --------------------------------------------------------------------------------------------
# TOML text


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return tomli_w.dumps({"x": v}).removeprefix("x = ").strip()


class _Toml:
    """A TOML document written line by line, with comments; ``commented`` lines start with ``# ``."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def comment(self, text: str, commented: bool = False) -> None:
        lead = "# " if not commented else "# # "
        self.lines += textwrap.wrap(
            text, _WIDTH, initial_indent=lead, subsequent_indent=lead + "  ", break_on_hyphens=False
        ) or ["#"]

    def blank(self) -> None:
        self.lines.append("")

    def section(self, name: str, note: str = "", commented: bool = False) -> None:
        self.blank()
        if note:
            self.comment(f"[{name}]: {note}")
        self.lines.append(f"{'# ' if commented else ''}[{name}]")

    def key(self, key: str, value: Any, note: str = "", commented: bool = False) -> None:
        if note:
            self.comment(note, commented)
        lead = "# " if commented else ""
        line = f"{lead}{key} = {_value(value)}"
        if len(line) <= _WIDTH + 2 or not isinstance(value, (list, tuple)):
            self.lines.append(line)
            return
        body = textwrap.wrap(", ".join(_value(x) for x in value) + ",", _WIDTH - 4, break_long_words=False)
        self.lines += [f"{lead}{key} = ["] + [f"{lead}    {b}" for b in body] + [f"{lead}]"]

    def table(self, name: str, values: Mapping[str, str]) -> None:
        """A table of strings (``[sources]``), written by tomli_w (its keys need quotes)."""
        self.lines += tomli_w.dumps({name: dict(values)}).rstrip("\n").splitlines()

    def text(self) -> str:
        return "\n".join(self.lines).strip("\n") + "\n"


def _bundled_toml(path: str) -> dict[str, Any]:
    return tomllib.loads(Path(path).read_text(encoding="utf-8"))


def _header(doc: _Toml, kind: str, origin: str, command: str, extra: tuple[str, ...] = ()) -> None:
    doc.comment(f"A tcsim {kind} file written by 'tcsim init {kind}': {origin}.")
    doc.comment(f"Run it: {command}")
    for line in extra:
        doc.comment(line)


def _top(doc: _Toml, name: str, source: str | None, description: str | None) -> None:
    doc.blank()
    doc.key("name", name, "the name outputs and messages use")
    if source is not None:
        doc.key("source", source, "where the data come from")
    if description is not None:
        doc.key("description", description)


# --------------------------------------------------------------------------------------------
# the templates


def _converter_sections(doc: _Toml, raw: dict[str, Any], sections: tuple[str, ...], study: bool = False) -> None:
    sources = raw.get("sources", {})
    for section in sections:
        doc.section(section, _CONVERTER_SECTIONS[section])
        for key, value in raw[section].items():
            schema = _CONVERTER_SCHEMA[section]
            doc.key(key, value, _note(key, value, schema, sources.get(f"{section}.{key}"), study))
    kept = {k: v for k, v in sources.items() if k.partition(".")[0] in sections}
    doc.blank()
    doc.comment(_CONVERTER_SECTIONS["sources"])
    doc.table("sources", kept)


def _arg(path: str) -> str:
    """``path`` as one shell word in a suggested command line."""
    return shlex.quote(path)


def converter_template(out_name: str, study: bool = False) -> Template:
    """The bundled :data:`TEMPLATE_CONVERTER` as a commented file (``study``: its ``[geometry]`` alone,
    with the ranges ``tcsim study`` sweeps)."""
    conv = load_converter(TEMPLATE_CONVERTER)
    raw = _bundled_toml(conv.path)
    kind = "study" if study else "converter"
    command = f"tcsim study {_arg(out_name)}" if study else f"tcsim characterise {_arg(out_name)}"
    extra: tuple[str, ...] = (
        "Sections and keys: docs/conventions.md and docs/models.md; each model needs only its own sections, "
        "unknown keys are errors. Replace every value (and its [sources] line) with your converter's.",
    )
    if study:
        extra += (
            "tcsim study moves one [geometry] value at a time over its Table D.1 range (Li & Sundén 2016, "
            "Appendix D) and draws TR, capacity factor and flow against speed ratio for each.",
        )
    doc = _Toml()
    _header(doc, kind, f"the values of the bundled converter {TEMPLATE_CONVERTER}", command, extra)
    _top(doc, Path(out_name).stem, raw["source"], f"starting point: the values of {TEMPLATE_CONVERTER}")
    sections = ("geometry",) if study else ("characteristic", "inertia", "geometry", "quasi_dynamic")
    _converter_sections(doc, raw, sections, study)
    return Template(kind, doc.text(), (), command)


def _table_rows(table: Characteristic) -> dict[str, Any]:
    """One table in its own capacity convention, the values as read (15 significant digits)."""
    cap = np.asarray(_core.cf_to_capacity(table.convention, np.ascontiguousarray(table.capacity_factor_nm_s2)))
    out: dict[str, Any] = {}
    if table.input_torque_nm is not None:
        out["input_torque_nm"] = float(table.input_torque_nm)
    out["speed_ratio"] = [float(v) for v in table.speed_ratio]
    out["torque_ratio"] = [float(v) for v in table.torque_ratio]
    out[table.convention] = [float(f"{v:.15g}") for v in cap]  # without the conversion's last-bit noise
    return out


def _file_comments(path: str) -> list[str]:
    """The comment lines (``#``) at the top of a table file: they usually say where it comes from."""
    try:
        lines = Path(path).read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError):
        return []
    out = []
    for line in lines:
        if not line.strip().startswith("#"):
            break
        out.append(line.strip().lstrip("#").strip())
    return out


def table_template(table_spec: str, out_name: str) -> Template:
    """A converter whose ``[characteristic]`` is the table of ``table_spec`` (a .csv or .vtcc table, a
    converter .toml or a bundled name), the other sections commented out with a ``# TODO``."""
    conv = load_converter(table_spec)
    if conv.characteristic is None:
        raise InputError(conv.path, "[characteristic]", "missing", "a characteristic table (.csv, .vtcc or .toml)")
    table_name = Path(conv.path).name
    command = f"tcsim characterise {_arg(out_name)} --model table"
    todo = tuple(TODO_SECTIONS)
    doc = _Toml()
    _header(doc, "converter", f"[characteristic] from {table_name}", command)
    for line in _file_comments(conv.path):
        doc.comment(f"{table_name}: {line}")
    doc.comment(
        "TODO: fill " + ", ".join(f"[{s}]" for s in todo) + " (commented out below, with the bundled "
        f"{TEMPLATE_CONVERTER}'s values as placeholders, not this converter's): "
        + "; ".join(f"[{s}] for {why}" for s, why in TODO_SECTIONS.items())
        + ". Until then the table model's steady state runs and the other models refuse the file."
    )
    _top(doc, Path(out_name).stem, f"characteristic table {table_name}", None)
    tables = conv.characteristic.tables()
    rules = dict(conv.characteristic.core_rules())
    if conv.lag_time_constant_s is not None:
        rules["lag_time_constant_s"] = conv.lag_time_constant_s
    for i, t in enumerate(tables):
        name = "[characteristic]" if len(tables) > 1 else "characteristic"
        doc.section(name, _CONVERTER_SECTIONS["characteristic"] + f", as read from {table_name}")
        for key, value in (_table_rows(t) | (rules if i == 0 else {})).items():
            doc.key(key, value, unit_of(key))
    ref = _bundled_toml(load_converter(TEMPLATE_CONVERTER).path)
    for section, why in TODO_SECTIONS.items():
        doc.section(section, f"TODO: needed by {why}; placeholders from {TEMPLATE_CONVERTER}", commented=True)
        for key, value in ref[section].items():
            doc.key(key, value, _note(key, value, _CONVERTER_SCHEMA[section], None), commented=True)
    doc.blank()
    keys = ("speed_ratio", "torque_ratio", tables[0].convention)
    doc.table("sources", {f"characteristic.{k}": table_name for k in keys})
    return Template("converter", doc.text(), todo, command)


def vehicle_template(out_name: str) -> Template:
    """The bundled vehicle :data:`~tcsim.models.vehicle.DEFAULT_VEHICLE` as a commented file."""
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    raw = _bundled_toml(vehicle.path)
    command = f"tcsim launch {_arg(out_name)}"
    extra = (
        "Every key, its unit, its range (checked when the file is read) and its meaning: docs/vehicle.md. "
        "The converter's inertias belong to the converter file, not here.",
    )
    doc = _Toml()
    _header(doc, "vehicle", f"the values of the bundled vehicle {DEFAULT_VEHICLE}", command, extra)
    _top(doc, Path(out_name).stem, raw["source"], f"starting point: the values of {DEFAULT_VEHICLE}")
    where = "a bundled converter (tcsim converters) or a converter .toml, relative to this file"
    doc.key("converter", raw["converter"], where)
    sources = raw.get("sources", {})
    for section in vehicle.sections:
        doc.section(section)
        for key, value in raw[section].items():
            doc.key(key, value, _note(key, value, None, sources.get(f"{section}.{key}"), ranges=False))
    doc.blank()
    doc.comment(_CONVERTER_SECTIONS["sources"])
    doc.table("sources", sources)
    return Template("vehicle", doc.text(), (), command)


def scenario_template(out_name: str) -> Template:
    """The built-in flip-flop launch (:func:`tcsim.simulation.scenarios.flip_flop`) as a CSV scenario."""
    scenario = flip_flop()
    t, pedal, brake = scenario.time_s, scenario.accelerator_pedal, scenario.brake_pedal
    command = f"tcsim launch --scenario {_arg(out_name)}"
    doc = _Toml()
    _header(doc, "scenario", f"the built-in scenario {scenario.name}", command)
    notes = (
        "Columns: time_s (s, strictly increasing; or time_ms), accelerator_pedal and brake_pedal (0 to 1; or "
        "accelerator_pedal_percent and brake_pedal_percent, 0 to 100), optionally engine_torque_nm (N·m, a "
        "logged crank torque replayed instead of the engine model). Lines starting with # are comments; the "
        "same columns are read from Parquet, .mat and MDF4 files.",
        f"The run starts braked at rest at the first time stamp (times are shifted to start at 0) and ends at the "
        f"last; its span must be plausible, {RANGES['scenario_duration_s'].describe()}. The launch summary's "
        "times are measured from where the brake pedal's last fall to zero begins.",
        f"These rows: brake {brake[0]:g} and pedal {pedal[0]:g} to {t[1]:g} s, then brake {brake[2]:g} and pedal "
        f"{pedal[2]:g} from {t[2]:g} s to {t[-1]:g} s (Li & Sundén 2016, §3.2.2 and §3.5.1). The built-in "
        "scenario also stops at 100 km/h; a file runs to its last time stamp. docs/vehicle.md describes the run.",
    )
    for line in notes:
        doc.comment(line)
    doc.lines.append("time_s,accelerator_pedal,brake_pedal")
    doc.lines += [f"{a!r},{b!r},{c!r}" for a, b, c in zip(t.tolist(), pedal.tolist(), brake.tolist(), strict=True)]
    return Template("scenario", doc.text(), (), command)


def design_template(out_name: str) -> Template:
    """The bundled design :data:`TEMPLATE_DESIGN` as a commented file."""
    file = load_design_file(TEMPLATE_DESIGN)
    raw = _bundled_toml(file.path)
    command = f"tcsim design {_arg(out_name)}"
    extra = ("Every key and what the command derives from it: docs/design.md, 'Design files'.",)
    doc = _Toml()
    _header(doc, "design", f"the values of the bundled design {TEMPLATE_DESIGN}", command, extra)
    _top(doc, Path(out_name).stem, None, raw.get("description"))
    doc.section("design", "the torus and its blades; the core checks the values when it derives the converter")
    for key, value in raw["design"].items():
        doc.key(key, value, _note(key, value, None, None))
    optional = [f.name for f in fields(TorusDesign) if f.default is not MISSING and f.name not in raw["design"]]
    doc.comment("optional keys of [design] (docs/design.md): " + ", ".join(optional))
    notes = {
        "inertia": "the metal inertias; tcsim adds the fluid's inertia of the torus",
        "losses": "optional: a loss coefficient not given takes Table D.1's value",
    }
    for section, note in notes.items():
        doc.section(section, note)
        for key, value in raw[section].items():
            doc.key(key, value, _note(key, value, InertiaSection if section == "inertia" else None, None))
    return Template("design", doc.text(), (), command)


#: The Monte Carlo template's cases (a first look; a tolerance study's tails need 10⁴ or more).
TEMPLATE_RUNS = 100
#: The Monte Carlo template's distributions: (parameter, kind, spread relative to the bundled value).
#: The means are the bundled vehicle's and its converter's values, read when the template is written.
TEMPLATE_DISTRIBUTIONS: tuple[tuple[str, str, float], ...] = (
    ("vehicle.body.mass_kg", "truncated-normal", 0.02),
    ("vehicle.engine.inertia_kg_m2", "lognormal", 0.05),
    ("converter.inertia.turbine_kg_m2", "uniform", 0.05),
    ("converter.quasi_dynamic.pump_shape_effect_m2", "normal", 0.1),
)


def _template_distribution(kind: str, value: float, spread: float) -> dict[str, Any]:
    """A distribution of ``kind`` around ``value``: std (or half-width) ``spread`` of it, truncated at 3 std."""
    d = float(f"{abs(value) * spread:.6g}")
    if kind == "uniform":
        return {"kind": kind, "low": float(f"{value - d:.6g}"), "high": float(f"{value + d:.6g}")}
    if kind == "truncated-normal":
        low, high = float(f"{value - 3 * d:.6g}"), float(f"{value + 3 * d:.6g}")
        return {"kind": kind, "mean": value, "std": d, "low": low, "high": high}
    return {"kind": kind, "mean": value, "std": d}


def monte_carlo_template(out_name: str) -> Template:
    """A Monte Carlo study file (:mod:`tcsim.models.study_file`) of the bundled vehicle
    :data:`~tcsim.models.vehicle.DEFAULT_VEHICLE` and its converter, the means their values."""
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    files = {"vehicle": vehicle.to_toml_dict(), "converter": vehicle.converter.to_toml_dict()}
    command = f"tcsim monte-carlo {_arg(out_name)}"
    extra = (
        "Every key: docs/study.md, 'Monte Carlo studies'. Each case draws every parameter below from its "
        "distribution (seeded by seed and the case's number alone) and launches every model; a distribution "
        "whose support leaves a parameter's valid range is refused before anything runs.",
    )
    doc = _Toml()
    _header(doc, "monte-carlo", f"the bundled vehicle {DEFAULT_VEHICLE} and its converter", command, extra)
    doc.blank()
    doc.key("name", Path(out_name).stem, "the name outputs and messages use")
    doc.key("vehicle", DEFAULT_VEHICLE, "a bundled vehicle (tcsim vehicles) or a vehicle .toml, relative to this file")
    doc.comment("converter: a bundled converter or a converter .toml relative to this file (default: the vehicle's)")
    doc.key("converter", vehicle.converter_spec, commented=True)
    doc.key("scenario", "flip-flop", "flip-flop (full pedal, to 100 km/h) | part-pedal (pedal 0.3, to 50 km/h)")
    doc.key("models", list(vehicle.converter.models), "launched in each case; the dip is against the table run")
    doc.key(
        "runs", TEMPLATE_RUNS, "cases (per grid point); run with --chunk-size N for many (resumable Parquet shards)"
    )
    doc.key("seed", 1, "the same file and seed give the same cases bit for bit, however the study is chunked")
    outputs = ["time_0_50_km_h_s", "time_0_100_km_h_s", "effective_torque_ratio_dip_first_0_5_s"]
    doc.key("outputs", outputs, "launch summary columns kept per case and model (docs/launch_summary.md)")
    doc.section(
        "distributions",
        "parameter as the file writes it (converter.<section>.<key>, vehicle.<section>.<key>) = normal "
        "{mean, std} | uniform {low, high} | lognormal {mean, std of the value itself} | truncated-normal "
        "{mean, std, low, high} | grid {values} or {start, stop, num} (swept: the grids a full factorial, "
        "runs cases per grid point); the means below are the bundled values",
    )
    for key, kind, spread in TEMPLATE_DISTRIBUTIONS:
        target, section, name = key.split(".")
        value = float(files[target][section][name])
        items = ", ".join(f"{k} = {_value(v)}" for k, v in _template_distribution(kind, value, spread).items())
        doc.lines.append(f'"{key}" = {{ {items} }}')
    return Template("monte-carlo", doc.text(), (), command)


#: The builder of each kind (``init converter --from`` is :func:`table_template`).
_BUILDERS: dict[str, Callable[[str], Template]] = {
    "converter": converter_template,
    "vehicle": vehicle_template,
    "scenario": scenario_template,
    "study": lambda out_name: converter_template(out_name, study=True),
    "monte-carlo": monte_carlo_template,
    "design": design_template,
}


def check_kind(kind: str) -> None:
    """Refuse a ``KIND`` that is not one of :data:`KINDS` (:class:`~tcsim.errors.InputError`)."""
    if kind not in KINDS:
        raise InputError("command line", "KIND", kind, f"one of {', '.join(KINDS)}")


def make_template(kind: str, out_name: str, table: str | None = None) -> Template:
    """The template of ``kind`` for a file named ``out_name`` (its stem is the file's ``name``); ``table``
    (``--from``) only for a converter."""
    check_kind(kind)
    if table is not None and kind != "converter":
        raise InputError("command line", "--from", table, "no --from: only 'tcsim init converter' reads a table")
    if table is not None:
        return table_template(table, out_name)
    return _BUILDERS[kind](out_name)


def write_template(template: Template, out: str | Path, force: bool = False, inputs: tuple[str, ...] = ()) -> None:
    """Write ``template`` to ``out`` atomically; an existing ``out`` is refused unless ``force``, and an
    input of the run (the ``--from`` table) always (:class:`~tcsim.errors.InputError`, nothing written)."""
    check_output_file(out, inputs)
    if Path(out).exists() and not force:
        raise InputError("command line", "--out", str(out), "a file that does not exist yet (--force replaces it)")
    with output_file(out, inputs) as tmp:
        tmp.write_text(template.text, encoding="utf-8")
