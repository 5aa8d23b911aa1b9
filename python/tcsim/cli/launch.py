"""``tcsim launch``: whole-vehicle take-off with every converter model on the same vehicle.

The thesis's central comparison (Li & Sundén 2016, §3.2.2, §3.5.2.2, §4.1): a vehicle held on
the brake in first gear, then brake off and pedal on; the steady-state (table) model against the
dynamic models, whose effective torque ratio dips in the first tenths of a second.

::

    tcsim launch [VEHICLE] [--out DIR] [--scenario flip-flop|part-pedal|FILE] [--model M ...]
                 [--sweep-shape-effects]

Scenarios
---------
A :class:`~tcsim.simulation.scenarios.Scenario` is accelerator and brake pedal positions (0–1,
linearly interpolated) against time, an end time, an optional stop speed (the run ends when the
vehicle reaches it) and the brake release time from which the summary's times are measured.

* :func:`tcsim.simulation.scenarios.flip_flop` (``--scenario flip-flop``, the default; thesis §3.2.2
  and §3.5.1): first gear, brake 1 and pedal 0 for ``hold_s`` = 5 s, then within 0.05 s brake 0 and
  pedal 1; to 100 km/h or 30 s.
* :func:`tcsim.simulation.scenarios.part_pedal` (``--scenario part-pedal``): the same with pedal
  0.3; to 50 km/h or 40 s.
* :func:`tcsim.io.scenario.read_scenario` (``--scenario FILE``): a CSV, Parquet, ``.mat`` or MDF4
  file with ``time_s`` (or ``time_ms``), ``accelerator_pedal`` and ``brake_pedal`` (0–1; or
  ``accelerator_pedal_percent``/``brake_pedal_percent``, 0–100). Runs to the last time stamp. The
  brake release time is where the brake pedal's last fall to zero begins. The file's times are
  shifted so that its first sample is time 0.

Time 0 is the start of the scenario: the vehicle at rest (held by the brake if it is applied).

Runs
----
:func:`tcsim.simulation.launch.run_launch` is the only call into the core
(``tcsim._core.launch_runs``): all models in one call, the GIL released, one worker per core. Each
run gives a time series with at least :data:`tcsim.simulation.launch.LAUNCH_COLUMNS` and events
(gear shifts, lock-up, converter events) as ``(time_s, kind, ...)``, the ``events`` field of each
:class:`~tcsim.simulation.launch.LaunchRun`.

Outputs (in DIR, default ``launch``; written all at once, nothing on error)
---------------------------------------------------------------------------
* ``summary.csv``: one row per model, :data:`tcsim.analysis.launch.SUMMARY_COLUMNS`. Times are
  measured from the brake release; "first 0.5 s" is the 0.5 s after it; NaN where a speed is not reached.
  The launch peak apart from the shift transients, the effective-TR dip and recovery against the
  table model: docs/launch_summary.md, which defines every column.
* ``<model>.csv``: each model's time series; ``timeseries.csv``: all of them with a ``model`` column.
* ``events.csv``: ``model, time_s, kind, detail``; ``scenario.csv``: the pedal inputs.
* Plots like thesis figures 3.5, 3.6 and 3.20 (:mod:`tcsim.plots.launch`).
* With ``--sweep-shape-effects``: ``shape_sweep.csv``, ``shape_sweep_summary.csv`` and, per dynamic
  model, plots like figures 4.3–4.6: S_p = S_t over the thesis's values (quasi-dynamic, with the
  thesis's pair S_p = 0.4, S_t = 0.3) or over admissible values (Hrovat & Tobler,
  :func:`tcsim.models.shape_effects.sweep_values`), all runs in one batched core call, each to
  :data:`tcsim.simulation.launch.SWEEP_SPAN_S` after the brake release. A sweep run that fails is
  left out with a warning.

Errors: a bad vehicle file, scenario file or option is an :class:`~tcsim.errors.InputError` (exit 2,
nothing written); a solver failure is a :class:`~tcsim.simulation.transient.SolverError` (exit 1).

:func:`launch_files` (load → compute) and :func:`write_launch` (files and figures) are the Python
API of the command.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from .app import AllowImplausibleOpt, FormatOpt, ModelsOpt, OutOpt, PlotsOpt, SpeedUnitOpt, stdout, table_format

if TYPE_CHECKING:
    from ..analysis.launch import Launch
    from ..io.tables import TableFormat
    from ..models.vehicle import Vehicle
    from ..simulation.scenarios import Scenario

#: The command's ``--help`` text.
HELP = (
    "Vehicle take-off with every converter model: DIR/summary.csv, DIR/<model>.csv, plots like thesis "
    "figs 3.5, 3.6, 3.20."
)


def launch_files(
    vehicle: Vehicle | str | None = None,
    scenario: Scenario | str = "flip-flop",
    models: Sequence[str] = (),
    sweep: bool = False,
    threads: int = 0,
    options: dict[str, Any] | None = None,
    progress: bool = False,
    allow_implausible: bool = False,
) -> Launch:
    """Run the launch (no files written): the vehicle (bundled name, file or :class:`Vehicle`), the
    scenario (``flip-flop``, ``part-pedal``, a file or a :class:`Scenario`), every model, then the
    optional shape-effect sweep; ``progress`` shows a progress display on a terminal. A scenario
    file's implausible values (:func:`tcsim.io.scenario.read_scenario`) are refused unless
    ``allow_implausible``."""
    from ..analysis.launch import run_comparison
    from ..io.scenario import scenario_from_option
    from ..models.vehicle import Vehicle, load_vehicle
    from ..reports.console import progress_display
    from ..simulation.scenarios import Scenario

    veh = vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)
    scen = scenario if isinstance(scenario, Scenario) else scenario_from_option(scenario, allow_implausible)
    with progress_display(progress) as display:
        task = display.add_task("launch", total=None)
        return run_comparison(
            veh, scen, models, sweep, threads, options, on_step=lambda text: display.update(task, description=text)
        )


def write_launch(result: Launch, out_dir: Path, tf: TableFormat | None = None, plots: bool = True) -> list[Path]:
    """The tables (``tf``: format and speed unit, default CSV in rad/s) and, if ``plots``, the figures
    of a launch into ``out_dir`` (a staging directory)."""
    from ..io.results import write_launch_files
    from ..io.tables import CSV

    out_dir = Path(out_dir)
    paths = write_launch_files(result, out_dir, tf or CSV)
    if not plots:
        return paths
    from ..plots.launch import plot_launch, plot_sweep  # only with plots: matplotlib's import

    first_events = next(iter(result.runs.values())).events if result.runs else []
    release = result.scenario.brake_release_time_s
    paths += plot_launch(result.frames, first_events, release, result.scenario.name, out_dir, result.summary)
    if result.sweep is not None:
        paths += plot_sweep(result.sweep, result.frames.get("table"), release, out_dir)
    return paths


def launch(
    vehicle: Annotated[
        str | None, typer.Argument(help="bundled vehicle name or vehicle .toml (default: midsize-awd-8at)")
    ] = None,
    out: OutOpt = Path("launch"),
    scenario: Annotated[
        str,
        typer.Option("--scenario", help="flip-flop | part-pedal | FILE with time_s, accelerator_pedal, brake_pedal"),
    ] = "flip-flop",
    model: ModelsOpt = None,
    sweep_shape_effects: Annotated[
        bool,
        typer.Option(
            "--sweep-shape-effects", help="also sweep S_p = S_t of the dynamic models (like thesis figs 4.3–4.6)"
        ),
    ] = False,
    allow_implausible: AllowImplausibleOpt = False,
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..io.outputs import check_output_dir, output_dir
    from ..reports.console import launch_report, progress_display
    from ..reports.format import rich_text

    tf = table_format(file_format, speed_unit)
    check_output_dir(out, [p for p in (vehicle, scenario) if p])
    result = launch_files(
        vehicle, scenario, model or [], sweep_shape_effects, progress=True, allow_implausible=allow_implausible
    )
    inputs = [p for p in (vehicle, scenario, result.vehicle.path, result.vehicle.converter.path) if p]
    with output_dir(out, inputs) as stage, progress_display(True) as display:
        display.add_task(rich_text(f"writing {out}/ (files{' and plots' if plots else ''})"), total=None)
        write_launch(result, stage, tf, plots)
    stdout.print(launch_report(result, Path(out), tf.format, plots))
