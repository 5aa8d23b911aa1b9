"""Gallery: thesis figures 3.13–3.17, the isolated converter driven by measured signals ("mode 2", Li &
Sundén 2016, §3.4 and §3.5.2.1): turbine torque and pump speed of a slow rig launch (3.13, 3.14), the
torque flow of eqs 3.1–3.2 (3.15), and the effective pump input and turbine output torques of a
flip-flop take-off (eqs 3.3, 3.4; figures 3.16, 3.17).

The thesis's rig and in-vehicle measurements are not public, so the measurements here are
**synthetic**: the bundled vehicle ``midsize-awd-8at`` launched with the quasi-dynamic (Drenth) model of
its converter ``li-sunden-2016-fitted`` (S_p = 0.4, S_t = 0.3 m², the thesis's best match), logged at
100 Hz with the channels the thesis logged (pump = engine torque and speed, turbine speed and torque).
The rig launch is a 30 % pedal launch (the rig's slow acceleration), the take-off a flip-flop launch.
Each record is written as CSV and replayed with :func:`tcsim.replay.replay` (what ``tcsim replay``
runs), drive (a): pump torque and turbine speed in, pump speed and turbine torque out. The
quasi-dynamic model replays its own launch, so its line lies on the measurement: the check that the
isolated converter reproduces the converter in the vehicle.

Run it::

    python docs/gallery/fig_3_13_3_17_replay.py [--fast] [--out DIR]

writes ``fig_3_13.png`` … ``fig_3_17.png``, their data as CSV and the two synthetic measurements
(``synthetic_rig_launch.csv``, ``synthetic_takeoff.csv``); ``--fast`` holds the brake 1 s instead of
5 s (the time axis shifts by 4 s) and ends each record 2 s after the release instead of 3 s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from _common import parse_args, save, synthetic_measurement

from tcsim.plots.common import plt
from tcsim.plots.styles import model_line
from tcsim.replay import Replay, replay
from tcsim.simulation.scenarios import Scenario, flip_flop, part_pedal

MEASUREMENT = "Measurement (synthetic)"


def measure(scenario: Scenario, path: Path) -> tuple[Replay, float]:
    """Launch the bundled vehicle with the quasi-dynamic model under ``scenario``, log it to ``path``
    at 100 Hz and replay that file with every model; the replay and the brake-release time, s."""
    vehicle, _ = synthetic_measurement(scenario, path)
    return replay(vehicle.converter, path), scenario.brake_release_time_s


def lines(rep: Replay, column: str, measured: np.ndarray | None, window: tuple[float, float]) -> pd.DataFrame:
    """``column`` of every model (and the measurement) in the time window, one long frame."""
    time_s = rep.measurement.time_s
    keep = (time_s >= window[0]) & (time_s <= window[1])
    parts = [
        pd.DataFrame({"curve": m, "time_s": time_s[keep], column: r[column][keep]}) for m, r in rep.results.items()
    ]
    if measured is not None:
        parts.insert(0, pd.DataFrame({"curve": MEASUREMENT, "time_s": time_s[keep], column: measured[keep]}))
    return pd.concat(parts, ignore_index=True)


def compare(data: pd.DataFrame, column: str, ylabel: str, release_s: float):
    """One quantity against time: the measurement in black, the models in their styles."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    for curve, g in data.groupby("curve", sort=False):
        style = dict(color="k", lw=2.6, alpha=0.35, label=MEASUREMENT) if curve == MEASUREMENT else model_line(curve)
        ax.plot(g["time_s"], g[column], **style)
    ax.axvline(release_s, color="0.6", ls=":", lw=1, label="brake release")
    ax.set_xlabel("Time [s]")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig


#: The torque flow of eqs 3.1 and 3.2: each side's torques, the sum first.
FLOW = {
    "pump (eq 3.1)": [
        ("pump_torque_nm", "T_p, pump torque"),
        ("pump_inertia_torque_nm", "T_inertia,p"),
        ("pump_fluid_torque_nm", "T_fluid,p"),
        ("pump_transferred_torque_nm", "T_transfer,p"),
    ],
    "turbine (eq 3.2)": [
        ("turbine_transferred_torque_nm", "T_transfer,t"),
        ("turbine_inertia_torque_nm", "T_inertia,t"),
        ("turbine_fluid_torque_nm", "T_fluid,t"),
        ("turbine_torque_nm", "T_t, turbine torque"),
    ],
}


def torque_flow(rep: Replay, window: tuple[float, float]):
    """Figure 3.15 from the quasi-dynamic model's run: how the pump torque splits into inertia, fluid
    and transferred torque (eq 3.1), and the transferred torque at the turbine (eq 3.2)."""
    run = rep.results["quasi-dynamic"]
    keep = (run["time_s"] >= window[0]) & (run["time_s"] <= window[1])
    data = pd.DataFrame({c: run[c][keep] for c in ["time_s"] + [c for side in FLOW.values() for c, _ in side]})
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0), layout="constrained", sharey=True)
    for ax, (side, terms) in zip(axes, FLOW.items()):
        for i, (column, label) in enumerate(terms):
            style = dict(color="k", lw=2.0) if i == 0 else model_line(label, i - 1)
            ax.plot(data["time_s"], data[column], **{**style, "label": label})
        ax.set_title(f"{side}, quasi-dynamic model", fontsize="medium")
        ax.set_xlabel("Time [s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    axes[0].set_ylabel("Torque [N·m]")
    return fig, data


def main() -> None:
    args = parse_args(__doc__, "gallery_replay")
    hold_s, span_s = (1.0, 2.0) if args.fast else (5.0, 3.0)
    rig, release_s = measure(part_pedal(0.3, hold_s, hold_s + span_s), args.out / "synthetic_rig_launch.csv")
    window = (release_s - 0.5, release_s + span_s)
    channels = rig.measurement.channels
    data = lines(rig, "turbine_torque_nm", channels["turbine_torque_nm"], window)
    fig = compare(data, "turbine_torque_nm", "Turbine torque [N·m]", release_s)
    save(fig, args.out, "fig_3_13", data, "Figure 3.13: Comparison of turbine torque (output), synthetic rig launch")
    data = lines(rig, "pump_speed_rad_s", channels["pump_speed_rad_s"], window)
    fig = compare(data, "pump_speed_rad_s", "Pump speed [rad/s]", release_s)
    save(fig, args.out, "fig_3_14", data, "Figure 3.14: Comparison of pump speed (output), synthetic rig launch")

    takeoff, release_s = measure(flip_flop(hold_s, hold_s + span_s), args.out / "synthetic_takeoff.csv")
    window = (release_s - 0.5, release_s + 1.5)
    fig, data = torque_flow(takeoff, window)
    save(fig, args.out, "fig_3_15", data, "Figure 3.15: Torque flow (eqs 3.1, 3.2), flip-flop take-off")
    for number, column, what in (
        ("3_16", "effective_pump_torque_nm", "effective pump input torque (eq 3.3)"),
        ("3_17", "effective_turbine_torque_nm", "effective turbine output torque (eq 3.4)"),
    ):
        data = lines(takeoff, column, takeoff.measured_effective[column], window)
        fig = compare(data, column, f"{what[0].upper()}{what[1:]} [N·m]", release_s)
        save(fig, args.out, f"fig_{number}", data, f"Figure {number.replace('_', '.')}: Comparison of {what}")


if __name__ == "__main__":
    main()
