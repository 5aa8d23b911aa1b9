"""The gallery of the thesis's figures (issue 17, ``docs/gallery/``): every script runs in its fast
mode and makes exactly its figures (valid PNG files, each with its CSV data); the gallery page shows
every figure the issue lists, with an image in ``docs/gallery/img/`` that a script makes; and each
group of figures shows the physics it is there for, read from the CSV data the scripts write."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tcsim.models.converter import load_converter
from tcsim.steady import characterise
from tcsim.study import TABLE_D1

REPO = Path(__file__).resolve().parents[2]
GALLERY = REPO / "docs" / "gallery"
pytestmark = pytest.mark.subprocess

#: The figures issue 17 asks for: 3.3–3.6, 3.13–3.17, 4.1–4.6, C.1–C.2, D.1–D.15.
ISSUE_FIGURES = (
    [f"3.{n}" for n in (3, 4, 5, 6, 13, 14, 15, 16, 17)]
    + [f"4.{n}" for n in range(1, 7)]
    + ["C.1", "C.2"]
    + [f"D.{n}" for n in range(1, 16)]
)
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _png_name(number: str) -> str:
    """``3.13`` -> ``fig_3_13``, ``C.1`` -> ``fig_c_1``."""
    return "fig_" + number.lower().replace(".", "_")


def _scripts() -> dict[str, tuple[str, ...]]:
    """``SCRIPTS`` of docs/gallery/make_all.py: each script and the figures it makes."""
    spec = importlib.util.spec_from_file_location("gallery_make_all", GALLERY / "make_all.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.SCRIPTS


@pytest.fixture(scope="module")
def outputs(tmp_path_factory) -> dict[str, Path]:
    """Every gallery script run once in its fast mode, each into its own folder."""
    out = {}
    for script in _scripts():
        folder = tmp_path_factory.mktemp(Path(script).stem)
        run = subprocess.run(
            [sys.executable, str(GALLERY / script), "--fast", "--out", str(folder)],
            cwd=folder,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert run.returncode == 0, f"{script}: {run.stderr[-4000:]}"
        out[script] = folder
    return out


def _csv(outputs: dict[str, Path], name: str) -> pd.DataFrame:
    script = next(s for s, names in _scripts().items() if name in names)
    return pd.read_csv(outputs[script] / f"{name}.csv")


# ---------------------------------------------------------------------------------------------
# files and the page


def test_each_script_makes_exactly_its_figures(outputs):
    for script, names in _scripts().items():
        made = sorted(outputs[script].glob("*.png"))
        assert {p.stem for p in made} == set(names), script
        for png in made:
            data = png.read_bytes()
            assert data[:8] == PNG_SIGNATURE and len(data) > 10_000, png.name
            assert len(pd.read_csv(png.with_suffix(".csv"))) > 0, png.name


def test_page_shows_every_figure_of_the_issue_with_a_made_image():
    page = (GALLERY / "index.md").read_text(encoding="utf-8")
    wanted = {_png_name(n) for n in ISSUE_FIGURES}
    made = {name for names in _scripts().values() for name in names}
    assert made == wanted
    committed = {p.stem for p in (GALLERY / "img").glob("*.png")}
    assert committed == wanted
    shown = set(re.findall(r"!\[Figure [^\]]+\]\(img/(fig_[a-z0-9_]+)\.png\)", page))
    assert shown == wanted
    for number in ISSUE_FIGURES:
        name = _png_name(number)
        assert re.search(rf"^### Figure {re.escape(number)}: \S", page, flags=re.M), number
        assert f"![Figure {number}](img/{name}.png)" in page, number
        image = (GALLERY / "img" / f"{name}.png").read_bytes()
        assert image[:8] == PNG_SIGNATURE and 10_000 < len(image) <= 100_000, name
    for script in _scripts():
        assert f'--8<-- "docs/gallery/{script}"' in page, script


# ---------------------------------------------------------------------------------------------
# the physics of each group


def test_steady_figures_fall_with_speed_ratio_and_the_fitted_model_meets_table_c1(outputs):
    data = _csv(outputs, "fig_3_3")
    table = data[data.curve.str.startswith("Drenth")]
    points = data[data.curve.str.startswith("Manufacturer")].set_index("speed_ratio")
    below = table[table.speed_ratio < 0.85]
    assert np.all(np.diff(below.torque_ratio) < 0) and np.all(np.diff(table.torque_ratio) <= 1e-12)
    for curve, tr_tol, cf_tol in (("H&T model, geometry fitted", 0.02, 0.015), ("H&T model, Table D.1", 0.1, 0.15)):
        model = data[data.curve.str.startswith(curve)].set_index("speed_ratio").loc[points.index[points.index <= 0.85]]
        ref = points.loc[model.index]
        assert np.max(np.abs(model.torque_ratio - ref.torque_ratio)) <= tr_tol, curve
        assert np.max(np.abs(model.capacity_factor_nm_s2 / ref.capacity_factor_nm_s2 - 1)) <= cf_tol, curve
    # Table D.1's geometry misses the table's stall capacity (page: 10 % below), the fitted one meets it
    d1 = data[data.curve.str.startswith("H&T model, Table D.1")].set_index("speed_ratio")
    assert d1.capacity_factor_nm_s2.loc[0.0] < 0.95 * points.capacity_factor_nm_s2.loc[0.0]


def test_table_figures_pass_through_table_c1(outputs):
    data = _csv(outputs, "fig_c_1")
    line = data[data.curve.str.startswith("SS table")].set_index("speed_ratio")
    points = data[data.curve == "Table C.1"].set_index("speed_ratio")
    assert len(points) == 13
    for column in ("torque_ratio", "capacity_factor_nm_s2"):
        np.testing.assert_allclose(line.loc[points.index, column], points[column], rtol=1e-12)
    assert (line.capacity_factor_nm_s2 > 0).all() and (line.torque_ratio.loc[0.85:] == 1.0).all()


def test_launch_figures_dip_after_the_release_by_model(outputs):
    data = _csv(outputs, "fig_3_5")
    release = data.brake_release_s.iloc[0]
    before = data[data.time_s < release]
    assert (before.speed_ratio.abs() < 1e-9).all()
    # braked: each model holds its stall state, Table C.1's TR 2.14 (fitted H&T: 2.138)
    np.testing.assert_allclose(before.effective_torque_ratio, 2.14, atol=0.005)
    assert (before.groupby("model").effective_torque_ratio.agg(np.ptp) < 1e-6).all()
    after = data[(data.time_s >= release) & (data.time_s <= release + 0.5)]
    dips = after.groupby("model").effective_torque_ratio.min()
    assert dips["quasi-dynamic"] < dips["hrovat-tobler"] < dips["table"]
    assert (data[data.time_s > release + 0.8].groupby("model").speed_ratio.min() > 0.2).all()


def test_replay_figures_reproduce_the_measurement_and_the_torque_flow_adds_up(outputs):
    for name, column, tol, apart in (
        ("fig_3_13", "turbine_torque_nm", 1.0, 2.0),
        ("fig_3_14", "pump_speed_rad_s", 0.2, 0.5),
        ("fig_3_17", "effective_turbine_torque_nm", 1.0, 10.0),
    ):
        data = _csv(outputs, name).pivot(index="time_s", columns="curve", values=column)
        error = (data.drop(columns="Measurement (synthetic)").sub(data["Measurement (synthetic)"], axis=0)).abs().max()
        # the quasi-dynamic model replays its own launch; the table model's own dynamics differ
        assert error["quasi-dynamic"] < tol and error["table"] > apart, (name, error.to_dict())
    flow = _csv(outputs, "fig_3_15")
    pump = flow.pump_inertia_torque_nm + flow.pump_fluid_torque_nm + flow.pump_transferred_torque_nm
    turbine = flow.turbine_inertia_torque_nm + flow.turbine_fluid_torque_nm + flow.turbine_torque_nm
    np.testing.assert_allclose(pump, flow.pump_torque_nm, rtol=1e-9, atol=1e-9)  # eq 3.1
    np.testing.assert_allclose(turbine, flow.turbine_transferred_torque_nm, rtol=1e-9, atol=1e-9)  # eq 3.2
    assert flow.pump_fluid_torque_nm.max() > 1.0  # the fluid takes a visible share in the take-off


def _by_shape_effect(data: pd.DataFrame, model: str, column: str, span_s: float, how: str) -> pd.Series:
    """Per S_p = S_t of ``model``, the minimum or mean of ``column`` over ``span_s`` after the release."""
    release = data.brake_release_s.iloc[0]
    runs = data[(data.model == model) & data.admissible & (data.pump_shape_effect_m2 == data.turbine_shape_effect_m2)]
    window = runs[(runs.time_s >= release) & (runs.time_s <= release + span_s)]
    return window.groupby("pump_shape_effect_m2")[column].agg(how).sort_index()


def test_shape_effect_figures_dip_deeper_with_larger_shape_effects(outputs):
    for name, model, column, how in (
        ("fig_4_1", "quasi-dynamic", "effective_torque_ratio", "min"),
        ("fig_4_2", "hrovat-tobler", "effective_torque_ratio", "min"),
        ("fig_4_3", "quasi-dynamic", "effective_torque_ratio", "min"),
        ("fig_4_4", "hrovat-tobler", "effective_torque_ratio", "min"),
        ("fig_4_5", "quasi-dynamic", "vehicle_accel_m_s2", "mean"),
        ("fig_4_6", "hrovat-tobler", "vehicle_accel_m_s2", "mean"),
    ):
        values = _by_shape_effect(_csv(outputs, name), model, column, 0.5 if how == "min" else 1.0, how)
        assert len(values) == 4 and values.index[0] == 0.0, name
        assert np.all(np.diff(values.to_numpy()) < 0), (name, values.to_dict())
    refused = _csv(outputs, "fig_4_2")
    refused = refused[~refused.admissible]
    assert sorted(refused.pump_shape_effect_m2) == [0.05, 0.1, 0.15] and refused.note.str.contains("inadmissible").all()


def test_study_figures_pass_through_the_base_converter(outputs):
    conv = load_converter("li-sunden-2016")
    for number, parameter in enumerate(TABLE_D1, start=1):
        data = _csv(outputs, f"fig_d_{number}")
        assert set(data.parameter) == {parameter.key}
        assert data.parameter_value.nunique() >= 3  # the fast mode's values and the reference
        at_reference = data[data.parameter_value == data.reference_value].set_index("speed_ratio")
        base = characterise(conv, "hrovat-tobler", 2000.0, at_reference.index.to_numpy()).set_index("speed_ratio")
        for column in ("torque_ratio", "capacity_factor_nm_s2", "flow_m3_s"):
            np.testing.assert_allclose(at_reference[column], base[column], rtol=1e-9, err_msg=parameter.key)
