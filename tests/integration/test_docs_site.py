"""The documentation site (issue 17): ``mkdocs build --strict`` (warnings are errors: a broken link or
anchor, a page missing from the nav, a docstring mkdocstrings cannot read) and the worked examples
of ``docs/examples/`` (a K-factor table to an FMU in FMPy, replaying a measurement and fitting shape
effects, the launch comparison, a drive cycle, a design study), each run in its fast mode, producing
its figure; and the generated input-file reference (vehicle, scenario, measurement parts).

The build needs the ``docs`` extra (``pip install ".[docs]"``); without it the build test is skipped,
except in CI (``CI`` set), where the extra is installed and a skip would hide the check."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tcsim import _core
from tcsim.io import measurement as measurement_io
from tcsim.models.converter import load_converter
from tcsim.transient import PumpTorqueTurbineSpeed, dynamic_model, simulate

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.subprocess


def _need_mkdocs() -> None:
    if importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings") is None:
        if os.environ.get("CI"):
            pytest.fail('CI: the docs extra is not installed (pip install ".[docs]")')
        pytest.skip('the docs extra is not installed (pip install ".[docs]")')


def test_site_builds_strict(tmp_path):
    _need_mkdocs()
    site = tmp_path / "site"
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    run = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(REPO / "mkdocs.yml"), "-d", str(site)],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-4000:]
    assert not re.search(r"^WARNING", run.stderr, flags=re.M), run.stderr[-4000:]
    # the generated reference, the API reference and the example's included script are on the site
    reference = (site / "reference" / "input-files" / "index.html").read_text(encoding="utf-8")
    assert "pump_exit_angle_deg" in reference and "capacity_factor_nm_s2" in reference
    assert "a finite number at least 50 and at most 200000" in reference  # [body].mass_kg, from the core
    api = (site / "api" / "transient" / "index.html").read_text(encoding="utf-8")
    assert "simulate_batch" in api
    assert not re.search(r":(func|class|mod):<code>", api), "a docstring's Sphinx role rendered as text"
    example = (site / "examples" / "launch-comparison" / "index.html").read_text(encoding="utf-8")
    assert "run_comparison" in example
    assert not (REPO / "site").exists()


def _run_example(script: str, out: Path) -> subprocess.CompletedProcess[str]:
    """``docs/examples/<script> --fast --out <out>``, run in ``out``; it must succeed."""
    run = subprocess.run(
        [sys.executable, str(REPO / "docs" / "examples" / script), "--fast", "--out", str(out)],
        cwd=out,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-4000:]
    return run


def test_launch_comparison_example(tmp_path):
    run = _run_example("launch_comparison.py", tmp_path)
    figure = tmp_path / "launch_comparison.png"
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = {line.split()[0]: line.split()[1:] for line in run.stdout.splitlines()[1:4]}
    assert set(rows) == {"table", "hrovat-tobler", "quasi-dynamic"}
    # every model passes 50 km/h in the short run; the dynamic models dip below the table model
    dips = {model: float(values[2]) for model, values in rows.items()}
    assert all(0.0 < float(values[0]) < 4.0 for values in rows.values())
    assert dips["table"] == 0.0 and dips["quasi-dynamic"] > dips["hrovat-tobler"] > 0.0


def test_design_study_example(tmp_path):
    run = _run_example("design_study.py", tmp_path)
    assert (tmp_path / "pareto.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = [line.split() for line in run.stdout.splitlines()[1:5]]
    assert len(rows) == 4 and all(len(r) == 6 for r in rows), run.stdout  # the 2 x 2 corners, no error
    figures = {(float(r[0]), float(r[1])): (float(r[2]), float(r[3]), r[5]) for r in rows}
    # a larger pump exit radius lowers the stall TR; a more negative exit angle deepens the take-off dip
    for angle in (-30.0, -10.0):
        assert figures[(0.11, angle)][0] > figures[(0.13, angle)][0]
    for radius in (0.11, 0.13):
        assert figures[(radius, -30.0)][1] > figures[(radius, -10.0)][1]
    assert any(front == "True" for _, _, front in figures.values())


def test_sphinx_roles_become_plain_code():
    _need_mkdocs()
    sys.path.insert(0, str(REPO / "tools"))
    try:
        import docs_hooks  # noqa: PLC0415  (tools/ is not a package; mkdocs is the docs extra only)
    finally:
        sys.path.remove(str(REPO / "tools"))
    html = "a :class:<code>~tcsim.transient.TransientResult</code>, :func:<code>simulate</code>; x:<code>y</code>"
    assert docs_hooks.plain_roles(html) == "a <code>TransientResult</code>, <code>simulate</code>; x:<code>y</code>"


def _docs_reference():
    sys.path.insert(0, str(REPO / "tools"))
    try:
        import docs_reference  # noqa: PLC0415  (tools/ is not a package)
    finally:
        sys.path.remove(str(REPO / "tools"))
    return docs_reference


def test_vehicle_reference_is_the_core_schema():
    """The vehicle part of the input-file reference lists every key of the core's schema with its
    unit, whether it is required, and the range the core's check uses (the core's tests check each
    row against the check); docs/vehicle.md keeps no hand-written copy of the ranges."""
    part = "\n".join(_docs_reference().vehicle_part())
    schema = _core.vehicle_schema()
    assert len(schema) > 50
    for row in schema:
        required = "required" if row["required"] else f"optional, default {row['default']}"
        allowed = row["range"].replace("|", "\\|")
        assert f"| `{row['key']}` | {row['unit']} | {required} | {allowed} |" in part, row
    assert "| `mass_kg` | kg | required | a finite number at least 50 and at most 200000 | `" in part
    assert "| `min_gear` |  | required | an integer from 1 to the number of gears | `3` |" in part
    vehicle_md = (REPO / "docs" / "vehicle.md").read_text(encoding="utf-8")
    assert (
        "200 000" not in vehicle_md.split("## Coordinates")[0] and "reference/input-files.md#vehicle-file" in vehicle_md
    )


def test_scenario_and_measurement_reference():
    """The scenario part lists the columns tcsim.io.scenario reads, with units and ranges; the
    measurement part lists every channel tcsim.io.measurement knows, with its check and the
    commands that read it."""
    ref = _docs_reference()
    scenario = "\n".join(ref.scenario_part())
    assert "| `time_s` or `time_ms` | s, ms | required |" in scenario
    assert "| `accelerator_pedal` or `accelerator_pedal_percent` | 1, % | required | 0 to 1, 0 to 100 |" in scenario
    assert "| `engine_torque_nm` | N·m | optional |" in scenario
    rows = {line.split(" | ")[0].strip("| `"): line for line in ref.measurement_part() if line.startswith("| `")}
    assert set(rows) == set(measurement_io.INPUT_CHANNELS)
    assert "replay `--drive pump-torque`: input" in rows["pump_torque_nm"]
    assert "at least 0" in rows["lockup_capacity_nm"] and "torque-estimate: required" in rows["engine_torque_nm"]
    assert "fit-shapes: required" in rows["turbine_torque_nm"] and "-1100 to 1100 rad/s" in rows["turbine_speed_rad_s"]


def _example_module(name: str):
    """A docs example script as a module (its functions, not its ``main``)."""
    spec = importlib.util.spec_from_file_location(name, REPO / "docs" / "examples" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_fmu_from_table_example(tmp_path):
    """Example (a): the K-factor table → fitted converter → FMU → FMPy. The FMU's co-simulation (1 ms,
    with the turbine's rate) agrees with tcsim's own transient run of the fitted converter on the same
    inputs to 0.5 % of each output's range (docs/fmu.md's bound for this causality)."""
    run = _run_example("fmu_from_table.py", tmp_path)
    assert (tmp_path / "fmu_takeoff.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "table" / "characteristic.csv").is_file()  # the table model ran on the init file
    rows = [line.split() for line in run.stdout.splitlines()]
    printed = np.array([[float(x) for x in r] for r in rows if len(r) == 3 and r[0][0].isdigit()])
    assert printed.shape == (5, 3), run.stdout
    inputs = _example_module("fmu_from_table").takeoff_inputs(2.0)
    t = inputs["time"]
    drive = PumpTorqueTurbineSpeed(t, inputs["pump_torque_nm"], inputs["turbine_speed_rad_s"])
    model = dynamic_model(load_converter(tmp_path / "fit" / "fitted.toml"), "hrovat-tobler")
    ref = simulate(model, drive, times_s=printed[:, 0].tolist())
    for k, column in ((1, "pump_speed_rad_s"), (2, "turbine_torque_nm")):
        expected = np.asarray(ref[column])
        span = np.ptp(simulate(model, drive, times_s=t[::10].tolist())[column])
        assert np.max(np.abs(printed[:, k] - expected)) <= 0.005 * span + 0.01, (column, printed[:, k], expected)


def test_replay_fit_shapes_example(tmp_path):
    """Example (b): the synthetic rig record of a converter with known shape effects is replayed and
    fitted. The Hrovat & Tobler replay beats the table model on both compared channels, and the
    fitted (S_p, S_t) are within the printed bound of the true ones: |bias| + 3 standard deviations
    of the parametric bootstrap (the fit's uncertainty from the record's noise); the bound is
    informative (below half of each true value)."""
    run = _run_example("replay_fit_shapes.py", tmp_path)
    assert (tmp_path / "replay_fit_shapes.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "fit-shapes" / "shape_fit.json").is_file()
    lines = [line.split() for line in run.stdout.splitlines()]
    rmse = {(r[0], r[1]): float(r[2]) for r in lines if len(r) == 4 and r[1].endswith(("_rad_s", "_nm"))}
    assert len(rmse) == 6, run.stdout
    for channel in ("pump_speed_rad_s", "turbine_torque_nm"):
        assert rmse[("hrovat-tobler", channel)] < rmse[("table", channel)], (channel, rmse)
    shapes = {r[0]: [float(x) for x in r[1:]] for r in lines if r and r[0] in ("S_p", "S_t") and len(r) == 6}
    assert set(shapes) == {"S_p", "S_t"}, run.stdout
    for name, (true, fitted, bias, std, bound) in shapes.items():
        assert bound == pytest.approx(abs(bias) + 3 * std, abs=2e-5), (name, shapes[name])
        assert abs(fitted - true) <= bound, (name, true, fitted, bound)
        assert 0.0 < bound < 0.5 * true, (name, bound, true)


def test_drive_cycle_example(tmp_path):
    """Example (d): the bundled vehicle on the first 128 s of US06 with the three models. Each model
    follows the trace within docs/drive.md's bound (RMS speed error at most 2 km/h, above which
    ``tcsim drive`` warns), the energy balance closes to docs/drive.md's 1e-4 of the engine's work,
    and the lock-up is locked most of the time the trace is above 80 km/h."""
    run = _run_example("drive_cycle.py", tmp_path)
    assert (tmp_path / "drive_cycle.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    models = ("table", "hrovat-tobler", "quasi-dynamic")
    lines = [line.split() for line in run.stdout.splitlines()]
    summary = {r[0]: [float(x) for x in r[1:]] for r in lines if len(r) == 9 and r[0] in models}
    highway = {r[0]: float(r[1]) for r in lines if len(r) == 2 and r[0] in models}
    assert set(summary) == set(highway) == set(models), run.stdout
    for model, (rms, max_error, work, converter, lockup, brakes, residual, locked) in summary.items():
        assert 0.0 < rms <= 2.0 and rms <= max_error, (model, rms, max_error)
        assert abs(residual) <= 1e-4, (model, residual)
        assert work > converter + lockup > 0.0 and brakes > 0.0, (model, work, converter, lockup, brakes)
        assert 0.0 < locked < 1.0 and highway[model] > 0.5, (model, locked, highway[model])
