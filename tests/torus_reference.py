"""A plain reference implementation of the circular torus, for tests only (the package's owner of
these formulas is the core's design model, ``tcsim_core::converter::design``; docs/design.md).

It was tcsim's estimate of the fluid parameters Table D.1 does not give (``tcsim.models.torus``,
until issue 15 moved the geometry into the core); written independently of the core, it checks the
core's circle. The geometry is the simplest that honours the stated radii: the mean meridional
streamline is a circle whose innermost point is the stator exit / pump inlet radius ``R_s`` and
whose outermost point is the pump exit radius ``R_p``. The pump runs from ``R_s`` outwards to
``R_p``, the turbine inwards from ``R_p`` to ``R_t``, the stator from ``R_t`` to ``R_s``. Along each
element the blade angle varies linearly from the inlet angle to the exit angle.

* Shape effect, the arc reading of eqs 2.16–2.18: ``S_x = ∫ R tan α dl`` over the element (signed
  as the angles); and the thesis's literal reading (§4.1.1, eqs 4.1–4.2) that tcsim uses,
  ``R_x,exit·|tan α_x,exit|·L_x`` with ``L_x`` the axial extent of the element's arc.
* Fluid inertia of an element: ``I_x = ρ A ∫ R² dl``.
* Equivalent fluid length: ``L_f = Σ ∫ (1 + tan² α) dl``, the path length weighted by the square
  of the relative velocity along the blades (``|V_re|² = q²(1 + tan²α)``), so that
  ``½ (ρ L_f / A) Q²`` is the kinetic energy of the through-flow relative to the blades.

With these definitions the Cauchy–Schwarz inequality gives ``ρ² S_x² / I_x ≤ (ρ/A) ∫_x tan²α dl``
for each element, so the mass matrix of eqs 2.12–2.15 is positive definite whenever each element's
inertia includes the fluid it carries (docs/physics.md §4). The literal reading has no such bound
(docs/design.md, "Mass-matrix bound").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TorusEstimate:
    fluid_length_m: float
    pump_shape_effect_m2: float
    turbine_shape_effect_m2: float
    stator_shape_effect_m2: float
    pump_literal_shape_effect_m2: float
    turbine_literal_shape_effect_m2: float
    stator_literal_shape_effect_m2: float
    pump_fluid_inertia_kg_m2: float
    turbine_fluid_inertia_kg_m2: float
    stator_fluid_inertia_kg_m2: float
    path_length_m: float


def _integrate(f: np.ndarray, dl: float) -> float:
    """Trapezoidal integral of samples ``f`` spaced ``dl`` apart."""
    return float(np.sum(0.5 * (f[1:] + f[:-1])) * dl)


def torus_estimate(
    pump_exit_radius_m: float,
    turbine_exit_radius_m: float,
    stator_exit_radius_m: float,
    pump_inlet_angle_deg: float,
    pump_exit_angle_deg: float,
    turbine_inlet_angle_deg: float,
    turbine_exit_angle_deg: float,
    stator_inlet_angle_deg: float,
    stator_exit_angle_deg: float,
    flow_area_m2: float,
    fluid_density_kg_m3: float,
    n: int = 2001,
) -> TorusEstimate:
    rp, rt, rs = pump_exit_radius_m, turbine_exit_radius_m, stator_exit_radius_m  # exit radii: pump, turbine, stator
    if not rs < rt < rp:
        raise ValueError("the torus estimate needs stator exit radius < turbine exit radius < pump exit radius")
    rc, a = 0.5 * (rp + rs), 0.5 * (rp - rs)
    theta_t = 2.0 * math.pi - math.acos((rc - rt) / a)
    spans = {
        "pump": (0.0, math.pi, pump_inlet_angle_deg, pump_exit_angle_deg),
        "turbine": (math.pi, theta_t, turbine_inlet_angle_deg, turbine_exit_angle_deg),
        "stator": (theta_t, 2.0 * math.pi, stator_inlet_angle_deg, stator_exit_angle_deg),
    }
    exits = {"pump": rp, "turbine": rt, "stator": rs}
    shape, literal, inertia, length, path = {}, {}, {}, 0.0, 0.0
    for name, (t0, t1, a_in, a_out) in spans.items():
        # z = a·sin θ: the axial extent of the arc θ0..θ1 (its extrema at θ = π/2, 3π/2 if inside)
        z = [a * math.sin(t) for t in (t0, t1, *(x for x in (0.5 * math.pi, 1.5 * math.pi) if t0 < x < t1))]
        literal[name] = exits[name] * abs(math.tan(math.radians(a_out))) * (max(z) - min(z))
        th = np.linspace(t0, t1, n)
        r = rc - a * np.cos(th)
        tan = np.tan(np.radians(np.linspace(a_in, a_out, n)))
        dl = a * (t1 - t0) / (n - 1)
        shape[name] = _integrate(r * tan, dl)
        inertia[name] = fluid_density_kg_m3 * flow_area_m2 * _integrate(r * r, dl)
        length += _integrate(1.0 + tan * tan, dl)
        path += a * (t1 - t0)
    return TorusEstimate(
        length,
        shape["pump"],
        shape["turbine"],
        shape["stator"],
        literal["pump"],
        literal["turbine"],
        literal["stator"],
        inertia["pump"],
        inertia["turbine"],
        inertia["stator"],
        path,
    )
