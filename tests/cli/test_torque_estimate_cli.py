"""``tcsim torque-estimate ESTIMATE DYNO`` end to end (issue 15 item 4): the outputs, a known delay and
the errors of a synthetic pair through the files, any supported format, the coarse-sampling warning;
bad input is exit 2 with one ``error:`` line naming the file, the field and the value, nothing
written and no input changed; an interrupt while writing leaves nothing."""

from __future__ import annotations

import hashlib
import os
import signal
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.io

from interrupts import interrupt
from torque_steps import load_response

DELAY_S = 0.2
HANG_GUARD_S = 600  # a hang guard only; nothing is asserted about durations
OUTPUTS = {"summary.csv", "steps.csv", "timeseries.csv", "torque_estimate.png", "steps.png", "tcsim-manifest.json"}


def write_dyno(path: Path) -> None:
    t = np.arange(0.0, 15.0, 1e-3)
    pd.DataFrame({"time_s": t, "engine_torque_nm": load_response(t)}).to_csv(path, index=False)


def estimate_columns(interval_s: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.013, 15.0, interval_s)
    return t, load_response(t - DELAY_S)


def sha(paths: list[Path]) -> dict[Path, str]:
    return {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths if p.is_file()}


def test_a_delayed_slow_copy_through_the_command(cli, tmp_path):
    """An ECM torque as a .mat v5 in milliseconds under its own name, the dyno's as CSV."""
    write_dyno(tmp_path / "dyno.csv")
    t, torque = estimate_columns(0.1)
    scipy.io.savemat(tmp_path / "ecm.mat", {"time_ms": t * 1000.0, "EngTrq": torque})
    r = cli("torque-estimate", "ecm.mat", "dyno.csv", "--estimate-column", "EngTrq", "--out", "o", cwd=tmp_path)
    assert r.code == 0, r.stderr
    assert set(os.listdir(tmp_path / "o")) == OUTPUTS
    summary = pd.read_csv(tmp_path / "o" / "summary.csv").iloc[0]
    assert abs(summary["delay_s"] - DELAY_S) <= summary["grid_step_s"] == pytest.approx(1e-3)
    grid = pd.read_csv(tmp_path / "o" / "timeseries.csv")
    error = np.interp(grid["time_s"], t, torque) - load_response(grid["time_s"].to_numpy())
    assert summary["rmse_nm"] == pytest.approx(np.sqrt(np.mean(error**2)), rel=1e-6)
    steps = pd.read_csv(tmp_path / "o" / "steps.csv")
    assert steps["step"].tolist() == [1, 2]
    assert steps["t90_error_s"].to_numpy() == pytest.approx([DELAY_S, DELAY_S], abs=0.1)  # one estimate sample
    # 0.1 s samples against step 2's 0.236 s rise: the one warning line (thesis §3.3)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning:") and "too coarse" in lines[0], r.stderr
    assert "delay 0.2" in r.stdout and "step 2" in r.stdout


def test_a_fine_estimate_gives_no_warning_and_parquet_is_read(cli, tmp_path):
    write_dyno(tmp_path / "dyno.csv")
    t, torque = estimate_columns(0.02)
    pd.DataFrame({"time_s": t, "engine_torque_knm": torque / 1000.0}).to_parquet(tmp_path / "ecm.parquet")
    r = cli("torque-estimate", "ecm.parquet", "dyno.csv", "-o", "o", cwd=tmp_path)
    assert r.code == 0 and r.stderr == "", r.stderr
    summary = pd.read_csv(tmp_path / "o" / "summary.csv").iloc[0]
    assert summary["coarse_sampling"] == 0
    assert summary["rmse_aligned_nm"] < 0.05 * summary["rmse_nm"]  # kN·m converted, the delay removed


def _dyno(tmp: Path) -> None:
    write_dyno(tmp / "dyno.csv")


def _ecm(tmp: Path, name: str = "ecm.csv", **columns) -> None:
    t, torque = estimate_columns(0.1)
    data = {"time_s": t, "engine_torque_nm": torque}
    data.update(columns)
    pd.DataFrame({k: v for k, v in data.items() if v is not None}).to_csv(tmp / name, index=False)


def _with_nan(tmp: Path) -> None:
    t, torque = estimate_columns(0.1)
    torque[5] = np.nan
    _ecm(tmp, engine_torque_nm=torque)


def _backwards(tmp: Path) -> None:
    write_dyno(tmp / "dyno.csv")
    text = (tmp / "dyno.csv").read_text().splitlines()
    text[3], text[4] = text[4], text[3]
    (tmp / "dyno.csv").write_text("\n".join(text) + "\n")


def _text_cell(tmp: Path) -> None:
    t, torque = estimate_columns(0.1)
    cells = torque.astype(object)
    cells[2] = "abc"
    _ecm(tmp, engine_torque_nm=cells)


