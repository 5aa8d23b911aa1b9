"""The Appendix D parameter study (Li & Sundén 2016, Table D.1, figures D.1–D.15)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from tcsim.converter import load_converter
from tcsim.steady import characterise_hrovat_tobler
from tcsim.study import default_definition, run_study


@pytest.fixture(scope="module")
def study():
    return run_study(load_converter("li-sunden-2016"))


def test_reference_rows_equal_the_closed_form_characteristic(study):
    conv = load_converter("li-sunden-2016")
    sr = np.round(np.arange(0, 0.9 + 1e-9, 0.05), 10)
    ref = characterise_hrovat_tobler(conv, 2000.0, sr)
    g = conv.geometry
    for parameter, rows in study.groupby("parameter"):
        value = getattr(g, parameter)
        sub = rows[np.isclose(rows["parameter_value"], value, rtol=1e-12, atol=0)].sort_values("speed_ratio")
        assert len(sub) == len(sr), parameter
        np.testing.assert_allclose(sub["torque_ratio"], ref["torque_ratio"], rtol=1e-13, err_msg=parameter)
        np.testing.assert_allclose(sub["capacity_factor_nm_s2"], ref["capacity_factor_nm_s2"], rtol=1e-13)
        np.testing.assert_allclose(sub["flow_m3_s"], ref["flow_m3_s"], rtol=1e-13)


def test_capacity_is_proportional_to_density_and_torque_ratio_independent_of_it(study):
    """ρ multiplies every term of eqs 2.12–2.15 at steady state: Q is independent of ρ, CF ∝ ρ."""
    rows = study[study["parameter"] == "fluid_density_kg_m3"]
    ref = rows[rows["parameter_value"] == 840.0].set_index("speed_ratio")
    for value, sub in rows.groupby("parameter_value"):
        sub = sub.set_index("speed_ratio")
        np.testing.assert_allclose(sub["capacity_factor_nm_s2"], ref["capacity_factor_nm_s2"] * value / 840.0, rtol=1e-12)
        np.testing.assert_allclose(sub["torque_ratio"], ref["torque_ratio"], rtol=1e-12)
        np.testing.assert_allclose(sub["flow_m3_s"], ref["flow_m3_s"], rtol=1e-12)


def test_larger_pump_radius_absorbs_more_torque_at_stall(study):
    rows = study[(study["parameter"] == "pump_exit_radius_m") & (study["speed_ratio"] == 0.0)].sort_values("parameter_value")
    assert np.all(np.diff(rows["capacity_factor_nm_s2"].to_numpy()) > 0)


def test_study_covers_table_d1(study):
    d = default_definition()
    assert len(d.parameters) == 15
    assert set(study["parameter"]) == {p.key for p in d.parameters}
    assert np.isclose(study["speed_ratio"].max(), 0.9) and study["speed_ratio"].min() == 0.0


def test_study_command_writes_figures_and_csv(tmp_path):
    from tcsim.cli import main

    out = tmp_path / "study"
    assert main(["study", "li-sunden-2016", "--out", str(out)]) == 0
    assert len(list(out.glob("study_*.png"))) == 15
    df = pd.read_csv(out / "study.csv")
    assert len(df) == len(run_study(load_converter("li-sunden-2016")))


def test_study_of_a_table_only_converter_is_refused(cli, tmp_path, c1_csv):
    r = cli("study", c1_csv, "--out", tmp_path / "o")
    assert r.code == 2 and "[geometry]" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists()
