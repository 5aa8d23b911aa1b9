"""Figures of ``tcsim replay``: models against the measurement over time (Li & Sundén 2016,
figures 3.11–3.14, 3.16 and 3.17). The measurement is a black line, each model in its own colour,
line style and marker (:mod:`tcsim.plots.styles`); where the measurement lacks a channel only the
model curves are drawn."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .common import finish_figure, mpl_text, plt, save_figure
from .styles import model_line

#: Signals by name (a measurement's channels, or a run's columns), each an array over time.
Signals = Mapping[str, np.ndarray]

#: channel -> (axis label, file name, thesis figure)
FIGURES = {
    "pump_speed_rad_s": ("Pump speed [rad/s]", "pump_speed.png", "cf. thesis fig. 3.14"),
    "pump_torque_nm": ("Pump torque [N·m]", "pump_torque.png", "drive (b) output"),
    "turbine_torque_nm": ("Turbine torque [N·m]", "turbine_torque.png", "cf. thesis fig. 3.13"),
    "effective_pump_torque_nm": (
        "Effective pump input torque [N·m]",
        "effective_pump_torque.png",
        "T_p − I_p·dω_p/dt, thesis eq 3.3, fig. 3.16",
    ),
    "effective_turbine_torque_nm": (
        "Effective turbine output torque [N·m]",
        "effective_turbine_torque.png",
        "T_t + I_t·dω_t/dt, thesis eq 3.4, fig. 3.17",
    ),
}
INPUT_LABELS = {
    "pump_torque_nm": "Pump torque [N·m]",
    "pump_speed_rad_s": "Pump speed [rad/s]",
    "turbine_speed_rad_s": "Turbine speed [rad/s]",
}


def plot_inputs(time_s: np.ndarray, channels: Signals, inputs: Sequence[str], title: str, out_dir: Path) -> Path:
    """The drive's measured ``inputs`` (names of ``channels``), one panel each (thesis figures 3.11
    and 3.12)."""
    fig, axes = plt.subplots(len(inputs), 1, figsize=(6.4, 5.6), sharex=True, layout="constrained")
    for ax, channel in zip(axes, inputs):
        ax.plot(time_s, channels[channel], color="k", lw=1.2)
        ax.set_ylabel(INPUT_LABELS[channel])
        ax.grid(True, alpha=0.3)
    axes[0].set_title(mpl_text(title), fontsize="medium")
    axes[-1].set_xlabel("Time [s]")
    path = out_dir / "inputs.png"
    save_figure(fig, path)
    plt.close(fig)
    return path


def plot_channel(
    time_s: np.ndarray, measured_channels: Signals, runs: Mapping[str, Signals], channel: str, out_dir: Path
) -> Path:
    """One channel of every model's run over time, with the measured one when there is one."""
    label, filename, note = FIGURES[channel]
    measured = measured_channels.get(channel)
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    if measured is not None:
        ax.plot(time_s, measured, color="k", lw=1.6, label="measurement")
    for i, (name, result) in enumerate(runs.items()):
        y = np.asarray(result[channel], dtype=float)
        ax.plot(result["time_s"], y, **model_line(name, i, label=mpl_text(f"{name} model"), y=y))
    ax.set_ylabel(label)
    title = f"{label.split(' [')[0]} ({note})" + ("" if measured is not None else ", not measured")
    return finish_figure(fig, ax, out_dir / filename, title)


def plot_replay(
    time_s: np.ndarray,
    measured_channels: Signals,
    runs: Mapping[str, Signals],
    inputs: Sequence[str],
    outputs: Sequence[str],
    inputs_title: str,
    out_dir: Path,
) -> list[Path]:
    """All figures of a replay: the measured ``inputs``, the drive's ``outputs`` and the effective
    torques of every run against the measured ones (``measured_channels``, effective torques
    included)."""
    channels = [*outputs, "effective_pump_torque_nm", "effective_turbine_torque_nm"]
    return [
        plot_inputs(time_s, measured_channels, inputs, inputs_title, out_dir),
        *(plot_channel(time_s, measured_channels, runs, c, out_dir) for c in channels),
    ]
