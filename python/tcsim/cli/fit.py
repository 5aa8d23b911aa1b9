"""``tcsim fit``: Hrovat & Tobler parameters fitted to a characteristic table."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer

from .app import OutOpt, PlotsOpt, and_plots, say


def fit_command(
    converter: str,
    target: str,
    out: Path,
    free: str | None,
    bounds: list[str],
    speed_ratio_max: float | None,
    plots: bool = True,
) -> str:
    """Fit ``converter``'s [geometry] to the table of ``target``; write ``out`` (the figures if
    ``plots``); the line to print."""
    from ..analysis import fitting
    from ..errors import InputError, TcsimWarning
    from ..io.outputs import check_output_dir, output_dir
    from ..io.results import write_fit_files
    from ..models.converter import load_converter
    from ..models.steady import coupling_point
    from ..plots.fit import plot_fit
    from ..reports.fit import report_markdown

    check_output_dir(out, [converter, target])
    free_names = fitting.check_free(fitting.parse_free(free))
    user_bounds = fitting.parse_bounds(bounds)
    start = load_converter(converter)
    start.require("hrovat-tobler")
    assert start.geometry is not None  # require() checked it
    table = fitting.target_table(target)
    inputs = [converter, target, start.path, table.source]
    check_output_dir(out, inputs)
    try:
        result = fitting.fit_hrovat_tobler(start.geometry, table, free_names, user_bounds, speed_ratio_max)
    except InputError as e:
        if e.source == "start converter":
            raise e.replace(source=start.path) from None
        raise
    outcome = fitting.fit_outcome(start, result, table, fitting.target_label(target))
    for line in outcome.warnings:  # only once the fitted converter passed its checks
        warnings.warn(line, TcsimWarning, stacklevel=1)
    fitted = outcome.converter
    report = report_markdown(result, start, outcome.provenance, outcome.warnings)
    with output_dir(out, inputs) as stage:
        write_fit_files(stage, start, fitted, result, table, report, outcome.provenance)
        curves = {
            "fitted Hrovat & Tobler": fitting.model_curve(fitted),
            "start Hrovat & Tobler": fitting.model_curve(start),
        }
        title = f"Fit to {Path(table.source).name or table.source} (SR 0–{result.speed_ratio_max:g})"
        if plots:
            plot_fit(curves, stage, title, table, result.speed_ratio_max, coupling_point(fitted))
    kept = [p for p in outcome.provenance if p.startswith(("[inertia]", "[quasi_dynamic]"))]
    return "\n".join(
        [
            f"{result.one_line()}.",
            *kept,
            f"Written to {out}/: fitted.toml, fit_report.md, fit_report.json{and_plots(plots)}.",
        ]
    )


def fit(
    converter: Annotated[str, typer.Argument(help="converter whose Hrovat & Tobler parameters are the start point")],
    target: Annotated[
        str, typer.Option("--target", help="characteristic table to fit: .csv, .vtcc or converter .toml")
    ],
    out: OutOpt = Path("fit"),
    free: Annotated[
        str | None, typer.Option(help="comma-separated parameters to free (default: losses and the six angles)")
    ] = None,
    bound: Annotated[list[str] | None, typer.Option(help="NAME=LO:HI bounds of a free parameter, repeatable")] = None,
    speed_ratio_max: Annotated[
        float | None, typer.Option(help="fit SR from 0 up to this (default: the table's coupling point)")
    ] = None,
    plots: PlotsOpt = True,
) -> None:
    """Fit Hrovat & Tobler parameters to a characteristic table: DIR/fitted.toml, report, plots."""
    say(fit_command(converter, target, out, free, bound or [], speed_ratio_max, plots))
