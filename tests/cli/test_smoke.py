"""Smoke tests of the installed command as a user starts it, in a subprocess: the entry point, a
successful run, the bad-input contract (exit 2, one line, nothing written) and a usage error.
Every other command-line test runs in-process (the ``cli`` fixture)."""

from __future__ import annotations

import pandas as pd
import pytest

from conftest import run_cli

pytestmark = pytest.mark.subprocess


def test_help_lists_every_command():
    r = run_cli("--help")
    assert r.code == 0, r.stderr
    commands = ("launch", "converters", "characterise", "fit", "study", "replay", "fit-shapes", "export-fmu")
    for command in (*commands, "operating-point"):
        assert command in r.stdout


def test_characterise_writes_its_table(tmp_path):
    out = tmp_path / "out"
    r = run_cli("characterise", "li-sunden-2016", "--model", "table", "--out", out)
    assert r.code == 0, r.stderr
    frame = pd.read_csv(out / "characteristic.csv")
    assert len(frame) > 50 and frame["speed_ratio"].is_monotonic_increasing


def test_bad_input_is_exit_2_with_one_line_and_nothing_written(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("speed_ratio,torque_ratio,capacity_factor_nm_s2\n0,2.1,-1e-3\n0.5,1.4,2e-3\n")
    out = tmp_path / "out"
    r = run_cli("characterise", bad, "--out", out)
    assert r.code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "bad.csv" in lines[0] and "Traceback" not in r.stderr
    assert not out.exists()


def test_usage_error_is_exit_2():
    r = run_cli("characterise")
    assert r.code == 2 and "Traceback" not in r.stderr
