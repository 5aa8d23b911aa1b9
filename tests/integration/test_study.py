"""The Appendix D parameter study (Li & Sundén 2016, Table D.1, figures D.1–D.15): ``tcsim study``.

Trends asserted here are either derived from the steady-state equations (eqs 2.12–2.25 with zero
left-hand sides, stated in each test) or were checked numerically first (said so in the test).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import tcsim.analysis.study as study
from tcsim.analysis.study import COLUMNS, ParameterRange, default_definition, run_study
from tcsim.cli import main
from tcsim.errors import InputError
from tcsim.models.converter import load_converter
from tcsim.models.steady import characterise_hrovat_tobler

REFERENCE_TOML = Path(__file__).resolve().parents[1] / "data" / "converters" / "li_sunden_2016_appendix_d.toml"
N_SR = 19  # SR 0 to 0.9 in steps of 0.05


@pytest.fixture(scope="module")
def conv():
    return load_converter("li-sunden-2016")


@pytest.fixture(scope="module")
def df(conv):
    return run_study(conv)


def pivot(df: pd.DataFrame, parameter: str, column: str) -> pd.DataFrame:
    """Rows: speed ratio; columns: parameter value (ascending)."""
    return df[df["parameter"] == parameter].pivot(index="speed_ratio", columns="parameter_value", values=column)


def expected_values(conv) -> int:
    d = default_definition()
    return sum(len(p.values(getattr(conv.geometry, p.key), d.values_per_parameter)) for p in d.parameters)


# --------------------------------------------------------------------------------------------
# the command


@pytest.fixture(scope="module")
def cli_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("study") / "out"
    return out, main(["study", "li-sunden-2016", "--out", str(out)])


def test_cli_writes_fifteen_figures_and_the_csv(cli_out, conv):
    out, code = cli_out
    assert code == 0
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert pngs == sorted(f"study_{p.key}.png" for p in default_definition().parameters)
    assert len(pngs) == 15
    csv = pd.read_csv(out / "study.csv")
    assert list(csv.columns) == COLUMNS
    # 5 values per parameter plus the converter's own where it is not one of them: 81 for this one
    assert expected_values(conv) == 81
    assert len(csv) == 81 * N_SR
    assert set(csv["stator_mode"]) <= {"locked", "free-wheeling", "no-flow"}


def test_table_only_converter_is_exit_2_and_writes_nothing(tmp_path, c1_csv):
    out = tmp_path / "out"
    assert main(["study", str(c1_csv), "--out", str(out)]) == 2
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [c1_csv.name]


def test_table_only_converter_message_names_the_section(cli, tmp_path, c1_csv):
    r = cli("study", c1_csv, "--out", tmp_path / "o")
    assert r.code == 2 and "[geometry]" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists()


def test_run_study_without_geometry_raises_input_error(c1_csv):
    with pytest.raises(InputError, match=r"\[geometry\]"):
        run_study(load_converter(c1_csv))


# --------------------------------------------------------------------------------------------
# the definition


def test_default_definition_is_table_d1():
    ref = tomllib.loads(REFERENCE_TOML.read_text())
    d = default_definition()
    assert [p.key for p in d.parameters] == list(ref["range"])
    for p in d.parameters:
        lo, hi = ref["range"][p.key]
        if p.relative:
            assert (lo, hi) == (f"{p.low * 100:+.0f}%", f"{p.high * 100:+.0f}%")
        else:
            assert (lo, hi) == (p.low, p.high)
    assert d.pump_speed_rpm == ref["study"]["pump_speed_rpm"]
    assert np.allclose(d.speed_ratio, np.arange(0.0, 0.9 + 1e-9, ref["study"]["speed_ratio_step"]), atol=1e-12)
    assert len(d.speed_ratio) == N_SR


def test_every_parameter_includes_the_reference_value(df, conv):
    for p in default_definition().parameters:
        values = df.loc[df["parameter"] == p.key, "parameter_value"].unique()
        assert getattr(conv.geometry, p.key) in values
        assert len(values) in (5, 6)


def test_unknown_parameter_is_an_input_error(conv):
    bad = default_definition().replace(parameters=(ParameterRange("blade_count", "Blades", "-", 1, 2),))
    with pytest.raises(InputError, match="blade_count"):
        run_study(conv, bad)


def test_all_points_in_one_batched_call(conv, monkeypatch):
    calls = []
    real = study.hrovat_tobler_steady_state

    def counting(geometry, *args, **kwargs):
        calls.append(geometry.shape)
        return real(geometry, *args, **kwargs)

    monkeypatch.setattr(study, "hrovat_tobler_steady_state", counting)
    run_study(conv)
    assert calls == [(81 * N_SR, 15)]


# --------------------------------------------------------------------------------------------
# agreement with the characteristic


def test_reference_rows_equal_the_characteristic_exactly(df, conv):
    d = default_definition()
    ref = characterise_hrovat_tobler(conv, d.pump_speed_rpm, np.asarray(d.speed_ratio))
    for p in d.parameters:
        rows = df[(df["parameter"] == p.key) & (df["parameter_value"] == getattr(conv.geometry, p.key))]
        assert len(rows) == N_SR, p.key
        for column in COLUMNS[2:-1]:
            assert np.array_equal(rows[column].to_numpy(), ref[column].to_numpy()), (p.key, column)
        assert list(rows["stator_mode"]) == list(ref["stator_mode"]), p.key


# --------------------------------------------------------------------------------------------
# trends


def test_capacity_scales_exactly_with_density(df):
    # The balance of eq 2.15 is ρ times a function of q = Q/A, so Q does not depend on ρ; the
    # torques of eqs 2.12–2.14 are ρ·Q·(...): CF ∝ ρ, TR and Q independent of ρ.
    key = "fluid_density_kg_m3"
    rho = pivot(df, key, "capacity_factor_nm_s2").columns.to_numpy()
    cf_per_rho = pivot(df, key, "capacity_factor_nm_s2").to_numpy() / rho
    for a in (cf_per_rho, pivot(df, key, "torque_ratio").to_numpy(), pivot(df, key, "flow_m3_s").to_numpy()):
        np.testing.assert_allclose(a, a[:, [0]] * np.ones_like(a), rtol=1e-13, atol=0)
    assert (pivot(df, key, "stator_mode").nunique(axis=1) == 1).all()


def test_capacity_and_flow_scale_exactly_with_flow_area(df):
    # The balance of eq 2.15 contains A only through q = Q/A: q is independent of A, so Q ∝ A and
    # every torque ∝ ρ·Q: CF ∝ A, TR independent of A.
    key = "flow_area_m2"
    area = pivot(df, key, "flow_m3_s").columns.to_numpy()
    for column in ("capacity_factor_nm_s2", "flow_m3_s"):
        a = pivot(df, key, column).to_numpy() / area
        np.testing.assert_allclose(a, a[:, [0]] * np.ones_like(a), rtol=1e-13, atol=0)
    tr = pivot(df, key, "torque_ratio").to_numpy()
    np.testing.assert_allclose(tr, tr[:, [0]] * np.ones_like(tr), rtol=1e-13, atol=0)


def test_turbine_exit_radius_at_stall(df, conv):
    # At stall with the stator locked (ω_t = ω_s = 0) R_t appears neither in the balance of eq 2.15
    # (its terms carry ω_t or ω_s, and eq 2.22 reduces to q(tan α_t − tan α_ss)) nor in the pump
    # torque of eq 2.12: CF(0) does not depend on R_t. The delivered turbine torque of eq 2.13 is
    # ρQ(ω_p R_p² + q(R_p tan α_p − R_t tan α_t)): TR(0) is affine in R_t, rising as tan α_t < 0.
    key = "turbine_exit_radius_m"
    assert (pivot(df, key, "stator_mode").loc[0.0] == "locked").all()
    cf0 = pivot(df, key, "capacity_factor_nm_s2").loc[0.0].to_numpy()
    np.testing.assert_allclose(cf0, cf0[0], rtol=1e-13, atol=0)
    tr0 = pivot(df, key, "torque_ratio").loc[0.0]
    radius, tr0 = tr0.index.to_numpy(), tr0.to_numpy()
    slope = np.diff(tr0) / np.diff(radius)
    assert np.tan(np.radians(conv.geometry.turbine_exit_angle_deg)) < 0
    assert (slope > 0).all()
    np.testing.assert_allclose(slope, slope[0], rtol=1e-9)


def test_capacity_rises_strongly_with_pump_exit_radius(df):
    # Checked numerically: CF rises with R_p at every SR, by a factor ≥ 5.0 from 0.75 R_p to
    # 1.25 R_p (more than the cube of the radius ratio, 4.63; the Euler head ω_p R_p² alone gives
    # the square and the flow rises with R_p too).
    cf = pivot(df, "pump_exit_radius_m", "capacity_factor_nm_s2").to_numpy()
    assert (np.diff(cf, axis=1) > 0).all()
    assert (cf[:, -1] / cf[:, 0] > (1.25 / 0.75) ** 3).all()


def test_stall_torque_ratio_rises_with_stator_exit_angle(df):
    # Checked numerically: TR(0) = 1.00 (stator free-wheeling), 1.28, 1.58, 1.84, 2.12 for the
    # stator exit angle −60, −30, 0, 30, 60°; the locked stall value is
    # (ω_p R_p² + q(R_p tan α_p − R_t tan α_t)) / (ω_p R_p² + q(R_p tan α_p − R_s tan α_s)).
    key = "stator_exit_angle_deg"
    tr0 = pivot(df, key, "torque_ratio").loc[0.0].to_numpy()
    assert (np.diff(tr0) > 0.2).all()
    assert tr0[0] == 1.0 and pivot(df, key, "stator_mode").loc[0.0].iloc[0] == "free-wheeling"


@pytest.mark.parametrize("key", ["friction_loss", "pump_shock_loss", "turbine_shock_loss", "stator_shock_loss"])
def test_flow_falls_as_a_loss_coefficient_rises(df, key):
    # Locked stator: the balance of eq 2.15 is positive at q = 0 and has a negative q² coefficient;
    # a larger loss coefficient subtracts C·V²/2 ≥ 0 (eq 2.19) at every q > 0, so the positive root
    # (the flow) falls. Compare at speed ratios where every value leaves the stator locked.
    locked = (pivot(df, key, "stator_mode") == "locked").all(axis=1)
    assert locked.sum() >= 17
    flow = pivot(df, key, "flow_m3_s")[locked].to_numpy()
    assert (np.diff(flow, axis=1) < 0).all()


# --------------------------------------------------------------------------------------------
# points without a steady state


def test_invalid_values_and_missing_steady_states_are_nan_not_a_crash(conv):
    d = default_definition().replace(
        parameters=(
            ParameterRange("stator_exit_angle_deg", "Stator exit angle", "°", -90.0, 90.0),
            ParameterRange("stator_shock_loss", "Stator shock-loss coefficient", "-", 1.0, 20.0),
        ),
        values_per_parameter=3,
        speed_ratio=(0.0, 0.5, 0.9, 1.0),
    )
    res = run_study(conv, d)
    assert len(res) == (3 + 1) * 4 + 3 * 4  # the stator exit angle of 60° is added to -90, 0, 90
    at_90 = res["parameter_value"].abs() == 90.0
    assert (res.loc[at_90, "stator_mode"] == study.INVALID_PARAMETER).all()
    # a stator shock loss of 10.5 or 20 leaves the locked head below the shock loss near SR 1: the
    # flow is held at rest either way (F_Q(0+) <= 0 <= F_Q(0-), issue 11), a steady state without flow
    held = (res["parameter"] == "stator_shock_loss") & (res["parameter_value"] > 1) & (res["speed_ratio"] >= 0.9)
    assert (res.loc[held, "stator_mode"] == "no-flow").all()
    assert (res.loc[held, "pump_torque_nm"] == 0.0).all()
    assert res.loc[at_90, COLUMNS[3:-1]].isna().all().all()
    assert res.loc[~at_90 & ~held, COLUMNS[3:-1]].notna().all().all()
