"""Replay inputs that hung or went wrong quietly (issue 10, defects 3, 6, 9): windows the record
cannot hold are refused, the smoothed derivative and the metric windows cost O(n) (run under a
subprocess hang guard, no timing asserted), implausible measured values need
``--allow-implausible``, and a corrupt MDF4 file gives exactly one line on stderr."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from asammdf import MDF, Signal

from tcsim.analysis.replay import error_metrics

#: A generous bound for runs that take well under a second when O(n) and minutes when not.
HANG_GUARD_S = 120

N = 300
TIME_S = np.round(np.arange(N) * 0.01, 12)  # 100 Hz, a 2.99 s record


def measurement(path: Path, **changes) -> Path:
    """A take-off-like measurement: pump torque and turbine speed (the inputs of drive pump-torque),
    pump speed and turbine torque (its reference outputs)."""
    frame = pd.DataFrame(
        {
            "time_s": TIME_S,
            "pump_torque_nm": 150.0 + 40.0 * np.sin(3.0 * TIME_S),
            "turbine_speed_rad_s": 60.0 * TIME_S,
            "pump_speed_rad_s": 100.0 + 50.0 * TIME_S,
            "turbine_torque_nm": 200.0 - 10.0 * TIME_S,
            **changes,
        }
    )
    frame.to_csv(path, index=False, float_format="%.17g")
    return path


def one_line_error(r, *words: str) -> str:
    assert r.code == 2, (r.code, r.stdout, r.stderr)
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    for word in words:
        assert word in lines[0], (word, lines[0])
    return lines[0]


def run_python(code: str) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter, killed (and the test failed) after :data:`HANG_GUARD_S`."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=HANG_GUARD_S
    )


# --------------------------------------------------------------------------------------------
# windows the record cannot hold


@pytest.mark.parametrize(
    ("option", "value", "words"),
    [
        ("--metrics-window", "1e-9", ["median sample spacing 0.01 s", "span 2.99 s"]),
        ("--metrics-window", "0.005", ["median sample spacing 0.01 s"]),
        ("--metrics-window", "10", ["span 2.99 s"]),
        ("--window", "1e300", ["derivative window from 0 s", "span 2.99 s"]),
        ("--window", "3.5", ["span 2.99 s"]),
    ],
)
def test_windows_the_record_cannot_hold_are_refused(cli, tmp_path, option, value, words):
    path = measurement(tmp_path / "m.csv")
    out = tmp_path / "out"
    r = cli("replay", "li-sunden-2016", path, "--out", out, "-m", "table", option, value)
    msg = one_line_error(r, f"command line: {option} = {float(value):g}", str(path), *words)
    assert "expected" in msg and not out.exists()


def test_windows_within_the_record_and_the_defaults_on_a_short_record_run(cli, tmp_path):
    path = measurement(tmp_path / "m.csv")
    out = tmp_path / "out"
    r = cli("replay", "li-sunden-2016", path, "--out", out, "-m", "table", "--metrics-window", "0.01", "--window", "0")
    assert r.code == 0, r.stderr
    metrics = pd.read_csv(out / "metrics.csv")
    assert (metrics.groupby("channel").size() == N).all()  # "all", then a window per step (the last holds two)
    short = tmp_path / "short.csv"  # 0.5 s: shorter than the default metrics window of 1 s
    pd.read_csv(path).iloc[:51].to_csv(short, index=False)
    r = cli("replay", "li-sunden-2016", short, "--out", tmp_path / "short", "-m", "table")
    assert r.code == 0, r.stderr


# --------------------------------------------------------------------------------------------
# O(n): the derivative and the metric windows of a long record


def test_the_smoothed_derivative_of_a_megasample_record_does_not_hang():
    r = run_python(
        """
        import numpy as np
        from tcsim import _core
        t = np.arange(1_000_000) * 1e-6  # 1 MHz: 40 001 samples in each 40 ms window
        rate = _core.smoothed_rate(t, 3.0 * t + np.sin(50.0 * t), 0.04)
        t2 = np.arange(200_000) * 1e-3  # a window longer than the record: every sample in every window
        whole = _core.smoothed_rate(t2, 2.0 * t2 - 1.0, 1e300)
        print(np.isfinite(rate).all(), np.allclose(whole, 2.0, rtol=1e-9))
        """
    )
    assert r.returncode == 0 and r.stdout.split() == ["True", "True"], r.stderr


def test_metric_windows_of_one_sample_each_over_a_long_record_do_not_hang():
    r = run_python(
        """
        import numpy as np
        from tcsim.analysis.replay import error_metrics
        t = np.arange(200_000) * 1e-3
        m = np.sin(t)
        df = error_metrics(t, m, m + 0.5, window_s=1e-3)
        print(len(df), float(df["rmse"].max()), int(df["n"][1:].max()))
        """
    )
    assert r.returncode == 0, r.stderr
    rows, worst, most = r.stdout.split()
    # "all", then 199 999 windows: the last one closed at the last sample holds two
    assert (int(rows), int(most)) == (200_000, 2)
    assert float(worst) == pytest.approx(0.5, rel=1e-12)


def test_window_statistics_match_the_direct_formulas():
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.002, 0.02, 2000))
    m, s = np.sin(t), np.sin(t) + rng.normal(0.0, 0.1, len(t))
    s[37] = np.nan  # a NaN is the largest error of its window, as np.argmax has it
    df = error_metrics(t, m, s, window_s=0.7)
    edges = t[0] + 0.7 * np.arange(1, 100)
    for _, row in df.iloc[1:].iterrows():
        k = int(row["window"]) - 1
        inside = (t >= t[0] + 0.7 * k - 1e-12) & ((t < edges[k] - 1e-9) | (k == len(df) - 2))
        err = s[inside] - m[inside]
        j = int(np.argmax(np.abs(err)))
        assert row["n"] == inside.sum()
        np.testing.assert_allclose(row["rmse"], np.sqrt(np.mean(err**2)), rtol=1e-12)
        np.testing.assert_allclose(row["max_abs_error"], abs(err[j]), rtol=1e-12)
        assert row["max_abs_error_time_s"] == t[inside][j]


# --------------------------------------------------------------------------------------------
# implausible measured values: refused, or run with --allow-implausible


def test_rpm_in_a_rad_s_column_needs_allow_implausible(cli, tmp_path):
    rpm = 450.0 * TIME_S  # to 1345 "rad/s": rpm
    path = measurement(tmp_path / "m.csv", turbine_speed_rad_s=rpm)
    out = tmp_path / "out"
    r = cli("replay", "li-sunden-2016", path, "--out", out, "-m", "table")
    one_line_error(r, str(path), "turbine_speed_rad_s = 1", "rad/s at row", "--allow-implausible")
    r = cli("fit-shapes", "li-sunden-2016", path, "--out", out)
    one_line_error(r, "turbine_speed_rad_s", "--allow-implausible")
    r = cli("replay", "li-sunden-2016", path, "--out", out, "-m", "table", "--allow-implausible")
    assert r.code == 0, r.stderr
    assert "warning:" in r.stderr and "outside the plausible" in r.stderr


def test_a_scenario_in_milliseconds_needs_allow_implausible(cli, tmp_path):
    path = tmp_path / "s.csv"
    t = np.arange(0.0, 20_001.0, 100.0)  # a 20 s take-off in ms, under time_s
    pd.DataFrame({"time_s": t, "accelerator_pedal": 1.0, "brake_pedal": 0.0}).to_csv(path, index=False)
    r = cli("launch", "--scenario", path, "--out", tmp_path / "out")
    one_line_error(r, str(path), "time_s (time span, s) = 20000", "--allow-implausible")


# --------------------------------------------------------------------------------------------
# a corrupt MDF4: the message and nothing after it


@pytest.mark.parametrize("keep", [0.5, 0.02])
def test_a_corrupt_mdf4_gives_one_line_and_no_traceback(tmp_path, keep):
    good = tmp_path / "good.mf4"
    mdf = MDF(version="4.10")
    mdf.append([Signal(np.full(N, 40.0), TIME_S, name="pump_torque_nm"), Signal(TIME_S, TIME_S, name="x")])
    mdf.save(good, overwrite=True)
    mdf.close()
    data = good.read_bytes()
    bad = tmp_path / "bad.mf4"
    bad.write_bytes(data[: int(len(data) * keep)])
    env = dict(os.environ, COLUMNS="200")
    p = subprocess.run(
        [sys.executable, "-m", "tcsim", "replay", "li-sunden-2016", str(bad), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
        env=env,
    )
    assert p.returncode == 2
    assert p.stderr.count("\n") == 1 and p.stderr.startswith(f"error: {bad}: (file) = "), p.stderr
    assert "readable ASAM MDF" in p.stderr and p.stdout == ""
