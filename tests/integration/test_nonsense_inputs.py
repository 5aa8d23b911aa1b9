"""Nonsense that ran before (issue 10, defects 6 and 12): an overflowing steady state reported as
``no-flow``, implausible commanded speeds and initial states, non-finite cells written silently,
converter geometry without plausibility checks."""

from __future__ import annotations

import re
import warnings
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tcsim import _core
from tcsim import transient as tr
from tcsim.cli import main
from tcsim.errors import InputError, TcsimWarning
from tcsim.io.results import non_finite_columns, write_frames
from tcsim.models.characteristic import Characteristic
from tcsim.models.converter import bundled_converters, load_converter
from tcsim.models.dynamic import dynamic_model
from tcsim.models.steady import characterise, coupling_point, hrovat_tobler_steady_state

BUNDLED = resources.files("tcsim") / "data" / "converters" / "li-sunden-2016.toml"


def _lines(capsys) -> list[str]:
    return capsys.readouterr().err.strip().splitlines()


# ---------------------------------------------------------------------------------------------
# the overflowing steady state


def test_an_overflowing_steady_state_is_never_no_flow():
    g = load_converter("li-sunden-2016").core_geometry()
    wp = np.array([1e155, 1e200, 1e300])
    out = hrovat_tobler_steady_state(g, wp, 0.5 * wp, strict=False)
    assert list(out["stator_mode"]) == [-1, -1, -1]  # no steady state, values NaN
    assert np.isnan(out["pump_torque_nm"]).all()
    with pytest.raises(InputError) as e:  # the API's error, not the core's (a trial: it escaped as CoreInputError)
        hrovat_tobler_steady_state(g, wp, 0.5 * wp, strict=True)
    assert (e.value.source, e.value.field, e.value.core_source) == ("argument", "pump_speed_rad_s (point 0)", "drive")


def test_the_closed_form_steady_state_refuses_bad_arguments_as_input_errors():
    g = load_converter("li-sunden-2016").core_geometry()
    bad_geometry = g.copy()
    bad_geometry[..., list(_core.ht_parameter_names()).index("flow_area_m2")] = np.nan
    for args, kwargs, field in [
        ((bad_geometry, [200.0], [0.0]), {}, "geometry"),
        ((g, [np.nan], [0.0]), {}, "pump_speed_rad_s (point 0)"),
        ((np.atleast_2d(g)[:, :5], [200.0], [0.0]), {}, "geometry"),
        ((g, ["a"], [0.0]), {}, "pump_speed_rad_s"),
        ((g, [200.0], [0.0]), {"threads": -1}, "threads"),
        # a review: these were bare ValueErrors and a TypeError from the binding
        ((g, [100.0, 200.0], [0.0, 1.0, 2.0]), {}, "turbine_speed_rad_s"),
        ((np.zeros((0, g.size)), [200.0], [0.0]), {}, "geometry"),
        ((np.tile(g, (2, 1)), [100.0, 200.0, 300.0], [0.0, 1.0, 2.0]), {}, "geometry"),
        ((g.reshape(1, 1, -1), [200.0], [0.0]), {}, "geometry"),
        ((g, [1.0], [0.0]), {"strict": "no"}, "strict"),
    ]:
        with pytest.raises(InputError) as e:
            hrovat_tobler_steady_state(*args, **kwargs)
        assert (e.value.source, e.value.field) == ("argument", field), str(e.value)


def test_the_closed_form_steady_state_broadcasts_a_speed_against_an_array():
    """As :func:`steady_state` does: one pump speed with several turbine speeds (a review: it was a
    ValueError, "equal lengths")."""
    g = load_converter("li-sunden-2016").core_geometry()
    wt = np.array([0.0, 50.0, 100.0])
    one = hrovat_tobler_steady_state(g, 200.0, wt)
    each = hrovat_tobler_steady_state(g, np.full(3, 200.0), wt)
    assert all(np.array_equal(one[k], each[k]) for k in each) and one["pump_torque_nm"].shape == (3,)
    rows = hrovat_tobler_steady_state(np.tile(g, (3, 1)), 200.0, wt)
    assert all(np.array_equal(rows[k], each[k]) for k in each)


