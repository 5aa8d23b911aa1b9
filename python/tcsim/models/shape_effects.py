"""Shape effects of the dynamic models: the mass-matrix bound of the Hrovat & Tobler model (physics
notes §4) and the shape-effect values the sweeps use (Li & Sundén 2016 §4.1)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .dynamic import DynamicModel

#: The shape effects of thesis figures 4.1–4.4 (S_p = S_t = v) and its largest pair (figure 4.1).
THESIS_VALUES_M2 = (0.0, 0.05, 0.1, 0.2)
THESIS_PAIR_M2 = (0.4, 0.3)


# ---------------------------------------------------------------------------------------------
# the mass-matrix bound of the Hrovat & Tobler model (physics notes §4)


@dataclass(frozen=True)
class MassMatrixBound:
    """``M`` is positive definite iff ``ρL_f/A > Σ ρ²S_x²/I_x`` (Schur complement of the inertias).
    ``room`` is ``ρL_f/A`` less the stator's term, which the fit and the sweep keep as given."""

    density_kg_m3: float
    pump_inertia_kg_m2: float
    turbine_inertia_kg_m2: float
    inertance_kg_m4: float  # ρ L_f / A
    stator_term_kg_m4: float

    @property
    def room(self) -> float:
        return self.inertance_kg_m4 - self.stator_term_kg_m4

    def load(self, pump_m2: float, turbine_m2: float) -> float:
        """``ρ²S_p²/I_p + ρ²S_t²/I_t``."""
        rho2 = self.density_kg_m3**2
        return rho2 * (pump_m2**2 / self.pump_inertia_kg_m2 + turbine_m2**2 / self.turbine_inertia_kg_m2)

    def admissible(self, pump_m2: float, turbine_m2: float) -> bool:
        """The core's test: ``ρ²S_p²/I_p + ρ²S_t²/I_t < room``."""
        return self.load(pump_m2, turbine_m2) < self.room

    def within(self, pump_m2: float, turbine_m2: float, fraction: float) -> bool:
        """The fit's joint condition: ``load ≤ fraction²·room`` (the box corners of the default
        bounds, ±fraction·:meth:`single`, lie on its edge)."""
        return self.load(pump_m2, turbine_m2) <= fraction**2 * self.room * (1.0 + 1e-9)

    def single(self) -> tuple[float, float]:
        """Largest admissible |S_p| with S_t = 0 and |S_t| with S_p = 0, m²."""
        room = max(self.room, 0.0)
        return (
            math.sqrt(room * self.pump_inertia_kg_m2) / self.density_kg_m3,
            math.sqrt(room * self.turbine_inertia_kg_m2) / self.density_kg_m3,
        )

    def equal(self) -> float:
        """Largest admissible |S| with S_p = S_t = S, m²."""
        return math.sqrt(max(self.room, 0.0) / self.load(1.0, 1.0))


def mass_matrix_bound(model: DynamicModel) -> MassMatrixBound | None:
    """The bound of a Hrovat & Tobler model from its core spec (geometry row: flow area at index
    0, density at 1); None for the quasi-dynamic model, which has no such bound (§5)."""
    if model.name != "hrovat-tobler":
        return None
    s = model.spec
    area, rho = s["geometry"][0], s["geometry"][1]
    ip, it, i_s = s["inertia_kg_m2"]
    stator = s["shape_effect_m2"][2]
    return MassMatrixBound(rho, ip, it, rho * s["fluid_length_m"] / area, rho**2 * stator**2 / i_s)


def inadmissible_note(bound: MassMatrixBound, pump_m2: float, turbine_m2: float) -> str:
    return (
        f"inadmissible for hrovat-tobler: ρ²S_p²/I_p + ρ²S_t²/I_t = {bound.load(pump_m2, turbine_m2):.6g} "
        f"must stay below ρL_f/A − ρ²S_s²/I_s = {bound.room:.6g} kg/m⁴ (mass matrix positive definite, "
        f"physics notes §4); largest S_p = S_t is {bound.equal():.4g} m²"
    )


def sweep_values(model: DynamicModel) -> tuple[float, ...]:
    """The command's sweep: the thesis's values (quasi-dynamic), or 0, ¼, ½, ¾ of the largest
    admissible S_p = S_t (Hrovat & Tobler, whose bound lies below the thesis's values here)."""
    bound = mass_matrix_bound(model)
    if bound is None:
        return THESIS_VALUES_M2
    return tuple(float(f"{f * bound.equal():.3g}") for f in (0.0, 0.25, 0.5, 0.75))
