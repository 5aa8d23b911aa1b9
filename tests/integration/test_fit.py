"""Tests of ``tcsim fit``: fitting Hrovat & Tobler parameters to a characteristic table.

Li & Sundén (2016) §3.2.1 (matching the model to manufacturer data) and §4.3.2 (the match needs
angles outside their measured ranges); Hrovat & Tobler (1985) steady state.
"""

from __future__ import annotations

import json
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from tcsim import _core
from tcsim.analysis.fitting import (
    ANGLES,
    DEFAULT_FREE,
    LOSSES,
    PUMP_SPEED_RAD_S,
    RADII,
    fit_hrovat_tobler,
    target_table,
)
from tcsim.api import steady_state
from tcsim.cli import main
from tcsim.errors import InputError, TcsimWarning
from tcsim.models.characteristic import Characteristic
from tcsim.models.converter import load_converter
from tcsim.models.design_ranges import DESIGN_RANGES

SHARED_TABLES = Path(__file__).resolve().parents[1] / "data" / "converters"


@pytest.fixture(scope="module")
def bundled():
    return load_converter("li-sunden-2016")


def model_table(geometry, speed_ratio) -> Characteristic:
    """TR and CF of the model itself at ``speed_ratio``: a table the model can match exactly."""
    tr, cf, _, _ = _core.ht_ratio_gradients(geometry.core_row()[None, :], PUMP_SPEED_RAD_S, speed_ratio, [])
    assert np.isfinite(tr).all() and np.isfinite(cf).all()
    return Characteristic.from_columns(speed_ratio, tr, cf, "capacity_factor_nm_s2", "synthetic table")


