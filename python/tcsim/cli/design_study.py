"""``tcsim design-study``: one or two parameters of a design swept over a full grid, each design's
steady-state and take-off figures (:mod:`tcsim.analysis.design_study`).

::

    tcsim design-study DESIGN --sweep NAME=MIN:MAX:N [--sweep NAME2=MIN:MAX:N] [--out DIR]

DIR (default ``design-study``) receives, all at once and nothing on error (:mod:`tcsim.io.outputs`):
``study.csv`` (one row per design) and ``pareto.png``. Bad input: exit 2, one line.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .app import FormatOpt, OutOpt, PlotsOpt, SpeedUnitOpt, say, table_format

#: The command's ``--help`` text.
HELP = (
    "Sweep one or two design parameters (NAME=MIN:MAX:N each) over a full grid: DIR/study.csv with each "
    "design's stall TR, K-factor, peak efficiency, coupling point and take-off dip, and a Pareto plot."
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
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..analysis.design_study import check_sweep, design_study, parse_sweep
    from ..errors import InputError
    from ..io.outputs import check_output_dir, output_dir
    from ..io.tables import write_table
    from ..models.design_file import load_design_file
    from ..plots.design_study import plot_design_pareto

    tf = table_format(file_format, speed_unit)
    parsed = [parse_sweep(s) for s in sweep]
    names = [n for n, _ in parsed]
    if len(set(names)) != len(names):
        raise InputError("--sweep", "NAME", names[-1], "two different parameters")
    values = dict(parsed)
    check_sweep(values)
    check_output_dir(out, [design])
    file = load_design_file(design)
    study = design_study(file, values)
    inputs = [design, file.path]
    with output_dir(out, inputs) as stage:
        write_table(study, stage, "study.csv", tf)
        if plots:
            plot_design_pareto(study, stage, f"{file.name}: design study of {' × '.join(names)}")
    failed = int((study["error"] != "").sum())
    say(f"{file.name}: {len(study)} designs of {' × '.join(names)}, {failed} without figures, written to {out}")
    front = study[study["pareto_front"]]
    say(f"Pareto front: {len(front)} designs (stall TR against take-off effective-TR dip)")
