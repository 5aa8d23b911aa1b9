"""The input-file reference of the documentation site, generated from the schemas (issue 17).

Used two ways:

* by the MkDocs hook ``tools/docs_hooks.py`` (``hooks:`` in ``mkdocs.yml``), which adds the page
  ``reference/input-files.md`` to the site at build time, so it is never stored and cannot drift;
* as a script, ``python tools/docs_reference.py [FILE]``, which prints (or writes) the same page.

Every fact on the page is read from its one owner: the pydantic models of
:mod:`tcsim.models.converter` and :mod:`tcsim.models.design_file` (keys, required or default, the
bounds they enforce), the ``#:`` comments and docstrings beside them (meanings), the unit a key's
name carries, the plausible and measured ranges (:func:`tcsim.io.templates` notes), the vehicle
schema of the Rust core (``tcsim._core.vehicle_schema()``: keys, units, defaults, the validator's
ranges, meanings), the scenario columns of :mod:`tcsim.io.scenario`, the measurement channels of
:mod:`tcsim.io.measurement` with the commands that read them, and the starting files ``tcsim init``
writes.
"""

from __future__ import annotations

import inspect
import math
import re
import sys
import tomllib
from pathlib import Path
from typing import Any, get_args

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from tcsim import _core
from tcsim.analysis import shape_fit
from tcsim.analysis.replay import DRIVES as REPLAY_DRIVES
from tcsim.analysis.replay import LOCKUP_CHANNEL
from tcsim.analysis.torque_estimate import CHANNEL as TORQUE_ESTIMATE_CHANNEL
from tcsim.io import measurement as measurement_io
from tcsim.io import scenario as scenario_io
from tcsim.io import templates
from tcsim.models import study_file
from tcsim.models.characteristic import CAPACITY_KEYS
from tcsim.models.converter import ConverterFile, load_converter
from tcsim.models.design import TorusDesign
from tcsim.models.design_file import DesignFileModel, load_design_file
from tcsim.models.plausibility import RANGES
from tcsim.models.study_file import Distribution, MonteCarloFile
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
    """The vehicle file: every key from the core's schema (``tcsim._core.vehicle_schema()``, whose
    ranges are the validator's own), the example values from the bundled vehicle."""
    raw = tomllib.loads(Path(load_vehicle(DEFAULT_VEHICLE).path).read_text(encoding="utf-8"))
    out = [
        "## Vehicle file",
        "",
        "A TOML file: the `VEHICLE` argument of `tcsim launch`, `tcsim drive` and `tcsim design --vehicle`",
        "([the vehicle](../vehicle.md) describes the plant). The Rust core owns its schema and checks every",
        "value once, when the file is read; the tables below are generated from that schema",
        "(`crates/tcsim-core/src/vehicle/file.rs`, `SCHEMA`), whose ranges are the constants the check",
        "uses. Every number must be finite; integers are accepted for numbers, `min_gear` must be an",
        "integer; for an array the range holds for each value. Unknown keys, missing keys and sections",
        "are errors. The example column is the bundled",
        f"`{DEFAULT_VEHICLE}` (`tcsim vehicles` lists the bundled vehicles).",
        "",
    ]
    schema = _core.vehicle_schema()
    for section in dict.fromkeys(row["section"] for row in schema):
        out += [f"### `[{section}]`" if section else "### Top level", ""]
        out += ["| key | unit | required | range | example | meaning |", "|---|---|---|---|---|---|"]
        for row in (r for r in schema if r["section"] == section):
            value = raw.get(section, {}) if section else raw
            required = "required" if row["required"] else f"optional, default {row['default']}"
            cells = (row["unit"], required, row["range"], _example(value.get(row["key"])), row["meaning"])
            out.append(f"| `{row['key']}` | {' | '.join(_cell(c) for c in cells)} |")
        out.append("")
    out += [
        "### `[sources]`",
        "",
        'Optional: `"section.key" = "where the value comes from"` (`"assumed: why"` where assumed); each key',
        "must name a value of this file.",
        "",
    ]
    return [*out, *_starting_file("vehicle", ".toml")]


