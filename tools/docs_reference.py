"""The input-file reference of the documentation site, generated from the schemas (issue 17).

Used two ways:

* by the MkDocs hook ``tools/docs_hooks.py`` (``hooks:`` in ``mkdocs.yml``), which adds the page
  ``reference/input-files.md`` to the site at build time, so it is never stored and cannot drift;
* as a script, ``python tools/docs_reference.py [FILE]``, which prints (or writes) the same page.

Every fact on the page is read from its one owner: the pydantic models of
:mod:`tcsim.models.converter` and :mod:`tcsim.models.design_file` (keys, required or default, the
bounds they enforce), the ``#:`` comments and docstrings beside them (meanings), the unit a key's
name carries, the plausible and measured ranges (:func:`tcsim.io.templates` notes), the bundled
vehicle (the core owns the vehicle schema: its keys are listed from the bundled file, its ranges
are in ``docs/vehicle.md``), the measurement channels of :mod:`tcsim.io.measurement`, and the
starting files ``tcsim init`` writes.
"""

from __future__ import annotations

import inspect
import re
import sys
import tomllib
from pathlib import Path
from typing import Any, get_args

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from tcsim.io import measurement as measurement_io
from tcsim.io import templates
from tcsim.models.characteristic import CAPACITY_KEYS
from tcsim.models.converter import ConverterFile, load_converter
from tcsim.models.design import TorusDesign
from tcsim.models.design_file import DesignFileModel, load_design_file
from tcsim.models.vehicle import DEFAULT_VEHICLE, load_vehicle

#: Where the page lives in the site (``docs_dir``-relative).
PAGE = "reference/input-files.md"


# --------------------------------------------------------------------------------------------
# meanings, from the comments and docstrings beside the schemas


def comment_notes(cls: type) -> dict[str, str]:
    """The ``#:`` comment lines above each annotated attribute of ``cls`` (Sphinx style), by name."""
    try:
        lines = inspect.getsource(cls).splitlines()
    except (OSError, TypeError):
        return {}
    notes: dict[str, str] = {}
    pending: list[str] = []
    for line in lines:
        stripped = line.strip()
        if stripped.startswith("#:"):
            pending.append(stripped[2:].strip())
            continue
        m = re.match(r"(\w+)\s*:", stripped)
        if m and pending:
            notes[m[1]] = " ".join(pending)
        pending = []
    return notes


def attribute_notes(cls: type) -> dict[str, str]:
    """The numpydoc ``Attributes`` entries of ``cls``'s docstring, by name; an entry ``a, ..., z``
    applies to every name with ``z``'s last two ``_`` parts (``pump_inlet_angle_deg, ...,
    stator_exit_angle_deg`` to every ``*_angle_deg``)."""
    doc = inspect.getdoc(cls) or ""
    body = doc.split("Attributes\n----------\n", 1)[1] if "Attributes\n----------\n" in doc else ""
    notes: dict[str, str] = {}
    for m in re.finditer(r"^(\S[^\n]*?) : [^\n]*\n((?:    [^\n]*\n?)+)", body, flags=re.M):
        names = [n.strip() for n in m[1].split(",")]
        text = " ".join(line.strip() for line in m[2].splitlines())
        for name in names:
            notes[name] = text
        if "..." in names:
            notes["*_" + "_".join(names[-1].split("_")[-2:])] = text
    return notes


def _meaning(key: str, notes: dict[str, str]) -> str:
    if key in notes:
        return notes[key]
    wild = next((text for pattern, text in notes.items() if pattern.startswith("*") and key.endswith(pattern[1:])), "")
    return wild


# --------------------------------------------------------------------------------------------
# tables


def _cell(text: Any) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _example(value: Any) -> str:
    if value is None or isinstance(value, dict):
        return ""
    if isinstance(value, list) and len(value) > 4:
        return f"`[{', '.join(f'{v:g}' if isinstance(v, float) else str(v) for v in value[:3])}, …]` ({len(value)})"
    return f"`{value!r}`" if isinstance(value, str) else f"`{value}`"


def _section_model(model: type[BaseModel], key: str) -> type[BaseModel] | None:
    """The pydantic model of a field that is a TOML section (``X`` or ``X | None``), or None."""
    annotation = model.model_fields[key].annotation
    for candidate in (annotation, *get_args(annotation)):
        if isinstance(candidate, type) and issubclass(candidate, BaseModel):
            return candidate
    return None


