"""A converter design's torus and blades, and what the Hrovat & Tobler model needs from them
(issue 15; ``docs/design.md``). A thin facade: every formula and check is the core's
(``tcsim_core::converter::design``).

The mean meridional streamline runs through the pump from the pump inlet (the stator exit radius
``R_s``, the innermost point) out to the pump exit (``R_p``, the outermost), through the turbine
in to the turbine exit ``R_t`` and through the stator back to ``R_s`` (Li & Sundén 2016,
Appendix B). Per element the core gives the shape effect as the thesis's text defines it (§4.1.1,
eqs 4.1–4.2, fig. 4.7): ``S = R_exit · |tan α_exit| · L``, the exit radius and exit blade angle
times the length of the axial projection ``L`` of the element's path (its axial extent), a magnitude
as chapter 4 uses it (docs/design.md, "Sign convention"); for comparison, signed as the angles, the
variable-integrand axial reading ``∫ R tan α |dz|`` and the arc reading ``∫ R tan α dl``; the fluid
mass ``ρAl`` and inertia ``ρA∫R²dl``, and the equivalent fluid length ``L_f = Σ∫(1 + tan²α) dl``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any

from .. import _core
from ..errors import from_core
from .converter import GeometrySection

#: The profiles: ``circular``, ``elliptic`` (with ``squash_ratio``), ``polyline`` (with the paths).
PROFILES: tuple[str, ...] = tuple(_core.design_profiles())
#: Integration nodes per element: the default, the fewest and the most; polyline tolerance, m.
DEFAULT_POINTS, MIN_POINTS, MAX_POINTS, POLYLINE_TOLERANCE_M = _core.design_integration()

#: A meridional path: ``(r, z)`` points in m, in the flow direction.
MeridionalPath = tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class TorusDesign:
    """A converter design: torus, blades and fluid. Radii as Li & Sundén Appendix D names them;
    angles in degrees, signed as its Table D.1 (pump exit −20°, turbine exit −50°).

    Attributes
    ----------
    pump_exit_radius_m, turbine_exit_radius_m, stator_exit_radius_m : float
        ``R_p`` (the torus's outer radius), ``R_t``, ``R_s`` (its inner radius, the pump inlet), m;
        ``R_s < R_t < R_p``.
    pump_inlet_angle_deg, ..., stator_exit_angle_deg : float
        Blade angles, degrees, strictly between −90 and 90; along each element the angle varies
        linearly with the path length from inlet to exit.
    flow_area_m2 : float
        Flow area A perpendicular to the through-flow, constant around the path (thesis
        assumption 2), m².
    fluid_density_kg_m3 : float
        Fluid density ρ, kg/m³.
    profile : str
        ``circular``, ``elliptic`` or ``polyline``.
    squash_ratio : float or None
        Elliptic only: ``1 − axial width / radial height`` of the torus, in [0, 1); 0 is the circle
        (thesis §4.3.2: 20 % squash is a width of 80 % of the height).
    pump_path_m, turbine_path_m, stator_path_m : tuple of (r, z) or None
        Polyline only: each element's meridional path, m, in the flow direction; consecutive
        elements share end points (closed to 1 µm), the pump runs from ``R_s`` to ``R_p`` with r
        never falling, the turbine to ``R_t`` with r never rising, no point outside ``[R_s, R_p]``.
    """

    pump_exit_radius_m: float
    turbine_exit_radius_m: float
    stator_exit_radius_m: float
    pump_inlet_angle_deg: float
    pump_exit_angle_deg: float
    turbine_inlet_angle_deg: float
    turbine_exit_angle_deg: float
    stator_inlet_angle_deg: float
    stator_exit_angle_deg: float
    flow_area_m2: float
    fluid_density_kg_m3: float
    profile: str = "circular"
    squash_ratio: float | None = None
    pump_path_m: MeridionalPath | None = None
    turbine_path_m: MeridionalPath | None = None
    stator_path_m: MeridionalPath | None = None

    def core_dict(self) -> dict[str, Any]:
        """The design as the core reads it (``tcsim._core.design_geometries``)."""
        d = asdict(self)
        for key in ("pump_path_m", "turbine_path_m", "stator_path_m"):
            if d[key] is not None:
                d[key] = [[float(r), float(z)] for r, z in d[key]]
        return d


@dataclass(frozen=True)
class ElementGeometry:
    """What a design gives for one element (pump, turbine or stator).

    Attributes
    ----------
    shape_effect_m2 : float
        ``S = R_exit · |tan α_exit| · L_axial``: the element's exit radius and exit blade angle
        times the length of the axial projection of its path, its axial extent (eqs 4.1–4.2 and
        2.16–2.18 as §4.1.1 reads them, fig. 4.7), m², ≥ 0 (docs/design.md, "Sign convention").
    axial_integral_shape_effect_m2 : float
        ``∫ R tan α |dz|`` with R and α varying along the path (comparison only), m², signed.
    arc_shape_effect_m2 : float
        ``∫ R tan α dl`` along the path (comparison only: the bundled values before issue 15), m²,
        signed.
    path_length_m, axial_length_m, axial_extent_m : float
        Path length ``l``, length of its axial projection ``∫|dz|``, axial extent, m.
    fluid_length_m : float
        ``∫ (1 + tan² α) dl``, the element's part of ``L_f``, m.
    fluid_mass_kg, fluid_inertia_kg_m2 : float
        ``ρ A l``, kg, and ``ρ A ∫ R² dl``, kg·m² (to add to the metal inertias).
    """

    shape_effect_m2: float
    axial_integral_shape_effect_m2: float
    arc_shape_effect_m2: float
    path_length_m: float
    axial_length_m: float
    axial_extent_m: float
    fluid_length_m: float
    fluid_mass_kg: float
    fluid_inertia_kg_m2: float


@dataclass(frozen=True)
class DesignGeometry:
    """What a design gives: per element, the equivalent fluid length ``L_f`` (m), the length of the
    mean streamline (m) and the fluid mass of the torus (kg)."""

    pump: ElementGeometry
    turbine: ElementGeometry
    stator: ElementGeometry
    fluid_length_m: float
    path_length_m: float
    fluid_mass_kg: float


def design_table(
    designs: Sequence[TorusDesign], points: int = DEFAULT_POINTS, strict: bool = True, source: str = "design"
) -> dict[str, Any]:
    """The geometry of many designs at once, computed by the core on two threads.

    Parameters
    ----------
    designs : sequence of TorusDesign
    points : int
        Integration nodes per element (``MIN_POINTS`` to ``MAX_POINTS``).
    strict : bool
        Raise on the first bad design; otherwise its row is NaN and ``error`` says why.
    source : str
        The file the designs came from, named in an :class:`~tcsim.errors.InputError`.

    Returns
    -------
    dict
        float64 arrays named ``pump_shape_effect_m2``, …, ``fluid_mass_kg``
        (``tcsim._core.design_columns()``), one value per design, and ``error``: a list, per
        design None or the message of its bad input.

    Raises
    ------
    tcsim.errors.InputError
        With ``strict``, for the first bad design: ``<source>: <field> = <value>: expected <what>``
        (the field with `` (design i)`` when there are several).
    """
    try:
        return _core.design_geometries([d.core_dict() for d in designs], points, strict)
    except _core.CoreInputError as e:
        raise from_core(e, source) from None


def geometry_of_row(cols: dict[str, Any], i: int) -> DesignGeometry:
    """Design ``i``'s geometry from the columns of :func:`design_table` (NaN for a failed design)."""
    names = [f.name for f in fields(ElementGeometry)]

    def element(name: str) -> ElementGeometry:
        return ElementGeometry(*(float(cols[f"{name}_{q}"][i]) for q in names))

    return DesignGeometry(
        element("pump"),
        element("turbine"),
        element("stator"),
        float(cols["fluid_length_m"][i]),
        float(cols["path_length_m"][i]),
        float(cols["fluid_mass_kg"][i]),
    )


def design_geometry(design: TorusDesign, points: int = DEFAULT_POINTS, source: str = "design") -> DesignGeometry:
    """The geometry of one design (:func:`design_table` of one); raises
    :class:`~tcsim.errors.InputError` naming ``source`` on bad input."""
    return geometry_of_row(design_table([design], points, True, source), 0)


def design_of_geometry(
    geometry: GeometrySection, profile: str = "circular", squash_ratio: float | None = None
) -> TorusDesign:
    """The design with a converter's ``[geometry]`` radii, blade angles, flow area and density, and
    a profile (e.g. the bundled ``li-sunden-2016``'s: Li & Sundén Table D.1)."""
    keys = [f.name for f in fields(TorusDesign) if f.name.endswith(("_radius_m", "_angle_deg"))]
    values: dict[str, Any] = {k: float(getattr(geometry, k)) for k in [*keys, "flow_area_m2", "fluid_density_kg_m3"]}
    return TorusDesign(**values, profile=profile, squash_ratio=squash_ratio)


__all__ = [
    "DEFAULT_POINTS",
    "PROFILES",
    "DesignGeometry",
    "ElementGeometry",
    "TorusDesign",
    "design_geometry",
    "design_table",
    "design_of_geometry",
    "geometry_of_row",
]
