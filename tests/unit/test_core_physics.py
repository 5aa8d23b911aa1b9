"""Physics owned by the core (issue 9, "no physics in Python"): each fact the Python layer used to
compute itself now comes from ``tcsim._core``, bit for bit what the Python copy gave. The copies
live on here only as reference formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tcsim import _core, units
from tcsim.analysis.study import _columns
from tcsim.models.converter import load_converter
from tcsim.models.dynamic import FLOW_TIME_CONSTANT_PUMP_SPEED_RAD_S, default_flow_time_constant_s, dynamic_model
from tcsim.models.shape_effects import mass_matrix_bound, sweep_values
from tcsim.models.steady import STATOR_MODES, characterise_hrovat_tobler, hrovat_tobler_steady_state

CONVERTERS = ("li-sunden-2016", "li-sunden-2016-fitted")


def reference_flow_time_constant_s(conv) -> float:
    """The Python copy of τ_Q the core replaced: ``L_f / |∂(eq 2.15 rhs / ρ)/∂q|`` at stall, 2000 rpm."""
    g = conv.geometry
    wp = 2000.0 * (math.pi / 30.0)
    flow = float(_core.ht_steady_states(conv.core_geometry(), np.array([wp]), np.array([0.0]))["flow_m3_s"][0])
    rad = math.pi / 180.0
    tp, tt, ts = (math.tan(getattr(g, f"{e}_exit_angle_deg") * rad) for e in ("pump", "turbine", "stator"))
    tpp, ttt, tss = (math.tan(getattr(g, f"{e}_inlet_angle_deg") * rad) for e in ("pump", "turbine", "stator"))
    rp, rs = g.pump_exit_radius_m, g.stator_exit_radius_m
    q = flow / g.flow_area_m2
    slope = wp * (rp * tp - rs * ts) - (
        g.pump_shock_loss * (-rs * wp + q * (ts - tpp)) * (ts - tpp)
        + g.turbine_shock_loss * (rp * wp + q * (tp - ttt)) * (tp - ttt)
        + g.stator_shock_loss * q * (tt - tss) ** 2
        + g.friction_loss * (3 + tp * tp + tt * tt + ts * ts) * q
    )
    return g.fluid_length_m / abs(slope)


@pytest.mark.parametrize("name", CONVERTERS)
def test_default_flow_time_constant_is_the_reference_formula(name):
    conv = load_converter(name)
    assert default_flow_time_constant_s(conv) == reference_flow_time_constant_s(conv)


def test_quasi_dynamic_model_takes_the_core_default():
    conv = load_converter("li-sunden-2016")
    assert conv.quasi_dynamic is not None and conv.quasi_dynamic.flow_time_constant_s is None
    spec = dynamic_model(conv, "quasi-dynamic").spec
    assert spec["flow_time_constant_s"] == reference_flow_time_constant_s(conv)


def test_reference_pump_speed_is_the_core_one():
    assert units.DEFAULT_PUMP_SPEED_RPM == 2000.0 == _core.reference_pump_speed_rpm()
    assert units.DEFAULT_PUMP_SPEED_RAD_S == 2000.0 * (math.pi / 30.0) == _core.reference_pump_speed_rad_s()
    assert FLOW_TIME_CONSTANT_PUMP_SPEED_RAD_S == units.DEFAULT_PUMP_SPEED_RAD_S


@pytest.mark.parametrize("name", CONVERTERS)
def test_mass_matrix_bound_is_the_reference_formula(name):
    model = dynamic_model(name, "hrovat-tobler")
    s = model.spec
    area, rho = s["geometry"][0], s["geometry"][1]
    ip, it, i_s = s["inertia_kg_m2"]
    inertance = rho * s["fluid_length_m"] / area
    stator = rho**2 * s["shape_effect_m2"][2] ** 2 / i_s
    room = inertance - stator
    b = mass_matrix_bound(model)
    assert (b.density_kg_m3, b.pump_inertia_kg_m2, b.turbine_inertia_kg_m2) == (rho, ip, it)
    assert (b.inertance_kg_m4, b.stator_term_kg_m4, b.room) == (inertance, stator, room)
    assert b.single() == (math.sqrt(room * ip) / rho, math.sqrt(room * it) / rho)
    assert b.equal() == math.sqrt(room / (rho**2 * (1 / ip + 1 / it)))
    assert b.load(0.03, 0.02) == pytest.approx(rho**2 * (0.03**2 / ip + 0.02**2 / it), rel=1e-15)
    e = b.equal()
    assert b.admissible(e * (1 - 1e-9), e * (1 - 1e-9)) and not b.admissible(e * (1 + 1e-9), e * (1 + 1e-9))
    assert b.within(*b.single()[:1], 0.0, 1.0) and not b.within(e, e, 0.98)
    assert mass_matrix_bound(dynamic_model(name, "quasi-dynamic")) is None


def test_sweep_values_do_not_move():
    # recorded before the bound moved to the core (0.00895, 0.0179 before issue 15 changed the
    # bundled S_t, S_s that the pump's bound leaves room for)
    assert sweep_values(dynamic_model("li-sunden-2016", "hrovat-tobler")) == (0.0, 0.00892, 0.0178, 0.0268)


def test_stator_modes_are_the_core_ones():
    assert STATOR_MODES == {0: "locked", 1: "free-wheeling", 2: "no-flow", -1: "no-steady-state"}
    assert STATOR_MODES == _core.steady_mode_names()


def reference_torque_ratio(out) -> np.ndarray:
    """The Python copy of the no-flow rule the core replaced (``steady.py``, ``study.py``)."""
    mode, tp, tt = out["stator_mode"], out["pump_torque_nm"], out["turbine_torque_nm"]
    tr = np.where(mode == 2, 1.0, tt / np.where(tp == 0, 1.0, tp))
    return np.where(mode < 0, np.nan, tr)


def test_steady_torque_ratio_is_the_reference_rule():
    conv = load_converter("li-sunden-2016")
    g = conv.core_geometry().copy()
    g[0, 1] *= 1.88  # a dense fluid: locked, free-wheeling, no-flow (and reverse flow past SR ≈ 1.03)
    wp = 200.0
    sr = np.linspace(0.0, 1.3, 131)
    sr[-1] = np.nan  # only a non-finite speed has no steady state
    out = hrovat_tobler_steady_state(g, np.full(sr.shape, wp), sr * wp, strict=False)
    assert set(out["stator_mode"].tolist()) == {-1, 0, 1, 2}
    np.testing.assert_array_equal(_columns(out, wp)["torque_ratio"], reference_torque_ratio(out))
    df = characterise_hrovat_tobler(conv)
    strict = hrovat_tobler_steady_state(conv.core_geometry(), df["pump_speed_rad_s"], df["turbine_speed_rad_s"])
    np.testing.assert_array_equal(df["torque_ratio"], reference_torque_ratio(strict))


def test_unit_constants_are_the_core_ones_and_the_plain_values():
    # one owner (tcsim_core::units); bit for bit what the Python side computed before
    assert units.RAD_S_PER_RPM == _core.unit_constants()["rad_s_per_rpm"] == math.pi / 30.0
    assert units.KM_H == _core.unit_constants()["m_s_per_km_h"] == 1.0 / 3.6
    assert units.LBF_FT_IN_NM == _core.unit_constants()["nm_per_lbf_ft"] == 1.3558179483314004
    assert 2000.0 * units.RAD_S_PER_RPM == pytest.approx(units.DEFAULT_PUMP_SPEED_RAD_S, rel=1e-15)


#: The most points the core's steady-state and backward batches compute between two looks at the
#: cancel flag (``CANCEL_CHECK_POINTS``, ``POINTS_PER_CHUNK``): a batch of no more runs on the
#: calling thread, one of more on the cancellable helper thread.
STEADY_PIECE, BACKWARD_PIECE = 4096, 16_384


def _bits(d: dict) -> dict:
    return {k: np.asarray(v).view(np.uint8).tobytes() for k, v in d.items()}


def test_a_batch_of_one_piece_is_the_longer_batchs_points_bit_for_bit_and_fails_alike():
    # a batch that the core computes without looking at the cancel flag runs on the calling thread,
    # without the cancellable helper thread; it must give the points and the errors of the same
    # points in a batch one point longer, which takes the helper thread
    rng = np.random.default_rng(16)
    g = load_converter("li-sunden-2016").core_geometry()
    wp, wt = rng.uniform(-300.0, 400.0, (2, BACKWARD_PIECE + 1))
    torque = rng.uniform(-200.0, 300.0, BACKWARD_PIECE + 1)
    for threads in (0, 1, 2):
        for m in (STEADY_PIECE, BACKWARD_PIECE):
            one, two = (_core.ht_steady_states(g, wp[:n], wt[:n], False, threads) for n in (m, m + 1))
            assert _bits(one) == _bits({k: v[:m] for k, v in two.items()}), (threads, m)
        m = BACKWARD_PIECE
        one, two = (_core.ht_operating_points(g, wt[:n], torque[:n], threads=threads) for n in (m, m + 1))
        assert _bits(one) == _bits({k: v[:m] for k, v in two.items()}), threads
    bad = wt.copy()
    bad[7] = np.nan
    steady = []
    for n in (1 + 7, STEADY_PIECE, STEADY_PIECE + 1):
        with pytest.raises(Exception) as e:
            _core.ht_steady_states(g, wp[:n], bad[:n], True, 0)
        steady.append((type(e.value), str(e.value)))
    assert steady[0] == steady[1] == steady[2] and "point 7" in steady[0][1]
    backward = []
    for n in (8, BACKWARD_PIECE, BACKWARD_PIECE + 1):
        with pytest.raises(Exception) as e:
            _core.ht_operating_points(g, wt[:n], torque[: n - 1])
        backward.append((type(e.value), str(e.value).replace(str(n), "N").replace(str(n - 1), "N-1")))
    assert backward[0] == backward[1] == backward[2] and "turbine_torque_nm" in backward[0][1]