def _flat_dyno(tmp: Path) -> None:
    t = np.arange(0.0, 15.0, 0.01)
    pd.DataFrame({"time_s": t, "engine_torque_nm": np.full_like(t, 5.0)}).to_csv(tmp / "dyno.csv", index=False)


#: id -> (writers of the inputs, extra arguments, file named, fragments of the message)
BAD: dict[str, tuple[list[Callable[[Path], None]], list[str], str, list[str]]] = {
    "estimate-column-missing": (
        [_dyno, lambda p: _ecm(p, engine_torque_nm=None, EngTrq=estimate_columns()[1])],
        [],
        "ecm.csv",
        ["engine_torque_nm = 'missing'", "--estimate-column COLUMN", "EngTrq"],
    ),
    "measured-column-missing": (
        [_ecm, lambda p: pd.DataFrame({"time_s": [0.0, 1.0], "torque": [1.0, 2.0]}).to_csv(p / "dyno.csv")],
        [],
        "dyno.csv",
        ["engine_torque_nm = 'missing'", "--measured-column COLUMN"],
    ),
    "mapped-column-missing": ([_dyno, _ecm], ["--estimate-column", "Trq"], "ecm.csv", ["Trq = 'missing'"]),
    "time-not-increasing": ([_ecm, _backwards], [], "dyno.csv", ["time_s", "strictly increasing"]),
    "nan": ([_dyno, _with_nan], [], "ecm.csv", ["engine_torque_nm", "NaN at row 6", "finite"]),
    "text-cell": ([_dyno, _text_cell], [], "ecm.csv", ["engine_torque_nm", "'abc' at row 3", "numbers only"]),
    "one-row": (
        [_dyno, lambda p: (p / "ecm.csv").write_text("time_s,engine_torque_nm\n1.0,20.0\n")],
        [],
        "ecm.csv",
        ["1 rows", "at least 2 data rows"],
    ),
    "no-overlap": (
        [_dyno, lambda p: _ecm(p, time_s=estimate_columns()[0] + 100.0)],
        [],
        "ecm.csv",
        ["time_s", "100.013 s to", "overlapping the measured one (dyno.csv", "overlap has 0"],
    ),
    "constant-measured": ([_ecm, _flat_dyno], [], "dyno.csv", ["engine_torque_nm = 'constant 5 N·m", "varies"]),
    "max-delay-zero": ([_dyno, _ecm], ["--max-delay", "0"], "command line", ["--max-delay = 0", "> 0"]),
    "max-delay-nan": ([_dyno, _ecm], ["--max-delay", "nan"], "command line", ["--max-delay = nan", "finite"]),
    "unknown-extension": ([_dyno, lambda p: _ecm(p, name="ecm.txt")], [], "ecm.txt", ["(extension)", ".txt"]),
    "missing-file": ([_dyno], [], "ecm.csv", ["(file) = 'not found'"]),
    "implausible-torque": (
        [_dyno, lambda p: _ecm(p, engine_torque_nm=estimate_columns()[1] * 1000.0)],
        [],
        "ecm.csv",
        ["engine_torque_nm", "--allow-implausible"],
    ),
}


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
def test_bad_input_is_one_line_and_nothing_written(cli, tmp_path, case):
    writers, extra, file, fragments = BAD[case]
    for write in writers:
        write(tmp_path)
    estimate = "ecm.txt" if case == "unknown-extension" else "ecm.csv"
    before = sha(list(tmp_path.iterdir()))
    r = cli("torque-estimate", estimate, "dyno.csv", *extra, "--out", "o", cwd=tmp_path)
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("error: ")]
    assert r.code == 2, r.stderr
    assert len(errors) == 1 and errors == lines[-1:], r.stderr
    assert errors[0].startswith(f"error: {file}: ") and "expected" in errors[0], errors[0]
    for fragment in fragments:
        assert fragment in errors[0], (fragment, errors[0])
    assert "Traceback" not in r.stdout + r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in before)  # no o, no staging folder
    assert sha(list(before)) == before


def test_the_output_may_not_be_an_input(cli, tmp_path):
    _dyno(tmp_path)
    _ecm(tmp_path)
    r = cli("torque-estimate", "ecm.csv", "dyno.csv", "--out", "dyno.csv", cwd=tmp_path)
    assert r.code == 2 and r.stderr.strip().splitlines() == [
        "error: command line: --out = 'dyno.csv': expected a directory, not an input file of this run"
    ]


@pytest.mark.subprocess
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interrupt_while_writing_leaves_nothing(tmp_path, sig):
    _dyno(tmp_path)
    _ecm(tmp_path)
    inputs = sha(list(tmp_path.iterdir()))
    r = interrupt(["torque-estimate", "ecm.csv", "dyno.csv", "--out", "o"], sig, "writing", tmp_path)
    err = r.stderr
    assert r.returncode == 128 + sig, err
    assert err.strip().splitlines()[-1] == f"interrupted ({sig.name}): nothing written", err
    assert sorted(os.listdir(tmp_path)) == ["dyno.csv", "ecm.csv"]
    assert sha(list(inputs)) == inputs