def write_csv(table: Characteristic, path: Path) -> Path:
    sr, tr, cf = table.arrays()
    rows = "\n".join(f"{float(a)!r},{float(b)!r},{float(c)!r}" for a, b, c in zip(sr, tr, cf))
    path.write_text(f"speed_ratio,torque_ratio,capacity_factor_nm_s2\n{rows}\n", encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------
# (1) recovery of known parameters

#: Appendix D reference with three losses and three angles changed (the "truth").
TRUTH = dict(
    pump_shock_loss=0.7,
    turbine_shock_loss=0.8,
    stator_shock_loss=1.3,
    friction_loss=0.3,
    pump_exit_angle_deg=-25.0,
    turbine_exit_angle_deg=-45.0,
    turbine_inlet_angle_deg=50.0,
)
GRID = np.round(np.arange(0.0, 0.8501, 0.05), 10)


@pytest.fixture(scope="module")
def truth(bundled):
    return bundled.geometry.model_copy(update=TRUTH)


def test_recovers_identifiable_parameters(bundled, truth):
    # With radii, area and density fixed, TR and CF over the locked-stator range determine only 7
    # combinations of the 4 losses and 6 angles: with ω_s = 0 the steady flow q(SR) lies on a conic
    # a0 + a1·SR + a2·SR² + 2(m0 + m1·SR)q − D·q² = 0 whose coefficients the losses and angles set,
    # and a conic is known only up to a common factor; TR and CF add the exit-angle combinations
    # R_p tan α_p − R_s tan α_s and R_t tan α_t − R_p tan α_p. These 7 parameters are such a set
    # (full-rank Jacobian): each is recovered. The start is the Appendix D reference, 10–60 % away.
    free = LOSSES + ("pump_exit_angle_deg", "turbine_exit_angle_deg", "turbine_inlet_angle_deg")
    r = fit_hrovat_tobler(bundled.geometry, model_table(truth, GRID), free)
    assert r.jacobian_rank == len(free) and r.identifiable.all()
    assert r.rms_tr < 1e-6 and r.rms_cf < 1e-6
    assert r.max_tr < 1e-6 and r.max_cf < 1e-6
    for name in free:
        assert r.values[name] == pytest.approx(TRUTH[name], rel=1e-6), name


def test_a_fit_with_fewer_values_than_free_parameters_warns(bundled, truth):
    """A trial: 10 parameters fitted to 2 points reported success with exit 0; only fit_report.md
    said that JᵀJ was singular. A full table with the default free set (rank 7 of 10) does not warn."""
    with pytest.warns(TcsimWarning, match=r"not unique: 2 points give 4 values \(TR and CF\) for 10 free"):
        r = fit_hrovat_tobler(bundled.geometry, model_table(truth, np.array([0.0, 0.5])), n_starts=2)
    assert r.singular
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*not unique.*", category=TcsimWarning)
        r = fit_hrovat_tobler(bundled.geometry, model_table(truth, GRID), n_starts=2)
    assert r.singular  # the default set's own deficiency, explained in the report


def test_default_free_set_recovers_the_curve_not_the_parameters(bundled, truth):
    # The default set frees all 10 losses and angles: 3 more than the table determines (see
    # above), so the fit finds one of a 3-parameter family of equivalent points. It must still
    # reproduce TR and CF exactly, also between the fitted points, and report the rank.
    r = fit_hrovat_tobler(bundled.geometry, model_table(truth, GRID))
    assert r.free == DEFAULT_FREE
    assert r.max_tr < 1e-6 and r.max_cf < 1e-6
    assert r.jacobian_rank == 7 and not r.identifiable.any()
    assert any("singular" in n for n in r.notes)
    between = GRID[:-1] + 0.025
    tr, cf, _, _ = _core.ht_ratio_gradients(r.geometry.core_row()[None, :], PUMP_SPEED_RAD_S, between, [])
    tr0, cf0, _, _ = _core.ht_ratio_gradients(truth.core_row()[None, :], PUMP_SPEED_RAD_S, between, [])
    np.testing.assert_allclose(tr, tr0, rtol=1e-6)
    np.testing.assert_allclose(cf, cf0, rtol=1e-6)


def test_fit_is_deterministic(bundled, truth):
    table = model_table(truth, GRID)
    a = fit_hrovat_tobler(bundled.geometry, table, n_starts=3)
    b = fit_hrovat_tobler(bundled.geometry, table, n_starts=3)
    assert a.values == b.values and a.nfev == b.nfev


# --------------------------------------------------------------------------------------------
# (2) the bundled converter against its own Table C.1


def test_bundled_converter_fits_table_c1(bundled):
    r = fit_hrovat_tobler(bundled.geometry, bundled.characteristic)
    assert r.speed_ratio_max == pytest.approx(0.85)  # the table's coupling point
    assert r.speed_ratio[0] == 0.0 and r.speed_ratio[-1] == pytest.approx(0.85)
    assert r.rms_tr < 0.015 and r.rms_cf < 0.03
    for name, (lo, hi) in r.bounds.items():
        assert lo <= r.values[name] <= hi
    assert r.bounds["pump_exit_angle_deg"] == (-60.0, 60.0)
    corr = r.correlation
    assert corr.shape == (10, 10) and np.allclose(corr, corr.T, equal_nan=True)


def test_speed_ratio_max_option(bundled):
    r = fit_hrovat_tobler(bundled.geometry, bundled.characteristic, LOSSES, speed_ratio_max=0.5)
    assert r.speed_ratio.tolist() == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])


# --------------------------------------------------------------------------------------------
# (3) the command end to end


def test_fit_command_end_to_end(bundled, tmp_path):
    target = write_csv(bundled.characteristic, tmp_path / "table_c1.csv")
    out = tmp_path / "fit"
    assert main(["fit", "li-sunden-2016", "--target", str(target), "--out", str(out)]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"fitted.toml", "fit_report.md", "fit_report.json", "torque_ratio.png", "capacity_factor.png"} <= names

    report = json.loads((out / "fit_report.json").read_text())
    assert report["errors"]["rms_torque_ratio"] < 0.015 and report["errors"]["rms_capacity_factor"] < 0.03
    assert set(report["parameters"]) == set(DEFAULT_FREE)
    assert report["optimiser"]["nfev"] > 0
    assert len(report["correlation"]["matrix"]) == len(DEFAULT_FREE)

    fitted = load_converter(out / "fitted.toml")
    for name, p in report["parameters"].items():
        assert getattr(fitted.geometry, name) == pytest.approx(p["fitted"], rel=1e-12)
    assert "fitted by tcsim fit" in fitted.sources["geometry.friction_loss"]
    assert fitted.inertia == bundled.inertia  # the start converter's other sections are kept
    assert "RMS relative error" in (out / "fit_report.md").read_text()
    assert main(["characterise", str(out / "fitted.toml"), "--out", str(tmp_path / "char")]) == 0
    assert (tmp_path / "char" / "characteristic.csv").exists()