def _required(model: type[BaseModel], key: str) -> str:
    info = model.model_fields[key]
    if info.is_required():
        return "required"
    if info.default is None or info.default is PydanticUndefined or isinstance(info.default, BaseModel):
        return "optional"
    return f"optional, default `{info.default!r}`"


def schema_table(
    model: type[BaseModel], example: dict[str, Any], notes: dict[str, str], ranges: bool = True
) -> list[str]:
    """A Markdown table of the fields of ``model``: key, unit, required or default, the bounds the
    schema enforces with the plausible and measured ranges, an example value and the meaning."""
    rows = [
        "| key | unit | required | range | example | meaning |",
        "|---|---|---|---|---|---|",
    ]
    for key in model.model_fields:
        if _section_model(model, key) is not None:
            rows.append(f"| `{key}` |  | {_required(model, key)} |  |  | the section `[{key}]`, below |")
            continue
        bounds = templates._schema_bounds(model, key).removeprefix("required ")
        rng = "; ".join([b for b in (bounds, *(templates._ranges(key) if ranges else ())) if b])
        cells = (key, templates.unit_of(key), _required(model, key), rng, _example(example.get(key)))
        meaning = _meaning(key, notes)
        if key in CAPACITY_KEYS:
            meaning = "one capacity convention: exactly one of the capacity keys (docs/physics.md §1)"
        rows.append(f"| `{cells[0]}` | {' | '.join(_cell(c) for c in cells[1:])} | {_cell(meaning)} |")
    return rows


def _starting_file(kind: str, suffix: str) -> list[str]:
    """The file ``tcsim init KIND`` writes, folded (it carries each key's unit, range and source)."""
    text = templates.make_template(kind, f"my_{kind}{suffix}").text
    lang = "toml" if suffix == ".toml" else "text"
    body = "\n".join("    " + line if line else "" for line in [f"``` {lang}", *text.splitlines(), "```"])
    return [f'??? example "The starting file `tcsim init {kind} --out my_{kind}{suffix}` writes"', "", body, ""]


# --------------------------------------------------------------------------------------------
# sections of the page


def converter_part() -> list[str]:
    """The converter file: top-level keys and the four sections."""
    raw = tomllib.loads(Path(load_converter(templates.TEMPLATE_CONVERTER).path).read_text(encoding="utf-8"))
    out = [
        "## Converter file",
        "",
        "A TOML file: the `CONVERTER` argument of `characterise`, `fit`, `study`, `replay`, `fit-shapes`,",
        "`export-fmu`, `operating-point` and the `converter` key of a vehicle file. Each model needs only its",
        "own sections (`table`: `[characteristic]`; `hrovat-tobler`: `[geometry]`; `quasi-dynamic`:",
        "`[characteristic]` and `[quasi_dynamic]`; every transient run also `[inertia]`); unknown keys are",
        f"errors. The example column is the bundled `{templates.TEMPLATE_CONVERTER}`.",
        "",
        "### Top level",
        "",
        *schema_table(ConverterFile, raw, comment_notes(ConverterFile)),
        "",
    ]
    for section, model in templates._CONVERTER_SCHEMA.items():
        notes = comment_notes(model)
        example = raw.get(section, {})
        example = example[0] if isinstance(example, list) else example
        out += [f"### `[{section}]`", "", templates._CONVERTER_SECTIONS[section] + ".", ""]
        doc = inspect.getdoc(model)
        out += [doc, ""] if doc and model.__doc__ != BaseModel.__doc__ and "\n" not in doc.strip() else []
        out += [*schema_table(model, example, notes), ""]
    out += [
        "### `[sources]`",
        "",
        templates._CONVERTER_SECTIONS["sources"] + ".",
        "",
        *_starting_file("converter", ".toml"),
    ]
    return out


def design_part() -> list[str]:
    """The design file of ``tcsim design``."""
    raw = tomllib.loads(Path(load_design_file(templates.TEMPLATE_DESIGN).path).read_text(encoding="utf-8"))
    out = [
        "## Design file",
        "",
        "A TOML file: the `DESIGN` argument of `tcsim design` and `tcsim design-study` (docs: [design](../design.md)).",
        f"The example column is the bundled `{templates.TEMPLATE_DESIGN}`.",
        "",
        "### Top level",
        "",
        *schema_table(DesignFileModel, raw, {}),
        "",
    ]
    for section in DesignFileModel.model_fields:
        model = _section_model(DesignFileModel, section)
        if model is None:
            continue
        notes = attribute_notes(TorusDesign) if section == "design" else comment_notes(model)
        doc = (inspect.getdoc(model) or "") if section != "design" else ""
        out += [f"### `[{section}]`", "", *([doc.replace("\n", " "), ""] if doc else [])]
        out += [*schema_table(model, raw.get(section, {}), notes, ranges=section != "design"), ""]
    out += _starting_file("design", ".toml")
    return out


