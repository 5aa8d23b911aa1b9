"""The commands' terminal tables on an 80-column terminal (issue 17 item 3): no line longer than the
terminal, every model's name whole on one line, every number's unit shown."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tcsim import transient
from tcsim.models.converter import bundled_converters

MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
HANG_GUARD_S = 600  # a hang guard only; nothing is asserted about durations


def run_80(*args: str, cwd: Path) -> str:
    """``tcsim ARGS`` in a subprocess on an 80-column terminal; its stdout."""
    env = dict(os.environ, COLUMNS="80")
    p = subprocess.run(
        [sys.executable, "-m", "tcsim", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=HANG_GUARD_S
    )
    assert p.returncode == 0, (p.returncode, p.stderr)
    return p.stdout


def assert_reads_well(stdout: str, units: tuple[str, ...]) -> None:
    lines = stdout.splitlines()
    assert all(len(line) <= 80 for line in lines), max(lines, key=len)
    words = {w.strip("│┃ ,") for line in lines for w in line.split()}
    for model in MODELS:
        assert model in words, (model, stdout)
    for unit in units:
        assert unit in stdout, (unit, stdout)


@pytest.mark.subprocess
def test_the_launch_table_fits_80_columns(tmp_path):
    out = run_80("launch", "--out", "o", cwd=tmp_path)
    assert_reads_well(out, ("[s]", "[m/s²]", "[-]", "[s after release]"))


@pytest.mark.subprocess
def test_the_drive_table_fits_80_columns(tmp_path):
    out = run_80("drive", "--cycle", "hwfet", "--out", "o", cwd=tmp_path)
    assert_reads_well(out, ("[km/h]", "[kJ]", "[-]"))


@pytest.mark.subprocess
def test_the_replay_table_fits_80_columns_with_a_unit_on_every_number(tmp_path):
    """The NRMSE column had no unit."""
    t = np.round(np.arange(401) * 5e-3, 12)
    f = transient.simulate("li-sunden-2016", transient.isolated_takeoff(), "hrovat-tobler", times_s=t).frame()
    f[["time_s", "pump_torque_nm", "turbine_speed_rad_s", "turbine_torque_nm"]].to_csv(tmp_path / "m.csv", index=False)
    out = run_80("replay", "li-sunden-2016", "m.csv", "--out", "o", cwd=tmp_path)
    assert_reads_well(out, ("RMSE", "[N·m]", "NRMSE [-]"))


@pytest.mark.subprocess
def test_converters_shows_each_source_whole(tmp_path):
    # fresh-eyes trial: a source holding a long path ended in "tests/data/converters/l…"
    stdout = run_80("converters", cwd=tmp_path)
    assert "…" not in stdout and all(len(line) <= 80 for line in stdout.splitlines())
    source_cells = [line.split("│")[3] for line in stdout.splitlines() if line.count("│") == 4]
    shown = "".join("".join(source_cells).split())
    for conv in bundled_converters():
        assert conv.name in stdout and "".join(conv.source.split()) in shown, conv.name
