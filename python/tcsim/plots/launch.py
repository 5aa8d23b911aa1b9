"""Figures of ``tcsim launch`` (Li & Sundén 2016, figures 3.5, 3.6, 3.20 and 4.3–4.6).

* ``torque_speed_ratio.png`` (fig. 3.5): TR (solid) and SR (dashed) of every model, 1 s either
  side of the brake release;
* ``effective_torque_ratio.png``: the effective TR (eqs 3.1–3.4) over the same window;
* ``vehicle_accel_release.png`` (fig. 3.6): vehicle acceleration from 0.5 s before to 1 s after
  the release;
* ``vehicle_accel.png`` (fig. 3.20): vehicle acceleration over the whole run after the release,
  with the first model's shift and lock-up events marked;
* ``vehicle_speed.png``: vehicle speed and gear; ``speeds.png``: pump (engine) and turbine speeds.

With the shape-effect sweep, per dynamic model: ``shape_sweep_<model>_effective_torque_ratio.png``
(figs 4.3 and 4.4) and ``shape_sweep_<model>_vehicle_accel.png`` (figs 4.5 and 4.6), one line per
S, the table model dashed ("SS model").
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd
from matplotlib.ticker import MaxNLocator

from ..units import KM_H
from .common import finish_figure, mpl_text, plt

COLOURS = {"table": "C0", "hrovat-tobler": "C1", "quasi-dynamic": "C2"}
LABELS = {"table": "SS (table) model", "hrovat-tobler": "H&T model", "quasi-dynamic": "quasi-dynamic model"}
#: Window around the brake release of figures 3.5 and 3.6: (before, after), s.
RATIO_WINDOW_S = (1.0, 1.0)
ACCEL_WINDOW_S = (0.5, 1.0)
SWEEP_WINDOW_S = (0.2, 1.5)
#: Events not drawn as markers (converter events are in events.csv).
_CONVERTER_EVENTS = ("stator-release", "stator-lock", "flow-zero", "flow-start")


def _style(name: str) -> dict:
    return {"color": COLOURS.get(name), "label": LABELS.get(name, name)}


def _window(df: pd.DataFrame, start: float, end: float) -> pd.DataFrame:
    t = df["time_s"]
    return df[(t >= start) & (t <= end)]


_save = finish_figure


def _release_line(ax, release: float) -> None:
    ax.axvline(release, color="0.6", ls=":", lw=1)


Frames = Mapping[str, pd.DataFrame]


def plot_ratios(frames: Frames, release: float, out_dir: Path) -> list[Path]:
    """Figure 3.5 (TR and SR against time) and the effective TR, around the brake release."""
    a, b = release - RATIO_WINDOW_S[0], release + RATIO_WINDOW_S[1]
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    for name, f in frames.items():
        w = _window(f, a, b)
        style = _style(name)
        # the effective TR (eqs 3.1–3.4): the table's TR(SR) for the table model; the plain ratio
        # of external torques would also carry the pump's and turbine's inertia torques
        ax.plot(w["time_s"], w["effective_torque_ratio"], lw=1.3, **style)
        ax.plot(w["time_s"], w["speed_ratio"], lw=1.1, ls="--", color=style["color"])
    _release_line(ax, release)
    ax.set_ylabel("Ratio [-]")
    ax.set_ylim(bottom=0)
    p1 = _save(
        fig,
        ax,
        Path(out_dir) / "torque_speed_ratio.png",
        "Effective torque ratio (solid) and speed ratio (dashed), cf. thesis fig. 3.5",
    )

    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    for name, f in frames.items():
        w = _window(f, a, b)
        ax.plot(w["time_s"], w["effective_torque_ratio"], lw=1.3, **_style(name))
    _release_line(ax, release)
    ax.set_ylabel("Effective torque ratio [-]")
    p2 = _save(
        fig,
        ax,
        Path(out_dir) / "effective_torque_ratio.png",
        "Effective torque ratio (eqs 3.1–3.4) around the brake release",
    )
    return [p1, p2]


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


def plot_acceleration(frames: Frames, events: Sequence[Sequence[Any]], release: float, out_dir: Path) -> list[Path]:
    """Figures 3.6 (around the release) and 3.20 (the whole run) of the vehicle acceleration;
    ``events`` (``(time_s, kind, ...)``, those of the first model) are marked on the second."""
    paths = []
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    for name, f in frames.items():
        w = _window(f, release - ACCEL_WINDOW_S[0], release + ACCEL_WINDOW_S[1])
        ax.plot(w["time_s"], w["vehicle_accel_m_s2"], lw=1.3, **_style(name))
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

    fig, ax = plt.subplots(figsize=(7.2, 4.2), layout="constrained")
    start = release - ACCEL_WINDOW_S[0]
    for name, f in frames.items():
        w = f[f["time_s"] >= start]
        ax.plot(w["time_s"], w["vehicle_accel_m_s2"], lw=1.1, **_style(name))
    _mark_events(ax, events, start)
    ax.set_ylabel("Acceleration [m/s²]")
    paths.append(
        _save(
            fig,
            ax,
            Path(out_dir) / "vehicle_accel.png",
            "Vehicle acceleration over the run (events of the first model), cf. thesis fig. 3.20",
        )
    )
    return paths


def plot_speeds(frames: Frames, scenario_name: str, out_dir: Path) -> list[Path]:
    """Vehicle speed with the gear, and the pump and turbine speeds."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    gear_ax = ax.twinx()
    for name, f in frames.items():
        style = _style(name)
        ax.plot(f["time_s"], f["vehicle_speed_m_s"] / KM_H, lw=1.3, **style)
        if "gear" in f:
            gear_ax.step(f["time_s"], f["gear"], where="post", lw=0.8, ls="--", color=style["color"], alpha=0.7)
    ax.set_ylabel("Vehicle speed [km/h]")
    gear_ax.set_ylabel("Gear (dashed)")
    gear_ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    p1 = _save(fig, ax, Path(out_dir) / "vehicle_speed.png", f"Vehicle speed and gear, scenario {scenario_name}")

    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    for name, f in frames.items():
        style = _style(name)
        ax.plot(f["time_s"], f["pump_speed_rad_s"], lw=1.3, color=style["color"], label=f"{style['label']}: pump")
        ax.plot(
            f["time_s"],
            f["turbine_speed_rad_s"],
            lw=1.1,
            ls="--",
            color=style["color"],
            label=f"{style['label']}: turbine",
        )
    ax.set_ylabel("Speed [rad/s]")
    p2 = _save(fig, ax, Path(out_dir) / "speeds.png", "Pump (engine) and turbine speeds")
    return [p1, p2]


def plot_launch(
    frames: Frames, first_events: Sequence[Sequence[Any]], release: float, scenario_name: str, out_dir: Path
) -> list[Path]:
    """All figures of a launch: ``frames`` by model, the first model's events, the brake release time."""
    return [
        *plot_ratios(frames, release, out_dir),
        *plot_acceleration(frames, first_events, release, out_dir),
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
            fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
            for label, run in g.groupby("label", sort=False):
                w = _window(run, a, b)
                ax.plot(w["time_s"], w[column], lw=1.1, label=mpl_text(label))
            if steady is not None:
                w = _window(steady, a, b)
                ax.plot(w["time_s"], w[column], color="0.3", ls="--", lw=1.2, label=LABELS["table"])
            _release_line(ax, release)
            ax.set_ylabel(ylabel)
            title = f"Shape effect and {what}, {LABELS.get(model, model)}, cf. thesis fig. {figure.get(model, '4.3')}"
            paths.append(
                _save(fig, ax, Path(out_dir) / f"shape_sweep_{model}_{column.removesuffix('_m_s2')}.png", title)
            )
    return paths
