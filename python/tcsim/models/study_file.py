"""Monte Carlo study files (``tcsim monte-carlo FILE``, docs/study.md "Monte Carlo studies"): a
vehicle launch repeated ``runs`` times with converter and vehicle parameters drawn from the
distributions the file gives.

The file is TOML, read by one pydantic model, :class:`MonteCarloFile` (the field-by-field reference
of the documentation site is generated from it). A ``[distributions]`` key names a parameter as the
converter or vehicle file writes it, prefixed by the file: ``converter.<section>.<key>`` (a number
of ``[inertia]``, ``[geometry]`` or ``[quasi_dynamic]``, or ``converter.characteristic.lag_time_constant_s``)
or ``vehicle.<section>.<key>`` (a real number of a vehicle section; not an array element). Its
value is one of :class:`Normal`, :class:`Uniform`, :class:`Lognormal`, :class:`TruncatedNormal`
(drawn at random), or :class:`Grid` (swept).

**The support is checked, not the samples.** Before anything runs, the converter (or vehicle) is
built with the parameter at each end of its distribution's support (an open end: the nearest
number inside it; an unbounded end: ±1.797e308), the other values as the file has them, and
validated by the converter's schema or the core's vehicle checks, the one owners of the ranges. A
distribution whose support reaches a refused value is an :class:`~tcsim.errors.InputError` naming
the study file, the distribution and the value refused: a ``normal`` on a positive quantity is
refused (its support is every real number), a ``truncated-normal`` or ``lognormal`` is not.
A grid's every value is checked the same way. Constraints between parameters (the core's geometry
checks) can still refuse a drawn case; that case's rows carry the reason in ``error`` and the study
goes on.

**Grids.** The grid parameters form a full factorial, the first grid parameter of the file varying
slowest; each grid point is run ``runs`` times with the random parameters drawn, so a study has
(grid points × ``runs``) cases, at most :data:`MAX_RUNS` (10⁷; :data:`MAX_RUNS_UNCHUNKED`, 10⁵, without
``--chunk-size``). ``runs`` is required when a parameter is drawn at random; when every parameter
is a grid it may be omitted and may only be 1 (the runs of a grid point would be the same case).
"""

from __future__ import annotations

import math
import sys
import tomllib
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import tomli_w
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from .. import _core
from ..errors import CoreText, InputError, TcsimWarning, from_core, read_user_text
from .converter import MODELS, Converter, bundled_names, parse_converter
from .vehicle import DEFAULT_VEHICLE, SECTIONS, Vehicle, _load_named_converter, bundled_vehicle_names, load_vehicle

#: The most cases of one study, and the most without ``--chunk-size`` (all rows in memory).
MAX_RUNS = 10_000_000
MAX_RUNS_UNCHUNKED = 100_000
#: The built-in scenarios a study can run (:mod:`tcsim.simulation.scenarios`).
SCENARIOS = ("flip-flop", "part-pedal")
#: The converter sections whose numbers a study can draw, and the one key of ``[characteristic]``.
CONVERTER_SECTIONS = ("inertia", "geometry", "quasi_dynamic")
CHARACTERISTIC_KEYS = ("lag_time_constant_s",)
#: The smallest probability of a truncated normal's interval (below it the bounds are a mistake).
MIN_TRUNCATED_MASS = 1e-9
#: The most values of one grid parameter (each is built and checked before the study runs).
MAX_GRID_POINTS = 100_000
_FINITE = Field(allow_inf_nan=False)
#: The ``kind`` of each distribution (:data:`Distribution`).
KINDS = ("normal", "uniform", "lognormal", "truncated-normal", "grid")


class FieldError(ValueError):
    """A validator's error naming its field below the model validated (``loc``, e.g. ``("start",)``)
    and the value refused: the study file's error names that field, not the whole table."""

    def __init__(self, loc: tuple[str | int, ...], value: Any, expected: str):
        super().__init__(expected)
        self.loc = loc
        self.value = value
        self.expected = expected


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


class Normal(_Strict):
    """``{ kind = "normal", mean, std }``: the normal distribution of mean ``mean`` and standard
    deviation ``std``."""

    kind: Literal["normal"]
    mean: float = _FINITE
    std: float = Field(gt=0, allow_inf_nan=False)

    def support(self) -> tuple[float, float, bool]:
        """``(low, high, open)``: the support's ends and whether they are excluded."""
        return -math.inf, math.inf, True


