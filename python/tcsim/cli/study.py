"""``tcsim study``: the parameter study of Li & Sundén (2016), Appendix D.

Without ``--chunk-size``: DIR/study.csv and one figure per parameter, written atomically. With
``--chunk-size N``: the study in chunks of N cases, each written as a Parquet shard as it finishes
(``tcsim.io.shards``), resumable, optionally on a dask cluster (``--scheduler``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from ..errors import InputError
from .app import FormatOpt, OutOpt, SpeedUnitOpt, say, table_format

if TYPE_CHECKING:
    from ..analysis.chunked import ChunkedStudy
    from ..analysis.study import StudyDefinition
    from ..io.shards import ShardRun
    from ..io.tables import TableFormat

#: ``--values-per-parameter``: the most with ``--chunk-size``, and without it (one curve per value
#: in each figure).
MAX_VALUES_PER_PARAMETER = 1_000_000
MAX_VALUES_PER_PARAMETER_UNCHUNKED = 1000

#: The options of every sharded command (``tcsim study``, ``monte-carlo``, ``design-study``).
ChunkSizeOpt = Annotated[
    int | None,
    typer.Option(help="write Parquet shards of this many cases each (DIR/shards, DIR/manifest.json), resumable"),
]
SchedulerOpt = Annotated[
    str | None,
    typer.Option(help="with --chunk-size: 'local' (a dask LocalCluster) or a dask scheduler's address"),
]
WorkersOpt = Annotated[int | None, typer.Option(help="worker processes of --scheduler local (default: cores)")]
NoProgressOpt = Annotated[bool, typer.Option("--no-progress", help="no progress bar")]


def refuse_cluster_options(scheduler: str | None, workers: int | None) -> None:
    """``--scheduler`` and ``--workers`` without ``--chunk-size``: an :class:`InputError`."""
    for option, value in (("--scheduler", scheduler), ("--workers", workers)):
        if value is not None:
            raise InputError("command line", option, value, "to be given with --chunk-size (a sharded study)")


def refuse_format_with_shards(file_format: str) -> None:
    """``--format`` other than the default with ``--chunk-size``: an :class:`InputError` (the shards
    are Parquet whatever the format; a silently ignored option would surprise)."""
    if file_format != "csv":
        raise InputError(
            "command line", "--format", file_format, "csv (the default) with --chunk-size: shards are always Parquet"
        )


HELP = (
    "Appendix D parameter study: one figure per parameter and DIR/study.csv; with --chunk-size, "
    "DIR/shards/part-NNNNN.parquet and DIR/manifest.json instead, written as the chunks finish and "
    "resumed by running the same command again."
)


def study_command(
    converter: str,
    out: str | Path,
    definition: StudyDefinition | None = None,
    tf: TableFormat | None = None,
) -> str:
    """DIR/study.csv (``tf``: its format and speed unit, default CSV in rad/s) and
    DIR/study_<parameter>.png; the line to print."""
    from ..analysis.study import default_definition, run_study
    from ..io.outputs import check_output_dir, output_dir
    from ..io.results import write_frames
    from ..io.tables import CSV
    from ..models.converter import load_converter
    from ..plots.study import plot_study
    from ..reports.console import study_line

    tf = tf or CSV
    check_output_dir(out, [converter])
    conv = load_converter(converter)
    inputs = [converter, conv.path]
    check_output_dir(out, inputs)
    conv.require("hrovat-tobler")
    definition = definition or default_definition()
    df = run_study(conv, definition)
    title = f"{conv.name}, pump at {definition.pump_speed_rpm:g} rpm (stator free-wheeling above the coupling point)"
    references = {p.key: getattr(conv.geometry, p.key) for p in definition.parameters}
    with output_dir(out, inputs) as stage:
        write_frames({"study.csv": df}, stage, tf)
        plot_study(df, definition.parameters, references, title, stage)
    return study_line(df, definition, Path(out), tf.format)


def sharded_study_command(
    converter: str,
    out: str | Path,
    chunk_size: int,
    definition: StudyDefinition | None = None,
    speed_unit: str = "rad/s",
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool = True,
) -> str:
    """The study in chunks of ``chunk_size`` cases as DIR/shards/part-NNNNN.parquet and
    DIR/manifest.json (``tcsim.io.shards``), resuming what DIR holds; the line to print."""
    from ..analysis.chunked import appendix_d_study, check_chunk_size, check_scheduler
    from ..models.converter import load_converter

    check_chunk_size(chunk_size)
    check_scheduler(scheduler, workers)
    conv = load_converter(converter)
    study = appendix_d_study(conv, definition)
    inputs = [p for p in (converter, conv.path) if p]
    run = run_sharded(study, out, chunk_size, speed_unit, scheduler, workers, inputs, progress)
    return f"study: {run.n_cases} cases, {run.rows} points in {shards_line(run)}"


def run_sharded(
    study: ChunkedStudy,
    out: str | Path,
    chunk_size: int,
    speed_unit: str,
    scheduler: str | None,
    workers: int | None,
    inputs: Sequence[str | Path],
    progress: bool,
) -> ShardRun:
    """``study`` in chunks of ``chunk_size`` cases as DIR/shards/part-NNNNN.parquet and
    DIR/manifest.json (:func:`tcsim.io.shards.run_to_shards`), resuming what DIR holds, with a
    progress bar of the chunks unless ``progress`` is False: what every sharded command runs."""
    from ..io.shards import run_to_shards
    from ..reports.console import progress_display

    with progress_display(progress) as display:
        task = display.add_task(f"{study.kind} chunks", total=None)

        def advance(done: int, total: int) -> None:
            display.update(task, completed=done, total=total)

        return run_to_shards(study, out, chunk_size, speed_unit, scheduler, workers, inputs, advance)


def shards_line(run: ShardRun) -> str:
    """``N chunks of M cases (C computed, K kept from an earlier run) in DIR/shards and
    DIR/manifest.json``: the end of every sharded command's output line."""
    out = Path(run.out)
    return (
        f"{run.n_chunks} chunks of {run.chunk_size} cases ({len(run.computed)} computed, {len(run.kept)} kept "
        f"from an earlier run) in {out / 'shards'} and {out / 'manifest.json'}"
    )