def test_start_without_table_gets_the_target_table(bundled, tmp_path):
    start = tmp_path / "geometry_only.toml"
    start.write_text(tomli_w.dumps({"name": "bare", "source": "test", "geometry": bundled.geometry.model_dump()}))
    target = write_csv(bundled.characteristic, tmp_path / "c1.csv")
    out = tmp_path / "fit"
    assert main(["fit", str(start), "--target", str(target), "--out", str(out), "--free", ",".join(LOSSES)]) == 0
    doc = tomllib.loads((out / "fitted.toml").read_text())
    assert doc["characteristic"]["torque_ratio"] == bundled.characteristic.torque_ratio.tolist()
    assert "fitting target" in doc["sources"]["characteristic.torque_ratio"]
    models = load_converter(out / "fitted.toml").models
    assert "table" in models and "hrovat-tobler" in models


# --------------------------------------------------------------------------------------------
# (4) bad input: exit code 2, one message, nothing written

BAD_OPTIONS = [
    (["--free", "pump_shock_loss,warp_factor"], "--free"),
    (["--free", "pump_exit_angle_rad"], "--free"),  # core name, not the user's
    (["--free", "friction_loss,friction_loss"], "--free"),
    (["--free", ","], "--free"),
    (["--bound", "pump_shock_loss=0.1"], "--bound"),
    (["--bound", "pump_shock_loss=a:b"], "--bound"),
    (["--bound", "pump_shock_loss:0.1:2"], "--bound"),
    (["--bound", "pump_shock_loss=2:0.5"], "--bound"),  # LO > HI
    (["--bound", "pump_shock_loss=1:1"], "--bound"),  # LO = HI
    (["--bound", "pump_shock_loss=2:3"], "--bound"),  # start value 1 outside
    (["--bound", "pump_exit_angle_deg=-95:60"], "--bound"),  # the model needs |angle| < 90
    (["--bound", "friction_loss=-1:2"], "--bound"),
    (["--bound", "pump_exit_radius_m=0.1:0.2"], "--bound"),  # not free
    (["--bound", "nonsense=0:1"], "--bound"),
    (["--bound", "pump_shock_loss=0.1:2", "--bound", "pump_shock_loss=0.2:2"], "--bound"),
    (["--speed-ratio-max", "1.5"], "--speed-ratio-max"),
    (["--speed-ratio-max", "0.05"], "--speed-ratio-max"),  # a single point
]


@pytest.mark.parametrize("options, field", BAD_OPTIONS)
def test_bad_options_exit_2_and_write_nothing(options, field, bundled, tmp_path, capsys):
    target = write_csv(bundled.characteristic, tmp_path / "c1.csv")
    out = tmp_path / "fit"
    assert main(["fit", "li-sunden-2016", "--target", str(target), "--out", str(out), *options]) == 2
    assert field in capsys.readouterr().err
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c1.csv"]  # no staging directory left


def test_target_without_table_names_the_file(bundled, tmp_path, capsys):
    target = tmp_path / "geometry_only.toml"
    target.write_text(tomli_w.dumps({"name": "bare", "source": "test", "geometry": bundled.geometry.model_dump()}))
    assert main(["fit", "li-sunden-2016", "--target", str(target), "--out", str(tmp_path / "fit")]) == 2
    err = capsys.readouterr().err
    assert "geometry_only.toml" in err and "[characteristic]" in err
    assert not (tmp_path / "fit").exists()


def test_start_without_geometry_is_an_input_error(bundled, tmp_path):
    table = write_csv(bundled.characteristic, tmp_path / "c1.csv")
    assert main(["fit", str(table), "--target", str(table), "--out", str(tmp_path / "fit")]) == 2
    assert not (tmp_path / "fit").exists()