class Uniform(_Strict):
    """``{ kind = "uniform", low, high }``: every value from low to high equally likely."""

    kind: Literal["uniform"]
    low: float = _FINITE
    high: float = _FINITE

    @model_validator(mode="after")
    def _ordered(self):
        if not self.low < self.high:
            raise ValueError(f"low < high (low = {self.low:g}, high = {self.high:g})")
        return self

    def support(self) -> tuple[float, float, bool]:
        return self.low, self.high, False


class Lognormal(_Strict):
    """``{ kind = "lognormal", mean, std }``: mean and standard deviation of the quantity itself
    (not of its logarithm): ``ln X`` is normal with ``σ² = ln(1 + (std/mean)²)`` and
    ``μ = ln(mean) − σ²/2``; support above 0."""

    kind: Literal["lognormal"]
    mean: float = Field(gt=0, allow_inf_nan=False)
    std: float = Field(gt=0, allow_inf_nan=False)

    def log_parameters(self) -> tuple[float, float]:
        """``(μ, σ)`` of ``ln X``."""
        s2 = math.log1p((self.std / self.mean) ** 2)
        return math.log(self.mean) - s2 / 2, math.sqrt(s2)

    def support(self) -> tuple[float, float, bool]:
        return 0.0, math.inf, True


class TruncatedNormal(_Strict):
    """``{ kind = "truncated-normal", mean, std, low, high }``: the normal of ``mean`` and ``std``
    restricted to ``[low, high]`` (``mean`` and ``std`` are the untruncated normal's)."""

    kind: Literal["truncated-normal"]
    mean: float = _FINITE
    std: float = Field(gt=0, allow_inf_nan=False)
    low: float = _FINITE
    high: float = _FINITE

    @model_validator(mode="after")
    def _interval(self):
        if not self.low < self.high:
            raise ValueError(f"low < high (low = {self.low:g}, high = {self.high:g})")
        if self.mass() < MIN_TRUNCATED_MASS:
            raise ValueError(f"low and high within a few std of mean (the interval holds {self.mass():.3g} of it)")
        return self

    def mass(self) -> float:
        """The normal's probability within ``[low, high]``."""
        a, b = (self.low - self.mean) / self.std, (self.high - self.mean) / self.std
        if a > 0:  # both in the upper tail: the mirror image, for precision
            a, b = -b, -a
        return 0.5 * (math.erfc(-b / math.sqrt(2)) - math.erfc(-a / math.sqrt(2)))

    def support(self) -> tuple[float, float, bool]:
        return self.low, self.high, False


class Grid(_Strict):
    """``{ kind = "grid", values }`` or ``{ kind = "grid", start, stop, num }``: swept, not drawn (the
    grids of a file form a full factorial, each point run ``runs`` times). ``values``: distinct finite
    numbers, run in the order given; ``start, stop, num``: ``num`` values evenly spaced from
    ``start`` to ``stop``, both included (value ``k`` is ``start + k·(stop − start)/(num − 1)``, the
    last exactly ``stop``, as ``numpy.linspace``; ``num = 1``: ``start`` alone). Exactly one of the
    two forms."""

    kind: Literal["grid"]
    values: list[Annotated[float, Field(allow_inf_nan=False)]] | None = None
    start: float | None = Field(default=None, allow_inf_nan=False)
    stop: float | None = Field(default=None, allow_inf_nan=False)
    num: int | None = Field(default=None, ge=1, le=MAX_GRID_POINTS)

    @model_validator(mode="after")
    def _one_form(self):
        if self.values is not None:
            extra = next((k for k in ("start", "stop", "num") if getattr(self, k) is not None), None)
            if extra is not None:
                raise FieldError((extra,), getattr(self, extra), "values or start, stop and num, not both")
            if not self.values:
                raise FieldError(("values",), [], "at least one value")
            if len(self.values) > MAX_GRID_POINTS:
                raise FieldError(("values",), f"{len(self.values)} values", f"at most {MAX_GRID_POINTS} values")
            seen: set[float] = set()
            for j, v in enumerate(self.values):
                if v in seen:
                    raise FieldError(("values", j), v, "distinct values (this one is given twice)")
                seen.add(v)
            return self
        missing = [k for k in ("start", "stop", "num") if getattr(self, k) is None]
        if len(missing) == 3:
            raise FieldError(("values",), "missing", "values, or start, stop and num (one of the two forms)")
        if missing:
            raise FieldError((missing[0],), "missing", "start, stop and num together (or values alone)")
        assert self.start is not None and self.stop is not None and self.num is not None
        if self.num > 1 and self.start == self.stop:
            raise FieldError(("stop",), self.stop, f"a stop other than start ({self.start:g}) when num > 1")
        if self.num > 1 and not math.isfinite(self.stop - self.start):
            raise FieldError(("stop",), self.stop, "stop − start a finite number")
        if len(set(self.points())) < self.num:  # rounding: start and stop too close for num values
            expected = f"at most as many values as distinct numbers lie from {self.start!r} to {self.stop!r}"
            raise FieldError(("num",), self.num, expected)
        return self

    def __len__(self) -> int:
        """The number of values."""
        return len(self.values) if self.values is not None else int(self.num or 0)

    def value(self, k: int) -> float:
        """Value ``k`` (0 ≤ k < len) of the grid."""
        if self.values is not None:
            return self.values[k]
        assert self.start is not None and self.stop is not None and self.num is not None
        if k == self.num - 1 and self.num > 1:
            return self.stop
        if k == 0:
            return self.start
        return k * ((self.stop - self.start) / (self.num - 1)) + self.start

    def points(self) -> list[float]:
        """Every value of the grid, in order."""
        return [self.value(k) for k in range(len(self))]

    def support(self) -> tuple[float, float, bool]:
        points = self.points()
        return min(points), max(points), False


