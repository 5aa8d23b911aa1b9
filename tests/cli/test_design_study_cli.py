"""``tcsim design-study DESIGN --sweep NAME=MIN:MAX:N [--sweep ...]`` end to end (issue 15 item 3):
study.csv and pareto.png written together; bad sweeps exit 2 with one ``error:`` line, nothing
written."""

from __future__ import annotations

import importlib
import os
import signal

import pandas as pd
import pytest

import tcsim.analysis.design_study as ds

APP = importlib.import_module("tcsim.cli.app")  # the module (``tcsim.cli.app`` the attribute is the Typer app)

OUTPUTS = {"study.csv", "pareto.png", "tcsim-manifest.json"}


def test_a_two_parameter_study_through_the_command(cli, tmp_path):
    r = cli(
        "design-study",
        "li-sunden-2016-design",
        "--sweep",
        "pump_exit_radius_m=0.11:0.13:3",
        "--sweep",
        "pump_exit_angle_deg=-30:-10:2",
        "--out",
        "o",
        cwd=tmp_path,
    )
    assert r.code == 0, r.stderr
    assert r.stderr == ""
    assert set(os.listdir(tmp_path / "o")) == OUTPUTS
    study = pd.read_csv(tmp_path / "o" / "study.csv", keep_default_na=False, na_values=[""])
    assert len(study) == 6
    assert study["pump_exit_radius_m"].tolist() == pytest.approx([0.11, 0.11, 0.12, 0.12, 0.13, 0.13])
    assert study["pump_exit_angle_deg"].tolist() == [-30.0, -10.0] * 3
    assert study["error"].isna().all()
    assert study["stall_torque_ratio"].notna().all() and study["takeoff_effective_tr_dip"].notna().all()
    assert study["pareto_front"].any()
    assert "6 designs of pump_exit_radius_m × pump_exit_angle_deg" in r.stdout


@pytest.mark.parametrize(
    ("sweeps", "fragments"),
    [
        (["axial_length_m=0.1:0.2:3"], ["--sweep", "NAME", "axial_length_m", "squash_ratio"]),
        (["squash_ratio=0.3:0.1:3"], ["--sweep", "squash_ratio bounds", "0.3:0.1", "MIN < MAX"]),
        (["squash_ratio=0:0.3:1"], ["--sweep", "squash_ratio count", "= 1", "from 2 to 1000"]),
        (["squash_ratio=0:0.3:100000"], ["--sweep", "squash_ratio count", "100000"]),
        (["squash_ratio=0:0.3:x"], ["--sweep", "squash_ratio count", "x"]),
        (["squash_ratio=0:0.3:200", "pump_exit_radius_m=0.11:0.13:200"], ["--sweep", "designs", "40000"]),
        (["squash_ratio=0:0.3:2", "squash_ratio=0:0.2:2"], ["--sweep", "NAME", "two different"]),
        (
            ["squash_ratio=0:0.3:2", "pump_exit_radius_m=0.11:0.13:2", "pump_exit_angle_deg=-30:-10:2"],
            ["--sweep", "parameters", "3", "one or two"],
        ),
    ],
)
def test_bad_sweeps_exit_2_with_one_line_and_write_nothing(cli, tmp_path, sweeps, fragments):
    args = [a for s in sweeps for a in ("--sweep", s)]
    r = cli("design-study", "li-sunden-2016-design", *args, "--out", "o", cwd=tmp_path)
    assert r.code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert "expected" in lines[0]
    for f in fragments:
        assert f in lines[0], (f, lines[0])
    assert os.listdir(tmp_path) == []


def test_a_missing_design_exits_2_naming_it(cli, tmp_path):
    r = cli("design-study", "nope.toml", "--sweep", "squash_ratio=0:0.3:2", "--out", "o", cwd=tmp_path)
    assert r.code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: nope.toml: design = 'nope.toml': expected"), r.stderr
    assert os.listdir(tmp_path) == []


def test_without_out_it_writes_the_default_folder(cli, tmp_path):
    """The default ``--out`` (a Path) goes through the ``--out`` parser too (it failed with exit 1)."""
    r = cli("design-study", "li-sunden-2016-design", "--sweep", "squash_ratio=0:0.3:2", cwd=tmp_path)
    assert r.code == 0, r.stderr
    assert os.listdir(tmp_path) == ["design-study"]
    assert set(os.listdir(tmp_path / "design-study")) == OUTPUTS


def test_a_signal_swallowed_into_another_exception_is_still_an_interrupt(cli, tmp_path, monkeypatch):
    """SIGTERM arriving while an extension module initialises becomes ``ImportError: initialization
    failed``; it exited 1 ("tcsim failed") instead of 143 (seen in test_signals' start phase)."""

    def interrupted_import(*args, **kwargs):
        APP._received.append(signal.SIGTERM)
        raise ImportError("initialization failed")

    monkeypatch.setattr(ds, "design_study", interrupted_import)
    r = cli("design-study", "li-sunden-2016-design", "--sweep", "squash_ratio=0:0.3:2", "--out", "o", cwd=tmp_path)
    assert r.code == 128 + signal.SIGTERM, r.stderr
    assert r.stdout.strip().splitlines() + r.stderr.strip().splitlines() == ["interrupted (SIGTERM): nothing written"]
    assert os.listdir(tmp_path) == []


def test_a_study_without_any_figures_says_so(cli, tmp_path):
    # fresh-eyes trial: every design refused, and the run read like a good one (exit 0, no warning)
    r = cli("design-study", "li-sunden-2016-design", "--sweep", "squash_ratio=1.0:1.5:2", "--out", tmp_path / "o")
    assert r.code == 0, r.stderr
    assert "warning: none of the 2 designs has figures (the first: --sweep: squash_ratio = 1: " in r.stderr, r.stderr
    ok = cli("design-study", "li-sunden-2016-design", "--sweep", "squash_ratio=0.0:1.0:2", "--out", tmp_path / "p")
    assert ok.code == 0 and "none of the" not in ok.stderr, ok.stderr