def test_api_raises_input_errors(bundled):
    with pytest.raises(InputError) as e:
        fit_hrovat_tobler(bundled.geometry, bundled.characteristic, ["pump_shock_loss", "bogus"])
    assert e.value.field == "free"
    with pytest.raises(InputError) as e:
        fit_hrovat_tobler(bundled.geometry, bundled.characteristic, LOSSES, bounds={"friction_loss": (0.5, 0.4)})
    assert e.value.field == "bounds"


# --------------------------------------------------------------------------------------------
# (5) every shared table (docs/fitting.md lists the errors measured here)


def shared_tables() -> list[Path]:
    return sorted(SHARED_TABLES.glob("*.csv"))


@pytest.mark.parametrize("path", shared_tables(), ids=lambda p: p.stem)
def test_fit_runs_on_every_shared_table(path, bundled, tmp_path, cli):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)  # e.g. the Allison TC-521 is a truck converter
        table = target_table(str(path))
    start_cf = _core.ht_ratio_gradients(bundled.core_geometry(), PUMP_SPEED_RAD_S, np.array([0.0]), [])[1][0]
    ratio = table.capacity_factor_nm_s2[np.searchsorted(table.speed_ratio, 0.0)] / start_cf
    resized = not 0.5 < ratio < 2.0  # another size of converter: free the radii and the flow area
    free = DEFAULT_FREE + (RADII + ("flow_area_m2",) if resized else ())
    out = tmp_path / "fit"
    run = cli("fit", "li-sunden-2016", "--target", path, "--out", out, "--free", ",".join(free))
    assert run.code == 0, run.stderr
    report = json.loads((out / "fit_report.json").read_text())
    sr, e = np.array(report["points"]["speed_ratio"]), report["errors"]
    # the fit improves on the start in both quantities
    tr0, cf0, _, _ = _core.ht_ratio_gradients(bundled.core_geometry(), PUMP_SPEED_RAD_S, sr, [])
    assert e["rms_torque_ratio"] < np.sqrt(np.mean((tr0 / report["points"]["torque_ratio_table"] - 1) ** 2))
    assert e["rms_capacity_factor"] < np.sqrt(np.mean((cf0 / report["points"]["capacity_factor_table"] - 1) ** 2))
    assert_the_report_is_the_written_converters(out)
    if resized:  # the size is the whole difference: radii and area close it (measured 0.03–0.6 %)
        assert e["rms_torque_ratio"] < 0.01 and e["rms_capacity_factor"] < 0.01
    # every free parameter at a bound or outside its measured range (thesis §4.1.1) is warned about in
    # one line, on stderr and in the report; the others are not
    warned = [line for line in run.stderr.splitlines() if ": fitted " in line]
    assert all(line.startswith("warning: ") for line in warned)
    assert [line.removeprefix("warning: ") for line in warned] == [w for w in report["warnings"] if ": fitted " in w]
    for name, p in report["parameters"].items():
        lo, hi, x = p["lower"], p["upper"], p["fitted"]
        assert p["active"] is not None or min(x - lo, hi - x) > 1e-9 * (hi - lo), name
        outside = name in DESIGN_RANGES and not DESIGN_RANGES[name].contains(x)
        lines = [line for line in warned if f": fitted {name} = " in line]
        assert len(lines) == (p["active"] is not None or outside), (name, lines)
        if p["active"] is not None:
            assert f"ends at its {p['active']} bound" in lines[0]
        if outside:
            assert "outside the measured range" in lines[0] and "§4.1.1" in lines[0]
    # the fitted converter is usable: it characterises (test_fit_derived.py runs the other commands)
    assert cli("characterise", out / "fitted.toml", "--out", tmp_path / "char").code == 0
    angles = ", ".join(f"{n.removesuffix('_angle_deg')} {report['parameters'][n]['fitted']:.1f}" for n in ANGLES)
    print(
        f"\n{path.name}: SR 0–{report['speed_ratio_max']:g}, {len(free)} free, CF(0) ratio {ratio:.2f}: "
        f"RMS TR {100 * e['rms_torque_ratio']:.2f} %, CF {100 * e['rms_capacity_factor']:.2f} %; "
        f"max {100 * e['max_torque_ratio']:.2f} %, {100 * e['max_capacity_factor']:.2f} %\n  angles: {angles}\n  "
        + "\n  ".join(warned)
    )