def describe(distribution: BaseModel) -> str:
    """``normal(mean=1900, std=50)``, ``grid(values=[0, 0.001])``: a distribution as one short text."""
    values = distribution.model_dump(exclude_none=True)
    kind = values.pop("kind")

    def show(v: Any) -> str:
        return "[" + ", ".join(f"{x:g}" for x in v) + "]" if isinstance(v, list) else f"{v:g}"

    return f"{kind}(" + ", ".join(f"{k}={show(v)}" for k, v in values.items()) + ")"


Distribution = Annotated[Normal | Uniform | Lognormal | TruncatedNormal | Grid, Field(discriminator="kind")]


def count_grid_points(distributions: Iterable[Any]) -> int:
    """The number of points of the full factorial of the grids among ``distributions`` (1 without a grid)."""
    return math.prod(len(d) for d in distributions if isinstance(d, Grid))


class MonteCarloFile(BaseModel):
    """The study file's top level."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)

    #: The study's name (default: the file's stem).
    name: str | None = None
    description: str | None = None
    #: A bundled vehicle (tcsim vehicles lists them) or a vehicle .toml, relative to this file.
    vehicle: str = DEFAULT_VEHICLE
    #: A bundled converter or a converter .toml relative to this file (default: the vehicle's).
    converter: str | None = None
    #: The launch: flip-flop (full pedal at the brake release, to 100 km/h) or part-pedal (pedal 0.3, to 50 km/h).
    scenario: Literal["flip-flop", "part-pedal"] = "flip-flop"
    #: The converter models run in each case (default: every model the converter supports).
    models: list[Literal["table", "hrovat-tobler", "quasi-dynamic"]] | None = Field(default=None, min_length=1)
    #: Cases (launches of every model) per grid point, each drawn from the seed and its index alone;
    #: required when a parameter is drawn at random, else at most 1 (default 1).
    runs: int | None = Field(default=None, ge=1, le=MAX_RUNS)
    #: The random seed: the same file and seed give the same cases bit for bit, however the study is chunked.
    seed: int = Field(ge=0, le=2**63 - 1)
    #: Launch summary columns (docs/launch_summary.md) kept per case and model.
    outputs: list[str] = Field(
        default=["time_0_50_km_h_s", "time_0_100_km_h_s", "effective_torque_ratio_dip_first_0_5_s"], min_length=1
    )
    #: Parameter (converter.<section>.<key> or vehicle.<section>.<key>) → its distribution (below).
    distributions: dict[str, Distribution] = Field(min_length=1)

    @model_validator(mode="after")
    def _cases(self):
        random = [k for k, d in self.distributions.items() if not isinstance(d, Grid)]
        if self.runs is None and random:
            raise FieldError(
                ("runs",), "missing", f"this key: {random[0]} is drawn at random (a grid alone may omit it)"
            )
        if self.runs is not None and self.runs > 1 and not random:
            expected = "1 or no runs when every parameter is a grid (the runs of a grid point would be the same case)"
            raise FieldError(("runs",), self.runs, expected)
        if self.n_cases > MAX_RUNS:
            raise FieldError(("runs",), self.n_runs, f"at most {MAX_RUNS} cases: {self.cases_text()}")
        return self

    @property
    def n_runs(self) -> int:
        """The runs per grid point (``runs``, 1 when omitted)."""
        return 1 if self.runs is None else self.runs

    @property
    def grid_points(self) -> int:
        """The number of grid points (1 without a grid)."""
        return count_grid_points(self.distributions.values())

    @property
    def n_cases(self) -> int:
        """The study's cases: grid points × runs."""
        return self.grid_points * self.n_runs

    def cases_text(self) -> str:
        """``3 × 4 grid points × 10 runs = 120 cases``."""
        sizes = " × ".join(str(len(d)) for d in self.distributions.values() if isinstance(d, Grid))
        runs = f"{self.n_runs} run{'s' if self.n_runs > 1 else ''}"
        return f"{sizes} grid points × {runs} = {self.n_cases} cases"


