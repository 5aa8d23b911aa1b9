"""What the commands print: the launch and replay tables (rich), the study's line, and the progress
display of long runs (on stderr, silent when stderr is not a terminal)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
from rich import box
from rich.console import Console, Group
from rich.progress import BarColumn, MofNCompleteColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn
from rich.table import Table

from ..analysis.launch import Launch
from ..analysis.replay import Replay
from ..analysis.study import StudyDefinition
from .format import fmt_number, rich_text


@contextlib.contextmanager
def progress_display(enabled: bool) -> Iterator[Progress]:
    """A rich progress display on stderr; silent when stderr is not a terminal."""
    console = Console(stderr=True)
    with Progress(
        SpinnerColumn(),
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        transient=True,
        disable=not (enabled and console.is_terminal),
    ) as progress:
        yield progress


#: Rows of the launch table: (label with unit, summary.csv column, format). The table has one
#: column per model, so that it fits 80 columns with the three models' names whole.
LAUNCH_ROWS: tuple[tuple[str, str, str], ...] = (
    ("0–50 km/h [s]", "time_0_50_km_h_s", ".2f"),
    ("0–100 km/h [s]", "time_0_100_km_h_s", ".2f"),
    ("launch peak accel [m/s²]", "launch_peak_accel_m_s2", ".2f"),
    ("  at [s after release]", "launch_peak_accel_time_s", ".2f"),
    ("shift peak accel [m/s²]", "shift_peak_accel_m_s2", ".2f"),
    ("  ÷ accel before the shift [-]", "max_shift_accel_ratio", ".2f"),
    ("mean accel 0–0.5 s [m/s²]", "mean_accel_first_0_5_s_m_s2", ".2f"),
    ("min eff. TR 0–0.5 s [-]", "min_effective_torque_ratio_first_0_5_s", ".3f"),
    ("eff. TR dip vs table [-]", "effective_torque_ratio_dip_first_0_5_s", ".3f"),
    ("  at [s after release]", "effective_torque_ratio_dip_time_s", ".2f"),
    ("eff. TR recovery (±0.05) [s]", "effective_torque_ratio_recovery_time_s", ".2f"),
)


def _launch_table(result: Launch) -> Table:
    """The summary as rows of metrics, one column per model (names never cut)."""
    s = result.scenario
    table = Table(
        title=rich_text(
            f"launch of {result.vehicle.name} ({result.vehicle.converter.name}), scenario {s.name}, "
            f"brake release at {s.brake_release_time_s:g} s"
        ),
        box=box.SIMPLE_HEAD,
        pad_edge=False,
    )
    table.add_column("metric", no_wrap=True)
    names = [str(m) for m in result.summary["model"]]
    for name in names:
        table.add_column(rich_text(name), justify="right", no_wrap=True, min_width=len(name))
    reached = {"missing": "–"}
    for label, column, spec in LAUNCH_ROWS:
        values = result.summary[column] if column in result.summary.columns else [None] * len(names)
        table.add_row(rich_text(label), *(fmt_number(v, spec, **reached) for v in values))
    return table


def launch_report(result: Launch, out: Path, ext: str = "csv", plots: bool = True) -> Group:
    """A rich table of the launch summary (docs/launch_summary.md) and where the files are (tables
    with the suffix ``ext``; and plots if ``plots``)."""
    lines = [
        "–: not reached or nothing to compare with; times are from the brake release",
        f"compute {result.compute_s * 1e3:.0f} ms for {len(result.runs)} model{'s' if len(result.runs) != 1 else ''}"
        + (f", sweep {result.sweep_compute_s * 1e3:.0f} ms" if result.sweep is not None else ""),
        rich_text(
            f"written to {out}/: summary.{ext}, {', '.join(f'{m}.{ext}' for m in result.runs)}, timeseries.{ext}, "
            f"events.{ext}, scenario.{ext}{f', shape_sweep*.{ext}' if result.sweep is not None else ''}"
            + (" and plots" if plots else "")
        ),
    ]
    return Group(_launch_table(result), *lines)


def replay_report(replay: Replay, out: Path, ext: str = "csv", plots: bool = True) -> Group:
    """A short rich summary: per model the events and the turbine-torque RMSE, then where the files
    are (tables with the suffix ``ext``). Model names and numbers are never cut; the events wrap."""
    table = Table(
        title=rich_text(
            f"replay of {replay.measurement.source} on {replay.converter}, drive {replay.drive.name}, "
            f"{len(replay.measurement.time_s)} samples"
        )
    )
    names = [str(name) for name in replay.results]
    table.add_column("model", no_wrap=True, min_width=max(map(len, names), default=5))
    table.add_column("events", overflow="fold")
    table.add_column("turbine torque RMSE [N·m]", justify="right", min_width=9)
    table.add_column("NRMSE [-]", justify="right", min_width=9)
    metrics = replay.metrics
    rows = metrics[(metrics["channel"] == "turbine_torque_nm") & (metrics["window"] == "all")]
    for name, result in replay.results.items():
        events = ", ".join(f"{e.kind} {e.time_s:.3f} s" for e in result.events) or "none"
        row = rows[rows["model"] == name]
        rmse, nrmse = (f"{row[c].iloc[0]:.4g}" for c in ("rmse", "nrmse")) if len(row) else ("n/a", "n/a")
        table.add_row(rich_text(name), rich_text(events), rmse, nrmse)
    return Group(
        table,
        rich_text(
            f"written to {out}/: {', '.join(f'{m}.{ext}' for m in replay.results)}, events.{ext}, "
            f"measurement.{ext}{f', metrics.{ext}' if len(metrics) else ''}" + (" and plots" if plots else "")
        ),
    )


def study_line(df: pd.DataFrame, definition: StudyDefinition, out: Path, ext: str = "csv") -> str:
    """The one line ``tcsim study`` prints, the table with the suffix ``ext`` (plain text: escape it
    with :func:`rich_text` for rich)."""
    n_values = df.groupby("parameter", sort=False)["parameter_value"].nunique().sum()
    solved = int(np.isfinite(df["torque_ratio"]).sum())
    free = int(df["stator_mode"].isin(["free-wheeling", "no-flow"]).sum())
    return (
        f"study: {len(definition.parameters)} parameters, {n_values} values, {len(df)} points "
        f"({solved} with a steady state, {free} of them past the coupling point) written to {out}/study.{ext} "
        f"and {len(definition.parameters)} figures"
    )
