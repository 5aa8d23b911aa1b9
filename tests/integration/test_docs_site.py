"""The documentation site (issue 17): ``mkdocs build --strict`` (warnings are errors: a broken link or
anchor, a page missing from the nav, a docstring mkdocstrings cannot read) and the worked examples
of ``docs/examples/`` (a K-factor table to an FMU in FMPy, the launch comparison, a design study),
each run in its fast mode, producing its figure.

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