@dataclass(frozen=True)
class Parameter:
    """A drawn parameter: its key as the study file writes it, the file it belongs to
    (``converter`` or ``vehicle``), the section and key there, and its distribution."""

    key: str
    target: str
    section: str
    name: str
    distribution: Normal | Uniform | Lognormal | TruncatedNormal | Grid

    @property
    def is_grid(self) -> bool:
        return isinstance(self.distribution, Grid)


@dataclass(frozen=True)
class StudyFile:
    """A validated study file: the file, the vehicle and converter it names, its models and parameters."""

    path: str
    doc: MonteCarloFile
    vehicle: Vehicle
    converter: Converter
    models: tuple[str, ...]
    parameters: tuple[Parameter, ...]

    @property
    def name(self) -> str:
        return self.doc.name or Path(self.path).stem


def _flatten(table: Any, path: str, prefix: str = "") -> dict[str, Any]:
    """``[distributions]`` with dotted keys written bare (``vehicle.body.mass_kg = {...}`` is a
    nested table in TOML) flattened to ``{"vehicle.body.mass_kg": {...}}``; a table with ``kind`` is a
    leaf. A parameter written both quoted and bare (two TOML keys, one parameter) is an
    :class:`InputError`: the later would silently replace the earlier."""
    if not isinstance(table, dict) or "kind" in table:
        return {prefix: table}
    out: dict[str, Any] = {}
    for k, v in table.items():
        for key, leaf in _flatten(v, path, f"{prefix}.{k}" if prefix else str(k)).items():
            if key in out:
                raise InputError(path, f'distributions."{key}"', leaf, "each parameter once (it is given twice)")
            out[key] = leaf
    return out


def _field_name(loc: tuple[Any, ...]) -> str:
    parts = [x for x in loc if x not in KINDS]
    if len(parts) >= 2 and parts[0] == "distributions":
        rest = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in parts[2:])
        return f'distributions."{parts[1]}"' + rest
    return ".".join(str(p) for p in parts) or "(file)"


def _validation_error(err: ValidationError, path: str) -> InputError:
    e = err.errors()[0]
    cause = e.get("ctx", {}).get("error")
    if isinstance(cause, FieldError):  # a validator naming its field
        field = _field_name((*tuple(e["loc"]), *cause.loc))
        return InputError(path, field, cause.value, cause.expected)
    field = _field_name(tuple(e["loc"]))
    value = e.get("input", "")
    msg = e["msg"].removeprefix("Input should be ").removeprefix("Value error, ")
    if e["type"] == "extra_forbidden":
        msg = "a known key (docs/study.md lists the keys of a study file)"
    elif e["type"] == "missing":
        value, msg = "missing", "this required key"
    elif e["type"] in ("int_type", "int_from_float") and isinstance(value, float):
        # shown as written: `num = 3` would hide why 3.0 is refused (a trial finding)
        value, msg = CoreText(repr(value)), "an integer, written without a decimal point"
    elif e["type"] in ("union_tag_invalid", "union_tag_not_found"):
        value = value.get("kind", "missing") if isinstance(value, dict) else value
        field, msg = f"{field}.kind", "one of " + ", ".join(f"'{k}'" for k in KINDS)
    if isinstance(value, dict | list) and len(str(value)) > 60:
        value = f"{type(value).__name__} of {len(value)}"
    return InputError(path, field, value, msg)


