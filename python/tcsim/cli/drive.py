"""``tcsim drive``: every converter model in one vehicle follows a drive cycle.

::

    tcsim drive [VEHICLE] --cycle NAME|FILE [--model M ...] [--out DIR]

A driver (PI on the vehicle speed with feed-forward, engine braking before the brakes, the brake
held at stops; ``docs/drive.md``) follows the speed trace with the gears and the lock-up clutch by
the vehicle's schedules and the converter in all four quadrants.

Cycles: ``us06``, ``udds``, ``hwfet``, ``wltc-3b`` (bundled, sources in their files' headers), or a
trace file (CSV, Parquet, ``.mat``, MDF4) with ``time_s``, ``vehicle_speed_m_s`` and optionally
``grade_percent`` (:func:`tcsim.io.cycle.read_cycle`).

Outputs (in DIR, default ``drive``; written all at once, nothing on error): ``<model>.csv`` (time
series every control step, 0.1 s), ``summary.csv`` (:data:`tcsim.analysis.drive.SUMMARY_COLUMNS`),
``events.csv``, ``cycle.csv`` (the trace), ``speed.png`` and ``losses.png``; on the console the
summary as a table of metrics by model (:func:`tcsim.reports.drive.drive_report`).

Errors: a bad vehicle file, trace file or option is an :class:`~tcsim.errors.InputError` (exit 2,
nothing written); a solver failure exit 1.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .app import FormatOpt, ModelsOpt, OutOpt, PlotsOpt, SpeedUnitOpt, stdout, table_format

#: The command's ``--help`` text.
HELP = (
    "Follow a drive cycle with every converter model: DIR/summary.csv (speed error, converter and lock-up "
    "losses, brake energy, heat), DIR/<model>.csv, plots. Cycles: us06, udds, hwfet, wltc-3b or a FILE."
)


def drive(
    vehicle: Annotated[
        str | None, typer.Argument(help="bundled vehicle name or vehicle .toml (default: midsize-awd-8at)")
    ] = None,
    cycle: Annotated[
        str,
        typer.Option(
            "--cycle",
            help="us06 | udds | hwfet | wltc-3b | FILE with time_s, vehicle_speed_m_s [, grade_percent]",
        ),
    ] = "us06",
    model: ModelsOpt = None,
    out: OutOpt = Path("drive"),
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..analysis.drive import BUNDLED_CYCLES
    from ..analysis.drive import drive as run
    from ..io.cycle import cycle_from_option, write_drive_files
    from ..io.outputs import check_output_dir, output_dir
    from ..models.vehicle import load_vehicle
    from ..plots.drive import plot_drive
    from ..reports.console import progress_display
    from ..reports.drive import drive_report
    from ..reports.format import rich_text

    tf = table_format(file_format, speed_unit)
    trace_file = None if cycle in BUNDLED_CYCLES else cycle
    check_output_dir(out, [p for p in (vehicle, trace_file) if p])
    veh = load_vehicle(vehicle)
    trace = cycle_from_option(cycle)
    with progress_display(True) as display:
        display.add_task(rich_text(f"driving {trace.name}"), total=None)
        result = run(veh, trace, model or [])
    inputs = [p for p in (vehicle, trace_file, veh.path, veh.converter.path) if p]
    with output_dir(out, inputs) as stage:
        write_drive_files(result, stage, tf)
        if plots:
            plot_drive(result, stage)
    stdout.print(drive_report(result, out, tf.format, plots))