def _values_per_parameter(n: int | None, chunked: bool) -> int | None:
    if n is None:
        return None
    most = MAX_VALUES_PER_PARAMETER if chunked else MAX_VALUES_PER_PARAMETER_UNCHUNKED
    if not 1 <= n <= most:
        why = "" if chunked else " without --chunk-size (one curve per value in each figure)"
        raise InputError("command line", "--values-per-parameter", n, f"an integer from 1 to {most}{why}")
    return n


def study(
    converter: Annotated[str, typer.Argument(help=r"converter with a \[geometry] section")],
    out: OutOpt = Path("study"),
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    values_per_parameter: Annotated[
        int | None,
        typer.Option(help="values of each parameter over its range (default 5), plus the converter's own"),
    ] = None,
    chunk_size: Annotated[
        int | None,
        typer.Option(help="write Parquet shards of this many cases each (a case: one parameter value), resumable"),
    ] = None,
    scheduler: SchedulerOpt = None,
    workers: WorkersOpt = None,
    no_progress: Annotated[bool, typer.Option("--no-progress", help="no progress bar (--chunk-size)")] = False,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..analysis.study import default_definition

    tf = table_format(file_format, speed_unit)
    n = _values_per_parameter(values_per_parameter, chunk_size is not None)
    definition = default_definition() if n is None else default_definition().replace(values_per_parameter=n)
    if chunk_size is None:
        refuse_cluster_options(scheduler, workers)
        say(study_command(converter, out, definition, tf=tf))
        return
    refuse_format_with_shards(file_format)
    line = sharded_study_command(
        converter, out, chunk_size, definition, tf.speed_unit, scheduler, workers, progress=not no_progress
    )
    say(line)
