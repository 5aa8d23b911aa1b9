"""``tcsim study``: the parameter study of Li & Sundén (2016), Appendix D."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from .app import FormatOpt, OutOpt, SpeedUnitOpt, say, table_format

if TYPE_CHECKING:
    from ..analysis.study import StudyDefinition
    from ..io.tables import TableFormat


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


def study(
    converter: Annotated[str, typer.Argument(help="converter with a [geometry] section")],
    out: OutOpt = Path("study"),
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
) -> None:
    """Appendix D parameter study: one figure per parameter and DIR/study.csv."""
    tf = table_format(file_format, speed_unit)
    say(study_command(converter, out, tf=tf))
