"""Figures of ``tcsim launch`` (Li & Sundén 2016, figures 3.5, 3.6, 3.20 and 4.3–4.6).

Every model is drawn in its own colour, line style and marker (:mod:`tcsim.plots.styles`), the
brake release as a dotted grey line. The layouts follow the thesis's figures (docs/launch_summary.md):

* ``torque_speed_ratio.png`` (fig. 3.5, "upper lines are Torque Ratio, lower lines are Speed
  Ratio"): effective TR and SR of every model on one axis from 0, 1 s either side of the release;
* ``effective_torque_ratio.png`` (figs 3.5 and 4.3/4.4, window 0.2 s before to 1.5 s after the
  release): above, the effective TR (eqs 3.1–3.4) of every model; below, each dynamic model's
  deficit against the table model with the ±0.05 recovery band, its dip and its recovery time
  (the summary's columns) marked;
* ``vehicle_accel_release.png`` (fig. 3.6): vehicle acceleration from 0.5 s before to 1 s after
  the release;
* ``vehicle_accel.png`` (fig. 3.20, here over the whole run): vehicle acceleration from 0.5 s before
  the release to the end, the first model's shift transients shaded and its shift and lock-up
  events marked, every model's launch peak marked;
* ``vehicle_speed.png``: vehicle speed above, gear below; ``speeds.png``: pump (engine) speed
  above, turbine speed below.

With the shape-effect sweep, per dynamic model: ``shape_sweep_<model>_effective_torque_ratio.png``
(figs 4.3 and 4.4) and ``shape_sweep_<model>_vehicle_accel.png`` (figs 4.5 and 4.6), one line per
S, the table model in its own style ("SS model").
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.ticker import MaxNLocator

from ..analysis.launch import REFERENCE_MODEL
from ..analysis.launch_metrics import RECOVERY_BAND, deficit_series, shift_windows
from ..units import KM_H
from .common import finish_figure, fixed_figure, mpl_text, plt, save_figure
from .styles import MODEL_STYLES, model_line

LABELS = {name: style.label for name, style in MODEL_STYLES.items()}
#: Window around the brake release of figures 3.5 and 3.6: (before, after), s.
RATIO_WINDOW_S = (1.0, 1.0)
ACCEL_WINDOW_S = (0.5, 1.0)
SWEEP_WINDOW_S = (0.2, 1.5)
#: Window of the effective-TR figure (as figures 4.3/4.4), s.
EFFECTIVE_WINDOW_S = SWEEP_WINDOW_S
#: Events not drawn as markers (converter events are in events.csv).
_CONVERTER_EVENTS = ("stator-release", "stator-lock", "flow-zero", "flow-start")


def _style(name: str, index: int = 0) -> dict:
    return model_line(name, index)


def _window(df: pd.DataFrame, start: float, end: float) -> pd.DataFrame:
    t = df["time_s"]
    return df[(t >= start) & (t <= end)]


_save = finish_figure


def _release_line(ax, release: float) -> None:
    ax.axvline(release, color="0.6", ls=":", lw=1)


Frames = Mapping[str, pd.DataFrame]


def _summary_value(summary: pd.DataFrame | None, model: str, column: str) -> float:
    if summary is None or column not in summary.columns:
        return math.nan
    row = summary[summary["model"] == model]
    return float(row[column].iloc[0]) if len(row) else math.nan


def plot_torque_speed_ratio(frames: Frames, release: float, out_dir: Path) -> Path:
    """Figure 3.5: effective TR (upper lines) and SR (lower lines) against time around the release."""
    a, b = release - RATIO_WINDOW_S[0], release + RATIO_WINDOW_S[1]
    fig, ax = fixed_figure((6.4, 4.2))
    top = 2.5
    for i, (name, f) in enumerate(frames.items()):
        w = _window(f, a, b)
        # the effective TR (eqs 3.1–3.4): the table's TR(SR) for the table model; the plain ratio
        # of external torques would also carry the pump's and turbine's inertia torques
        ax.plot(w["time_s"], w["effective_torque_ratio"], **_style(name, i))
        ax.plot(w["time_s"], w["speed_ratio"], **model_line(name, i, label="_nolegend_"))
        etr = w["effective_torque_ratio"].to_numpy(dtype=float)
        top = max(top, float(np.max(etr[np.isfinite(etr)], initial=0.0)) + 0.1)  # all NaN: no torque
    _release_line(ax, release)
    ax.text(0.01, 0.97, "upper lines: effective torque ratio", transform=ax.transAxes, va="top", fontsize="small")
    ax.text(0.01, 0.03, "lower lines: speed ratio", transform=ax.transAxes, va="bottom", fontsize="small")
    ax.set_ylabel("Ratio [-]")
    ax.set_ylim(0, top)
    ax.set_xlim(a, b)
    return _save(fig, ax, Path(out_dir) / "torque_speed_ratio.png", "Speed ratio and torque ratio, cf. thesis fig. 3.5")


def plot_effective_torque_ratio(frames: Frames, release: float, out_dir: Path, summary: pd.DataFrame | None) -> Path:
    """The effective TR of every model (above) and each model's deficit against the table model
    (below) with the recovery band, the dip and the recovery time of ``summary`` marked."""
    a, b = release - EFFECTIVE_WINDOW_S[0], release + EFFECTIVE_WINDOW_S[1]
    ref = frames.get(REFERENCE_MODEL)
    fig, (ax, dax) = fixed_figure((6.4, 5.6), (3, 2), hspace=0.2)
    for i, (name, f) in enumerate(frames.items()):
        w = _window(f, a, b)
        ax.plot(w["time_s"], w["effective_torque_ratio"], **_style(name, i))
        if ref is None or name == REFERENCE_MODEL:
            continue
        d = deficit_series(w["time_s"], w["effective_torque_ratio"], ref["time_s"], ref["effective_torque_ratio"])
        line = dax.plot(w["time_s"], d, **model_line(name, i, label="_nolegend_"))[0]
        dip_t = _summary_value(summary, name, "effective_torque_ratio_dip_time_s")
        dip = _summary_value(summary, name, "effective_torque_ratio_dip_first_0_5_s")
        if math.isfinite(dip_t) and math.isfinite(dip):
            dax.plot(release + dip_t, dip, marker="v", ms=7, color=line.get_color(), ls="none")
        rec = _summary_value(summary, name, "effective_torque_ratio_recovery_time_s")
        if math.isfinite(rec) and rec > 0:
            dax.axvline(release + rec, color=line.get_color(), ls=line.get_linestyle(), lw=0.8)
    for axis in (ax, dax):
        _release_line(axis, release)
    ax.set_ylabel("Effective torque ratio [-]")
    dax.axhspan(-RECOVERY_BAND, RECOVERY_BAND, color="0.85", zorder=0)
    dax.axhline(0.0, color="0.5", lw=0.8)
    dax.set_ylabel("Table − model [-]")
    dax.set_xlabel("Time [s]")
    dax.grid(True, alpha=0.3)
    dax.set_title(
        f"Deficit against the table model: ▼ dip in the first 0.5 s, band ±{RECOVERY_BAND:g}, vertical line recovery",
        fontsize="small",
    )
    ax.set_xlabel("")
    ax.grid(True, alpha=0.3)
    ax.set_title("Effective torque ratio (eqs 3.1–3.4) around the brake release", fontsize="medium")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    path = Path(out_dir) / "effective_torque_ratio.png"
    save_figure(fig, path)
    plt.close(fig)
    return path


def plot_ratios(frames: Frames, release: float, out_dir: Path, summary: pd.DataFrame | None = None) -> list[Path]:
    """Figure 3.5 (TR and SR against time) and the effective TR with its deficit, around the release."""
    return [
        plot_torque_speed_ratio(frames, release, out_dir),
        plot_effective_torque_ratio(frames, release, out_dir, summary),
    ]


def _mark_events(ax, events: Sequence[Sequence[Any]], start: float) -> None:
    for e in events:
        t, kind = float(e[0]), str(e[1])
        if t < start or kind in _CONVERTER_EVENTS:
            continue
        ax.axvline(t, color="0.5", lw=0.8, ls=":")
        ax.text(
            t,
            0.98,
            f" {kind}",
            transform=ax.get_xaxis_transform(),
            rotation=90,
            va="top",
            ha="left",
            fontsize="x-small",
            color="0.35",
        )


def _shade_shifts(ax, frame: pd.DataFrame, start: float) -> None:
    """Shade the shift transients of ``frame`` (those of :mod:`tcsim.analysis.launch_metrics`)."""
    t = frame["time_s"].to_numpy(dtype=float)
    shifting = frame["shifting"].to_numpy(dtype=float) if "shifting" in frame else None
    gear = frame["gear"].to_numpy(dtype=float) if "gear" in frame else None
    label = "shift transient (first model)"
    for s in shift_windows(t, shifting, gear):
        if t[s.first] >= start:
            ax.axvspan(t[s.first], t[s.end - 1], color="0.9", zorder=0, label=label)
            label = "_nolegend_"


def plot_acceleration(
    frames: Frames, events: Sequence[Sequence[Any]], release: float, out_dir: Path, summary: pd.DataFrame | None = None
) -> list[Path]:
    """Figures 3.6 (around the release) and 3.20 (the whole run) of the vehicle acceleration;
    ``events`` (``(time_s, kind, ...)``, those of the first model) are marked on the second, with
    the first model's shift transients shaded and each model's launch peak (``summary``) marked."""
    paths = []
    fig, ax = fixed_figure((6.4, 4.2))
    for i, (name, f) in enumerate(frames.items()):
        w = _window(f, release - ACCEL_WINDOW_S[0], release + ACCEL_WINDOW_S[1])
        ax.plot(w["time_s"], w["vehicle_accel_m_s2"], **_style(name, i))
    _release_line(ax, release)
    ax.set_ylabel("Acceleration [m/s²]")
    paths.append(
        _save(
            fig,
            ax,
            Path(out_dir) / "vehicle_accel_release.png",
            "Vehicle acceleration around the brake release, cf. thesis fig. 3.6",
        )
    )

    fig, ax = fixed_figure((7.2, 4.2))
    start = release - ACCEL_WINDOW_S[0]
    for i, (name, f) in enumerate(frames.items()):
        w = f[f["time_s"] >= start]
        line = ax.plot(w["time_s"], w["vehicle_accel_m_s2"], **_style(name, i))[0]
        peak = _summary_value(summary, name, "launch_peak_accel_m_s2")
        peak_t = _summary_value(summary, name, "launch_peak_accel_time_s")
        if math.isfinite(peak) and math.isfinite(peak_t):
            ax.plot(release + peak_t, peak, marker="^", ms=7, color=line.get_color(), ls="none", label="_nolegend_")
    if frames:
        _shade_shifts(ax, next(iter(frames.values())), start)
    _mark_events(ax, events, start)
    ax.set_ylabel("Acceleration [m/s²]")
    paths.append(
        _save(
            fig,
            ax,
            Path(out_dir) / "vehicle_accel.png",
            "Vehicle acceleration (▲ launch peaks; events of the first model), cf. thesis fig. 3.20",
        )
    )
    return paths


def _two_panels(title: str):
    fig, (top, bottom) = fixed_figure((6.4, 5.6), (3, 2))
    top.set_title(mpl_text(title), fontsize="medium")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    bottom.set_xlabel("Time [s]")
    return fig, top, bottom


def _save_panels(fig, top, path: Path) -> Path:
    if top.get_legend_handles_labels()[0]:
        top.legend(fontsize="small")
    save_figure(fig, path)
    plt.close(fig)
    return path


def plot_speeds(frames: Frames, scenario_name: str, out_dir: Path) -> list[Path]:
    """Vehicle speed above the gear, and the pump speed above the turbine speed."""
    fig, ax, gear_ax = _two_panels(f"Vehicle speed and gear, scenario {scenario_name}")
    for i, (name, f) in enumerate(frames.items()):
        ax.plot(f["time_s"], f["vehicle_speed_m_s"] / KM_H, **_style(name, i))
        if "gear" in f:
            gear_ax.step(f["time_s"], f["gear"], where="post", **model_line(name, i, label="_nolegend_"))
    ax.set_ylabel("Vehicle speed [km/h]")
    gear_ax.set_ylabel("Gear [-]")
    gear_ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    p1 = _save_panels(fig, ax, Path(out_dir) / "vehicle_speed.png")

    fig, ax, turbine_ax = _two_panels("Pump (engine) and turbine speeds")
    for i, (name, f) in enumerate(frames.items()):
        ax.plot(f["time_s"], f["pump_speed_rad_s"], **_style(name, i))
        turbine_ax.plot(f["time_s"], f["turbine_speed_rad_s"], **model_line(name, i, label="_nolegend_"))
    ax.set_ylabel("Pump speed [rad/s]")
    turbine_ax.set_ylabel("Turbine speed [rad/s]")
    p2 = _save_panels(fig, ax, Path(out_dir) / "speeds.png")
    return [p1, p2]


def plot_launch(
    frames: Frames,
    first_events: Sequence[Sequence[Any]],
    release: float,
    scenario_name: str,
    out_dir: Path,
    summary: pd.DataFrame | None = None,
) -> list[Path]:
    """All figures of a launch: ``frames`` by model, the first model's events, the brake release
    time and the launch's summary (its dips, recovery times and launch peaks are marked)."""
    return [
        *plot_ratios(frames, release, out_dir, summary),
        *plot_acceleration(frames, first_events, release, out_dir, summary),
        *plot_speeds(frames, scenario_name, out_dir),
    ]


