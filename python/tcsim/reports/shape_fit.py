"""Reports of ``tcsim fit-shapes``: ``shape_fit.json`` and ``shape_fit.md``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis.shape_fit import ShapeFitResult
from ..models.converter import Converter
from ..models.drives import DERIVATIVE_WINDOW_S
from ..models.measurement import Measurement
from .format import fmt_number


def shape_fit_json(
    result: ShapeFitResult, conv: Converter, meas: Measurement, drive: str, minima: pd.DataFrame, plots: list[Path]
) -> str:
    """The text of ``shape_fit.json``: the result, the sweep's minima and the plot files."""
    doc = {
        **result.to_dict(),
        "converter": conv.path,
        "measurement": meas.source,
        "drive": drive,
        "sweep": json_safe(minima.to_dict(orient="records")),
        "files": [p.name for p in plots],
    }
    return json.dumps(json_safe(doc), indent=2, allow_nan=False) + "\n"


def json_safe(x):
    if isinstance(x, dict):
        return {k: json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_safe(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def report_markdown(
    r: ShapeFitResult, conv: Converter, meas: Measurement, drive: str, minima: pd.DataFrame, sweep: pd.DataFrame
) -> str:
    """``shape_fit.md``: fitted values, RMSE against S = 0, bounds, and the sweep's minima."""
    gain = 100.0 * (1.0 - r.rmse / r.rmse_at_zero) if r.rmse_at_zero > 0 else math.nan
    bound = (
        "none (the quasi-dynamic model has no mass-matrix bound, docs/physics.md §5)"
        if r.bound_m2 is None
        else f"|S_p| < {r.bound_m2[0]:.4g} m², |S_t| < {r.bound_m2[1]:.4g} m² (each with the other at 0"
        + (", S_p = S_t" if r.equal else "")
        + "; mass matrix positive definite, docs/physics.md §4)"
    )
    lines = [
        f"# Shape effects of {conv.name} ({r.model}) fitted to a transient measurement",
        "",
        f"Measurement: {meas.source}, drive {drive}, {r.points} samples over "
        f"{r.time_window_s[0]:g}–{r.time_window_s[1]:g} s. Target: {r.target}, measured by eqs 3.3/3.4 "
        f"(Li & Sundén 2016 §3.5.2) with ω̇ the local least-squares slope over ±{DERIVATIVE_WINDOW_S / 2 * 1e3:g} ms.",
        "",
        "| quantity | value |",
        "|---|---|",
        f"| S_p (pump shape effect) | {r.pump_shape_effect_m2:.6g} m² |",
        f"| S_t (turbine shape effect) | {r.turbine_shape_effect_m2:.6g} m² |",
        f"| RMSE at the fit | {fmt_number(r.rmse, '.4g')} {r.unit} |",
        f"| RMSE with S = 0 | {fmt_number(r.rmse_at_zero, '.4g')} {r.unit} "
        f"({fmt_number(gain, '.1f')} % lower at the fit) |",
        f"| bounds S_p | {r.pump_bounds_m2[0]:.4g} to {r.pump_bounds_m2[1]:.4g} m² |",
        f"| bounds S_t | {r.turbine_bounds_m2[0]:.4g} to {r.turbine_bounds_m2[1]:.4g} m² |",
        f"| admissible (mass matrix) | {bound} |",
        f"| active bounds | {', '.join(f'{n} ({s})' for n, s in r.active.items()) or 'none'} |",
        f"| optimiser | scipy least_squares (trf), {r.evaluations} model runs, {r.elapsed_s:.2f} s; {r.message} |",
        "",
        "Sign convention: effective turbine output = T_transfer,t − ρS_t·Q̇, effective pump input = "
        "T_transfer,p + ρS_p·Q̇ (eqs 2.12–2.18); positive S deepens the drop in effective TR while the flow builds up.",
        "",
        "## Sweep (thesis figures 4.1/4.2)",
        "",
        "Deepest drop: the largest amount by which the effective TR falls below that of S = 0 at the same time.",
        "",
        "| shape effects | admissible | min effective TR | at [s] | deepest drop below S = 0 | at [s] "
        "| final effective TR |",
        "|---|---|---|---|---|---|---|",
        *[
            f"| {m.label} | {'yes' if m.admissible else 'no'} | {fmt_number(m.min_effective_torque_ratio, '.4f')} | "
            f"{fmt_number(m.time_of_min_s, '.3f')} | {fmt_number(m.drop_below_zero, '.4f')} | "
            f"{fmt_number(m.time_of_drop_s, '.3f')} | "
            f"{fmt_number(m.final_effective_torque_ratio, '.4f')} |"
            for m in minima.itertuples()
        ],
        "",
    ]
    notes = [n for n in dict.fromkeys(sweep.loc[~sweep["admissible"], "note"]) if n]
    if r.bound_m2 is not None and r.active:
        notes.append(
            "The fit stopped at a bound near the mass-matrix limit: the Hrovat & Tobler model cannot give a "
            "deeper drop with this geometry and these inertias (thesis §4.1: it could only be run up to S = 0.15)."
        )
    if notes:
        lines += ["## Notes", "", *[f"- {n}" for n in notes], ""]
    return "\n".join(lines)
