"""Plots of a drive cycle (``tcsim drive``): the trace against each model's vehicle speed, the speed
error, and the cumulative energies (converter and lock-up losses, brakes, engine braking)."""

from __future__ import annotations

from pathlib import Path

from ..analysis.drive import Drive
from ..units import KM_H
from .common import finish_figure, mpl_text, plt

#: Line styles per model, so that lines are told apart without colour.
_STYLES = {"table": "-", "hrovat-tobler": "--", "quasi-dynamic": ":"}


def plot_drive(result: Drive, out_dir: Path) -> list[Path]:
    """``speed.png`` (trace and vehicle speeds, speed error) and ``losses.png`` (cumulative energies)."""
    out_dir = Path(out_dir)
    name = result.cycle.name
    fig, (ax, ax_err) = plt.subplots(2, 1, figsize=(10, 6), sharex=True, height_ratios=[3, 1])
    ax.plot(result.cycle.time_s, result.cycle.vehicle_speed_m_s / KM_H, color="0.6", lw=2.5, label="trace")
    for model, run in result.runs.items():
        f = run.frame
        style = _STYLES.get(model, "-.")
        ax.plot(f.time_s, f.vehicle_speed_m_s / KM_H, ls=style, lw=1, label=model)
        ax_err.plot(f.time_s, f.speed_error_m_s / KM_H, ls=style, lw=0.8, label=model)
    ax.set_ylabel("Speed [km/h]")
    ax_err.set_ylabel("Error [km/h]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(mpl_text(f"{name}: trace and vehicle speed"), fontsize="medium")
    paths = [finish_figure(fig, ax_err, out_dir / "speed.png", "speed error (trace minus vehicle)")]
    fig, ax = plt.subplots(figsize=(10, 5))
    for model, run in result.runs.items():
        f = run.frame
        style = _STYLES.get(model, "-.")
        for column, color in (("converter_loss_j", "C0"), ("lockup_loss_j", "C1"), ("brake_energy_j", "C2")):
            label = f"{model}: {column.removesuffix('_j').replace('_', ' ')}"
            ax.plot(f.time_s, f[column] / 1000.0, ls=style, color=color, lw=1, label=label)
    ax.set_ylabel("Cumulative energy [kJ]")
    paths.append(finish_figure(fig, ax, out_dir / "losses.png", f"{name}: converter, lock-up and brake energy"))
    return paths
