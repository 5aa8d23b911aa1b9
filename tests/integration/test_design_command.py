"""``tcsim design`` (issue 15 item 2, docs/design.md "tcsim design"): the derived converter file
loads and runs like any converter, its values are the design model's, the take-off compares with a
reference, bad design files exit 2 with one line and nothing written."""

from __future__ import annotations

import math
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import run_cli_in_process
from tcsim.analysis.design_report import SUMMARY_COLUMNS, design_report, summary_row, takeoff_frame
from tcsim.models.converter import load_converter
from tcsim.models.design import design_geometry
from tcsim.models.design_file import LOSS_KEYS, derive_converter, load_design_file, read_design_file
from tcsim.models.steady import characterise
from tcsim.transient import isolated_takeoff, simulate

BUNDLED = "li-sunden-2016-design"
REFERENCE = "li-sunden-2016"


def _bundled_text() -> str:
    return (resources.files("tcsim") / "data" / "designs" / f"{BUNDLED}.toml").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """``tcsim design li-sunden-2016-design --out o``: the run and its output directory."""
    cwd = tmp_path_factory.mktemp("design")
    run = run_cli_in_process("design", BUNDLED, "--out", "o", cwd=cwd)
    return run, cwd / "o"


def test_the_written_converter_is_the_design_model_and_runs_everywhere(written, cli):
    run, out = written
    assert run.code == 0, run.stderr
    conv = load_converter(out / "converter.toml")
    assert conv.models == ("hrovat-tobler",)
    file = load_design_file(BUNDLED)
    g = design_geometry(file.design)
    geo = conv.geometry
    assert geo is not None and conv.inertia is not None
    assert (geo.pump_shape_effect_m2, geo.turbine_shape_effect_m2, geo.stator_shape_effect_m2) == (
        g.pump.shape_effect_m2,
        g.turbine.shape_effect_m2,
        g.stator.shape_effect_m2,
    )
    assert geo.fluid_length_m == g.fluid_length_m
    for e in ("pump", "turbine", "stator"):
        fluid = getattr(g, e).fluid_inertia_kg_m2
        assert getattr(conv.inertia, f"{e}_kg_m2") == getattr(file.metal_inertia, f"{e}_kg_m2") + fluid
    # every value is traceable: a [sources] entry for each [geometry] and [inertia] key
    keys = {f"geometry.{k}" for k in geo.model_dump()} | {f"inertia.{k}" for k in conv.inertia.model_dump()}
    assert keys <= set(conv.sources)
    assert "S = R_exit·tan(α_exit)·L_axial" in conv.sources["geometry.turbine_shape_effect_m2"]
    # characteristic.csv is `tcsim characterise`'s closed form for this converter
    written_steady = pd.read_csv(out / "characteristic.csv")
    expected = characterise(conv, "hrovat-tobler")
    np.testing.assert_allclose(written_steady["torque_ratio"], expected["torque_ratio"], rtol=1e-12)
    # every command accepts it: characterise and the transient
    r = cli("characterise", out / "converter.toml", "--out", out.parent / "char")
    assert r.code == 0, r.stderr
    frame = simulate(conv, isolated_takeoff(), model="hrovat-tobler", times_s=[0.0, 1.0, 2.0]).frame()
    assert np.isfinite(frame["turbine_speed_rad_s"]).all() and frame["turbine_speed_rad_s"].iloc[-1] > 0.0


def test_the_report_files_and_the_reference(written):
    run, out = written
    names = {p.name for p in out.iterdir()}
    assert {
        "converter.toml",
        "characteristic.csv",
        "reference_characteristic.csv",
        "takeoff.csv",
        "summary.csv",
    } <= names
    assert {"takeoff_effective_torque_ratio.png", "torque_ratio.png", "tcsim-manifest.json"} <= names
    summary = pd.read_csv(out / "summary.csv")
    assert tuple(summary.columns) == SUMMARY_COLUMNS
    assert summary["role"].tolist() == ["design", "reference"]
    assert summary["converter"].tolist() == [BUNDLED, REFERENCE]
    takeoff = pd.read_csv(out / "takeoff.csv")
    assert set(takeoff["converter"]) == set(summary["converter"])
    # same Table D.1 steady state (the shape effects do not enter it), the same total inertias
    assert summary["stall_torque_ratio"][0] == pytest.approx(summary["stall_torque_ratio"][1], rel=1e-12)
    assert "li-sunden-2016-design" in run.stdout


def test_the_takeoff_dip_follows_the_signed_geometry_derived_shape_effects():
    """Thesis ch. 4 with geometry-derived values, the shape effects alone changed (same steady state,
    L_f and inertias): Table D.1's literal S_p, S_t are negative, and in the Hrovat & Tobler model as
    written (docs/transient.md) a positive S deepens the dip, so the negative values *lessen* it and
    their mirror images (+|S|) deepen it, the more the larger |S| is (docs/design.md "tcsim design")."""
    derived = derive_converter(load_design_file(BUNDLED))
    conv, g = derived.converter, derived.geometry
    assert conv.geometry is not None

    def dip(scale: float) -> float:
        values = {f"{e}_shape_effect_m2": scale * abs(getattr(g, e).shape_effect_m2) for e in ("pump", "turbine")}
        c = replace(conv, geometry=conv.geometry.model_copy(update=values))
        steady = characterise(c, "hrovat-tobler")
        return float(summary_row(c, "design", steady, takeoff_frame(c))["takeoff_effective_tr_dip"])

    as_derived = float(design_report(load_design_file(BUNDLED)).summary["takeoff_effective_tr_dip"][0])
    assert dip(-1.0) == pytest.approx(as_derived, rel=1e-9)  # the derived values are −|S|
    assert dip(-1.0) < dip(0.0) < dip(0.5) < dip(1.0)


