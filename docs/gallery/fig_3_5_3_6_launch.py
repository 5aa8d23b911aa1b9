"""Gallery: thesis figures 3.5 and 3.6, the three models in a whole-vehicle flip-flop launch (Li & Sundén
2016, §3.2.2): torque ratio and speed ratio (3.5) and vehicle acceleration (3.6) around the brake release.

The bundled vehicle ``midsize-awd-8at`` (a Volvo S90 T6 AWD class sedan with the converter
``li-sunden-2016-fitted``) stands braked in first gear for 5 s, then the brake comes off and the
pedal goes to the floor; the steady-state table (SS) model, the quasi-dynamic (Drenth) model and
Hrovat & Tobler run on the same vehicle in one core call (:func:`tcsim.analysis.launch.run_comparison`,
what ``tcsim launch`` runs). The torque ratio drawn is the effective one (the turbine's effective
output over the pump's effective input torque, eqs 3.3 and 3.4), the quantity the thesis compares.

Run it::

    python docs/gallery/fig_3_5_3_6_launch.py [--fast] [--out DIR]

writes ``fig_3_5.png``, ``fig_3_6.png`` and their data as CSV; ``--fast`` holds the brake 1 s instead
of 5 s (the time axis shifts by 4 s) and ends the run 2 s after the release instead of 4 s.
"""

from __future__ import annotations

import pandas as pd
from _common import parse_args, save, tidy

from tcsim.analysis.launch import run_comparison
from tcsim.models.vehicle import load_vehicle
from tcsim.plots.common import plt
from tcsim.plots.styles import model_line
from tcsim.simulation.scenarios import flip_flop

COLUMNS = ["time_s", "effective_torque_ratio", "speed_ratio", "vehicle_accel_m_s2", "vehicle_speed_m_s"]
#: What the figures show around the brake release, s (thesis: 4–6 s and 4.5–6 s with the release at 5 s).
WINDOW_S = {"fig_3_5": (-1.0, 1.0), "fig_3_6": (-0.5, 1.0)}


def launch(fast: bool) -> tuple[dict[str, pd.DataFrame], float]:
    """Each model's launch (the rows up to the figures' end) and the brake-release time, s."""
    hold_s = 1.0 if fast else 5.0
    scenario = flip_flop(hold_s=hold_s, end_time_s=hold_s + (2.0 if fast else 4.0))
    result = run_comparison(load_vehicle("midsize-awd-8at"), scenario)
    release_s = scenario.brake_release_time_s
    start, end = release_s - 1.0, release_s + 1.0
    return {m: f[(f.time_s >= start) & (f.time_s <= end)] for m, f in result.frames.items()}, release_s


def fig_3_5(frames: dict[str, pd.DataFrame], release_s: float):
    fig, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
    for model, f in frames.items():
        style = model_line(model)
        ax.plot(f["time_s"], f["effective_torque_ratio"], **style)
        ax.plot(f["time_s"], f["speed_ratio"], **{**style, "label": None})
    ax.axvline(release_s, color="0.6", ls=":", lw=1, label="brake release")
    ax.text(release_s - 0.95, 1.85, "upper lines: effective torque ratio", fontsize="small")
    ax.text(release_s - 0.95, 0.15, "lower lines: speed ratio", fontsize="small")
    ax.set_xlim(release_s + WINDOW_S["fig_3_5"][0], release_s + WINDOW_S["fig_3_5"][1])
    ax.set_ylim(0.0, 2.5)
    ax.set_xlabel("Time [s]")
    ax.set_ylabel("Ratio [-]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", loc="center right")
    return fig


def fig_3_6(frames: dict[str, pd.DataFrame], release_s: float):
    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    for model, f in frames.items():
        ax.plot(f["time_s"], f["vehicle_accel_m_s2"], **model_line(model))
    ax.axvline(release_s, color="0.6", ls=":", lw=1, label="brake release")
    ax.set_xlim(release_s + WINDOW_S["fig_3_6"][0], release_s + WINDOW_S["fig_3_6"][1])
    ax.set_xlabel("Time [s]")
    ax.set_ylabel("Acceleration [m/s²]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def main() -> None:
    args = parse_args(__doc__, "gallery_launch")
    frames, release_s = launch(args.fast)
    frame = tidy(frames, COLUMNS).rename(columns={"curve": "model"}).assign(brake_release_s=release_s)
    caption = "Figure 3.5: Comparison of the three models; upper lines TR, lower lines SR"
    save(fig_3_5(frames, release_s), args.out, "fig_3_5", frame, caption)
    caption = "Figure 3.6: Comparison of the three models; vehicle acceleration"
    save(fig_3_6(frames, release_s), args.out, "fig_3_6", frame, caption)


if __name__ == "__main__":
    main()
