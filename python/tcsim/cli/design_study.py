"""``tcsim design-study``: one or two parameters of a design swept over a full grid, each design's
steady-state and take-off figures (:mod:`tcsim.analysis.design_study`).

::

    tcsim design-study DESIGN --sweep NAME=MIN:MAX:N [--sweep NAME2=MIN:MAX:N] [--out DIR]
    tcsim design-study DESIGN --sweep ... --chunk-size N [--scheduler local|ADDRESS] [--workers N]

DIR (default ``design-study``) receives, all at once and nothing on error (:mod:`tcsim.io.outputs`):
``study.csv`` (one row per design) and ``pareto.png``. Bad input: exit 2, one line. With
``--chunk-size``: the rows of ``study.csv`` without ``pareto_front`` (it compares all designs) as
DIR/shards/part-NNNNN.parquet and DIR/manifest.json, written as the chunks finish and resumed by
running the same command again (:class:`tcsim.analysis.chunked.DesignSweepStudy`, docs/study.md).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer

from .app import FormatOpt, OutOpt, PlotsOpt, SpeedUnitOpt, say, table_format
from .study import (
    ChunkSizeOpt,
    NoProgressOpt,
    SchedulerOpt,
    WorkersOpt,
    refuse_cluster_options,
    refuse_format_with_shards,
)

#: The command's ``--help`` text.
HELP = (
    "Sweep one or two design parameters (NAME=MIN:MAX:N each) over a full grid: DIR/study.csv with each "
    "design's stall TR, K-factor, peak efficiency, coupling point and take-off dip, and a Pareto plot; with "
    "--chunk-size, resumable Parquet shards of the rows (without pareto_front), optionally on a dask cluster."
)


def design_study(
    design: Annotated[str, typer.Argument(help="design .toml or bundled design name (li-sunden-2016-design)")],
    sweep: Annotated[
        list[str], typer.Option("--sweep", help="NAME=MIN:MAX:N, N values from MIN to MAX; once or twice")
    ],
    out: OutOpt = Path("design-study"),
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
    chunk_size: ChunkSizeOpt = None,
    scheduler: SchedulerOpt = None,
    workers: WorkersOpt = None,
    no_progress: NoProgressOpt = False,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..analysis.chunked import check_chunk_size, check_scheduler, design_sweep_study
    from ..analysis.design_study import check_sweep, design_study, parse_sweep
    from ..errors import InputError, TcsimWarning
    from ..io.outputs import check_output_dir, output_dir
    from ..io.tables import write_table
    from ..models.design_file import load_design_file
    from ..plots.design_study import plot_design_pareto
    from .study import run_sharded, shards_line

    tf = table_format(file_format, speed_unit)
    parsed = [parse_sweep(s) for s in sweep]
    names = [n for n, _ in parsed]
    if len(set(names)) != len(names):
        raise InputError("--sweep", "NAME", names[-1], "two different parameters")
    values = dict(parsed)
    check_sweep(values, chunked=chunk_size is not None)
    if chunk_size is not None:
        check_chunk_size(chunk_size)
        check_scheduler(scheduler, workers)
        refuse_format_with_shards(file_format)
        file = load_design_file(design)
        chunked = design_sweep_study(file, values)
        run = run_sharded(
            chunked, out, chunk_size, tf.speed_unit, scheduler, workers, [design, file.path], not no_progress
        )
        say(f"{file.name}: {run.n_cases} designs of {' × '.join(names)}, {run.rows} rows in {shards_line(run)}")
        return
    refuse_cluster_options(scheduler, workers)
    check_output_dir(out, [design])
    file = load_design_file(design)
    study = design_study(file, values)
    inputs = [design, file.path]
    with output_dir(out, inputs) as stage:
        write_table(study, stage, "study.csv", tf)
        if plots:
            plot_design_pareto(study, stage, f"{file.name}: design study of {' × '.join(names)}")
    failed = int((study["error"] != "").sum())
    if failed == len(study):  # a script cannot tell it from a good study by the exit code alone
        first = study["error"].iloc[0]
        warnings.warn(f"none of the {failed} designs has figures (the first: {first})", TcsimWarning, stacklevel=1)
    say(f"{file.name}: {len(study)} designs of {' × '.join(names)}, {failed} without figures, written to {out}")
    front = study[study["pareto_front"]]
    say(f"Pareto front: {len(front)} designs (stall TR against take-off effective-TR dip)")