def _scenario_rows() -> list[str]:
    """One row per column ``tcsim.io.scenario.read_scenario`` reads: its names and units, its range."""
    times = " or ".join(f"`{c}`" for c in scenario_io._TIME_COLUMNS)
    time_units = ", ".join(f"{'s' if f == 1.0 else 'ms'}" for f in scenario_io._TIME_COLUMNS.values())
    span = RANGES["scenario_duration_s"].describe()
    rows = [
        "| column | unit | required | range | meaning |",
        "|---|---|---|---|---|",
        f"| {times} | {time_units} | required | finite, strictly increasing; span plausible: {span} | "
        "time; shifted so that the run starts at 0, braked and at rest, and ends at the last time stamp |",
    ]
    for pedal in scenario_io._PEDALS:
        names = scenario_io._pedal_columns(pedal)
        columns = " or ".join(f"`{c}`" for c in names)
        units = ", ".join("1" if f == 1.0 else "%" for f in names.values())
        ranges = ", ".join(f"0 to {1.0 / f:g}" for f in names.values())
        what = "accelerator pedal position" if pedal.startswith("acc") else "brake pedal position"
        rows.append(f"| {columns} | {units} | required | {ranges} | {what}, linear between samples |")
    torque = RANGES["torque_nm"].describe()
    rows.append(
        f"| `engine_torque_nm` | N·m | optional | finite; plausible: {_cell(torque)} | a logged crank torque "
        "replayed instead of the engine model (the pedal then drives only the shift and lock-up schedules) |"
    )
    return rows


def scenario_part() -> list[str]:
    """The scenario file of ``tcsim launch --scenario FILE``."""
    return [
        "## Scenario file",
        "",
        "A time series (CSV with `#` comment lines allowed, Parquet, `.mat`, MDF4): the `--scenario FILE` of",
        "`tcsim launch`. The columns below are the ones `tcsim.io.scenario.read_scenario` looks for (in MDF4",
        "files a channel's unit, `s`, `ms` or `%`, decides). A problem is exit 2 with one line naming the",
        "file, the column, the row and the value; an implausible span or engine torque is refused unless",
        "`--allow-implausible` (then a warning).",
        "",
        *_scenario_rows(),
        "",
        *_starting_file("scenario", ".csv"),
    ]


def _markdown(text: str) -> str:
    """A docstring's reST as Markdown: ````x```` and ``:class:`~a.b.X``` become `` `x` `` and `` `X` ``."""
    return re.sub(r":\w+:`~?(?:[\w.]+\.)?(\w+)`", r"`\1`", text).replace("``", "`")


def study_file_part() -> list[str]:
    """The two study files: the Appendix D study's converter file and the Monte Carlo study file
    (:class:`~tcsim.models.study_file.MonteCarloFile` and its distributions)."""
    raw = tomllib.loads(templates.make_template("monte-carlo", "my_monte-carlo.toml").text)
    out = [
        "## Study files",
        "",
        "### Appendix D study (`tcsim study`)",
        "",
        "A converter file whose `[geometry]` (above) `tcsim study` sweeps over the ranges of Li & Sundén (2016)",
        "Table D.1, one value at a time:",
        "",
        *_starting_file("study", ".toml"),
        "### Monte Carlo study (`tcsim monte-carlo`)",
        "",
        "A TOML file: the `FILE` argument of `tcsim monte-carlo`, a vehicle launch repeated `runs` times with",
        "converter and vehicle parameters drawn from the distributions it gives, at each point of its grids",
        '([study](../study.md), "Monte Carlo studies"). The example column is the starting file',
        "`tcsim init monte-carlo` writes.",
        "",
        *[
            row.replace("| `runs` |  | optional |", "| `runs` |  | required with a drawn parameter |")
            for row in schema_table(MonteCarloFile, raw, comment_notes(MonteCarloFile), ranges=False)
        ],
        "",
        "#### `[distributions]`",
        "",
        "Each key is a parameter as its file writes it, `converter.<section>.<key>` (a number of `[inertia]`,",
        "`[geometry]`, `[quasi_dynamic]`, or `converter.characteristic.lag_time_constant_s`) or",
        "`vehicle.<section>.<key>` (a real number of a vehicle section, not an array element); dotted keys",
        'may be quoted (`"vehicle.body.mass_kg" = {…}`) or bare. Its value is one of:',
        "",
        "| `kind` | keys | support | meaning |",
        "|---|---|---|---|",
    ]
    for model in get_args(get_args(Distribution)[0]):
        kind = get_args(model.model_fields["kind"].annotation)[0]
        keys = ", ".join(
            f"`{k}` ({templates._schema_bounds(model, k).removeprefix('required ') or 'finite'})"
            for k in model.model_fields
            if k != "kind"
        )
        if kind == "grid":
            support = "its values (swept, not drawn)"
        else:
            low, high, is_open = model.model_construct(low=0.0, high=1.0, mean=1.0, std=1.0).support()
            support = "every real number" if low == -math.inf else ("above 0" if is_open else "`low` to `high`")
        doc = " ".join((inspect.getdoc(model) or "").split()).split(": ", 1)[-1]
        out.append(f"| `{kind}` | {keys} | {support} | {_cell(_markdown(doc))} |")
    out += [
        "",
        *(_markdown(" ".join(part.split())) + "\n" for part in (inspect.getdoc(study_file) or "").split("\n\n")[2:4]),
        *_starting_file("monte-carlo", ".toml"),
    ]
    return out


