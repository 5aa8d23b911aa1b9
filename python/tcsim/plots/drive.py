"""Plots of a drive cycle (``tcsim drive``): the trace against each model's vehicle speed, the speed
error, and the cumulative energies (converter and lock-up losses, brakes, engine braking)."""

from __future__ import annotations

from pathlib import Path

from ..analysis.drive import Drive
from ..units import KM_H
from .common import finish_figure, mpl_text, plt
from .styles import OKABE_ITO, model_line

#: The colours of the energies in ``losses.png`` (the model is told by its line style and marker).
ENERGY_COLOURS = {
    "converter_loss_j": OKABE_ITO["vermillion"],
    "lockup_loss_j": OKABE_ITO["blue"],
    "brake_energy_j": OKABE_ITO["black"],
}


def plot_drive(result: Drive, out_dir: Path) -> list[Path]:
    """``speed.png`` (trace and vehicle speeds, speed error) and ``losses.png`` (cumulative energies);
    each model in its style of :mod:`tcsim.plots.styles`."""
    out_dir = Path(out_dir)
    name = result.cycle.name
    fig, (ax, ax_err) = plt.subplots(2, 1, figsize=(10, 6), sharex=True, height_ratios=[3, 1])
    ax.plot(result.cycle.time_s, result.cycle.vehicle_speed_m_s / KM_H, color="0.6", lw=2.5, label="trace")
    for i, (model, run) in enumerate(result.runs.items()):
        f = run.frame
        ax.plot(f.time_s, f.vehicle_speed_m_s / KM_H, **model_line(model, i, label=mpl_text(model)))
        ax_err.plot(f.time_s, f.speed_error_m_s / KM_H, **model_line(model, i, label=mpl_text(model)))
    ax.set_ylabel("Speed [km/h]")
    ax_err.set_ylabel("Error [km/h]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(mpl_text(f"{name}: trace and vehicle speed"), fontsize="medium")
    paths = [finish_figure(fig, ax_err, out_dir / "speed.png", "speed error (trace minus vehicle)")]
    fig, ax = plt.subplots(figsize=(10, 5))
    for i, (model, run) in enumerate(result.runs.items()):
        f = run.frame
        for column, colour in ENERGY_COLOURS.items():
            label = mpl_text(f"{model}: {column.removesuffix('_j').replace('_', ' ')}")
            ax.plot(f.time_s, f[column] / 1000.0, **{**model_line(model, i, label=label), "color": colour})
    ax.set_ylabel("Cumulative energy [kJ]")
    paths.append(finish_figure(fig, ax, out_dir / "losses.png", f"{name}: converter, lock-up and brake energy"))
    return paths