def assert_the_report_is_the_written_converters(out: Path) -> None:
    """The fit's reported model values and errors are those of the converter it wrote, computed
    afresh with the steady state every command uses (the flow starting from rest), and that
    converter flows at every fitted point."""
    report = json.loads((out / "fit_report.json").read_text())
    pts = report["points"]
    sr = np.array(pts["speed_ratio"])
    pump = report["pump_speed_rpm"] * np.pi / 30.0
    own = steady_state(str(out / "fitted.toml"), "hrovat-tobler", pump, sr * pump)
    assert (own["stator_mode"] != "no-flow").all(), own[["speed_ratio", "stator_mode"]]
    np.testing.assert_allclose(own["torque_ratio"], pts["torque_ratio_model"], rtol=1e-9)
    np.testing.assert_allclose(own["capacity_factor_nm_s2"], pts["capacity_factor_model"], rtol=1e-9)
    tr_err = own["torque_ratio"].to_numpy() / np.array(pts["torque_ratio_table"]) - 1.0
    assert report["errors"]["rms_torque_ratio"] == pytest.approx(np.sqrt(np.mean(tr_err**2)), rel=1e-9)


def test_a_fit_whose_flow_cannot_start_is_not_reported_as_a_good_fit(tmp_path, cli):
    """Fresh-eyes trial: a supplier K-factor table fitted 0.5 % on the forward-flow branch of a
    geometry whose flow is held at rest (two steady states); the converter written transmitted no
    torque anywhere (``characterise`` gave no flow) and a launch with it crashed in its plots."""
    target = tmp_path / "ktab.csv"
    target.write_text(
        "# a supplier's K-factor table\nspeed_ratio,torque_ratio,k_factor_rpm_per_sqrt_nm\n"
        "0.0,2.05,160\n0.2,1.80,162\n0.4,1.55,166\n0.6,1.30,175\n0.8,1.08,195\n0.87,1.00,215\n"
        "0.95,1.00,300\n1.0,1.00,900\n",
        encoding="utf-8",
    )
    out = tmp_path / "fit"
    run = cli("fit", "li-sunden-2016", "--target", target, "--out", out, "--no-plots")
    assert run.code == 0, run.stderr
    assert_the_report_is_the_written_converters(out)
    assert json.loads((out / "fit_report.json").read_text())["errors"]["rms_torque_ratio"] < 0.01


@pytest.mark.parametrize("n_starts", [0, -1, 1.5, True])
def test_a_start_count_below_one_or_not_an_integer_is_refused(bundled, n_starts):
    """``n_starts=0`` ran one start without a word (``max(1, n_starts)``)."""
    with pytest.raises(InputError) as e:
        fit_hrovat_tobler(bundled.geometry, bundled.characteristic, n_starts=n_starts)
    assert e.value.field == "n_starts" and e.value.source == "argument"


def test_the_api_names_its_own_arguments_and_refuses_wrong_types(bundled):
    """A trial: the function's errors named the command line's options (``--free``, ``--bound``,
    ``--speed-ratio-max``); ``free="friction_loss"`` was read as its letters (``--free = 'f'``); a
    Converter as the geometry or a name as the table was an AttributeError."""
    g, table = bundled.geometry, bundled.characteristic
    cases = [
        (dict(free="friction_loss"), "free", "friction_loss"),
        (dict(free=["nope"]), "free", "nope"),
        (dict(bounds={"friction_loss": (1.0, 0.1)}), "bounds", "friction_loss=1:0.1"),
        (dict(speed_ratio_max=1.5), "speed_ratio_max", 1.5),
    ]
    for kwargs, field, value in cases:
        with pytest.raises(InputError) as e:
            fit_hrovat_tobler(g, table, **kwargs)
        assert (e.value.source, e.value.field, e.value.value) == ("argument", field, value)
        option = "--bound" if field == "bounds" else "--" + field.replace("_", "-")
        assert str(e.value.on_command_line()).startswith(f"command line: {option} = ")
    with pytest.raises(InputError, match="^argument: geometry = 'Converter'"):
        fit_hrovat_tobler(bundled, table)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="^argument: table = 'str'"):
        fit_hrovat_tobler(g, "li-sunden-2016")  # type: ignore[arg-type]
