"""Design files (``tcsim design DESIGN``, docs/design.md "Design files"): a converter's hardware in
TOML, and the converter file derived from it.

A design file holds ``name`` (optional, default the file's stem) and ``description`` (optional),
a ``[design]`` section with the fields of :class:`~tcsim.models.design.TorusDesign`, an
``[inertia]`` section with the **metal** inertias (``pump_kg_m2``, ``turbine_kg_m2``,
``stator_kg_m2``, kg·m², the rules of a converter's ``[inertia]``), and an optional ``[losses]``
section with the Hrovat & Tobler loss coefficients (``pump_shock_loss``, ``turbine_shock_loss``,
``stator_shock_loss``, ``friction_loss``); a loss not given takes Li & Sundén's Table D.1 value
(the bundled ``li-sunden-2016``'s ``[geometry]``) and the derived file's ``[sources]`` says so.

The derived converter has ``[geometry]`` (the design's radii, angles, area and density, the losses,
and the fluid length and shape effects of :func:`tcsim.models.design.design_geometry`),
``[inertia]`` (metal plus fluid inertia of each element) and ``[sources]`` naming the design file
and the formula of every value. It has no ``[characteristic]``: it runs the ``hrovat-tobler`` model.
"""

from __future__ import annotations

import functools
import tomllib
import warnings
from collections.abc import Sequence
from dataclasses import MISSING, dataclass, fields
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, get_type_hints

from pydantic import BaseModel, ConfigDict, Field, ValidationError, create_model

from .. import _core
from ..errors import InputError, TcsimWarning, from_core, read_user_text
from .converter import Converter, GeometrySection, InertiaSection, load_converter, parse_converter
from .design import DEFAULT_POINTS, DesignGeometry, TorusDesign, design_geometry, design_table, geometry_of_row

#: The bundled converter whose ``[geometry]`` gives the default loss coefficients (Table D.1).
LOSS_DEFAULTS_FROM = "li-sunden-2016"
#: The loss coefficients of ``[losses]``.
LOSS_KEYS = ("pump_shock_loss", "turbine_shock_loss", "stator_shock_loss", "friction_loss")
_ELEMENTS = ("pump", "turbine", "stator")
_DOC = "docs/design.md"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=False)


def _design_section() -> type[_Strict]:
    """``[design]``: the fields of :class:`~.design.TorusDesign` (the one owner of the schema), typed;
    the values are checked by the core (docs/design.md, "Bad input")."""
    types = get_type_hints(TorusDesign)
    defs: dict[str, Any] = {
        f.name: (types[f.name], ... if f.default is MISSING else f.default) for f in fields(TorusDesign)
    }
    return create_model("DesignSection", __base__=_Strict, **defs)


if TYPE_CHECKING:
    DesignSection = _Strict
else:
    DesignSection = _design_section()


class LossSection(_Strict):
    """``[losses]``: the Hrovat & Tobler loss coefficients, each optional (rules of ``[geometry]``)."""

    pump_shock_loss: float | None = Field(default=None, allow_inf_nan=False)
    turbine_shock_loss: float | None = Field(default=None, allow_inf_nan=False)
    stator_shock_loss: float | None = Field(default=None, allow_inf_nan=False)
    friction_loss: float | None = Field(default=None, allow_inf_nan=False)


class DesignFileModel(_Strict):
    name: str | None = None
    description: str | None = None
    design: DesignSection
    inertia: InertiaSection
    losses: LossSection = LossSection()


@dataclass(frozen=True)
class DesignFile:
    """A read design file: its path, name, the design, the metal inertias (kg·m²), the loss
    coefficients given (by key) and its description."""

    path: str
    name: str
    design: TorusDesign
    metal_inertia: InertiaSection
    losses: dict[str, float]
    description: str | None = None


@dataclass(frozen=True)
class DerivedConverter:
    """The converter derived from a design: the TOML document, the validated converter, the design's
    geometry, and the loss coefficients taken from Table D.1 because the file gave none."""

    document: dict[str, Any]
    converter: Converter
    geometry: DesignGeometry
    default_losses: tuple[str, ...]


def _input_error(err: ValidationError, path: str) -> InputError:
    """The first pydantic error as one line naming the design file's field."""
    e = err.errors()[0]
    loc = [str(x) for x in e["loc"]]
    section = loc[0] if len(loc) > 1 else None
    field = (f"[{section}]" + "".join(f"[{x}]" if x.isdigit() else f".{x}" for x in loc[1:])) if section else loc[0]
    value: Any = e.get("input", "")
    expected = e["msg"].removeprefix("Input should be ")
    if e["type"] == "extra_forbidden":
        expected = f"a known key of {f'[{section}]' if section else 'the top level'} ({_DOC}, 'Design files')"
    elif e["type"] == "missing" and section is None and loc[0] in ("design", "inertia"):
        field, value, expected = f"[{loc[0]}]", "missing", f"a [{loc[0]}] section ({_DOC}, 'Design files')"
    elif e["type"] == "missing":
        value, expected = "missing", "this required key"
    if isinstance(value, (dict, list)):
        value = f"{type(value).__name__} of {len(value)}"
    return InputError(path, field, value, expected)


