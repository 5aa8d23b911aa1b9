"""The launch summary's phase and comparison metrics (launch peak apart from the shift transients,
the effective-TR dip and recovery against the table model), recomputed independently from the
written files; the terminal summary at 80 columns; the one model style in every figure that
overlays the models (docs/launch_summary.md)."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_hex
from matplotlib.lines import Line2D
from rich.console import Console

from tcsim.analysis.launch import SUMMARY_COLUMNS, launch_summary
from tcsim.analysis.launch_metrics import (
    RECOVERY_BAND,
    SHIFT_SETTLE_S,
    dip_metrics,
    phase_metrics,
    recovery_time,
    shift_windows,
)
from tcsim.cli.launch import launch_files, write_launch
from tcsim.plots.characteristic import plot_characteristic
from tcsim.plots.replay import plot_replay
from tcsim.plots.styles import MODEL_STYLES, model_key
from tcsim.reports.console import launch_report

MODELS = ("table", "hrovat-tobler", "quasi-dynamic")
RELEASE_S = 5.0
#: The columns summary.csv had before issue 14; they keep their names and meaning.
OLD_COLUMNS = [
    "model",
    "time_0_100_km_h_s",
    "time_0_50_km_h_s",
    "peak_accel_m_s2",
    "mean_accel_first_0_5_s_m_s2",
    "min_effective_torque_ratio_first_0_5_s",
]

# ---------------------------------------------------------------------------------------------
# the metrics on synthetic series


def test_shift_windows_from_the_shifting_column_and_from_gear_changes():
    t = np.round(np.arange(0.0, 3.0001, 0.01), 9)
    shifting = ((t >= 1.0) & (t < 1.3)) | ((t >= 1.4) & (t < 1.6))
    w = shift_windows(t, shifting, None)
    assert [(t[s.first], t[s.last]) for s in w] == [(1.0, 1.29), (1.4, 1.59)]
    assert w[0].end == w[1].first  # the settle time stops at the next shift
    assert t[w[1].end - 1] == pytest.approx(1.59 + SHIFT_SETTLE_S)
    gear = np.where(t < 2.0, 1.0, 2.0)
    (g,) = shift_windows(t, None, gear)
    assert (t[g.first], t[g.last]) == (1.99, 2.0)
    assert shift_windows(t, None, None) == [] and shift_windows(t, np.zeros_like(t), gear) == []


def _shift_run():
    """Launch peak 5 m/s² at 1.0 s, a shift at 2–2.3 s from 3 m/s² with a 4.5 m/s² spike."""
    t = np.round(np.arange(0.0, 4.0001, 0.01), 9)
    bump = 5.0 * np.exp(-(((t - 1.0) / 0.3) ** 2))
    a = np.where(t < 0.5, 0.0, np.where(t <= 1.0, bump, np.maximum(bump, 3.0)))
    shifting = (t >= 2.0) & (t < 2.3)
    a = np.where(shifting, 4.5, a)
    return t, a, shifting


def test_phase_metrics_split_the_launch_peak_from_the_shift():
    t, a, shifting = _shift_run()
    m = phase_metrics(t, a, shift_windows(t, shifting, None), 0.5)
    assert m["launch_peak_accel_m_s2"] == pytest.approx(5.0) and m["launch_peak_accel_time_s"] == pytest.approx(0.5)
    assert m["shift_count"] == 1 and m["shift_peak_accel_m_s2"] == 4.5
    assert m["max_shift_accel_ratio"] == pytest.approx(4.5 / 3.0)
    none = phase_metrics(t, a, [], 0.5)
    assert none["shift_count"] == 0 and math.isnan(none["shift_peak_accel_m_s2"])
    assert none["launch_peak_accel_m_s2"] == pytest.approx(5.0)
    coasting = phase_metrics(t, np.where(t < 2.0, -1.0, a), shift_windows(t, shifting, None), 0.5)
    assert math.isnan(coasting["max_shift_accel_ratio"])  # no ratio to a deceleration
    assert phase_metrics(t, a, shift_windows(t, shifting, None), 2.5)["shift_count"] == 0  # shifts before it


def test_dip_and_recovery_of_a_decaying_deficit():
    t = np.round(np.arange(0.0, 3.0001, 0.001), 9)
    table = np.full_like(t, 2.0)
    deficit = np.where(t < 1.0, 0.0, 0.3 * np.exp(-(t - 1.0) / 0.2) * (1 - np.exp(-(t - 1.0) / 0.01)))
    model = table - deficit
    d = dip_metrics(t, model, t, table, 1.0, 0.5)
    k = np.argmax(deficit)
    assert d["dip"] == pytest.approx(deficit[k]) and d["dip_time_s"] == pytest.approx(t[k] - 1.0)
    mean = np.trapezoid(deficit[(t >= 1.0) & (t <= 1.5)], t[(t >= 1.0) & (t <= 1.5)]) / 0.5
    assert d["mean_deficit"] == pytest.approx(mean, rel=1e-9)
    # |Δ| falls to the band at 0.2 ln(0.3 / 0.05) after the release (the rise term is 1 by then)
    assert recovery_time(t, model, t, table, 1.0, math.inf) == pytest.approx(0.2 * math.log(0.3 / 0.05), abs=1e-4)
    assert recovery_time(t, table, t, table, 1.0, math.inf) == 0.0
    stuck = table - np.where(t < 1.0, 0.0, 2 * RECOVERY_BAND)
    assert math.isnan(recovery_time(t, stuck, t, table, 1.0, math.inf))
    # an excursion after the first recovery counts: recovered for good only after it
    late = model - np.where((t > 2.0) & (t < 2.1), 0.2, 0.0)
    assert recovery_time(t, late, t, table, 1.0, math.inf) == pytest.approx(1.1, abs=2e-3)
    assert recovery_time(t, late, t, table, 1.0, 1.9) == pytest.approx(0.2 * math.log(6), abs=1e-4)  # phase end
    assert math.isnan(dip_metrics(t, model, t[:1500], table[:1500], 1.0, 0.5)["dip"])  # the table ends early


def test_summary_without_a_table_run_leaves_the_comparison_empty():
    t, a, shifting = _shift_run()
    f = pd.DataFrame(
        {
            "time_s": t,
            "vehicle_speed_m_s": np.cumsum(a) * 0.01,
            "vehicle_accel_m_s2": a,
            "effective_torque_ratio": 2.0 - 0.1 * (t > 1.0),
            "shifting": shifting.astype(float),
        }
    )
    s = launch_summary({"quasi-dynamic": f}, 0.5)
    assert list(s.columns) == list(SUMMARY_COLUMNS)
    assert s.effective_torque_ratio_dip_first_0_5_s.isna().all() and s.shift_count.iloc[0] == 1
    both = launch_summary({"table": f, "quasi-dynamic": f.assign(effective_torque_ratio=1.9)}, 0.5).set_index("model")
    assert both.loc["table"].effective_torque_ratio_dip_first_0_5_s == 0.0
    assert both.loc["quasi-dynamic"].effective_torque_ratio_dip_first_0_5_s == pytest.approx(0.1)
    # Δ falls from 0.1 at 1.00 s to 0 at 1.01 s: it crosses the band halfway, 0.505 s after the release
    assert both.loc["quasi-dynamic"].effective_torque_ratio_recovery_time_s == pytest.approx(0.505)


# ---------------------------------------------------------------------------------------------
# the bundled launch, its files and its figures


@pytest.fixture(scope="module")
def bundled(tmp_path_factory):
    """The bundled flip-flop launch, its files written, and the figures it drew (left open)."""
    out = tmp_path_factory.mktemp("launch")
    result = launch_files(None, "flip-flop")
    figures = []
    close = plt.close
    plt.close = lambda fig=None: figures.append(fig)  # keep each figure to inspect its lines
    try:
        write_launch(result, out)
    finally:
        plt.close = close
    yield result, out, figures
    for fig in figures:
        plt.close(fig)


def _first_shift_s(frame: pd.DataFrame) -> float:
    shifting = frame[(frame.time_s >= RELEASE_S) & (frame.shifting > 0.5)]
    return float(shifting.time_s.iloc[0]) if len(shifting) else math.inf


def test_launch_peak_is_before_the_first_shift_and_apart_from_the_shift_peak(bundled):
    result, out, _ = bundled
    s = pd.read_csv(out / "summary.csv")
    assert list(s.columns) == list(SUMMARY_COLUMNS) and list(SUMMARY_COLUMNS[: len(OLD_COLUMNS)]) == OLD_COLUMNS
    events = pd.read_csv(out / "events.csv")
    for row in s.itertuples():
        f = pd.read_csv(out / f"{row.model}.csv")
        first = _first_shift_s(f)
        shift_events = events[(events.model == row.model) & events.kind.str.contains("shift")]
        assert row.shift_count >= 1 and first == pytest.approx(shift_events.time_s.min(), abs=0.011)
        peak_t = RELEASE_S + row.launch_peak_accel_time_s
        assert peak_t < first
        before = f[(f.time_s >= RELEASE_S) & (f.time_s < first)]
        assert row.launch_peak_accel_m_s2 == pytest.approx(before.vehicle_accel_m_s2.max(), abs=1e-9)
        assert row.launch_peak_accel_m_s2 != pytest.approx(row.shift_peak_accel_m_s2, abs=1e-3)
        assert row.peak_accel_m_s2 >= max(row.launch_peak_accel_m_s2, row.shift_peak_accel_m_s2) - 1e-12


def _deficit(out: Path, model: str, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """Δ = table − model at the model's samples in [a, b] and at both edges, from the CSV files."""
    f, ref = pd.read_csv(out / f"{model}.csv"), pd.read_csv(out / "table.csv")
    t = f.time_s.to_numpy()
    times = np.union1d(t[(t >= a) & (t <= b)], [a, b])
    e = np.interp(times, t, f.effective_torque_ratio.to_numpy())
    return times, np.interp(times, ref.time_s.to_numpy(), ref.effective_torque_ratio.to_numpy()) - e


