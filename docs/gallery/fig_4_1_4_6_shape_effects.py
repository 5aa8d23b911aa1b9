"""Gallery: thesis figures 4.1–4.6, the influence of the shape effects S_p and S_t on the effective
torque ratio during a take-off (Li & Sundén 2016, §4.1): the isolated converter (4.1 quasi-dynamic
(Drenth) model, 4.2 Hrovat & Tobler), the whole vehicle (4.3, 4.4) and its acceleration (4.5, 4.6).

Isolated converter (4.1, 4.2): :func:`tcsim.analysis.shape_fit.shape_effect_sweep` (what
``tcsim fit-shapes`` sweeps) driven by the pump torque and turbine speed of a synthetic flip-flop
take-off (the bundled vehicle ``midsize-awd-8at`` launched with the quasi-dynamic model of its
converter, S_p = 0.4, S_t = 0.3 m²; the thesis's measurement is not public), with that
measurement's effective torque ratio (eqs 3.3, 3.4) and the steady-state table (SS) model under
the same drive. Vehicle (4.3–4.6): the shape-effect sweep of ``tcsim launch --sweep-shape-effects``
(:func:`tcsim.analysis.launch.run_comparison` with ``sweep=True``) on the same vehicle and launch.

The quasi-dynamic model runs the thesis's values S_p = S_t = 0, 0.05, 0.1, 0.2 m² and S_p = 0.4,
S_t = 0.3 m². Hrovat & Tobler accepts only shape effects that keep its mass matrix positive definite
(docs/shape_fit.md): it runs 0, ¼, ½ and ¾ of its largest admissible S_p = S_t; the thesis's 0.05,
0.10 and 0.15 m² lie above that bound and are recorded in the CSV as not admissible.

Run it::

    python docs/gallery/fig_4_1_4_6_shape_effects.py [--fast] [--out DIR]

writes ``fig_4_1.png`` … ``fig_4_6.png``, their data as CSV and the synthetic measurement
(``synthetic_takeoff.csv``); every run ends 1.5 s after the brake release; ``--fast`` holds the
brake 1 s instead of 5 s (the time axis shifts by 4 s).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from _common import VEHICLE, parse_args, save, synthetic_measurement

from tcsim.analysis.effective import measured_effective_torques
from tcsim.analysis.launch import run_comparison
from tcsim.analysis.shape_fit import shape_effect_sweep, steady_run
from tcsim.models.shape_effects import THESIS_PAIR_M2, sweep_values
from tcsim.models.vehicle import load_vehicle
from tcsim.plots.common import plt
from tcsim.plots.styles import model_line
from tcsim.simulation.scenarios import Scenario, flip_flop
from tcsim.transient import PumpTorqueTurbineSpeed, dynamic_model

#: The thesis's H&T values (figures 4.2, 4.4, 4.6), m²: run if admissible, else recorded as refused.
THESIS_HT_VALUES_M2 = (0.05, 0.10, 0.15)
KEEP = ["time_s", "effective_torque_ratio", "vehicle_accel_m_s2"]
DYNAMIC = ("quasi-dynamic", "hrovat-tobler")
#: The figures' time axis around the brake release, s (the thesis: 4.8–6.4 s, released at 5 s).
WINDOW_S = (-0.2, 1.4)
MEASURED = dict(color="k", lw=2.6, alpha=0.35, label="Measurement (synthetic)")
#: The columns of each figure's CSV.
CSV_COLUMNS = [
    "source",
    "model",
    "label",
    "pump_shape_effect_m2",
    "turbine_shape_effect_m2",
    "admissible",
    "note",
    "time_s",
    "effective_torque_ratio",
    "vehicle_accel_m_s2",
    "brake_release_s",
]
ETR = ("effective_torque_ratio", "Effective torque ratio [-]")
ACCEL = ("vehicle_accel_m_s2", "Vehicle acceleration [m/s²]")
#: Figure number, model, (column, y label), caption.
FIGURES = (
    ("4_1", "quasi-dynamic", ETR, "Drenth model, isolated converter"),
    ("4_2", "hrovat-tobler", ETR, "H&T model, isolated converter"),
    ("4_3", "quasi-dynamic", ETR, "Drenth model, vehicle"),
    ("4_4", "hrovat-tobler", ETR, "H&T model, vehicle"),
    ("4_5", "quasi-dynamic", ACCEL, "Drenth model, vehicle"),
    ("4_6", "hrovat-tobler", ACCEL, "H&T model, vehicle"),
)


def isolated(scenario: Scenario, out: Path) -> pd.DataFrame:
    """The isolated converter's sweep of both models, the measurement and the SS model, one long
    frame (``source`` isolated); the synthetic measurement is written into ``out``."""
    vehicle, log = synthetic_measurement(scenario, out / "synthetic_takeoff.csv")
    conv = vehicle.converter
    drive = PumpTorqueTurbineSpeed(log["time_s"], log["pump_torque_nm"], log["turbine_speed_rad_s"])
    parts = []
    for model in DYNAMIC:
        if model == "quasi-dynamic":
            sweep = shape_effect_sweep(conv, model, drive, pairs=[THESIS_PAIR_M2], times_s=log["time_s"])
        else:
            values = sorted({*sweep_values(dynamic_model(conv, model)), *THESIS_HT_VALUES_M2})
            sweep = shape_effect_sweep(conv, model, drive, values_m2=values, times_s=log["time_s"])
        parts.append(sweep.assign(model=model))
    inertia = conv.inertia
    assert inertia is not None
    measured = measured_effective_torques(log.to_dict("series"), inertia.turbine_kg_m2, inertia.pump_kg_m2)
    parts.append(pd.DataFrame(measured).assign(model="measurement", label="Measurement (synthetic)", admissible=True))
    steady = steady_run(conv, drive, log["time_s"])
    assert steady is not None
    parts.append(steady.assign(model="table", label="SS model", admissible=True))
    return pd.concat(parts, ignore_index=True).assign(source="isolated")


def vehicle(scenario: Scenario) -> pd.DataFrame:
    """The vehicle's shape-effect sweep of both models and the SS model's launch, one long frame
    (``source`` vehicle)."""
    launch = run_comparison(load_vehicle(VEHICLE), scenario, models=["table"] + list(DYNAMIC), sweep=True)
    assert launch.sweep is not None
    table = launch.frames["table"]
    parts = [
        launch.sweep.assign(admissible=True),
        table[KEEP].assign(model="table", label="SS model", admissible=True),
    ]
    return pd.concat(parts, ignore_index=True).assign(source="vehicle")


def shape_label(pump_m2: float, turbine_m2: float) -> str:
    return f"S_p = S_t = {pump_m2:g} m²" if pump_m2 == turbine_m2 else f"S_p = {pump_m2:g}, S_t = {turbine_m2:g} m²"


def plot(data: pd.DataFrame, model: str, column: str, ylabel: str):
    """One figure: a line per admissible shape-effect pair of ``model`` (light to dark as S grows),
    the SS model and the measurement (when the frame has it), around the brake release."""
    fig, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
    runs = data[(data.model == model) & data.admissible.astype(bool)]
    pairs = list(runs.groupby(["pump_shape_effect_m2", "turbine_shape_effect_m2"], sort=True))
    colours = plt.cm.viridis(np.linspace(0.85, 0.0, len(pairs)))
    for i, ((sp, st), g) in enumerate(pairs):
        style = {**model_line("", i, label=shape_label(sp, st)), "color": colours[i]}
        ax.plot(g["time_s"], g[column], **style)
    for other, style in (("table", model_line("table", label="SS model")), ("measurement", MEASURED)):
        g = data[data.model == other]
        if len(g) and g[column].notna().any():
            ax.plot(g["time_s"], g[column], **style)
    release_s = float(data["brake_release_s"].iloc[0])
    ax.axvline(release_s, color="0.6", ls=":", lw=1, label="brake release")
    ax.set_xlim(release_s + WINDOW_S[0], release_s + WINDOW_S[1])
    ax.set_xlabel("Time [s]")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def main() -> None:
    args = parse_args(__doc__, "gallery_shape_effects")
    hold_s = 1.0 if args.fast else 5.0
    scenario = flip_flop(hold_s, hold_s + WINDOW_S[1] + 0.1)
    release_s = scenario.brake_release_time_s
    frames = {"isolated": isolated(scenario, args.out), "vehicle": vehicle(scenario)}
    for number, model, (column, ylabel), what in FIGURES:
        data = frames["isolated" if number in ("4_1", "4_2") else "vehicle"].assign(brake_release_s=release_s)
        shown = data[
            data.model.isin([model, "table", "measurement"])
            & data.time_s.between(release_s + WINDOW_S[0], release_s + WINDOW_S[1])
            | ~data.admissible.astype(bool) & (data.model == model)
        ]
        caption = f"Figure {number.replace('_', '.')}: Influence of shape effect, {what}"
        fig = plot(shown, model, column, ylabel)
        save(fig, args.out, f"fig_{number}", shown[[c for c in CSV_COLUMNS if c in shown.columns]], caption)


if __name__ == "__main__":
    main()