def read_monte_carlo_file(path: str | Path) -> MonteCarloFile:
    """The study file's schema checked (no converter or vehicle read yet)."""
    path = Path(path)
    if path.suffix.lower() != ".toml" or not path.is_file():
        raise InputError(str(path), "study file", str(path), "an existing Monte Carlo study .toml file")
    try:
        data = tomllib.loads(read_user_text(path, "a readable UTF-8 TOML file"))
    except tomllib.TOMLDecodeError as e:
        raise InputError(str(path), "(syntax)", str(e), "valid TOML") from None
    if isinstance(data.get("distributions"), dict):
        data["distributions"] = _flatten(data["distributions"], str(path))
    try:
        return MonteCarloFile.model_validate(data)
    except ValidationError as err:
        raise _validation_error(err, str(path)) from None


def _relative(spec: str, path: Path) -> str:
    """A file name relative to the study file; a bundled name as it is."""
    candidate = Path(spec)
    if candidate.is_absolute() or not candidate.suffix:
        return spec
    return str(path.parent / candidate)


def _converter(spec: str, path: Path) -> Converter:
    """The study file's ``converter``: a bundled name or a converter .toml relative to the study file."""
    try:
        return _load_named_converter(spec, str(path))
    except InputError as e:
        if e.source != str(path):  # the converter file itself is bad: its own message
            raise
        names = ", ".join(bundled_names())
        expected = f"a bundled converter ({names}) or a converter .toml file relative to the study file"
        raise InputError(str(path), "converter", spec, expected) from None


def _vehicle(spec: str, path: Path) -> Vehicle:
    """The study file's ``vehicle``: a bundled name or a vehicle .toml relative to the study file."""
    where = _relative(spec, path)
    try:
        return load_vehicle(where)
    except InputError as e:
        if not (e.source == where and e.field == "vehicle"):  # the vehicle file itself is bad
            raise
        names = ", ".join(bundled_vehicle_names())
        expected = f"a bundled vehicle ({names}) or a vehicle .toml file relative to the study file"
        raise InputError(str(path), "vehicle", spec, expected) from None


def _parameter(key: str, dist: Any, path: str, converter: Converter, vehicle: Vehicle) -> Parameter:
    """The parameter a ``[distributions]`` key names, or :class:`InputError` naming it."""
    field = f'distributions."{key}"'
    target, _, rest = key.partition(".")
    section, _, name = rest.partition(".")
    if target == "converter":
        if section in CONVERTER_SECTIONS:
            model = getattr(converter, section)
            known = model is not None and name in type(model).model_fields
        else:
            known = section == "characteristic" and name in CHARACTERISTIC_KEYS and converter.characteristic is not None
        if known:
            return Parameter(key, target, section, name, dist)
        where = f"the converter {converter.name!r} ({converter.path})"
        expected = (
            f"a number of {where}: converter.<section>.<key> with <section> one of "
            f"{', '.join(CONVERTER_SECTIONS)} (present in the file) or converter.characteristic.lag_time_constant_s"
        )
        raise InputError(path, field, key, expected)
    if target == "vehicle":
        values = vehicle.core_spec().get(section, {}) if section in SECTIONS else {}
        if isinstance(values.get(name), float):
            return Parameter(key, target, section, name, dist)
        expected = (
            f"a real number of the vehicle {vehicle.name!r}: vehicle.<section>.<key> with <section> one of "
            f"{', '.join(SECTIONS)} (not an array or an integer)"
        )
        raise InputError(path, field, key, expected)
    raise InputError(path, field, key, "a parameter converter.<section>.<key> or vehicle.<section>.<key>")


def converter_data(data: dict[str, Any], values: dict[tuple[str, str], float]) -> dict[str, Any]:
    """A converter's TOML ``data`` (:meth:`Converter.to_toml_dict`) with ``values`` (by section and
    key) set; ``data`` is not changed."""
    data = dict(data)
    for (section, key), value in values.items():
        if section == "characteristic" and isinstance(data["characteristic"], list):
            data["characteristic"] = [{**data["characteristic"][0], key: value}, *data["characteristic"][1:]]
        else:
            data[section] = {**data.get(section, {}), key: value}
    return data