def test_dip_and_recovery_agree_with_a_recomputation_from_the_csv_files(bundled):
    _, out, _ = bundled
    s = pd.read_csv(out / "summary.csv").set_index("model")
    table = pd.read_csv(out / "table.csv")
    for model in MODELS:
        times, d = _deficit(out, model, RELEASE_S, RELEASE_S + 0.5)
        row = s.loc[model]
        assert row.effective_torque_ratio_dip_first_0_5_s == pytest.approx(d.max(), abs=1e-9)
        assert row.effective_torque_ratio_dip_time_s == pytest.approx(times[np.argmax(d)] - RELEASE_S, abs=1e-9)
        mean = np.sum(0.5 * (d[1:] + d[:-1]) * np.diff(times)) / 0.5
        assert row.mean_effective_torque_ratio_deficit_first_0_5_s == pytest.approx(mean, abs=1e-9)
        end = min(_first_shift_s(pd.read_csv(out / f"{model}.csv")), _first_shift_s(table))
        times, d = _deficit(out, model, RELEASE_S, end)
        outside = np.flatnonzero(np.abs(d[:-1]) > RECOVERY_BAND)
        if not outside.size:
            assert row.effective_torque_ratio_recovery_time_s == 0.0
        else:
            k = outside[-1]
            assert times[k] - RELEASE_S <= row.effective_torque_ratio_recovery_time_s <= times[k + 1] - RELEASE_S
    reference = s.loc["table"]
    assert reference.effective_torque_ratio_dip_first_0_5_s == 0 == reference.effective_torque_ratio_recovery_time_s