def read_design_file(path: str | Path) -> DesignFile:
    """Read and type-check a design file; the design's values are checked when its geometry is
    computed (:func:`derive_converter`). Raises :class:`~tcsim.errors.InputError` naming the file."""
    p = Path(path)
    try:
        data = tomllib.loads(read_user_text(p, "a readable UTF-8 TOML design file"))
    except tomllib.TOMLDecodeError as e:
        raise InputError(str(p), "(syntax)", str(e), "valid TOML") from None
    try:
        doc = DesignFileModel.model_validate(data)
    except ValidationError as err:
        raise _input_error(err, str(p)) from None
    d = doc.design.model_dump()
    for key in ("pump_path_m", "turbine_path_m", "stator_path_m"):
        if d[key] is not None:
            d[key] = tuple((float(r), float(z)) for r, z in d[key])
    losses = {k: v for k, v in doc.losses.model_dump().items() if v is not None}
    return DesignFile(str(p), doc.name or p.stem, TorusDesign(**d), doc.inertia, losses, doc.description)


def bundled_design_names() -> list[str]:
    """The bundled example designs (``python/tcsim/data/designs``)."""
    folder = resources.files("tcsim") / "data" / "designs"
    return sorted(p.name.removesuffix(".toml") for p in folder.iterdir() if p.name.endswith(".toml"))


def load_design_file(spec: str | Path) -> DesignFile:
    """A bundled design's name or a design ``.toml`` (:func:`read_design_file`)."""
    text = str(spec)
    if isinstance(spec, str) and text in bundled_design_names():
        with resources.as_file(resources.files("tcsim") / "data" / "designs" / f"{text}.toml") as p:
            return read_design_file(Path(p))
    if not Path(text).is_file():
        expected = f"a bundled design ({', '.join(bundled_design_names())}) or an existing design .toml file"
        raise InputError(text, "design", text, expected)
    return read_design_file(text)


def _sources(file: DesignFile, defaults: tuple[str, ...]) -> dict[str, str]:
    """``[sources]`` of the derived converter: the design file and the formula of each value."""
    name = Path(file.path).name
    given = {f.name: f"design file {name}, [design].{f.name}" for f in fields(TorusDesign)}
    out = {
        f"geometry.{k}": given[k]
        for k in given
        if k.endswith(("_radius_m", "_angle_deg")) or k in ("flow_area_m2", "fluid_density_kg_m3")
    }
    for k in LOSS_KEYS:
        out[f"geometry.{k}"] = (
            f"default: Li & Sundén (2016) Table D.1 (bundled {LOSS_DEFAULTS_FROM}); not given in {name}"
            if k in defaults
            else f"design file {name}, [losses].{k}"
        )
    profile = f"{file.design.profile} profile of {name}"
    out["geometry.fluid_length_m"] = f"L_f = Σ ∫(1 + tan²α) dl along the mean streamline, {profile} ({_DOC})"
    for e in _ELEMENTS:
        out[f"geometry.{e}_shape_effect_m2"] = (
            f"S = R_exit·|tan(α_exit)|·L_axial, Li & Sundén (2016) §4.1.1 eqs 4.1–4.2 / 2.16–2.18, "
            f"L_axial the axial extent of the {e}'s path, {profile} ({_DOC})"
        )
        out[f"inertia.{e}_kg_m2"] = f"metal {name} [inertia].{e}_kg_m2 + fluid ρA∫R²dl along the {e}'s path ({_DOC})"
    return out


@functools.cache
def _table_d1() -> GeometrySection:
    """The ``[geometry]`` of the bundled :data:`LOSS_DEFAULTS_FROM` (read once: a design study derives
    thousands of converters)."""
    geometry = load_converter(LOSS_DEFAULTS_FROM).geometry
    assert geometry is not None  # the bundled thesis converter has [geometry]
    return geometry


def _design_error(e: InputError) -> InputError:
    """The core's error on a design's field, with the field as the design file writes it."""
    field = e.field if e.field == "points" else f"[design].{e.field}"
    return e.replace(field=field)


def derive_converter(file: DesignFile, points: int | None = None) -> DerivedConverter:
    """The converter of a design: its geometry by the core (bad values name the design file), the
    converter TOML document, and the converter validated as any converter file is."""
    try:
        g = design_geometry(file.design, points or DEFAULT_POINTS, file.path)
    except InputError as e:  # the core names the design's field: it lives in [design]
        raise _design_error(e) from None
    return _converter_of(file, g)


