"""Dynamic converter models for the transient engine: :class:`DynamicModel` (the core's spec of one
model of one converter), :func:`dynamic_model`, :func:`resolve_model` and :func:`select_models`.
See ``docs/transient.md``."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .. import _core
from ..errors import InputError, TcsimWarning, from_core
from ..units import DEFAULT_PUMP_SPEED_RAD_S
from .arguments import real_number
from .characteristic import extension_message, extension_reached, warn_if_extended
from .converter import MODELS, Converter, load_converter

#: Pump speed at which the default quasi-dynamic flow time constant is evaluated (stall), rad/s:
#: the core's reference pump speed.
FLOW_TIME_CONSTANT_PUMP_SPEED_RAD_S = DEFAULT_PUMP_SPEED_RAD_S
#: The factor over the quasi-dynamic model's turbine stability bound on τ_Q below which a run warns:
#: with the thesis's shape effects the bundled launch rings (amplitude above 0.02 in some gear or
#: shift) at 1.8× the bound and not at 5.9× (docs/models.md).
COUPLING_MARGIN = 5.0


# ---------------------------------------------------------------------------------------------
# Models


class NearCouplingWarning(TcsimWarning):
    """:meth:`DynamicModel.warn_if_fragile_near_coupling`'s warning: a fit that runs the model at many
    trial shape effects (``fit-shapes``) keeps it for the fitted values alone."""


@dataclass(frozen=True)
class DynamicModel:
    """A converter model ready for the transient engine.

    ``spec`` is the dict the core takes; ``source`` names the converter file for messages.
    """

    name: str
    spec: dict[str, Any]
    source: str

    @property
    def shape_effect_m2(self) -> tuple[float, ...]:
        """The shape effects (pump, turbine[, stator]); empty for the table model."""
        return tuple(self.spec.get("shape_effect_m2", ()))

    def warn_if_fragile_near_coupling(self) -> None:
        """For the quasi-dynamic model, one warning when its flow time constant is below
        :data:`COUPLING_MARGIN` times the turbine's stability bound for its shape effects
        (``tcsim._core.qd_coupling_time_constant_bound_s``; docs/models.md, "The flow's time
        constant"): below the bound the turbine's effective inertia turns negative near coupling, and
        up to about 5× it the bundled launch still rings there (measured)."""
        if self.name != "quasi-dynamic":
            return
        bound = _core.qd_coupling_time_constant_bound_s(self.spec)
        tau = float(self.spec["flow_time_constant_s"])
        if tau < COUPLING_MARGIN * bound:
            warnings.warn(
                f"{self.source}: quasi_dynamic.flow_time_constant_s = {tau:g} s is below {COUPLING_MARGIN:g}× the "
                f"turbine's stability bound ({bound:.3g} s) for shape effects {self.shape_effect_m2[0]:g}, "
                f"{self.shape_effect_m2[1]:g} m²: the quasi-dynamic model may ring or oscillate near coupling "
                "(docs/models.md)",
                NearCouplingWarning,
                stacklevel=3,
            )

    def table(self) -> dict[str, Any] | None:
        """The characteristic of the table models as the core's table functions take it; None for
        Hrovat & Tobler."""
        if self.name not in ("table", "quasi-dynamic"):
            return None
        keys = (*TABLE_SPEC_KEYS, "overrun", "interpolation")
        table: dict[str, Any] = {}
        for k, v in self.spec.items():
            if k in ("input_torque_nm", "table_rows"):
                table[k] = [float(x) for x in v]
            elif k in keys:
                table[k] = v if isinstance(v, str) else np.asarray(v, dtype=float)
        return table

    def warn_if_extended(self, columns: Mapping[str, Any], what: str = "the run") -> None:
        """For the table models, one warning when the run's pump and turbine speeds (``columns``)
        reached the overrun rule's extension of the table (:func:`~.characteristic.warn_if_extended`)."""
        table = self.table()
        if table is not None:
            warn_if_extended(self.source, table, columns["pump_speed_rad_s"], columns["turbine_speed_rad_s"], what)

    def with_shape_effects(self, pump_m2: float, turbine_m2: float, stator_m2: float | None = None) -> DynamicModel:
        """The same model with other shape effects (eqs 2.16–2.18 sign convention)."""
        if self.name == "table":
            raise InputError.argument("model", self.name, "a model with shape effects: hrovat-tobler or quasi-dynamic")
        given = {"pump_m2": pump_m2, "turbine_m2": turbine_m2}
        if self.name == "hrovat-tobler":
            given["stator_m2"] = self.shape_effect_m2[2] if stator_m2 is None else stator_m2
        shape = [real_number(name, v) for name, v in given.items()]
        for name, v in zip(given, shape):
            if not math.isfinite(v):  # (the core would name the converter file's field)
                raise InputError.argument(name, v, "a finite shape effect in m²")
        return replace(self, spec={**self.spec, "shape_effect_m2": shape})


def _and_list(words: Sequence[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def warn_about_runs(kind: str, runs: Sequence[tuple[str, DynamicModel, Mapping[str, Any]]]) -> None:
    """The warnings about finished runs (``kind``: "drive", "launch"; ``runs``: label, model and
    columns of each): each model's :meth:`DynamicModel.warn_if_fragile_near_coupling`, and per
    converter one warning that names every run whose speeds reached the overrun rule's extension
    of its table (:func:`~.characteristic.extension_reached`), rather than one per run."""
    reached: dict[tuple[str, tuple[float, ...]], list[tuple[str, float, dict[str, Any]]]] = {}
    for label, model, columns in runs:
        model.warn_if_fragile_near_coupling()
        table = model.table()
        if table is None:
            continue
        sr = extension_reached(table, columns["pump_speed_rad_s"], columns["turbine_speed_rad_s"])
        if sr is not None:
            # one line per converter: its file and its table (two tables of one path stay apart)
            key = (model.source, tuple(np.asarray(table["speed_ratio"], dtype=float).tolist()))
            reached.setdefault(key, []).append((label, sr, table))
    for (source, _), found in reached.items():
        plural = "s" if len(found) > 1 else ""
        what = f"the {kind} run{plural} " + _and_list([repr(label) for label, _, _ in found])
        message = extension_message(source, found[0][2], what, _and_list([f"{sr:.3g}" for _, sr, _ in found]))
        warnings.warn(message, TcsimWarning, stacklevel=3)


def _require(conv: Converter, section: str, model: str) -> Any:
    value = getattr(conv, section)
    if value is None:
        raise InputError(conv.path, f"[{section}]", "missing", f"a [{section}] section for the transient {model} model")
    return value


#: The model specification's table keys (``input_torque_nm`` and ``table_rows`` for several tables).
TABLE_SPEC_KEYS = ("speed_ratio", "torque_ratio", "capacity_factor_nm_s2", "input_torque_nm", "table_rows")


def _table_spec(conv: Converter) -> dict[str, Any]:
    """The table keys of the specification: :meth:`~.characteristic.Characteristic.core_table` as lists."""
    c = conv.characteristic
    assert c is not None  # the caller's conv.require(model) checked it
    return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in c.core_table().items()}


def _inertia(conv: Converter, model: str) -> list[float]:
    i = _require(conv, "inertia", model)
    return [i.pump_kg_m2, i.turbine_kg_m2, i.stator_kg_m2]


def default_flow_time_constant_s(conv: Converter) -> float:
    """Default τ_Q of the quasi-dynamic model, from the core
    (``tcsim._core.default_flow_time_constant_s``): the fluid's inertance over the slope of the net
    head with respect to the flow, ``τ_Q = (ρL_f/A) / |∂F_Q/∂Q|``, for the Hrovat & Tobler geometry
    at stall (locked stator) and the reference pump speed (2000 rpm, docs/physics.md §5). It scales as
    1/ω_p."""
    g = _require(conv, "geometry", "quasi-dynamic (default flow time constant)")
    try:
        return _core.default_flow_time_constant_s(conv.core_geometry(), g.fluid_length_m)
    except _core.CoreInputError as e:
        raise from_core(e, conv.path) from None


def dynamic_model(converter: Converter | str, model: str = "hrovat-tobler") -> DynamicModel:
    """The transient model ``model`` of a converter (a :class:`Converter`, bundled name or file).

    * ``table``: [characteristic] (with its optional first-order lag ``lag_time_constant_s``,
      docs/lag.md) and [inertia];
    * ``hrovat-tobler``: [geometry] (with fluid length and shape effects) and [inertia];
    * ``quasi-dynamic``: [characteristic], [inertia] and [quasi_dynamic]; the fluid density and
      pump radius come from [quasi_dynamic] or else [geometry], and τ_Q from
      ``flow_time_constant_s`` or else :func:`default_flow_time_constant_s`; a
      ``[characteristic] lag_time_constant_s`` is the table model's and ignored here (the fluid
      inertia is this model's dynamics), as it is by ``hrovat-tobler``.
    """
    conv = converter if isinstance(converter, Converter) else load_converter(converter)
    conv.require(model)
    spec: dict[str, Any] = {"kind": model, "inertia_kg_m2": _inertia(conv, model)}
    if model == "table":
        spec.update(_table_spec(conv))
        if conv.lag_time_constant_s is not None:
            # the table model's only: the quasi-dynamic model has its own flow lag (docs/lag.md)
            spec["lag_time_constant_s"] = conv.lag_time_constant_s
    elif model == "hrovat-tobler":
        g = conv.geometry
        assert g is not None  # conv.require(model) checked it
        spec.update(
            geometry=conv.core_geometry()[0].tolist(),
            fluid_length_m=g.fluid_length_m,
            shape_effect_m2=[g.pump_shape_effect_m2, g.turbine_shape_effect_m2, g.stator_shape_effect_m2],
        )
    else:
        qd = _require(conv, "quasi_dynamic", model)
        spec.update(_table_spec(conv))
        spec["shape_effect_m2"] = [qd.pump_shape_effect_m2, qd.turbine_shape_effect_m2]
        for key in ("fluid_density_kg_m3", "pump_exit_radius_m"):
            value = getattr(qd, key, None)
            if value is None:
                value = getattr(_require(conv, "geometry", f"quasi-dynamic ({key} is not in [quasi_dynamic])"), key)
            spec[key] = value
        tau = qd.flow_time_constant_s
        spec["flow_time_constant_s"] = tau if tau is not None else default_flow_time_constant_s(conv)
    return DynamicModel(model, spec, conv.path)


def resolve_model(
    converter: Converter | str | DynamicModel | None,
    model: str | DynamicModel,
    allowed: Sequence[str] = MODELS,
    why: str = "",
) -> DynamicModel:
    """A :class:`DynamicModel` given directly (as ``model``, or as ``converter``), or the model named
    ``model`` of ``converter`` (a :class:`Converter`, bundled name or file). A model outside
    ``allowed`` is an InputError on the argument ``model`` (``why`` explains the restriction)."""
    expected = f"one of {', '.join(allowed)}{why}"
    if isinstance(model, DynamicModel):
        m = model
    elif isinstance(converter, DynamicModel):
        m = converter
    else:
        if model not in allowed:
            raise InputError.argument("model", model, expected)
        if converter is None:
            raise InputError.argument("converter", None, "a converter (or a DynamicModel as the model)")
        m = dynamic_model(converter, model)
    if m.name not in allowed:
        raise InputError.argument("model", m.name, expected)
    return m


def select_models(converter: Any, requested: Sequence[str]) -> list[DynamicModel]:
    """The transient models to run: those requested (each must be buildable), or by default every
    model of ``converter.models`` whose transient sections are present (at least one)."""
    for name in requested:
        if name not in MODELS:
            raise InputError.argument("model", name, f"one of {', '.join(MODELS)}")
    if requested:
        return [dynamic_model(converter, m) for m in dict.fromkeys(requested)]
    models, first_error = [], None
    for name in converter.models:
        try:
            models.append(dynamic_model(converter, name))
        except InputError as e:
            first_error = first_error or e
    if not models:
        raise first_error or InputError(converter.path, "(models)", "none", f"sections for one of {', '.join(MODELS)}")
    return models
