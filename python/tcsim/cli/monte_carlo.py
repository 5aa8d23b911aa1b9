"""``tcsim monte-carlo``: a Monte Carlo study of the vehicle launch, its parameters drawn from the
distributions of a study file (:mod:`tcsim.models.study_file`, :mod:`tcsim.analysis.monte_carlo`).

::

    tcsim monte-carlo FILE [--out DIR] [--format F] [--speed-unit U] [--no-plots]
    tcsim monte-carlo FILE --chunk-size N [--scheduler local|ADDRESS] [--workers N] [--no-progress]

Without ``--chunk-size``: DIR/monte_carlo.csv (one row per case and model: the drawn parameters
and the outputs) and DIR/monte_carlo_<output>.png (a histogram per output), written atomically,
for at most :data:`~tcsim.models.study_file.MAX_RUNS_UNCHUNKED` cases. With it: the same rows as
DIR/shards/part-NNNNN.parquet and DIR/manifest.json, written as the chunks finish, resumed by
running the same command again, optionally on a dask cluster (``tcsim.io.shards``).

A separate command, not ``tcsim study FILE.toml``: ``tcsim study`` takes a converter, which is
also a ``.toml`` file, and its options (``--values-per-parameter``) mean nothing here.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from .app import FormatOpt, OutOpt, PlotsOpt, SpeedUnitOpt, say, table_format
from .study import ChunkSizeOpt, NoProgressOpt, SchedulerOpt, WorkersOpt, refuse_cluster_options

if TYPE_CHECKING:
    import pandas as pd

    from ..analysis.monte_carlo import MonteCarloStudy

#: The command's ``--help`` text.
HELP = (
    "Monte Carlo study of the vehicle launch: converter and vehicle parameters drawn from the distributions "
    "of a study file (tcsim init monte-carlo writes one); DIR/monte_carlo.csv and a histogram per output, or "
    "with --chunk-size resumable Parquet shards, optionally on a dask cluster."
)
#: The table of an unchunked study.
TABLE = "monte_carlo.csv"


def summary_lines(df: pd.DataFrame, study: MonteCarloStudy) -> list[str]:
    """Per output one line: each model's mean and standard deviation over its finished runs, and
    how many finished runs have no value of it (a speed never reached)."""
    lines = []
    for output in study.outputs:
        parts = []
        for model in study.models:
            finished = df.loc[(df["model"] == model) & (df["error"] == ""), output].astype(float)
            v = finished[finished.notna()]
            spread = f" ± {v.std(ddof=1):.3g}" if len(v) > 1 else ""  # one run has no sample spread (it was ± nan)
            part = f"{model} {v.mean():.4g}{spread} (n = {len(v)}" if len(v) else f"{model} - (n = 0"
            missing = len(finished) - len(v)
            parts.append(part + (f"; {missing} finished without a value)" if missing else ")"))
        lines.append(f"  {output}: " + ", ".join(parts))
    return lines


def monte_carlo(
    file: Annotated[str, typer.Argument(help="Monte Carlo study file (.toml; tcsim init monte-carlo writes one)")],
    out: OutOpt = Path("monte-carlo"),
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
    chunk_size: ChunkSizeOpt = None,
    scheduler: SchedulerOpt = None,
    workers: WorkersOpt = None,
    no_progress: NoProgressOpt = False,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..analysis.chunked import check_chunk_size, check_scheduler
    from ..analysis.monte_carlo import monte_carlo_study, run_monte_carlo
    from ..errors import InputError
    from ..io.outputs import check_output_dir, output_dir
    from ..io.tables import write_table
    from ..models.study_file import MAX_RUNS_UNCHUNKED, load_study_file
    from ..plots.monte_carlo import plot_monte_carlo
    from ..reports.console import progress_display
    from .study import refuse_format_with_shards, run_sharded, shards_line

    tf = table_format(file_format, speed_unit)
    if chunk_size is None:
        refuse_cluster_options(scheduler, workers)
        check_output_dir(out, [file])
    else:
        check_chunk_size(chunk_size)
        check_scheduler(scheduler, workers)
        refuse_format_with_shards(file_format)
    sf = load_study_file(file)
    if chunk_size is None and sf.doc.n_cases > MAX_RUNS_UNCHUNKED:
        more = "more: --chunk-size streams them to shards"
        grid = sf.doc.grid_points > 1
        expected = f"at most {MAX_RUNS_UNCHUNKED}{' cases' if grid else ''} without --chunk-size ("
        expected += f"{sf.doc.cases_text()}; {more})" if grid else f"{more})"
        if grid and sf.doc.n_runs == 1:  # the grids alone: not the runs' fault
            raise InputError(file, "distributions", f"{sf.doc.grid_points} grid points", expected)
        raise InputError(file, "runs", sf.doc.n_runs, expected)
    study = monte_carlo_study(sf)
    inputs = [file, sf.vehicle.path, sf.converter.path]
    cases = f"{study.n_cases} cases"
    if sf.doc.grid_points > 1:
        cases += f" ({sf.doc.grid_points} grid points" + (f" × {sf.doc.n_runs} runs)" if sf.doc.n_runs > 1 else ")")
    models = f"{len(study.models)} model{'s' if len(study.models) != 1 else ''}"
    head = f"{sf.name}: {cases} × {models} ({', '.join(study.models)})"
    if chunk_size is not None:
        run = run_sharded(study, out, chunk_size, tf.speed_unit, scheduler, workers, inputs, not no_progress)
        say(f"{head}, {run.rows} rows in {shards_line(run)}")
        outputs = ", ".join(repr(o) for o in study.outputs)
        say(
            f"  statistics: tcsim.io.shards.read_shards({str(out)!r}, ['model', 'error', {outputs}]) reads "
            "the rows for them (a run without --chunk-size prints them and draws the histograms)"
        )
        return
    check_output_dir(out, inputs)
    with progress_display(not no_progress) as display:
        task = display.add_task("monte-carlo cases", total=study.n_cases)
        df = run_monte_carlo(study, progress=lambda done, total: display.update(task, completed=done))
    with output_dir(out, inputs) as stage:
        write_table(df, stage, TABLE, tf)
        if plots:
            plot_monte_carlo(df, study.outputs, study.models, sf.name, stage)
    failed = int((df["error"] != "").sum())
    say(f"{head}, {failed} of {len(df)} runs without outputs, written to {out}")
    for line in summary_lines(df, study):
        say(line)
