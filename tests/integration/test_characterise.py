"""Steady-state characterisation through the Python API and the command line."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import tcsim
from conftest import C1_CF, C1_SR, C1_TR, CONVERTER_DATA
from tcsim import _core
from tcsim.errors import TcsimWarning
from tcsim.models.converter import load_converter
from tcsim.models.steady import characterise, coupling_point
from torus_reference import torus_estimate

WP = 2000 * math.pi / 30


@pytest.fixture(scope="module")
def ls():
    return load_converter("li-sunden-2016")


def test_table_model_reproduces_table_c1_exactly(ls):
    df = characterise(ls, "table", speed_ratio=np.array(C1_SR))
    assert df["torque_ratio"].tolist() == C1_TR
    np.testing.assert_allclose(df["capacity_factor_nm_s2"], C1_CF, rtol=1e-15)
    np.testing.assert_allclose(df["pump_torque_nm"], np.array(C1_CF) * WP**2, rtol=1e-14)
    np.testing.assert_allclose(df["turbine_torque_nm"], np.array(C1_TR) * np.array(C1_CF) * WP**2, rtol=1e-14)
    assert not df["extrapolated"].any()


def test_quasi_dynamic_steady_state_is_the_table(ls):
    a = characterise(ls, "table")
    b = characterise(ls, "quasi-dynamic")
    pd.testing.assert_frame_equal(a, b)


def test_table_model_holds_its_first_row_below_and_mirrors_beyond_the_table(ls):
    # issue 11: SR 1.2 used to hold CF(1) > 0, driving a turbine already faster than the pump
    with pytest.warns(
        TcsimWarning, match='overrun = "mirror": the table ends at SR 1; the characteristic reached SR 1.2'
    ):
        df = characterise(ls, "table", speed_ratio=np.array([-0.2, 1.2]))
    assert df["extrapolated"].all()
    assert df["torque_ratio"].tolist() == [2.14, 1.0]
    # mirror: T_p = −CF(x)·ω_t² with x = 1/1.2 interpolated between the rows at 0.8 and 0.85
    x = 1.0 / 1.2
    cf_x = 2.481e-3 + (x - 0.8) / 0.05 * (2.370e-3 - 2.481e-3)
    np.testing.assert_allclose(df["capacity_factor_nm_s2"], [3.272e-3, -cf_x * 1.2**2], rtol=1e-12)


def test_overrun_rows_of_jambe_trami_table_reverse_the_torque():
    conv = load_converter(CONVERTER_DATA / "jambe_trami_9at.csv")
    df = characterise(conv, "table")
    assert df["speed_ratio"].min() == pytest.approx(-0.1) and df["speed_ratio"].max() == pytest.approx(2.1)
    over = df[df["speed_ratio"] > 1.0]
    assert (over["pump_torque_nm"] < 0).all() and (over["turbine_torque_nm"] < 0).all()
    at_one = df[np.isclose(df["speed_ratio"], 1.0)]
    assert at_one["pump_torque_nm"].abs().max() < 1e-12
    # 38e-6 N·m/rpm² at 2000 rpm is 152 N·m at stall
    assert df.loc[np.isclose(df["speed_ratio"], 0.0), "pump_torque_nm"].iloc[0] == pytest.approx(152.0, rel=1e-12)


def test_hrovat_tobler_torques_balance_and_clutch_modes(ls):
    df = characterise(ls, "hrovat-tobler")
    cp = coupling_point(ls)
    assert 0.85 < cp < 0.95
    # external torques: T_p + T_t + T_s = 0 where T_t = −(delivered turbine torque)
    balance = df["pump_torque_nm"] - df["turbine_torque_nm"] + df["stator_torque_nm"]
    assert (balance.abs() <= 1e-12 * df["pump_torque_nm"].abs().max()).all()
    locked = df[df["speed_ratio"] < cp]
    assert (locked["stator_mode"] == "locked").all()
    assert (locked["stator_torque_nm"] > 0).all() and (locked["torque_ratio"] > 1).all()
    free = df[(df["speed_ratio"] > cp) & (df["stator_mode"] == "free-wheeling")]
    assert len(free) >= 5
    np.testing.assert_allclose(free["torque_ratio"], 1.0, rtol=0, atol=1e-12)
    assert (free["stator_speed_rad_s"] > 0).all()
    assert df.iloc[-1]["stator_mode"] == "no-flow" and df.iloc[-1]["flow_m3_s"] == 0.0
    assert df["speed_ratio"].isin([cp]).any(), "the coupling point is part of the sweep"


def test_hrovat_tobler_reference_is_near_table_c1_at_stall(ls):
    """physics.md §1: the Appendix D parameters give CF(0) ≈ 2.94e-3 and TR(0) ≈ 2.12."""
    df = characterise(ls, "hrovat-tobler", speed_ratio=np.array([0.0]))
    assert df["capacity_factor_nm_s2"].iloc[0] == pytest.approx(2.944e-3, rel=1e-3)
    assert df["torque_ratio"].iloc[0] == pytest.approx(2.123, rel=1e-3)


def test_hrovat_tobler_characteristic_is_independent_of_pump_speed(ls):
    a = characterise(ls, "hrovat-tobler", pump_speed_rpm=1000)
    b = characterise(ls, "hrovat-tobler", pump_speed_rpm=3000)
    np.testing.assert_allclose(a["torque_ratio"], b["torque_ratio"], rtol=1e-12)
    np.testing.assert_allclose(a["capacity_factor_nm_s2"], b["capacity_factor_nm_s2"], rtol=1e-12)
    np.testing.assert_allclose(b["flow_m3_s"], 3 * a["flow_m3_s"], rtol=1e-12)


def test_efficiency_and_k_factor_columns(ls):
    df = characterise(ls, "table", speed_ratio=np.array([0.5]))
    row = df.iloc[0]
    assert row["efficiency"] == pytest.approx(0.5 * 1.43)
    assert row["k_factor_rpm_per_sqrt_nm"] == pytest.approx((30 / math.pi) / math.sqrt(3.017e-3), rel=1e-12)


CONVENTIONS = {
    "capacity_factor_nm_s2": lambda cf: cf,
    "k_factor_rpm_per_sqrt_nm": lambda cf: (30 / math.pi) / math.sqrt(cf),
    "k_factor_rad_s_per_sqrt_nm": lambda cf: 1 / math.sqrt(cf),
    "k_factor_rpm_per_sqrt_lbf_ft": lambda cf: (30 / math.pi) / math.sqrt(cf) * math.sqrt(1.3558179483314004),
    "capacity_nm_per_rpm2": lambda cf: cf * (math.pi / 30) ** 2,
    "mp1000_nm": lambda cf: cf * (1000 * math.pi / 30) ** 2,
}


@pytest.mark.parametrize("convention", sorted(CONVENTIONS))
def test_csv_import_in_every_capacity_convention(tmp_path, convention):
    to = CONVENTIONS[convention]
    rows = "\n".join(f"{s},{t},{to(c)!r}" for s, t, c in zip(C1_SR, C1_TR, C1_CF))
    p = tmp_path / f"c1_{convention}.csv"
    p.write_text(f"speed_ratio,torque_ratio,{convention}\n{rows}\n")
    conv = load_converter(p)
    assert conv.characteristic.convention == convention
    np.testing.assert_allclose(conv.characteristic.capacity_factor_nm_s2, C1_CF, rtol=1e-13)
    # and back through the core's conversion
    back = _core.cf_to_capacity(convention, np.array(C1_CF))
    np.testing.assert_allclose(back, [to(c) for c in C1_CF], rtol=1e-13)


def test_vecto_vtcc_import(tmp_path):
    p = tmp_path / "tc.vtcc"
    p.write_text(
        "# VECTO torque converter\nSpeed Ratio, Torque Ratio,MP1000\n0.0,1.80,377.80\n0.5,1.33,314.84\n"
        "1.0,1.0,0.00\n1.100,0.999,-40.0\n"
    )
    conv = load_converter(p)
    w1000 = 1000 * math.pi / 30
    np.testing.assert_allclose(
        conv.characteristic.capacity_factor_nm_s2, np.array([377.8, 314.84, 0.0, -40.0]) / w1000**2
    )
    df = characterise(conv, "table", pump_speed_rpm=1000, speed_ratio=np.array([0.0, 1.1]))
    np.testing.assert_allclose(df["pump_torque_nm"], [377.8, -40.0], rtol=1e-12)


def test_implausible_stall_torque_warns(tmp_path):
    # Table C.1 read per rpm² would give ~13 000 N·m at stall
    p = tmp_path / "per_rpm2.csv"
    rows = "\n".join(f"{s},{t},{c!r}" for s, t, c in zip(C1_SR, C1_TR, C1_CF))
    p.write_text("speed_ratio,torque_ratio,capacity_nm_per_rpm2\n" + rows + "\n")
    with pytest.warns(tcsim.TcsimWarning, match="capacity_nm_per_rpm2"):
        load_converter(p)


def test_bundled_converter_documents_every_value(ls):
    for section in ("inertia", "geometry", "quasi_dynamic"):
        model = getattr(ls, section)
        for key in type(model).model_fields:
            if getattr(model, key) is not None:
                assert f"{section}.{key}" in ls.sources, f"{section}.{key} has no source"
    for key in ("speed_ratio", "torque_ratio", "capacity_factor_nm_s2"):
        assert f"characteristic.{key}" in ls.sources


def test_bundled_fluid_parameters_come_from_the_circular_torus(ls):
    """The bundled [geometry]'s fluid length and shape effects are the circle's (docs/design.md: the
    literal reading of §4.1.1, R_exit·|tan α_exit|·L), checked against the plain reference."""
    g = ls.geometry
    e = torus_estimate(
        g.pump_exit_radius_m,
        g.turbine_exit_radius_m,
        g.stator_exit_radius_m,
        g.pump_inlet_angle_deg,
        g.pump_exit_angle_deg,
        g.turbine_inlet_angle_deg,
        g.turbine_exit_angle_deg,
        g.stator_inlet_angle_deg,
        g.stator_exit_angle_deg,
        g.flow_area_m2,
        g.fluid_density_kg_m3,
    )
    assert g.fluid_length_m == pytest.approx(e.fluid_length_m, abs=5e-5)
    assert g.pump_shape_effect_m2 == pytest.approx(e.pump_literal_shape_effect_m2, abs=5e-7)
    assert g.turbine_shape_effect_m2 == pytest.approx(e.turbine_literal_shape_effect_m2, abs=5e-7)
    assert g.stator_shape_effect_m2 == pytest.approx(e.stator_literal_shape_effect_m2, abs=5e-7)
    # the mass matrix of eqs 2.12–2.15 with the bundled inertias is positive definite:
    # ρL_f/A > ρ²S_p²/I_p + ρ²S_t²/I_t + ρ²S_s²/I_s
    rho, A, i = g.fluid_density_kg_m3, g.flow_area_m2, ls.inertia
    lhs = rho * g.fluid_length_m / A
    rhs = rho**2 * (
        g.pump_shape_effect_m2**2 / i.pump_kg_m2
        + g.turbine_shape_effect_m2**2 / i.turbine_kg_m2
        + g.stator_shape_effect_m2**2 / i.stator_kg_m2
    )
    assert lhs > rhs
    # and the element inertias are at least the fluid they carry
    assert i.pump_kg_m2 > e.pump_fluid_inertia_kg_m2 and i.turbine_kg_m2 > e.turbine_fluid_inertia_kg_m2


def test_torus_bound_holds_for_any_angles():
    """Cauchy–Schwarz for the arc reading: ρ²S²/I_fluid ≤ (ρ/A)∫tan²α dl < ρL_f/A, element by
    element (a property of the reference's formulas, docs/design.md "Mass-matrix bound")."""
    rng = np.random.default_rng(1)
    for _ in range(50):
        ang = rng.uniform(-75, 75, 6)
        e = torus_estimate(0.12, 0.065, 0.06, *ang, 0.01, 840.0)
        rho2 = 840.0**2
        total = sum(
            rho2 * s_**2 / i
            for s_, i in (
                (e.pump_shape_effect_m2, e.pump_fluid_inertia_kg_m2),
                (e.turbine_shape_effect_m2, e.turbine_fluid_inertia_kg_m2),
                (e.stator_shape_effect_m2, e.stator_fluid_inertia_kg_m2),
            )
        )
        assert total < 840.0 * e.fluid_length_m / 0.01


def test_characterise_command_writes_csv_and_plots(cli, tmp_path):
    out = tmp_path / "res"
    r = cli("characterise", "li-sunden-2016", "--out", out)
    assert r.code == 0, r.stderr
    assert "coupling point" in r.stdout
    df = pd.read_csv(out / "characteristic.csv")
    for col in (
        "speed_ratio",
        "torque_ratio",
        "capacity_factor_nm_s2",
        "k_factor_rpm_per_sqrt_nm",
        "efficiency",
        "pump_speed_rad_s",
        "pump_torque_nm",
        "turbine_torque_nm",
        "flow_m3_s",
        "stator_torque_nm",
        "stator_speed_rad_s",
    ):
        assert col in df.columns
    for png in ("torque_ratio.png", "capacity_factor.png", "k_factor.png", "efficiency.png"):
        assert (out / png).stat().st_size > 10_000
    assert not any(p.name.endswith(".partial") for p in tmp_path.iterdir())


@pytest.mark.parametrize("model", ["table", "quasi-dynamic"])
def test_characterise_command_table_models(cli, tmp_path, model):
    r = cli("characterise", "li-sunden-2016", "--model", model, "--pump-speed-rpm", "1500", "--out", tmp_path / model)
    assert r.code == 0, r.stderr
    df = pd.read_csv(tmp_path / model / "characteristic.csv")
    sub = df[df["speed_ratio"].isin(C1_SR)]
    assert sub["torque_ratio"].tolist() == C1_TR


def test_converters_command_lists_sources(cli):
    r = cli("converters")
    assert r.code == 0
    assert "li-sunden-2016" in r.stdout and "Table C.1" in r.stdout


def test_characterise_accepts_a_table_file(cli, tmp_path, c1_csv):
    r = cli("characterise", c1_csv, "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    assert "table" in r.stdout
