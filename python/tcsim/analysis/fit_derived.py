"""What ``tcsim fit`` derives from the fitted geometry, what it warns about, and what it checks.

A fitted converter must be one converter: every quantity that follows from the radii and angles is
recomputed from the *fitted* ones through the same geometry code the rest of tcsim uses, the core's
design model (:mod:`tcsim.models.design`, ``docs/design.md``) with the circular profile through the
fitted radii:

* ``fluid_length_m`` and the three ``*_shape_effect_m2`` of ``[geometry]`` (eqs 2.16–2.18 as
  §4.1.1 reads them, ``R_exit·|tan α_exit|·L``);
* the fluid's share of ``[inertia]``, ``ρA∫R²dl`` per element: when a radius, the flow area or the
  density is free, the start's metal part (its inertia less its torus fluid inertia) plus the fitted
  torus's fluid; otherwise the fitted angles leave the fluid inertia unchanged and ``[inertia]`` is
  the start's, which the report says.

The steady state (the only thing a table measures) does not depend on the fluid length or the shape
effects, so they cannot be fitted to a table, only derived. Also here: the one-line warnings on
fitted parameters at a bound or outside the measured ranges of :mod:`tcsim.models.design_ranges`,
and :func:`check_usable`, the checks the fitted converter passes before ``fitted.toml`` is written.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from .. import _core
from ..errors import CoreText, InputError
from ..models.converter import Converter, GeometrySection, InertiaSection
from ..models.design import DesignGeometry, design_geometry, design_of_geometry
from ..models.design_ranges import DESIGN_RANGES
from ..models.dynamic import dynamic_model
from ..models.steady import characterise_hrovat_tobler, coupling_point

#: ``[geometry]`` keys derived from the radii and angles (never fitted, never copied).
DERIVED_KEYS = ("fluid_length_m", "pump_shape_effect_m2", "turbine_shape_effect_m2", "stator_shape_effect_m2")
#: ``[geometry]`` keys that set the fluid inertia ``ρA∫R²dl`` of the elements.
SIZE_KEYS = (
    "pump_exit_radius_m",
    "turbine_exit_radius_m",
    "stator_exit_radius_m",
    "flow_area_m2",
    "fluid_density_kg_m3",
)
#: How the derived keys are computed (the text of the report, ``[sources]`` and the fitted.toml header).
DERIVATION = "design model (circular profile) of the fitted radii and angles (tcsim.models.design, docs/design.md)"
#: The radii's order the circular torus needs (and every converter has).
RADII_ORDER = "stator exit radius < turbine exit radius < pump exit radius"
_ELEMENTS = ("pump", "turbine", "stator")


def radii_ordered(pump_m: float, turbine_m: float, stator_m: float) -> bool:
    """Whether the exit radii, m, admit the circular torus: ``R_s < R_t < R_p``."""
    return bool(stator_m < turbine_m < pump_m)


def torus_of(g: GeometrySection) -> DesignGeometry:
    """The geometry of ``g``'s circular torus (:func:`tcsim.models.design.design_geometry`)."""
    return design_geometry(design_of_geometry(g, "circular"), source="fitted [geometry]")


def derive_geometry(g: GeometrySection) -> GeometrySection:
    """``g`` with its fluid length, m, and shape effects, m², recomputed from its radii and angles."""
    e = torus_of(g)
    derived = {"fluid_length_m": e.fluid_length_m}
    derived |= {f"{x}_shape_effect_m2": getattr(e, x).shape_effect_m2 for x in _ELEMENTS}
    return GeometrySection(**{**g.model_dump(), **derived})


def fluid_inertias(g: GeometrySection) -> np.ndarray:
    """Fluid inertia of pump, turbine and stator, kg·m² (``ρA∫R²dl`` over each element's torus arc)."""
    e = torus_of(g)
    return np.array([getattr(e, x).fluid_inertia_kg_m2 for x in _ELEMENTS])


def derive_inertia(
    inertia: InertiaSection | None, start: GeometrySection, fitted: GeometrySection
) -> tuple[InertiaSection | None, bool]:
    """``[inertia]`` of the fitted converter, kg·m², and whether its fluid part was re-derived.

    The start's metal part (its inertia less its torus fluid inertia, at least 0) plus the fitted
    torus's fluid inertia; when the fluid inertia does not change (no size parameter free), exactly
    the start's ``[inertia]``.
    """
    if inertia is None:
        return None, False
    before, after = fluid_inertias(start), fluid_inertias(fitted)
    if np.array_equal(before, after):
        return inertia, False
    total = np.array([getattr(inertia, f"{x}_kg_m2") for x in _ELEMENTS])
    new = np.maximum(total - before, 0.0) + after
    return InertiaSection(**{f"{x}_kg_m2": float(v) for x, v in zip(_ELEMENTS, new)}), True


# --------------------------------------------------------------------------------------------
# warnings


def parameter_warnings(
    label: str,
    values: Mapping[str, float],
    bounds: Mapping[str, tuple[float, float]],
    active: Mapping[str, str],
) -> list[str]:
    """One line per free parameter (``values``) that ends at a bound (``active``: name → ``lower`` or
    ``upper``) or outside its measured range (:data:`~tcsim.models.design_ranges.DESIGN_RANGES`)."""
    lines = []
    for name, value in values.items():
        reasons = []
        side = active.get(name)
        if side is not None:
            lo, hi = bounds[name]
            reasons.append(f"ends at its {side} bound (bounds {lo:.6g} to {hi:.6g}; wider bounds let it move)")
        rng = DESIGN_RANGES.get(name)
        if rng is not None and not rng.contains(value):
            reasons.append(f"lies outside the measured range {rng.describe()}")
        if reasons:
            lines.append(f"{label}: fitted {name} = {value:.6g} " + " and ".join(reasons))
    return lines


