"""Shape effects of the dynamic models: the mass-matrix bound of the Hrovat & Tobler model (physics
notes §4) and the shape-effect values the sweeps use (Li & Sundén 2016 §4.1)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import _core
from ..errors import from_core
from .dynamic import DynamicModel

#: The shape effects of thesis figures 4.1–4.4 (S_p = S_t = v) and its largest pair (figure 4.1).
THESIS_VALUES_M2 = (0.0, 0.05, 0.1, 0.2)
THESIS_PAIR_M2 = (0.4, 0.3)


# ---------------------------------------------------------------------------------------------
# the mass-matrix bound of the Hrovat & Tobler model (docs/physics.md §4)


@dataclass(frozen=True)
class MassMatrixBound:
    """``M`` is positive definite iff ``ρL_f/A > Σ ρ²S_x²/I_x`` (Schur complement of the inertias).
    ``room`` is ``ρL_f/A`` less the stator's term, which the fit and the sweep keep as given.

    Every number comes from the core (``tcsim._core.mass_matrix_bound``); the methods ask it again
    for other pump and turbine shape effects (the stator's kept)."""

    density_kg_m3: float
    pump_inertia_kg_m2: float
    turbine_inertia_kg_m2: float
    inertance_kg_m4: float  # ρ L_f / A
    stator_term_kg_m4: float
    #: The core's arguments but the pump and turbine shape effects: (geometry row as an (1, 15)
    #: array, fluid length, inertias, stator shape effect).
    core_args: tuple[Any, ...] = field(default=(), repr=False, compare=False)

    def _at(self, pump_m2: float, turbine_m2: float) -> dict[str, Any]:
        geometry, fluid_length_m, inertia, stator_m2 = self.core_args
        return _core.mass_matrix_bound(geometry, fluid_length_m, inertia, [pump_m2, turbine_m2, stator_m2])

    @property
    def room(self) -> float:
        """``ρL_f/A − ρ²S_s²/I_s``, kg/m⁴ (the core's ``pump_turbine_room_kg_m4``)."""
        return float(self._at(0.0, 0.0)["pump_turbine_room_kg_m4"])

    def load(self, pump_m2: float, turbine_m2: float) -> float:
        """``ρ²S_p²/I_p + ρ²S_t²/I_t``."""
        terms = self._at(pump_m2, turbine_m2)["shape_terms_kg_m4"]
        return terms[0] + terms[1]

    def admissible(self, pump_m2: float, turbine_m2: float) -> bool:
        """The core's test: ``ρL_f/A − Σ ρ²S_x²/I_x > 0``."""
        return self._at(pump_m2, turbine_m2)["margin_kg_m4"] > 0.0

    def within(self, pump_m2: float, turbine_m2: float, fraction: float) -> bool:
        """The fit's joint condition: ``load ≤ fraction²·room`` (the box corners of the default
        bounds, ±fraction·:meth:`single`, lie on its edge)."""
        return self.load(pump_m2, turbine_m2) <= fraction**2 * self.room * (1.0 + 1e-9)

    def single(self) -> tuple[float, float]:
        """Largest admissible |S_p| with S_t = 0 and |S_t| with S_p = 0, m²."""
        bounds = self._at(0.0, 0.0)["shape_effect_bounds_m2"]
        return bounds[0], bounds[1]

    def equal(self) -> float:
        """Largest admissible |S| with S_p = S_t = S, m² (the core's ``equal_shape_effect_bound_m2``)."""
        return float(self._at(0.0, 0.0)["equal_shape_effect_bound_m2"])


def mass_matrix_bound(model: DynamicModel) -> MassMatrixBound | None:
    """The bound of a Hrovat & Tobler model from its core spec, computed by the core; None for the
    quasi-dynamic model, which has no such bound (§5)."""
    if model.name != "hrovat-tobler":
        return None
    s = model.spec
    geometry = np.ascontiguousarray(np.atleast_2d(np.asarray(s["geometry"], dtype=float)))
    inertia = [float(i) for i in s["inertia_kg_m2"]]
    args = (geometry, float(s["fluid_length_m"]), inertia, float(s["shape_effect_m2"][2]))
    try:
        b = MassMatrixBound(0.0, 0.0, 0.0, 0.0, 0.0, args)._at(*s["shape_effect_m2"][:2])
    except _core.CoreInputError as e:
        raise from_core(e, model.source) from None
    return MassMatrixBound(
        b["density_kg_m3"], inertia[0], inertia[1], b["inertance_kg_m4"], b["shape_terms_kg_m4"][2], args
    )


def inadmissible_note(bound: MassMatrixBound, pump_m2: float, turbine_m2: float) -> str:
    return (
        f"inadmissible for hrovat-tobler: ρ²S_p²/I_p + ρ²S_t²/I_t = {bound.load(pump_m2, turbine_m2):.6g} "
        f"must stay below ρL_f/A − ρ²S_s²/I_s = {bound.room:.6g} kg/m⁴ (mass matrix positive definite, "
        f"docs/physics.md §4); largest S_p = S_t is {bound.equal():.4g} m²"
    )


def sweep_values(model: DynamicModel) -> tuple[float, ...]:
    """The command's sweep: the thesis's values (quasi-dynamic), or 0, ¼, ½, ¾ of the largest
    admissible S_p = S_t (Hrovat & Tobler, whose bound lies below the thesis's values here)."""
    bound = mass_matrix_bound(model)
    if bound is None:
        return THESIS_VALUES_M2
    return tuple(float(f"{f * bound.equal():.3g}") for f in (0.0, 0.25, 0.5, 0.75))
