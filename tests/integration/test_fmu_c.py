"""A take-off through the FMU's shared library from a plain C program (gcc, dlopen): no Python
inside the FMU at run time (issue 5)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from tcsim import transient

pytestmark = pytest.mark.subprocess

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("model", ["table", "quasi-dynamic", "hrovat-tobler"])
def test_plain_c_program_runs_a_takeoff(tmp_path, fmu_library, model):
    if shutil.which("gcc") is None:
        pytest.skip("needs gcc")
    resources = tmp_path / "resources"
    resources.mkdir()
    spec = transient.dynamic_model("li-sunden-2016", model).spec
    (resources / "model.json").write_text(json.dumps({"causality": "pump-torque", "model": spec, "parameters": []}))
    exe = tmp_path / "takeoff"
    subprocess.run(
        [
            "gcc",
            "-O2",
            "-Wall",
            "-Werror",
            "-o",
            exe,
            REPO / "tests" / "integration" / "c" / "takeoff.c",
            "-ldl",
            "-lm",
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    r = subprocess.run([exe, fmu_library, resources.as_uri()], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    rows = [list(map(float, line.split())) for line in r.stdout.splitlines()]
    assert len(rows) == 50 and rows[-1][0] == pytest.approx(5.0)
    # the same inputs through the Python API give the same pump speed at 5 s (first-order hold of
    # the inputs between communication points: the turbine speed ramp is linear, the torque ramp
    # has its corners on the 10 ms grid)
    t = [0.0, 0.1, 0.3, 5.0]
    ref = transient.simulate(
        "li-sunden-2016",
        transient.PumpTorqueTurbineSpeed(t, [40.0, 40.0, 250.0, 250.0], [40.0 * x for x in t], derivative_window_s=0.0),
        model=model,
        times_s=[0.0, 5.0],
    )
    assert rows[-1][1] == pytest.approx(ref["pump_speed_rad_s"][-1], rel=1e-3)
    assert rows[-1][2] == pytest.approx(ref["turbine_torque_nm"][-1], rel=1e-3)


def test_a_failure_is_an_fmi_error_with_a_message(tmp_path, fmu_library):
    """An inadmissible shape effect: fmi2ExitInitializationMode returns fmi2Error and the logger
    gets the bound; nothing crashes."""
    if shutil.which("gcc") is None:
        pytest.skip("needs gcc")
    resources = tmp_path / "resources"
    resources.mkdir()
    spec = transient.dynamic_model("li-sunden-2016", "hrovat-tobler").with_shape_effects(0.3, 0.0).spec
    (resources / "model.json").write_text(json.dumps({"model": spec, "parameters": []}))
    exe = tmp_path / "takeoff"
    subprocess.run(
        ["gcc", "-O2", "-o", exe, REPO / "tests" / "integration" / "c" / "takeoff.c", "-ldl", "-lm"], check=True
    )
    r = subprocess.run([exe, fmu_library, resources.as_uri()], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1
    assert "geometry.pump_shape_effect_m2" in r.stderr and "|S| <" in r.stderr