def build_converter(data: dict[str, Any], path: str) -> Converter:
    """A converter of TOML ``data`` (:func:`converter_data`), validated; no warnings (a study draws
    thousands; the support's check shows the implausible ones once)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return parse_converter(data, path)


def vehicle_data(data: dict[str, Any], values: dict[tuple[str, str], float]) -> dict[str, Any]:
    """A vehicle's TOML ``data`` (:meth:`Vehicle.to_toml_dict`) with ``values`` (by section and key)
    set; ``data`` is not changed."""
    data = dict(data)
    for (section, key), value in values.items():
        data[section] = {**data[section], key: value}
    return data


def build_vehicle(data: dict[str, Any], path: str, converter: Converter) -> Vehicle:
    """A vehicle of TOML ``data`` (:func:`vehicle_data`) checked by the core, driving ``converter``."""
    try:
        core = _core.read_vehicle(tomli_w.dumps(data), path)
    except _core.CoreInputError as e:
        raise from_core(e, path) from None
    return Vehicle(core, path, converter)


def _probes(dist: Any) -> list[float]:
    """The ends of the support of ``dist``: an open end the nearest number inside, an unbounded end ±max."""
    low, high, is_open = dist.support()
    big = sys.float_info.max
    lo = -big if low == -math.inf else (math.nextafter(low, math.inf) if is_open else low)
    hi = big if high == math.inf else (math.nextafter(high, -math.inf) if is_open else high)
    return [lo, hi]


def _refusal(
    p: Parameter, value: float, converter: Converter, vehicle: Vehicle, implausible: list[str] | None = None
) -> InputError | None:
    """Why the converter or vehicle is refused with ``p`` at ``value`` (the rest as the files have it), or None;
    the converter's plausibility warnings at ``value`` appended to ``implausible``."""
    try:
        values = {(p.section, p.name): value}
        if p.target == "converter":
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", TcsimWarning)
                parse_converter(converter_data(converter.to_toml_dict(), values), converter.path)
            if implausible is not None:
                prefix = f"{converter.path}: "
                implausible.extend(
                    str(w.message).removeprefix(prefix) for w in caught if issubclass(w.category, TcsimWarning)
                )
        else:
            build_vehicle(vehicle_data(vehicle.to_toml_dict(), values), vehicle.path, converter)
    except InputError as e:
        return e
    return None


def _model_refusal(p: Parameter, value: float, converter: Converter, models: Sequence[str]) -> InputError | None:
    """Why a model of the study refuses the converter with ``p`` at ``value`` (the core's checks of a
    run: the mass matrix's bound on the shape effects, …), or None."""
    from .dynamic import dynamic_model  # noqa: PLC0415  (dynamic imports this module's neighbours)

    if p.target != "converter":
        return None
    conv = build_converter(converter_data(converter.to_toml_dict(), {(p.section, p.name): value}), converter.path)
    for m in models:
        try:
            _core.check_model(dynamic_model(conv, m).spec)
        except _core.CoreInputError as e:
            err = from_core(e, "study")
            return InputError(err.source, f"{err.field} (the {m} model)", err.value, err.expected)
    return None


def _check_grid(
    p: Parameter, grid: Grid, path: str, converter: Converter, vehicle: Vehicle, models: Sequence[str]
) -> None:
    """Refuse ``p`` if the converter or vehicle is refused at any value of its grid, or a model of the
    study at any value (a grid's values are fixed: a value no run can use is refused before any runs,
    not in every row of its grid point)."""
    for k, value in enumerate(grid.points()):
        implausible: list[str] = []
        e = _refusal(p, value, converter, vehicle, implausible) or _model_refusal(p, value, converter, models)
        _warn_implausible(path, f"distributions.{_quoted(p.key)}.values[{k}]", value, implausible)
        if e is None:
            continue
        if grid.values is not None:
            expected = f"a value within the valid range of {p.key}: {e.field}: expected {e.expected}"
            raise InputError(path, f'distributions."{p.key}".values[{k}]', value, expected)
        expected = (
            f"a grid whose values lie within the valid range of {p.key}: "
            f"at value {k} ({value:.6g}), {e.field}: expected {e.expected}"
        )
        raise InputError(path, f'distributions."{p.key}"', describe(grid), expected)


def _quoted(key: str) -> str:
    return f'"{key}"'


def _warn_implausible(path: str, field: str, value: float, messages: list[str]) -> None:
    """The converter's plausibility warnings at a value of the study file, as the study file's: a
    trial found them silent (50 kg·m² of pump inertia ran without a word, which ``tcsim launch``
    warns of); once per value, not per case."""
    for message in dict.fromkeys(messages):
        warnings.warn(f"{path}: {field} = {value:g}: {message}", TcsimWarning, stacklevel=3)


