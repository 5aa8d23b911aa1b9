"""Measured design ranges of automotive torque converters (Li & Sundén 2016, §4.1.1), their one owner.

These are not the plausibility ranges of :mod:`tcsim.models.plausibility` (which catch unit mistakes
and typos, and refuse or warn on any input): they say what the blades and radii of a real automotive
converter measure, so that a *fitted* parameter outside them is flagged as a fitting artefact
(thesis §4.3.2: the match needed angles outside their measured ranges). ``tcsim fit`` warns, one
line per parameter, when a free parameter ends outside its range (``docs/fitting.md``).

§4.1.1 states: "Automotive torque converters are commonly about 230-300 millimetres in diameter ...
Impeller exit angles are commonly around 20° and rarely exceed 45°, while turbine exit angles are
usually around 60°." The thesis's own model convention gives these exit angles negative signs
(Table D.1: impeller −20°, turbine −50°), so the angle ranges bound the magnitude. §4.1.1 gives the
outside diameter only; the turbine and stator exit radii take Table D.1's reference (a 240 mm
converter) scaled to 230–300 mm, widened by the ±25 % of its parameter study.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Li & Sundén (2016) §4.1.1: outside diameters of automotive converters, m.
DIAMETER_RANGE_M = (0.230, 0.300)
#: Table D.1 reference: pump exit radius (the outside radius, 240 mm converter), turbine and stator exit radii, m.
REFERENCE_RADII_M = {"pump_exit_radius_m": 0.12, "turbine_exit_radius_m": 0.065, "stator_exit_radius_m": 0.06}
#: Table D.1: the parameter study varied each radius by ±25 % about its reference.
STUDY_SPAN = 0.25

_SOURCE = "Li & Sundén 2016 §4.1.1"


@dataclass(frozen=True)
class DesignRange:
    """The measured range of one ``[geometry]`` parameter, closed; of ``|value|`` if ``magnitude``."""

    parameter: str
    low: float
    high: float
    unit: str
    magnitude: bool
    source: str

    def contains(self, value: float) -> bool:
        """Whether ``value`` (in ``unit``) lies in the range."""
        v = abs(value) if self.magnitude else value
        return self.low <= v <= self.high

    def describe(self) -> str:
        """``|pump_exit_angle_deg| 0 to 45° (impeller exit angles …; Li & Sundén 2016 §4.1.1)``."""
        name = f"|{self.parameter}|" if self.magnitude else self.parameter
        unit = self.unit if self.unit == "°" else f" {self.unit}"
        return f"{name} {self.low:.4g} to {self.high:.4g}{unit} ({self.source})"


def _inner_radius(name: str, what: str) -> DesignRange:
    ref, outer = REFERENCE_RADII_M[name], 2.0 * REFERENCE_RADII_M["pump_exit_radius_m"]
    lo = ref * DIAMETER_RANGE_M[0] / outer * (1.0 - STUDY_SPAN)
    hi = ref * DIAMETER_RANGE_M[1] / outer * (1.0 + STUDY_SPAN)
    why = f"{what}: Table D.1's {ref:g} m scaled to a 230–300 mm converter, ±25 % as its parameter study; {_SOURCE}"
    return DesignRange(name, round(lo, 4), round(hi, 4), "m", False, why)


#: Every measured range, by parameter.
DESIGN_RANGES: dict[str, DesignRange] = {
    r.parameter: r
    for r in (
        DesignRange("pump_exit_angle_deg", 0.0, 45.0, "°", True, f"impeller exit angles rarely exceed 45°; {_SOURCE}"),
        DesignRange(
            "turbine_exit_angle_deg",
            45.0,
            75.0,
            "°",
            True,
            f"turbine exit angles are usually around 60°, read as 60° ± 15°; {_SOURCE}",
        ),
        DesignRange(
            "pump_exit_radius_m",
            DIAMETER_RANGE_M[0] / 2.0,
            DIAMETER_RANGE_M[1] / 2.0,
            "m",
            False,
            f"automotive converters are about 230–300 mm in diameter; {_SOURCE}",
        ),
        _inner_radius("turbine_exit_radius_m", "turbine exit radius"),
        _inner_radius("stator_exit_radius_m", "stator exit radius"),
    )
}
