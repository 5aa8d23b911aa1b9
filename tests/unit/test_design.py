"""The design geometry (issue 15, docs/design.md): the Python facade over the core's
``converter::design``, against the plain circular-torus reference (tests/torus_reference.py) and by
hand; bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tcsim import _core
from tcsim.errors import InputError
from tcsim.models.converter import load_converter
from tcsim.models.design import (
    DEFAULT_POINTS,
    TorusDesign,
    design_geometry,
    design_of_geometry,
    design_table,
)
from torus_reference import torus_estimate


@pytest.fixture(scope="module")
def bundled():
    """The bundled converter's geometry: Li & Sundén Table D.1."""
    return load_converter("li-sunden-2016").geometry


def _replace(d: TorusDesign, **kw) -> TorusDesign:
    return TorusDesign(**{**d.core_dict(), **kw})


def test_circle_reproduces_the_torus_estimate_where_the_definitions_agree(bundled):
    g = design_geometry(design_of_geometry(bundled))
    b = bundled
    e = torus_estimate(
        b.pump_exit_radius_m,
        b.turbine_exit_radius_m,
        b.stator_exit_radius_m,
        b.pump_inlet_angle_deg,
        b.pump_exit_angle_deg,
        b.turbine_inlet_angle_deg,
        b.turbine_exit_angle_deg,
        b.stator_inlet_angle_deg,
        b.stator_exit_angle_deg,
        b.flow_area_m2,
        b.fluid_density_kg_m3,
        n=DEFAULT_POINTS,
    )
    pairs = [
        (g.fluid_length_m, e.fluid_length_m),
        (g.path_length_m, e.path_length_m),
        (g.pump.fluid_inertia_kg_m2, e.pump_fluid_inertia_kg_m2),
        (g.turbine.fluid_inertia_kg_m2, e.turbine_fluid_inertia_kg_m2),
        (g.stator.fluid_inertia_kg_m2, e.stator_fluid_inertia_kg_m2),
        (g.pump.arc_shape_effect_m2, e.pump_shape_effect_m2),
        (g.turbine.arc_shape_effect_m2, e.turbine_shape_effect_m2),
        (g.stator.arc_shape_effect_m2, e.stator_shape_effect_m2),
        (g.pump.shape_effect_m2, e.pump_literal_shape_effect_m2),
        (g.turbine.shape_effect_m2, e.turbine_literal_shape_effect_m2),
        (g.stator.shape_effect_m2, e.stator_literal_shape_effect_m2),
    ]
    for ours, theirs in pairs:
        assert ours == pytest.approx(theirs, rel=1e-12)
    # the bundled file's values are these, rounded
    assert g.fluid_length_m == pytest.approx(b.fluid_length_m, abs=5e-5)
    for element in ("pump", "turbine", "stator"):
        ours = getattr(g, element).shape_effect_m2
        assert ours == pytest.approx(getattr(b, f"{element}_shape_effect_m2"), abs=5e-7), element


def test_the_three_readings_of_the_bundled_circle(bundled):
    """Where the readings differ (docs/design.md): the thesis's literal reading (exit radius × |tan(exit
    angle)| × axial extent) is positive for every element; the signed integral readings are not."""
    g = design_geometry(design_of_geometry(bundled))
    tan = lambda deg: math.tan(math.radians(deg))  # noqa: E731
    stator_extent = 0.03 * math.sqrt(1.0 - (0.025 / 0.03) ** 2)
    assert g.pump.shape_effect_m2 == pytest.approx(0.12 * tan(20.0) * 0.03, rel=1e-12)
    assert g.turbine.shape_effect_m2 == pytest.approx(0.065 * tan(50.0) * 0.03, rel=1e-12)
    assert g.stator.shape_effect_m2 == pytest.approx(0.06 * tan(60.0) * stator_extent, rel=1e-12)
    assert (g.pump.shape_effect_m2, g.turbine.shape_effect_m2, g.stator.shape_effect_m2) == pytest.approx(
        (0.001310, 0.002324, 0.001723), abs=1e-6
    )
    assert g.pump.axial_integral_shape_effect_m2 == pytest.approx(-0.003568, abs=1e-6)
    assert g.turbine.axial_integral_shape_effect_m2 == pytest.approx(0.001660, abs=1e-6)
    assert g.stator.axial_integral_shape_effect_m2 == pytest.approx(0.000867, abs=1e-6)
    assert g.pump.axial_extent_m == pytest.approx(0.03, rel=1e-12)
    assert g.pump.axial_length_m == pytest.approx(0.06, rel=1e-9)


def test_squash_zero_is_the_circle_and_squash_thins_the_shape_effect(bundled):
    circle = design_of_geometry(bundled)
    cols = design_table([circle, *(design_of_geometry(bundled, "elliptic", q) for q in (0.0, 0.2, 0.35, 0.5))])
    for name in _core.design_columns():
        assert cols[name][1] == pytest.approx(cols[name][0], rel=1e-14, abs=1e-300)
    for element in ("pump", "turbine"):
        s = np.abs(cols[f"{element}_shape_effect_m2"][1:])
        assert np.all(np.diff(s) < 0.0), element
        extent = cols[f"{element}_axial_extent_m"][1:]
        assert extent == pytest.approx(0.03 * (1.0 - np.array([0.0, 0.2, 0.35, 0.5])), rel=1e-6)
    assert cols["error"] == [None] * 5