def _check_support(p: Parameter, path: str, converter: Converter, vehicle: Vehicle, models: Sequence[str]) -> None:
    """Refuse ``p`` if the converter or vehicle is refused at an end of its distribution's support
    (a grid: at any of its values, also by the study's models)."""
    if isinstance(p.distribution, Grid):
        _check_grid(p, p.distribution, path, converter, vehicle, models)
        return
    for value in _probes(p.distribution):
        implausible: list[str] = []
        e = _refusal(p, value, converter, vehicle, implausible)
        _warn_implausible(path, f"distributions.{_quoted(p.key)} (an end of its support)", value, implausible)
        if e is not None:
            low, high, is_open = p.distribution.support()
            support = f"{'(' if is_open else '['}{low:g}, {high:g}{')' if is_open else ']'}"
            hint = " (a truncated-normal bounds a normal)" if isinstance(p.distribution, Normal) else ""
            expected = (
                f"a distribution whose support {support} lies within the valid range of {p.key}{hint}: "
                f"at {value:.6g}, {e.field}: expected {e.expected}"
            )
            raise InputError(path, f'distributions."{p.key}"', describe(p.distribution), expected) from None


def _model_specs(p: Parameter, value: float, converter: Converter, models: Sequence[str]) -> list[dict] | None:
    """The specifications of the study's models with ``p`` at ``value`` (None when refused)."""
    from .dynamic import dynamic_model  # noqa: PLC0415  (dynamic imports this module's neighbours)

    try:
        conv = build_converter(converter_data(converter.to_toml_dict(), {(p.section, p.name): value}), converter.path)
        return [dynamic_model(conv, m).spec for m in models]
    except InputError:
        return None


def _unused(p: Parameter, converter: Converter, models: Sequence[str]) -> bool:
    """Whether a converter parameter changes none of ``models``: their specifications compared at
    two values of it (its grid's, or its support's ends, else its value in the file)."""
    if p.target != "converter":
        return False
    candidates: list[Any] = p.distribution.points() if isinstance(p.distribution, Grid) else _probes(p.distribution)
    candidates.append(getattr(getattr(converter, p.section, None), p.name, None))
    specs = []
    for value in dict.fromkeys(v for v in candidates if isinstance(v, float) and math.isfinite(v)):
        spec = _model_specs(p, value, converter, models)
        if spec is not None:
            specs.append(spec)
        if len(specs) == 2:
            break
    return len(specs) == 2 and specs[0] == specs[1]


def warn_about_unused_parameters(file: StudyFile) -> None:
    """Warn of each converter parameter that changes none of the study's models (a trial swept an
    H&T geometry value with the table and quasi-dynamic models only: every grid point ran the
    same, without a word). Called once the study is checked whole, so that a refused file's
    message stays its one line."""
    for p in file.parameters:
        if _unused(p, file.converter, file.models):
            warnings.warn(
                f"{file.path}: distributions.{_quoted(p.key)}: none of the study's models "
                f"({', '.join(file.models)}) uses {p.key}; its values change no run",
                TcsimWarning,
                stacklevel=3,
            )


def load_study_file(path: str | Path) -> StudyFile:
    """A Monte Carlo study file read and checked: its schema, the vehicle and converter it names
    (relative to the file), its models (each buildable from the converter), and each parameter
    (known, and its distribution's support within the parameter's valid range); an
    :class:`InputError` (one line naming the file and field) before anything runs."""
    doc = read_monte_carlo_file(path)
    p = Path(path)
    vehicle = _vehicle(doc.vehicle, p)
    converter = vehicle.converter if doc.converter is None else _converter(doc.converter, p)
    models = tuple(dict.fromkeys(doc.models)) if doc.models else converter.models
    for m in models:
        if m not in converter.models:
            raise InputError(str(p), "models", m, f"a model of the converter {converter.name!r}: {converter.models}")
    if not models or any(m not in MODELS for m in models):
        raise InputError(str(p), "models", list(models), f"some of {', '.join(MODELS)}")
    vehicle = Vehicle(vehicle.core, vehicle.path, converter)
    params = tuple(_parameter(k, d, str(p), converter, vehicle) for k, d in doc.distributions.items())
    for param in params:
        _check_support(param, str(p), converter, vehicle, models)
    return StudyFile(str(p), doc, vehicle, converter, models, params)
