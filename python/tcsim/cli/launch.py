"""``tcsim launch``: whole-vehicle take-off with every converter model (see :mod:`tcsim.analysis.launch`).

:func:`launch_files` (load → compute) and :func:`write_launch` (files and figures) are also the
Python API ``tcsim.launch.launch`` and ``tcsim.launch.write_launch``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from .app import ModelsOpt, OutOpt, stdout

if TYPE_CHECKING:
    from ..analysis.launch import Launch
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
) -> Launch:
    """Run the launch (no files written): the vehicle (bundled name, file or :class:`Vehicle`), the
    scenario (``flip-flop``, ``part-pedal``, a file or a :class:`Scenario`), every model, then the
    optional shape-effect sweep; ``progress`` shows a progress display on a terminal."""
    from ..analysis.launch import run_comparison
    from ..io.scenario import scenario_from_option
    from ..models.vehicle import Vehicle, load_vehicle
    from ..reports.console import progress_display
    from ..simulation.scenarios import Scenario

    veh = vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)
    scen = scenario if isinstance(scenario, Scenario) else scenario_from_option(scenario)
    with progress_display(progress) as display:
        task = display.add_task("launch", total=None)
        return run_comparison(
            veh, scen, models, sweep, threads, options, on_step=lambda text: display.update(task, description=text)
        )


def write_launch(result: Launch, out_dir: Path) -> list[Path]:
    """The CSV files and figures of a launch into ``out_dir`` (a staging directory)."""
    from ..io.results import write_launch_files
    from ..plots.launch import plot_launch, plot_sweep

    out_dir = Path(out_dir)
    paths = write_launch_files(result, out_dir)
    first_events = next(iter(result.runs.values())).events if result.runs else []
    release = result.scenario.brake_release_time_s
    paths += plot_launch(result.frames, first_events, release, result.scenario.name, out_dir)
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
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..io.outputs import output_dir
    from ..reports.console import launch_report, progress_display

    result = launch_files(vehicle, scenario, model or [], sweep_shape_effects, progress=True)
    with output_dir(out) as stage, progress_display(True) as display:
        display.add_task(f"writing {out}/ (files and plots)", total=None)
        write_launch(result, stage)
    stdout.print(launch_report(result, Path(out)))