# --------------------------------------------------------------------------------------------
# usability of the fitted converter


def _refuse(label: str, value: object, expected: str) -> InputError:
    return InputError(label, "fitted [geometry]", value, expected + "; nothing was written")


def check_usable(conv: Converter, label: str, table_coupling_sr: float | None) -> list[str]:
    """Check the fitted converter ``conv`` as every command will use it; raise :class:`InputError`
    (on ``label``, the target table) if a command would refuse it; return the warnings of the checks.

    Refused: no steady state of the Hrovat & Tobler model at some SR of 0–1 (``characterise``); a
    transient model that does not build (``replay``, ``launch``, ``export-fmu``); a mass matrix of
    eqs 2.12–2.15 that is not positive definite. Warned (one line each): no coupling point below
    SR 1 (``table_coupling_sr``, the table's coupling point or None, for the message), no
    through-flow at some SR below 1.
    """
    try:
        curve = characterise_hrovat_tobler(conv)
    except InputError as e:
        raise _refuse(
            label,
            CoreText(f"no steady state at {e.field.removeprefix('[geometry] at ')} {e.value}"),
            "a fit with a steady state at every SR from 0 to 1 (free other parameters, narrow them "
            "with --bound, or lower --speed-ratio-max)",
        ) from None
    for model in conv.models:
        if model != "table" and conv.inertia is not None:
            dynamic_model(conv, model)
    g, i = conv.geometry, conv.inertia
    assert g is not None  # a fitted converter has [geometry]
    if i is not None:
        inertia = [i.pump_kg_m2, i.turbine_kg_m2, i.stator_kg_m2]
        shape = [g.pump_shape_effect_m2, g.turbine_shape_effect_m2, g.stator_shape_effect_m2]
        margin = _core.mass_matrix_bound(conv.core_geometry(), g.fluid_length_m, inertia, shape)["margin_kg_m4"]
        if not margin > 0:
            raise _refuse(label, CoreText(f"mass-matrix margin {margin:.6g} kg/m⁴"), "a positive-definite mass matrix")
    return _curve_warnings(curve, coupling_point(conv), label, table_coupling_sr)


def _curve_warnings(curve, cp: float | None, label: str, table_coupling_sr: float | None) -> list[str]:
    """The warnings on the fitted model's steady characteristic ``curve`` over SR 0–1."""
    sr, mode = curve["speed_ratio"].to_numpy(), curve["stator_mode"].to_numpy()
    lines = []
    if cp is None:
        table = (
            f"; the table couples at SR {table_coupling_sr:g}"
            if table_coupling_sr is not None
            else "; the table does not reach TR 1 below SR 1 either"
        )
        free = sr[mode == "free-wheeling"]
        if free.size:
            why = f"its stator free-wheels from SR {free[0]:g}, but it has no locked-stator steady state at SR 1"
        else:
            tr = curve["torque_ratio"].to_numpy()[sr < 1]
            why = f"its stator never free-wheels and its TR stays above 1 (TR {tr[-1]:.4g} at SR {sr[sr < 1][-1]:g})"
        lines.append(f"{label}: the fitted Hrovat & Tobler model has no coupling point below SR 1 ({why}{table})")
    gap = sr[(mode == "no-flow") & (sr < 1)]
    if gap.size:
        lines.append(
            f"{label}: the fitted Hrovat & Tobler model has no through-flow at SR {gap[0]:g}–{gap[-1]:g} "
            "(no-flow steady states below SR 1): its torques vanish there"
        )
    return lines


def provenance(
    start: Converter, free: Sequence[str], inertia_derived: bool, label: str, quasi_dynamic: bool
) -> list[str]:
    """Where each value of the fitted converter comes from: fitted, derived, or taken from the start."""
    assert start.geometry is not None
    kept = [k for k in type(start.geometry).model_fields if k not in free and k not in DERIVED_KEYS]
    lines = [
        f"fitted to {label}: {', '.join(free)}",
        f"derived: {', '.join(DERIVED_KEYS)}, by the {DERIVATION}",
        f"taken from the start converter {start.name} (not free): {', '.join(kept) or 'none'}",
    ]
    if start.inertia is None:
        lines.append("[inertia]: none (the start converter has none; the dynamic models need one)")
    elif inertia_derived:
        lines.append(
            f"[inertia]: the start converter's metal parts (its inertia less its torus fluid inertia) plus "
            f"the fluid inertia ρA∫R²dl of the fitted torus; the metal parts are {start.name}'s, not measured "
            "for the fitted size"
        )
    else:
        lines.append(
            f"[inertia]: taken from the start converter {start.name} on purpose (metal and fluid; no radius, "
            "flow area or density is free, so the fluid inertia ρA∫R²dl is unchanged)"
        )
    if quasi_dynamic:
        lines.append(
            f"[quasi_dynamic]: taken from the start converter {start.name} on purpose: its shape effects are the "
            "quasi-dynamic model's calibration constants (fit them to a take-off measurement with tcsim "
            "fit-shapes, thesis §4.1), not geometry; its density and pump radius, where it does not set them, "
            "follow the fitted [geometry]"
        )
    return lines