def test_losses_not_given_come_from_table_d1_and_say_so(tmp_path, cli):
    text = _bundled_text()
    design = tmp_path / "d.toml"
    design.write_text(text[: text.index("[losses]")], encoding="utf-8")
    r = cli("design", design, "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    assert "losses not in the design, taken from Table D.1" in r.stdout
    conv = load_converter(tmp_path / "o" / "converter.toml")
    assert conv.geometry is not None
    table_d1 = load_converter(REFERENCE).geometry
    for k in LOSS_KEYS:
        assert getattr(conv.geometry, k) == getattr(table_d1, k)
        assert conv.sources[f"geometry.{k}"].startswith("default: Li & Sundén (2016) Table D.1")
    assert read_design_file(design).losses == {}


def _edit(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new, 1)


BAD = [
    (
        lambda t: _edit(t, "turbine_exit_radius_m = 0.065", "turbine_exit_radius_m = 0.13"),
        "[design].turbine_exit_radius_m",
    ),
    (lambda t: _edit(t, "turbine_exit_radius_m = 0.065\n", ""), "[design].turbine_exit_radius_m"),
    (lambda t: _edit(t, 'profile = "circular"', 'profile = "oval"'), "[design].profile"),
    (lambda t: _edit(t, 'profile = "circular"', 'profile = "elliptic"\nsquash_ratio = 1.0'), "[design].squash_ratio"),
    (lambda t: _edit(t, "pump_exit_angle_deg = -20.0", "pump_exit_angle_deg = 95.0"), "[design].pump_exit_angle_deg"),
    (lambda t: _edit(t, "pump_exit_angle_deg = -20.0", 'pump_exit_angle_deg = "x"'), "[design].pump_exit_angle_deg"),
    (lambda t: _edit(t, "pump_kg_m2 = 0.102231", "pump_kg_m2 = -1.0"), "[inertia].pump_kg_m2"),
    (lambda t: _edit(t, "friction_loss = 0.2", "friction_loss = -0.2"), "[losses].friction_loss"),
    (lambda t: _edit(t, "friction_loss = 0.2", "friction_loss = 0.2\nswirl = 1"), "[losses].swirl"),
    (lambda t: t[: t.index("[inertia]")], "[inertia]"),
    (lambda t: t + "\n[[oops\n", "(syntax)"),
]


@pytest.mark.parametrize(("edit", "field"), BAD, ids=[f for _, f in BAD])
def test_a_bad_design_file_exits_2_with_one_line_and_writes_nothing(tmp_path, cli, edit, field):
    design = tmp_path / "bad.toml"
    design.write_text(edit(_bundled_text()), encoding="utf-8")
    before = design.read_bytes()
    r = cli("design", design, "--out", tmp_path / "o")
    assert r.code == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {design}: {field} = "), r.stderr
    assert "expected" in lines[0] and "Traceback" not in r.stdout + r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]
    assert design.read_bytes() == before


def test_a_missing_design_or_reference_without_geometry_exits_2(tmp_path, cli, c1_csv):
    r = cli("design", tmp_path / "none.toml", "--out", tmp_path / "o")
    assert r.code == 2 and r.stderr.strip().splitlines() == [
        f"error: {tmp_path / 'none.toml'}: design = '{tmp_path / 'none.toml'}': expected a bundled design "
        "(li-sunden-2016-design) or an existing design .toml file"
    ]
    r = cli("design", BUNDLED, "--reference", c1_csv, "--out", tmp_path / "o")
    assert r.code == 2 and len(r.stderr.strip().splitlines()) == 1 and "[geometry]" in r.stderr
    assert not (tmp_path / "o").exists()


def test_the_bundled_design_is_table_d1_with_the_bundled_total_inertias():
    file = load_design_file(BUNDLED)
    conv = load_converter(REFERENCE)
    assert conv.geometry is not None and conv.inertia is not None
    for k in ("pump_exit_radius_m", "turbine_exit_radius_m", "stator_exit_radius_m", "flow_area_m2"):
        assert getattr(file.design, k) == getattr(conv.geometry, k)
    g = design_geometry(file.design)
    for e in ("pump", "turbine", "stator"):
        total = getattr(file.metal_inertia, f"{e}_kg_m2") + getattr(g, e).fluid_inertia_kg_m2
        assert math.isclose(total, getattr(conv.inertia, f"{e}_kg_m2"), abs_tol=1e-6)
    assert Path(file.path).name == f"{BUNDLED}.toml" and file.name == BUNDLED