@pytest.mark.parametrize("model", ["hrovat-tobler", "table", "quasi-dynamic"])
def test_an_overflowing_characteristic_names_the_pump_speed(model):
    conv = load_converter("li-sunden-2016")
    with pytest.warns(TcsimWarning, match=r"^argument: pump_speed_rpm = 1e\+200"), pytest.raises(InputError) as e:
        characterise(conv, model, 1e200, allow_implausible=True)
    assert (e.value.source, e.value.field, e.value.value) == ("argument", "pump_speed_rpm", 1e200)


def test_an_implausible_pump_speed_is_refused_unless_allowed(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["characterise", "li-sunden-2016", "--pump-speed-rpm", "1e200", "--out", str(out)]) == 2
    (line,) = _lines(capsys)
    assert line.startswith(
        "error: command line: --pump-speed-rpm = 1e+200: expected a plausible speed, -10504 to 10504 rpm"
    )
    assert line.endswith("--allow-implausible runs it anyway") and not out.exists()
    args = ["characterise", "li-sunden-2016", "--pump-speed-rpm", "12000", "--allow-implausible", "--out", str(out)]
    assert main(args) == 0
    assert _lines(capsys)[0].startswith("warning: command line: --pump-speed-rpm = 12000 is outside the plausible")
    df = pd.read_csv(out / "characteristic.csv")
    assert np.isfinite(df["pump_torque_nm"]).all() and (df["pump_torque_nm"] >= 0).all()


# ---------------------------------------------------------------------------------------------
# --initial


@pytest.fixture
def measurement(tmp_path) -> str:
    t = np.arange(0.0, 2.0, 0.01)
    path = tmp_path / "log.csv"
    pd.DataFrame({"time_s": t, "pump_torque_nm": 40.0 + 0 * t, "turbine_speed_rad_s": 50.0 + t}).to_csv(
        path, index=False
    )
    return str(path)


@pytest.mark.parametrize(
    ("item", "field"), [("pump_speed_rad_s=1e300", "pump_speed_rad_s"), ("flow_m3_s=-50", "flow_m3_s")]
)
def test_implausible_initial_values_are_refused(measurement, tmp_path, capsys, item, field):
    out = tmp_path / "o"
    assert main(["replay", "li-sunden-2016", measurement, "--initial", item, "--out", str(out)]) == 2
    (line,) = _lines(capsys)
    assert line.startswith(f"error: command line: --initial {field} = ") and "--allow-implausible" in line
    assert not out.exists()


def test_an_allowed_initial_value_that_overflows_is_refused_not_run(measurement, tmp_path, capsys):
    out = tmp_path / "o"
    args = ["replay", "li-sunden-2016", measurement, "-m", "hrovat-tobler", "--initial", "pump_speed_rad_s=1e300"]
    assert main([*args, "--allow-implausible", "--out", str(out)]) == 2
    lines = _lines(capsys)
    assert lines[0].startswith("warning: command line: --initial pump_speed_rad_s = 1e+300 is outside")
    assert lines[1].startswith("error: command line: --initial pump_speed_rad_s = 1e+300: expected")
    assert len(lines) == 2 and not out.exists()


# ---------------------------------------------------------------------------------------------
# non-finite values in result files