def _channel_uses() -> dict[str, list[str]]:
    """Which command reads each channel, and how, from the commands' own channel lists."""
    uses: dict[str, list[str]] = {name: [] for name in measurement_io.INPUT_CHANNELS}
    uses["time_s"].append("every command: required")
    for drive, kind in REPLAY_DRIVES.items():
        for name in kind.inputs:
            uses[name].append(f"replay `--drive {drive}`: input")
        for name in kind.outputs:
            uses[name].append(f"replay `--drive {drive}`: compared if present")
    uses[LOCKUP_CHANNEL].append("replay: the lock-up clutch's capacity command if present")
    combos = [(drive, target) for drive in shape_fit.DRIVES for target in shape_fit.TARGETS]
    for name in uses:
        needed = [(d, t) for d, t in combos if name in shape_fit.required_channels(t, d)]
        if len(needed) == len(combos):
            uses[name].append("fit-shapes: required")
        elif needed:
            uses[name].append(
                "fit-shapes: required with " + ", ".join(f"`--drive {d} --target {t}`" for d, t in needed)
            )
    uses[TORQUE_ESTIMATE_CHANNEL].append("torque-estimate: required")
    return uses


def _channel_check(name: str, quantity: str) -> str:
    """What :func:`tcsim.io.measurement.read_measurement` checks of a channel beyond finiteness."""
    if name == "time_s":
        step = RANGES["sample_spacing_s"].describe()
        return f"strictly increasing; median step plausible: {step}; span at most {measurement_io.MAX_TIME_SPAN_S:g} s"
    checks = ["at least 0"] if name in measurement_io.NON_NEGATIVE else []
    if quantity in measurement_io._RANGE_OF:
        checks.append("plausible: " + RANGES[measurement_io._RANGE_OF[quantity]].describe())
    return "; ".join(checks)


def measurement_part() -> list[str]:
    """The channels a measurement file may have (``tcsim replay``, ``fit-shapes``, ``torque-estimate``)."""
    out = [
        "## Measurement channels",
        "",
        "A measured time series (CSV, Parquet, `.mat` v5/v7.3, MDF4) for `tcsim replay`, `tcsim fit-shapes` and",
        "`tcsim torque-estimate`. A channel is found by `--channel TARGET=COLUMN`, else by its canonical name,",
        "else by the same quantity with another unit suffix (converted); a unit in the file's metadata (MDF4)",
        "decides when present. Every value must be a finite number; a value outside its plausible range is",
        "refused unless `--allow-implausible` (then a warning). The commands: [replay](../replay.md),",
        "[fit-shapes](../shape_fit.md), [torque-estimate](../torque_estimate.md).",
        "",
        "| channel | quantity | unit suffixes accepted (first: SI) | checked | read by |",
        "|---|---|---|---|---|",
    ]
    uses = _channel_uses()
    for name in measurement_io.INPUT_CHANNELS:
        quantity = measurement_io._QUANTITY[name]
        stem = name.removesuffix("_" + next(iter(measurement_io._SUFFIXES[quantity])))
        suffixes = ", ".join(f"`{stem}_{s}`" for s in measurement_io._SUFFIXES[quantity])
        read_by = "; ".join(uses[name]) or "replay: compared when mapped with `--channel` and a model outputs it"
        out.append(f"| `{name}` | {quantity} | {suffixes} | {_cell(_channel_check(name, quantity))} | {read_by} |")
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
    parts = (converter_part(), vehicle_part(), design_part(), scenario_part(), study_file_part(), measurement_part())
    return "\n".join(head + [line for part in parts for line in part]).rstrip("\n") + "\n"


# --------------------------------------------------------------------------------------------
# script


if __name__ == "__main__":
    text = page()
    if len(sys.argv) > 1:
        Path(sys.argv[1]).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
