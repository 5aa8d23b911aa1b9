"""Worked example (b): replaying a measurement and fitting shape effects (Li & Sundén 2016 §3.4, §4.1).

There is no public test-rig record of a torque converter, so the "measurement" is made here: tcsim's
Hrovat & Tobler model of the bundled converter with KNOWN shape effects (S_p = 0.03 m², S_t = 0.02 m²,
the "real" converter) runs the isolated take-off, sampled at 100 Hz like a rig logger, with Gaussian
sensor noise on every channel (torques 2 N·m, speeds 5 rpm) and the speeds logged in rpm. The
script then

1. replays the record with the three models of the bundled converter (its own, nominal shape
   effects), as ``tcsim replay`` does, and prints each model's error;
2. fits the shape effects of the Hrovat & Tobler model to the record's effective turbine torque,
   as ``tcsim fit-shapes`` does (its files go to ``OUT/fit-shapes``);
3. prints the fitted against the true values with the fit's standard errors and draws the figure.

Run it::

    python docs/examples/replay_fit_shapes.py [--out DIR] [--fast]

``--fast`` (what CI runs) records 2 s of the take-off instead of 4 s.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from tcsim.models.converter import load_converter  # noqa: E402
from tcsim.replay import replay  # noqa: E402
from tcsim.shape_fit import fit_shape_effects, measured_effective_torques, shape_fit_command  # noqa: E402
from tcsim.transient import PumpTorqueTurbineSpeed, dynamic_model, isolated_takeoff, simulate  # noqa: E402
from tcsim.units import RAD_S_PER_RPM  # noqa: E402

CONVERTER = "li-sunden-2016"
#: The "real" converter's shape effects (S_p, S_t), m²: what the fit should find.
TRUE_SHAPE_EFFECTS_M2 = (0.03, 0.02)
#: The logger's sample rate, Hz.
SAMPLE_RATE_HZ = 1000.0
#: One standard deviation of the sensor noise per channel, in the channel's unit.
NOISE = {"pump_torque_nm": 0.5, "turbine_torque_nm": 0.5, "pump_speed_rpm": 1.0, "turbine_speed_rpm": 1.0}
TARGET = "effective_turbine_torque_nm"
#: Refits of the parametric bootstrap (the fit's uncertainty from the noise).
BOOTSTRAP_DRAWS = 16
#: The replayed channels compared with the measurement (drive (a)'s model outputs).
REPLAY_CHANNELS = ("pump_speed_rad_s", "turbine_torque_nm")


def synthetic_measurement(shape_effects_m2: tuple[float, float], end_s: float, seed: int) -> pd.DataFrame:
    """A rig record: the take-off of the converter with these shape effects (S_p, S_t), m², sampled at
    :data:`SAMPLE_RATE_HZ` with the sensor noise :data:`NOISE`, speeds in rpm."""
    model = dynamic_model(load_converter(CONVERTER), "hrovat-tobler").with_shape_effects(*shape_effects_m2)
    t = np.round(np.arange(0.0, end_s + 0.5 / SAMPLE_RATE_HZ, 1.0 / SAMPLE_RATE_HZ), 6)
    run = simulate(model, isolated_takeoff(), times_s=t.tolist())
    clean = {
        "pump_torque_nm": np.asarray(run["pump_torque_nm"]),
        "turbine_speed_rpm": np.asarray(run["turbine_speed_rad_s"]) / RAD_S_PER_RPM,
        "pump_speed_rpm": np.asarray(run["pump_speed_rad_s"]) / RAD_S_PER_RPM,
        "turbine_torque_nm": np.asarray(run["turbine_torque_nm"]),
    }
    rng = np.random.default_rng(seed)
    noisy = {name: values + rng.normal(0.0, NOISE[name], len(t)) for name, values in clean.items()}
    for name in ("turbine_speed_rpm", "pump_speed_rpm"):  # a speed sensor reads no negative speed
        noisy[name] = np.maximum(noisy[name], 0.0)
    return pd.DataFrame({"time_s": t, **noisy})


def measured_target(record: pd.DataFrame) -> dict[str, np.ndarray]:
    """The record in SI with its measured effective turbine torque (eqs 3.3, 3.4), N·m, under ``TARGET``."""
    channels = {
        "time_s": record["time_s"].to_numpy(),
        "pump_torque_nm": record["pump_torque_nm"].to_numpy(),
        "pump_speed_rad_s": record["pump_speed_rpm"].to_numpy() * RAD_S_PER_RPM,
        "turbine_speed_rad_s": record["turbine_speed_rpm"].to_numpy() * RAD_S_PER_RPM,
        "turbine_torque_nm": record["turbine_torque_nm"].to_numpy(),
    }
    inertia = dynamic_model(load_converter(CONVERTER), "hrovat-tobler").spec["inertia_kg_m2"]
    return {**channels, TARGET: measured_effective_torques(channels, inertia[1], inertia[0])[TARGET]}


def refit(record: pd.DataFrame) -> tuple[float, float]:
    """The fit of ``tcsim fit-shapes`` (drive (a), effective turbine torque) on a record in memory."""
    c = measured_target(record)
    drive = PumpTorqueTurbineSpeed(c["time_s"], c["pump_torque_nm"], c["turbine_speed_rad_s"])
    fit = fit_shape_effects(CONVERTER, "hrovat-tobler", drive, c["time_s"], c[TARGET], TARGET)
    return fit.pump_shape_effect_m2, fit.turbine_shape_effect_m2


def uncertainty(fitted: tuple[float, float], end_s: float) -> tuple[np.ndarray, np.ndarray]:
    """What the sensor noise does to the fit: a parametric bootstrap. The FITTED converter's take-off
    is recorded :data:`BOOTSTRAP_DRAWS` times with fresh noise and refitted; returns the refits' bias
    (mean − fitted) and standard deviation of (S_p, S_t), m². It covers the noise on the inputs (pump
    torque, turbine speed and its derivative) as well as on the outputs, which a Jacobian-based
    standard error of the output residuals alone does not."""
    refits = np.array([refit(synthetic_measurement(fitted, end_s, seed=1000 + k)) for k in range(BOOTSTRAP_DRAWS)])
    return refits.mean(axis=0) - np.asarray(fitted), refits.std(axis=0, ddof=1)


def main() -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("replay_fit_shapes"), help="folder of the outputs")
    parser.add_argument("--fast", action="store_true", help="a short record (CI)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    end_s = 2.0 if args.fast else 4.0

    # 1. The measurement a user would have: a CSV with tcsim's channel names (speeds in rpm).
    csv = args.out / "rig_takeoff.csv"
    record = synthetic_measurement(TRUE_SHAPE_EFFECTS_M2, end_s, seed=17)
    record.to_csv(csv, index=False)

    # 2. The replay (`tcsim replay li-sunden-2016 rig_takeoff.csv`): three models, nominal shape effects.
    rep = replay(CONVERTER, csv)
    metrics = rep.metrics[(rep.metrics["window"] == "all") & rep.metrics["channel"].isin(REPLAY_CHANNELS)]
    print(metrics[["model", "channel", "rmse", "max_abs_error"]].to_string(index=False, float_format="%.3f"))

    # 3. The fit (`tcsim fit-shapes li-sunden-2016 rig_takeoff.csv --model hrovat-tobler --out DIR`).
    print(shape_fit_command(CONVERTER, str(csv), args.out / "fit-shapes", "hrovat-tobler", TARGET))
    fit = json.loads((args.out / "fit-shapes" / "shape_fit.json").read_text(encoding="utf-8"))
    fitted = (fit["pump_shape_effect_m2"], fit["turbine_shape_effect_m2"])

    # 4. Its uncertainty from the noise, and the fitted against the true values.
    bias, spread = uncertainty(fitted, end_s)
    print("shape effect  true [m²]  fitted [m²]  bootstrap bias [m²]  bootstrap std [m²]  bound [m²]")
    for name, true, value, b, sd in zip(("S_p", "S_t"), TRUE_SHAPE_EFFECTS_M2, fitted, bias, spread):
        print(f"{name:12s}  {true:9.5f}  {value:11.5f}  {b:19.5f}  {sd:18.5f}  {abs(b) + 3 * sd:10.5f}")

    # 5. The figure: measured and replayed turbine torque; measured and fitted effective turbine torque.
    fig, (ax_torque, ax_effective) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    t = record["time_s"]
    ax_torque.plot(t, record["turbine_torque_nm"], ".", ms=1.5, color="0.6", label="measured")
    for (name, result), style in zip(rep.results.items(), ("-", "--", ":")):
        ax_torque.plot(result["time_s"], result["turbine_torque_nm"], style, label=f"{name} (nominal S)")
    sweep = pd.read_csv(args.out / "fit-shapes" / "shape_sweep.csv")
    fitted_run = sweep[sweep["label"].str.startswith("fitted")]
    ax_effective.plot(t, measured_target(record)[TARGET], ".", ms=1.5, color="0.6", label="measured")
    ax_effective.plot(fitted_run["time_s"], fitted_run[TARGET], "-", label=fitted_run["label"].iloc[0] + " m²")
    ax_torque.set_ylabel("turbine torque [N·m]")
    ax_effective.set_ylabel("effective turbine torque [N·m]")
    ax_effective.set_xlabel("time [s]")
    ax_effective.set_xlim(0.0, min(end_s, 1.5))
    for ax in (ax_torque, ax_effective):
        ax.legend(fontsize=8)
        ax.grid(True, alpha=0.3)
    figure = args.out / "replay_fit_shapes.png"
    fig.savefig(figure, dpi=120, bbox_inches="tight")
    print(f"figure: {figure}")
    return figure


if __name__ == "__main__":
    main()