def test_non_finite_results_are_written_with_a_warning_naming_file_and_columns(tmp_path):
    ok = pd.DataFrame(
        {
            "speed_ratio": [0.0, np.nan],  # undefined ratios may be NaN
            "k_factor_rpm_per_sqrt_nm": [100.0, np.inf],  # infinite at zero capacity by definition
            "pump_speed_rad_s": [1.0, 2.0],
        }
    )
    bad = ok.assign(pump_torque_nm=[np.inf, 1.0], flow_m3_s=[np.nan, 0.1], turbine_speed_rad_s=[-np.inf, 1.0])
    assert non_finite_columns(ok) == {}
    # a coordinate one model of a combined frame lacks is NaN for its whole run: not reported
    runs = pd.DataFrame({"model": ["table"] * 2 + ["hrovat-tobler"] * 2, "flow_m3_s": [np.nan, np.nan, 0.1, 0.2]})
    assert non_finite_columns(runs) == {}
    assert non_finite_columns(runs.assign(flow_m3_s=[np.nan, np.nan, 0.1, np.nan])) == {"flow_m3_s": 1}
    assert non_finite_columns(bad) == {"pump_torque_nm": 1, "flow_m3_s": 1, "turbine_speed_rad_s": 1}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_frames({"ok.csv": ok}, tmp_path)
    with pytest.warns(TcsimWarning, match=r"bad\.csv: non-finite values .* in pump_torque_nm \(1\), flow_m3_s \(1\)"):
        paths = write_frames({"bad.csv": bad}, tmp_path)
    assert paths == [tmp_path / "bad.csv"] and (tmp_path / "bad.csv").exists()


# ---------------------------------------------------------------------------------------------
# converter geometry


def _converter(tmp_path: Path, key: str, value: str, name: str = "c.toml") -> str:
    lines = BUNDLED.read_text(encoding="utf-8").splitlines()
    hits = [i for i, line in enumerate(lines) if line.split("=")[0].strip() == key]
    assert len(hits) == 1, key
    lines[hits[0]] = f"{key} = {value}"
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return str(path)


@pytest.mark.parametrize(
    ("key", "value", "shown"),
    [
        ("pump_exit_radius_m", "1e6", "1e+06"),
        ("stator_exit_angle_deg", "89.999999999", "90"),
        ("fluid_density_kg_m3", "8.4e-292", "8.4e-292"),
        ("flow_area_m2", "3.0", "3"),
        ("friction_loss", "50.0", "50"),
    ],
)
def test_implausible_design_values_warn_naming_the_field(tmp_path, key, value, shown):
    path = _converter(tmp_path, key, value)
    pattern = re.escape(f"c.toml: [geometry].{key} = {shown} is outside the plausible")
    with pytest.warns(TcsimWarning, match=pattern):
        load_converter(path)


def test_an_overflowing_density_is_refused_naming_the_field(tmp_path, capsys):
    path = _converter(tmp_path, "fluid_density_kg_m3", "1e300")
    with pytest.raises(InputError) as e, warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)
        load_converter(path)
    assert (e.value.source, e.value.field) == (path, "[geometry].fluid_density_kg_m3")
    assert main(["characterise", path, "--out", str(tmp_path / "o")]) == 2
    assert _lines(capsys)[-1].startswith(f"error: {path}: [geometry].fluid_density_kg_m3 = 1e+300: expected a value")


def test_a_density_that_overflows_the_quasi_dynamic_energy_is_refused(tmp_path):
    path = _converter(tmp_path, "fluid_density_kg_m3", "8.4e-292")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TcsimWarning)
        conv = load_converter(path)
    with pytest.raises(InputError) as e:
        tr.simulate(conv, tr.isolated_takeoff(), model="quasi-dynamic")
    assert (e.value.source, e.value.field, e.value.value) == (path, "fluid_density_kg_m3", 8.4e-292)


def test_the_bundled_converters_are_plausible():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        names = [c.name for c in bundled_converters()]
    assert {"li-sunden-2016", "li-sunden-2016-fitted"} <= set(names)