_SWEEP_FIGURES = (
    (
        "effective_torque_ratio",
        "Effective torque ratio [-]",
        "effective TR",
        {"hrovat-tobler": "4.4", "quasi-dynamic": "4.3"},
    ),
    (
        "vehicle_accel_m_s2",
        "Acceleration [m/s²]",
        "vehicle acceleration",
        {"hrovat-tobler": "4.6", "quasi-dynamic": "4.5"},
    ),
)


def plot_sweep(sweep: pd.DataFrame | None, steady: pd.DataFrame | None, release: float, out_dir: Path) -> list[Path]:
    """Per dynamic model of the sweep frame: effective TR and vehicle acceleration against time, one
    line per shape effect, with the table model's run ``steady`` dashed (figures 4.3–4.6)."""
    if sweep is None or sweep.empty:
        return []
    a, b = release - SWEEP_WINDOW_S[0], release + SWEEP_WINDOW_S[1]
    paths = []
    for key, g in sweep.groupby("model", sort=False):
        model = str(key)
        for column, ylabel, what, figure in _SWEEP_FIGURES:
            fig, ax = fixed_figure((6.4, 4.2))
            for label, run in g.groupby("label", sort=False):
                w = _window(run, a, b)
                ax.plot(w["time_s"], w[column], lw=1.1, label=mpl_text(label))
            if steady is not None:
                w = _window(steady, a, b)
                ax.plot(w["time_s"], w[column], **model_line(REFERENCE_MODEL))
            _release_line(ax, release)
            ax.set_ylabel(ylabel)
            title = f"Shape effect and {what}, {LABELS.get(model, model)}, cf. thesis fig. {figure.get(model, '4.3')}"
            paths.append(
                _save(fig, ax, Path(out_dir) / f"shape_sweep_{model}_{column.removesuffix('_m_s2')}.png", title)
            )
    return paths
