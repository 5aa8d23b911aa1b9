"""``fit_report.md`` of ``tcsim fit``: values, bounds, errors, correlations, optimiser statistics."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..analysis.fit_derived import DERIVED_KEYS
from ..analysis.fitting import SEED, FitResult
from ..models.converter import Converter
from .format import fmt_number


def _parameter_table(r: FitResult) -> list[str]:
    lines = ["| parameter | start | fitted | lower | upper | active | std. error |", "|---|---|---|---|---|---|---|"]
    shown = {True: fmt_number, False: lambda x: "not identifiable"}
    for i, n in enumerate(r.free):
        lo, hi = r.bounds[n]
        lines.append(
            f"| {n} | {fmt_number(r.start_values[n])} | {fmt_number(r.values[n])} | "
            f"{fmt_number(lo)} | {fmt_number(hi)} | "
            f"{r.active.get(n, '')} | {shown[bool(r.identifiable[i])](r.std_error[i])} |"
        )
    return lines


def _derived_table(r: FitResult) -> list[str]:
    lines = ["| derived | start | fitted |", "|---|---|---|"]
    for k in DERIVED_KEYS:
        lines.append(f"| {k} | {fmt_number(getattr(r.start, k))} | {fmt_number(getattr(r.geometry, k))} |")
    return lines


def _point_table(r: FitResult) -> list[str]:
    lines = [
        "| SR | TR table | TR model | TR error % | CF table | CF model | CF error % |",
        "|---|---|---|---|---|---|---|",
    ]
    for i, s in enumerate(r.speed_ratio):
        lines.append(
            f"| {s:g} | {r.torque_ratio_table[i]:.4g} | {r.torque_ratio_model[i]:.4f} | {100 * r.tr_error[i]:+.3f} | "
            f"{r.capacity_factor_table[i]:.4g} | {r.capacity_factor_model[i]:.4e} | {100 * r.cf_error[i]:+.3f} |"
        )
    return lines


def _correlation_table(r: FitResult) -> list[str]:
    short = [f"p{i + 1}" for i in range(len(r.free))]
    lines = ["| | " + " | ".join(short) + " |", "|---|" + "---|" * len(short)]
    for i, n in enumerate(r.free):
        lines.append(
            f"| p{i + 1} {n} | "
            + " | ".join("–" if not np.isfinite(v) else f"{v:+.2f}" for v in r.correlation[i])
            + " |"
        )
    return lines


def report_markdown(
    r: FitResult,
    start: Converter,
    provenance: Sequence[str] = (),
    warnings: Sequence[str] = (),
    notes: Sequence[str] = (),
) -> str:
    """``fit_report.md``: values, bounds, errors, warnings (one line per parameter at a bound or outside
    its measured range, and the checks'), where each value of ``fitted.toml`` comes from
    (``provenance``), the derived geometry, correlations and optimiser statistics."""
    active = ", ".join(f"{n} ({side})" for n, side in r.active.items()) or "none"
    singular = (
        f"singular, rank {r.jacobian_rank} of {len(r.free)} (correlations from the pseudo-inverse)"
        if r.singular
        else "full rank"
    )
    singular += f", condition number {r.condition_number:.3g} (scaled parameters, non-zero singular values)"
    lines = [
        "# Fit of Hrovat & Tobler parameters",
        "",
        f"Start: {start.name} ({start.path}). Target: {r.table_source}. Fitted: {len(r.speed_ratio)} table points "
        f"with SR 0–{r.speed_ratio_max:g}, residuals the relative errors of TR and CF (Li & Sundén 2016 §3.2.1; "
        "steady state of Hrovat & Tobler 1985, eqs 2.12–2.25 with zero left-hand sides).",
        "",
        f"- RMS relative error: TR {100 * r.rms_tr:.3f} %, CF {100 * r.rms_cf:.3f} %",
        f"- max relative error: TR {100 * r.max_tr:.3f} %, CF {100 * r.max_cf:.3f} %",
        f"- active bounds: {active}",
        f"- Jacobian at the solution: {singular}",
        f"- optimiser: scipy least_squares (trf, analytic Jacobian), {r.starts} starts (seed {SEED}), "
        f"{r.nfev} function evaluations, {r.njev} Jacobian evaluations in the best run, {r.elapsed_s:.2f} s; "
        f"{r.message}",
        "",
        "## Warnings",
        "",
        *([f"- {w}" for w in warnings] or ["- none: every free parameter ends inside its bounds and measured range"]),
        "",
        "## Where the values of fitted.toml come from",
        "",
        *[f"- {p}" for p in provenance],
        "",
        *_derived_table(r),
        "",
        "## Parameters",
        "",
        "Angles in degrees. Standard errors from s²·(JᵀJ)⁻¹ are indicative only: the residuals are model error, "
        "not noise.",
        "",
        *_parameter_table(r),
        "",
        "## Points",
        "",
        *_point_table(r),
        "",
        "## Correlation of the free parameters",
        "",
        *_correlation_table(r),
        "",
    ]
    if r.notes or notes:
        lines += ["## Notes", "", *[f"- {n}" for n in (*r.notes, *notes)], ""]
    return "\n".join(lines)