def test_hand_calculation_of_a_rectangular_torus_pins_the_signs(bundled):
    """Axial legs of width w at R_s and R_p (pump), R_p and R_t (turbine), a radial stator. The
    literal reading, by hand: S_p = R_p·w·|tan α_p,exit|, S_t = R_t·w·|tan α_t,exit|, S_s = 0:
    positive although Table D.1's exit angles (−20°, −50°) are negative (docs/design.md, "Sign
    convention"). The comparison reading with constant angles: over |dz|
    S_p = (R_s + R_p)·w·tan α_p < 0 for α_p = −30°, S_t = (R_p + R_t)·w·tan α_t > 0 for 45°."""
    rs, rt, rp, w = 0.06, 0.065, 0.12, 0.02
    d = _replace(
        design_of_geometry(bundled),
        profile="polyline",
        pump_path_m=((rs, 0.0), (rs, w), (rp, w), (rp, 0.0)),
        turbine_path_m=((rp, 0.0), (rp, -w), (rt, -w), (rt, 0.0)),
        stator_path_m=((rt, 0.0), (rs, 0.0)),
    )
    g = design_geometry(d)
    assert g.pump.shape_effect_m2 == pytest.approx(rp * w * math.tan(math.radians(20.0)), rel=1e-12)
    assert g.turbine.shape_effect_m2 == pytest.approx(rt * w * math.tan(math.radians(50.0)), rel=1e-12)
    assert g.pump.shape_effect_m2 > 0.0 and g.turbine.shape_effect_m2 > 0.0
    assert g.stator.shape_effect_m2 == 0.0
    c = design_geometry(
        _replace(
            d,
            pump_inlet_angle_deg=-30.0,
            pump_exit_angle_deg=-30.0,
            turbine_inlet_angle_deg=45.0,
            turbine_exit_angle_deg=45.0,
        )
    )
    assert c.pump.axial_integral_shape_effect_m2 == pytest.approx(
        (rs + rp) * w * math.tan(math.radians(-30.0)), rel=1e-12
    )
    assert c.turbine.axial_integral_shape_effect_m2 == pytest.approx((rp + rt) * w, rel=1e-12)
    assert c.stator.axial_integral_shape_effect_m2 == 0.0
    assert g.fluid_mass_kg == pytest.approx(840.0 * 0.01 * (4 * w + 2 * (rp - rs)), rel=1e-12)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"stator_exit_radius_m": 0.12}, "stator_exit_radius_m"),
        ({"turbine_exit_radius_m": 0.13}, "turbine_exit_radius_m"),
        ({"pump_exit_angle_deg": float("nan")}, "pump_exit_angle_deg"),
        ({"fluid_density_kg_m3": float("inf")}, "fluid_density_kg_m3"),
        ({"profile": "elliptic", "squash_ratio": 1.5}, "squash_ratio"),
        ({"profile": "elliptic"}, "squash_ratio"),
        ({"profile": "oval"}, "profile"),
        ({"profile": "polyline"}, "pump_path_m"),
    ],
)
def test_bad_input_is_one_line_naming_the_file_and_field(bundled, change, field):
    with pytest.raises(InputError) as info:
        design_geometry(_replace(design_of_geometry(bundled), **change), source="concept.toml")
    e = info.value
    assert (e.source, e.field) == ("concept.toml", field)
    assert str(e).startswith(f"concept.toml: {field} = ") and "\n" not in str(e)


def test_a_polyline_not_closed_is_refused(bundled):
    d = _replace(
        design_of_geometry(bundled),
        profile="polyline",
        pump_path_m=((0.06, 0.0), (0.12, 0.03)),
        turbine_path_m=((0.12, 0.03), (0.065, 0.0)),
        stator_path_m=((0.065, 0.0), (0.06, 0.001)),
    )
    with pytest.raises(InputError, match=r"^design: pump_path_m\[0\] = \(0\.06, 0\): expected the last point of "):
        design_geometry(d)


def test_batches_name_the_design_or_keep_going(bundled):
    good = design_of_geometry(bundled)
    bad = _replace(good, flow_area_m2=-0.01)
    with pytest.raises(InputError) as info:
        design_table([good, bad, good], source="study.toml")
    assert info.value.field == "flow_area_m2 (design 1)"
    cols = design_table([good, bad, good], strict=False)
    assert np.isnan(cols["pump_shape_effect_m2"][1]) and np.isfinite(cols["pump_shape_effect_m2"][[0, 2]]).all()
    assert cols["error"][0] is None and cols["error"][1].startswith("flow_area_m2 = -0.01: expected")
    with pytest.raises(InputError) as info:
        design_table([good], points=3)
    assert info.value.field == "points"