def vehicle_part() -> list[str]:
    """The vehicle file: the core owns its schema; the keys are those of the bundled vehicle."""
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    raw = tomllib.loads(Path(vehicle.path).read_text(encoding="utf-8"))
    out = [
        "## Vehicle file",
        "",
        "A TOML file: the `VEHICLE` argument of `tcsim launch`, `tcsim drive` and `tcsim design --vehicle`.",
        "The Rust core owns its schema and checks every value when the file is read; whether a key is",
        "optional (and its default), its range and its meaning are in [the vehicle page](../vehicle.md). The",
        f"example column is the bundled `{DEFAULT_VEHICLE}` (`tcsim vehicles` lists the bundled vehicles).",
        "",
        "| section | key | unit | example |",
        "|---|---|---|---|",
        "| (top level) | `name` |  | " + _example(raw["name"]) + " |",
        "| (top level) | `source` |  |  |",
        "| (top level) | `description` |  |  |",
        "| (top level) | `converter` |  | " + _example(raw["converter"]) + " |",
    ]
    for section in vehicle.sections:
        for key, value in raw[section].items():
            out.append(f"| `[{section}]` | `{key}` | {templates.unit_of(key)} | {_example(value)} |")
    return [*out, "", *_starting_file("vehicle", ".toml")]


def scenario_part() -> list[str]:
    """The scenario file of ``tcsim launch --scenario FILE`` and the study file."""
    return [
        "## Scenario file",
        "",
        "A time series (CSV, Parquet, `.mat`, MDF4): the `--scenario FILE` of `tcsim launch`. Its columns, their",
        "units and ranges are the comment lines of the starting file:",
        "",
        *_starting_file("scenario", ".csv"),
        "## Study file",
        "",
        "A converter file whose `[geometry]` (above) `tcsim study` sweeps over the ranges of Li & Sundén (2016)",
        "Table D.1, one value at a time:",
        "",
        *_starting_file("study", ".toml"),
    ]


def measurement_part() -> list[str]:
    """The channels a measurement file may have (``tcsim replay``, ``fit-shapes``, ``torque-estimate``)."""
    out = [
        "## Measurement channels",
        "",
        "A measured time series (CSV, Parquet, `.mat` v5/v7.3, MDF4) for `tcsim replay`, `tcsim fit-shapes` and",
        "`tcsim torque-estimate`. A channel is found by `--channel TARGET=COLUMN`, else by its canonical name,",
        "else by the same quantity with another unit suffix (converted); a unit in the file's metadata (MDF4)",
        "decides when present. Which channels a command needs: [replay](../replay.md),",
        "[torque-estimate](../torque_estimate.md).",
        "",
        "| channel | quantity | unit suffixes accepted (first: SI) |",
        "|---|---|---|",
    ]
    for name in measurement_io.INPUT_CHANNELS:
        quantity = measurement_io._QUANTITY[name]
        stem = name.removesuffix("_" + next(iter(measurement_io._SUFFIXES[quantity])))
        suffixes = ", ".join(f"`{stem}_{s}`" for s in measurement_io._SUFFIXES[quantity])
        out.append(f"| `{name}` | {quantity} | {suffixes} |")
    return [*out, ""]


def page() -> str:
    """The whole input-file reference, Markdown."""
    head = [
        "# Input files, field by field",
        "",
        "Generated from the schemas when the site is built (`tools/docs_reference.py`): the keys, units,",
        "bounds and defaults below are the ones tcsim checks. A value outside its bound is refused with one",
        "line, `error: <file>: <field> = <value>: expected <what>`, and exit code 2; a value outside its",
        "*plausible* range is read with a warning. Units are carried by the key names",
        "([conventions](../conventions.md)).",
        "`tcsim init KIND` writes each file below with every key commented.",
        "",
    ]
    parts = (converter_part(), vehicle_part(), design_part(), scenario_part(), measurement_part())
    return "\n".join(head + [line for part in parts for line in part]).rstrip("\n") + "\n"


# --------------------------------------------------------------------------------------------
# script


if __name__ == "__main__":
    text = page()
    if len(sys.argv) > 1:
        Path(sys.argv[1]).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