@pytest.mark.parametrize(
    ("arrays", "kwargs", "field"),
    [
        (([0.0, 0.5, 1.0], [2.0, 1.5, np.nan], [1e-3, 1e-3, 1e-3]), {}, "torque_ratio[2]"),
        (([0.0, 0.5], [2.0, 1.5, 1.0], [1e-3] * 3), {}, "torque_ratio"),
        (([], [], []), {}, "speed_ratio"),
        (([0.0], [2.0], [1e-3]), {}, "speed_ratio"),
        (([0.5, 0.0], [2.0, 1.0], [1e-3, 1e-3]), {}, "speed_ratio[1]"),
        (([0.0, 0.5], [-1.0, 1.0], [1e-3, 1e-3]), {}, "torque_ratio[0]"),
        (([0.0, 0.5], [2.0, 1.0], [0.0, 1e-3]), {}, "capacity_factor_nm_s2[0]"),
        (("abc", [1.0], [1.0]), {}, "speed_ratio"),
        (([[0.0, 0.5]], [2.0, 1.0], [1e-3, 1e-3]), {}, "speed_ratio"),
        (([0.0, 0.5], [2.0, 1.0], [1e-3, 1e-3]), {"convention": "k_factor"}, "convention"),
    ],
)
def test_a_table_made_in_python_is_checked_as_a_files_is(arrays, kwargs, field):
    """A trial: ``Characteristic`` (documented as validated) took NaN, mismatched lengths, an empty
    or decreasing table, a negative TR and a string; the fit then failed with an IndexError or
    blamed the start geometry, or "succeeded" on an unsorted table."""
    with pytest.raises(InputError) as e:
        Characteristic(*(np.asarray(a, dtype=object) if isinstance(a, str) else a for a in arrays), **kwargs)
    assert (e.value.source, e.value.field) == ("Characteristic", field), str(e.value)


def test_a_table_made_in_python_runs_like_the_files():
    c = load_converter("li-sunden-2016").characteristic
    again = Characteristic(list(c.speed_ratio), list(c.torque_ratio), list(c.capacity_factor_nm_s2), source="mine")
    assert all(np.array_equal(a, b) for a, b in zip(again.arrays(), c.arrays(), strict=True))
    assert again.speed_ratio.dtype == float


def test_the_coupling_point_of_a_bundled_name_is_that_of_its_converter():
    assert coupling_point("li-sunden-2016") == coupling_point(load_converter("li-sunden-2016"))


def test_a_converter_that_is_not_a_name_or_a_path_is_an_input_error():
    """A review: ``coupling_point(None)`` and ``load_converter(123)`` were bare TypeErrors of
    ``Path``; ``steady_state(None, ...)`` already named the argument."""
    for call in (lambda: coupling_point(None), lambda: load_converter(123), lambda: load_converter(["a"])):
        with pytest.raises(InputError) as e:
            call()
        assert (e.value.source, e.value.field) == ("argument", "converter")
        assert e.value.expected.startswith("a bundled converter's name")


def test_other_shape_effects_are_numbers_of_a_model_that_has_them():
    """A review: the table model's ``with_shape_effects`` was a bare ValueError, a string a
    ValueError of ``float`` and None a TypeError."""
    table = dynamic_model("li-sunden-2016", "table")
    with pytest.raises(InputError) as e:
        table.with_shape_effects(0.001, 0.001)
    assert (e.value.field, e.value.value) == ("model", "table")
    ht = dynamic_model("li-sunden-2016", "hrovat-tobler")
    bad = [(("a", 0.0), "pump_m2"), ((0.0, None), "turbine_m2"), ((0.0, 0.0, True), "stator_m2")]
    bad += [((np.nan, 0.0), "pump_m2"), ((0.0, np.inf), "turbine_m2"), ((0.0, 0.0, -np.inf), "stator_m2")]
    for args, field in bad:
        with pytest.raises(InputError) as e:
            ht.with_shape_effects(*args)
        assert (e.value.source, e.value.field) == ("argument", field)
    other = ht.with_shape_effects(np.float64(0.001), 0.002)
    assert other.shape_effect_m2 == (0.001, 0.002, ht.shape_effect_m2[2])
    assert all(type(v) is float for v in other.spec["shape_effect_m2"])