def test_terminal_summary_fits_80_columns_with_names_whole_and_units(bundled):
    result, out, _ = bundled
    console = Console(width=80, record=True)
    console.print(launch_report(result, out))
    text = console.export_text()
    assert max(len(line) for line in text.splitlines()) <= 80
    assert "…" not in text
    header = next(line for line in text.splitlines() if "table" in line and "quasi-dynamic" in line)
    assert all(name in header.split() for name in MODELS)
    for unit in ("[s]", "[m/s²]", "[-]"):
        assert unit in text


# ---------------------------------------------------------------------------------------------
# one style per model in every figure that overlays the models


def _model_of(line: Line2D) -> str | None:
    label = line.get_label()
    by_label = {style.label: name for name, style in MODEL_STYLES.items()}
    return by_label.get(label) or model_key(label)


def _check_styles(figures) -> int:
    """Every axes with lines of several models: each model's line in its own style, the styles
    pairwise distinct in line style and marker; the number of such axes."""
    checked = 0
    for fig in figures:
        for ax in fig.axes:
            seen: dict[str, tuple] = {}
            for line in ax.get_lines():
                model = _model_of(line)
                if model is None:
                    continue
                style = MODEL_STYLES[model]
                assert to_hex(line.get_color()) == style.colour.lower(), (model, ax.get_title())
                seen[model] = (line.get_linestyle(), line.get_marker())
            if len(seen) > 1:
                assert len(set(seen.values())) == len(seen), seen
                checked += 1
    return checked


def test_launch_figures_tell_the_models_apart(bundled):
    _, _, figures = bundled
    assert _check_styles(figures) >= 6  # figs 3.5, 3.6, 3.20, effective TR, speeds, vehicle speed


def test_replay_and_characterise_figures_tell_the_models_apart(tmp_path, monkeypatch):
    figures = []
    monkeypatch.setattr(plt, "close", lambda fig=None: figures.append(fig))
    t = np.linspace(0.0, 1.0, 101)
    runs = {m: {"time_s": t, "turbine_torque_nm": np.sin(t) * (i + 1)} for i, m in enumerate(MODELS)}
    measured = {"turbine_torque_nm": np.sin(t)}
    for m in MODELS:
        runs[m]["effective_pump_torque_nm"] = runs[m]["effective_turbine_torque_nm"] = runs[m]["turbine_torque_nm"]
    measured["turbine_speed_rad_s"] = measured["pump_torque_nm"] = np.ones_like(t)
    inputs = ["pump_torque_nm", "turbine_speed_rad_s"]
    plot_replay(t, measured, runs, inputs, ["turbine_torque_nm"], "inputs", tmp_path)
    curve = pd.DataFrame(
        {
            "speed_ratio": t,
            "torque_ratio": 2 - t,
            "capacity_factor_nm_s2": 0.003 + 0 * t,
            "k_factor_rpm_per_sqrt_nm": 170 + t,
            "efficiency": t * (2 - t),
        }
    )
    plot_characteristic({f"{m} model": curve for m in MODELS}, tmp_path, "curves")
    monkeypatch.undo()
    try:
        assert _check_styles(figures) == 3 + 4  # the three channels drawn with models, the four quantities
    finally:
        for fig in figures:
            plt.close(fig)
