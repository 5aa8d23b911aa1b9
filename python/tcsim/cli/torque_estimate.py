"""``tcsim torque-estimate``: an estimated engine torque (the ECM's) against a measured one (thesis §3.3).

::

    tcsim torque-estimate ESTIMATE DYNO [--estimate-column COLUMN] [--measured-column COLUMN]
                          [--max-delay S] [--allow-implausible] [--out DIR]

Both files are time series in any supported format (CSV, Parquet, ``.mat``, MDF4) with a time column
(``time_s`` or ``time_ms``) and an engine torque column: ``engine_torque_nm`` (or ``engine_torque_knm``,
``engine_torque_lbf_ft``, converted), or the column the option names. The method is
:mod:`tcsim.analysis.torque_estimate` (``docs/torque_estimate.md``).

Outputs (in DIR, default ``torque-estimate``; written all at once, nothing on error): ``summary.csv``
(one row), ``steps.csv`` (one row per load step), ``timeseries.csv`` (the common grid),
``torque_estimate.png`` and, with load steps, ``steps.png``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from .app import AllowImplausibleOpt, FormatOpt, OutOpt, PlotsOpt, SpeedUnitOpt, say, table_format

if TYPE_CHECKING:
    from ..analysis.torque_estimate import TorqueComparison, TorqueSignal
    from ..io.tables import TableFormat

#: The most steps the command prints (steps.csv lists all).
MAX_STEP_LINES = 10
#: The command's ``--help`` text.
HELP = (
    "Compare an estimated engine torque (e.g. the ECM's) with a measured one (dynamometer): delay, errors overall "
    "and per load step, time to 90 % torque, sampling check (thesis §3.3): DIR/summary.csv, steps.csv, "
    "timeseries.csv, plots."
)


def read_torque(path: str | Path, column: str | None, option: str, allow_implausible: bool = False) -> TorqueSignal:
    """The engine torque of a time-series file (``column``, else ``engine_torque_nm`` or the same
    quantity in another unit), in N·m over s; an InputError naming ``option`` when it is missing."""
    from ..analysis.torque_estimate import CHANNEL, TorqueSignal
    from ..errors import InputError
    from ..io.measurement import read_measurement

    channels = {CHANNEL: column} if column else {}
    try:
        meas = read_measurement(path, channels, required=(CHANNEL,), optional=(), allow_implausible=allow_implausible)
    except InputError as e:
        expected = e.expected.replace(f"--channel {CHANNEL}=", f"{option} ")
        raise e.replace(expected=expected) from None
    return TorqueSignal(meas.source, meas.time_s, meas.channels[CHANNEL])


def torque_estimate_files(
    estimate: str | Path,
    measured: str | Path,
    estimate_column: str | None = None,
    measured_column: str | None = None,
    max_delay_s: float = 1.0,
    allow_implausible: bool = False,
) -> TorqueComparison:
    """Read both files and compare them (no files written)."""
    from ..analysis.torque_estimate import check_max_delay, compare_torques

    check_max_delay(max_delay_s)
    est = read_torque(estimate, estimate_column, "--estimate-column", allow_implausible)
    meas = read_torque(measured, measured_column, "--measured-column", allow_implausible)
    return compare_torques(est, meas, max_delay_s)


def write_torque_estimate(
    comparison: TorqueComparison, out_dir: Path, tf: TableFormat | None = None, plots: bool = True
) -> list[Path]:
    """The tables (``tf``: format and speed unit, default CSV in rad/s) and (if ``plots``) figures of a comparison
    into ``out_dir`` (a staging directory). The aligned columns are empty where the shifted time lies
    outside the estimate's record, by design (so without the warning of
    :func:`tcsim.io.results.write_frames` of NaN in a result)."""
    from ..io.results import write_frames
    from ..io.tables import CSV
    from ..plots.torque_estimate import plot_torque_estimate

    files = {
        "summary.csv": comparison.summary(),
        "steps.csv": comparison.steps_frame(),
        "timeseries.csv": comparison.timeseries(),
    }
    paths = write_frames(files, Path(out_dir), tf or CSV, warn=False)
    return paths + plot_torque_estimate(comparison, Path(out_dir)) if plots else paths


def report_lines(comparison: TorqueComparison) -> list[str]:
    """What the command prints: the delay, the overall errors and one line per step (the first
    :data:`MAX_STEP_LINES`)."""
    row = comparison.summary().iloc[0]
    lines = [
        f"delay {row['delay_s']:.4g} s (positive: the estimate lags; correlation {row['correlation']:.4f}), "
        f"grid {row['grid_step_s']:.4g} s over {row['common_start_s']:.4g}–{row['common_end_s']:.4g} s",
        f"as logged: RMSE {row['rmse_nm']:.4g} N·m, largest error {row['largest_error_nm']:.4g} N·m "
        f"at {row['largest_error_time_s']:.4g} s",
        f"aligned:   RMSE {row['rmse_aligned_nm']:.4g} N·m, largest error {row['largest_error_aligned_nm']:.4g} N·m "
        f"at {row['largest_error_aligned_time_s']:.4g} s",
    ]
    steps = comparison.steps_frame()
    for _, s in steps.head(MAX_STEP_LINES).iterrows():
        lines.append(
            f"step {int(s['step'])} at {s['measured_t90_s']:.4g} s: {s['initial_torque_nm']:.4g} → "
            f"{s['final_torque_nm']:.4g} N·m, rise 10–90 % {s['measured_rise_10_90_s']:.3g} s, t90 error "
            f"{s['t90_error_s']:.3g} s (aligned {s['t90_error_aligned_s']:.3g} s), RMSE {s['rmse_nm']:.4g} N·m"
        )
    if len(steps) > MAX_STEP_LINES:
        lines.append(f"... and {len(steps) - MAX_STEP_LINES} more steps (steps.csv lists all)")
    return lines


def torque_estimate(
    estimate: Annotated[str, typer.Argument(help="estimated engine torque: .csv, .parquet, .mat or .mf4/.mdf")],
    dyno: Annotated[str, typer.Argument(help="measured engine torque (dynamometer), same formats")],
    estimate_column: Annotated[
        str | None, typer.Option("--estimate-column", help="ESTIMATE's torque column (default: engine_torque_nm)")
    ] = None,
    measured_column: Annotated[
        str | None, typer.Option("--measured-column", help="DYNO's torque column (default: engine_torque_nm)")
    ] = None,
    max_delay: Annotated[
        float, typer.Option("--max-delay", help="largest delay searched, s, either sign (at most half the overlap)")
    ] = 1.0,
    allow_implausible: AllowImplausibleOpt = False,
    out: OutOpt = Path("torque-estimate"),
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..io.outputs import check_output_dir, output_dir

    tf = table_format(file_format, speed_unit)
    check_output_dir(out, [estimate, dyno])
    result = torque_estimate_files(estimate, dyno, estimate_column, measured_column, max_delay, allow_implausible)
    with output_dir(out, [estimate, dyno]) as stage:
        write_torque_estimate(result, stage, tf, plots)
    for line in report_lines(result):
        say(line)
    say(f"written to {out}/")