def derive_converters(files: Sequence[DesignFile], points: int | None = None) -> list[DerivedConverter | InputError]:
    """:func:`derive_converter` of many designs, their geometry in one threaded core call; a design
    that fails gets its :class:`InputError` in its place (the same error the one-design call raises)."""
    cols = design_table([f.design for f in files], points or DEFAULT_POINTS, strict=False)
    out: list[DerivedConverter | InputError] = []
    for i, file in enumerate(files):
        if cols["error"][i] is not None:
            try:  # the one-design call names the field exactly as for a single design
                out.append(derive_converter(file, points))
            except InputError as e:
                out.append(e)
            continue
        try:
            out.append(_converter_of(file, geometry_of_row(cols, i)))
        except InputError as e:
            out.append(e)
    return out


def _converter_of(file: DesignFile, g: DesignGeometry) -> DerivedConverter:
    """The derived converter of ``file`` with its geometry ``g`` (see :func:`derive_converter`)."""
    table_d1 = _table_d1()
    defaults = tuple(k for k in LOSS_KEYS if k not in file.losses)
    d = file.design
    geometry: dict[str, Any] = {
        k: float(getattr(d, k))
        for k in ("flow_area_m2", "fluid_density_kg_m3")
        + tuple(f.name for f in fields(TorusDesign) if f.name.endswith(("_radius_m", "_angle_deg")))
    }
    geometry |= {k: float(file.losses.get(k, getattr(table_d1, k))) for k in LOSS_KEYS}
    geometry["fluid_length_m"] = g.fluid_length_m
    elements = {"pump": g.pump, "turbine": g.turbine, "stator": g.stator}
    geometry |= {f"{e}_shape_effect_m2": x.shape_effect_m2 for e, x in elements.items()}
    inertia = {
        f"{e}_kg_m2": getattr(file.metal_inertia, f"{e}_kg_m2") + x.fluid_inertia_kg_m2 for e, x in elements.items()
    }
    document: dict[str, Any] = {
        "name": file.name,
        "source": f"tcsim design {Path(file.path).name}: derived from the design ({_DOC})",
    }
    if file.description:
        document["description"] = file.description
    document |= {"inertia": inertia, "geometry": geometry, "sources": _sources(file, defaults)}
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", TcsimWarning)
            converter = parse_converter(document, file.path)
    except InputError as e:
        key = e.field.removeprefix("[geometry].")
        if key in file.losses:
            raise InputError(file.path, f"[losses].{key}", e.value, e.expected) from None
        raise
    for w in caught:
        if issubclass(w.category, TcsimWarning):
            warnings.warn(_as_design_field(file, str(w.message)), TcsimWarning, stacklevel=3)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    _check_dynamics(file, converter)
    return DerivedConverter(document, converter, g, defaults)


def _check_dynamics(file: DesignFile, converter: Converter) -> None:
    """The core's check of the derived converter's Hrovat & Tobler model (the mass matrix's bound on
    the shape effects), its refusal named as the design file's derived value: a blade angle of
    89.999° was blamed on ``model: geometry.pump_shape_effect_m2`` when the take-off ran."""
    from .dynamic import dynamic_model  # noqa: PLC0415  (dynamic imports this module's neighbours)

    try:
        _core.check_model(dynamic_model(converter, "hrovat-tobler").spec)
    except _core.CoreInputError as e:
        err = from_core(e, file.path)
        section, _, key = err.field.partition(".")
        field = _design_field(file, f"[{section}]", key)
        raise InputError(file.path, field, err.value, f"{err.expected}; check the [design] values") from None


def _design_field(file: DesignFile, section: str, key: str) -> str:
    """The derived converter's ``section.key`` (``[geometry]``, ``[inertia]``) as the design file
    names it: where the file holds the value (``[design].pump_exit_radius_m``,
    ``[losses].friction_loss``), else said to be derived (``the derived [inertia].pump_kg_m2``)."""
    if section == "[geometry]" and key in file.losses:
        return f"[losses].{key}"
    if section == "[geometry]" and key in {f.name for f in fields(TorusDesign)}:
        return f"[design].{key}"
    return f"the derived {section}.{key}"


def _as_design_field(file: DesignFile, message: str) -> str:
    """A plausibility warning of the derived converter as the design file's (:func:`_design_field`:
    a trial's warnings named ``[inertia].pump_kg_m2`` in a design file that has no such section)."""
    head = f"{file.path}: "
    rest = message.removeprefix(head)
    field, sep, tail = rest.partition(" = ")
    section, _, key = field.partition(".")
    if not (sep and message.startswith(head) and section.startswith("[")):
        return message
    return f"{head}{_design_field(file, section, key)} = {tail}"


__all__ = [
    "LOSS_DEFAULTS_FROM",
    "LOSS_KEYS",
    "DerivedConverter",
    "DesignFile",
    "bundled_design_names",
    "derive_converter",
    "derive_converters",
    "load_design_file",
    "read_design_file",
]
