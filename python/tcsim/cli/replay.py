"""``tcsim replay``: an isolated converter driven by measured signals (see :mod:`tcsim.analysis.replay`).

:func:`replay_files` (load → compute) and :func:`write_replay` (files and figures) are also the
Python API ``tcsim.replay.replay`` and ``tcsim.replay.write_replay``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from .app import (
    AllowImplausibleOpt,
    ChannelOpt,
    FormatOpt,
    ModelsOpt,
    OutOpt,
    PlotsOpt,
    SpeedUnitOpt,
    stdout,
    table_format,
)

if TYPE_CHECKING:
    from ..analysis.replay import Replay
    from ..io.tables import TableFormat


def replay_files(
    converter: Any,
    measurement: Any,
    models: Sequence[str] = (),
    drive: str = "pump-torque",
    channels: dict[str, str] | None = None,
    initial: dict[str, float] | None = None,
    window_s: float | None = None,
    metrics_window_s: float | None = 1.0,
    allow_implausible: bool = False,
) -> Replay:
    """Run the replay (no files written): read the converter (a :class:`~tcsim.models.converter.
    Converter`, bundled name or file) and the measurement, simulate every model, measure the errors.
    ``window_s`` (s) defaults to :data:`tcsim.models.drives.DERIVATIVE_WINDOW_S`; it may not exceed
    the record's span, nor ``metrics_window_s`` (s; ``None``: the whole record only) unless it is
    the default 1 s, and ``metrics_window_s`` may not be shorter than the median sample spacing.
    Measured values outside the plausibility ranges are refused unless ``allow_implausible``."""
    from ..analysis.replay import LOCKUP_CHANNEL, check_window, drive_kind, replay_measurement
    from ..io.measurement import read_measurement
    from ..models.converter import load_converter
    from ..models.dynamic import select_models

    kind = drive_kind(drive)
    if window_s is not None:
        check_window("--window", window_s, positive=False)
    if metrics_window_s is not None:
        check_window("--metrics-window", metrics_window_s, positive=True)
    conv = converter if not isinstance(converter, (str, Path)) else load_converter(converter)
    select_models(conv, models)  # a bad --model is reported before the measurement is read
    meas = read_measurement(
        measurement,
        channels,
        required=kind.inputs,
        optional=(*kind.outputs, LOCKUP_CHANNEL),
        allow_implausible=allow_implausible,
    )
    return replay_measurement(conv, meas, models, kind, initial, window_s, metrics_window_s)


def write_replay(replay: Replay, out_dir: Path, tf: TableFormat | None = None, plots: bool = True) -> list[Path]:
    """The tables (``tf``: format and speed unit, default CSV in rad/s) and, if ``plots``, the figures
    of a replay into ``out_dir`` (a staging directory)."""
    from ..io.results import write_replay_files
    from ..io.tables import CSV
    from ..plots.replay import plot_replay

    meas = replay.measurement
    measured = {**meas.channels, **replay.measured_effective}
    runs = {name: result.columns for name, result in replay.results.items()}
    title = f"Inputs (drive {replay.drive.name}): {Path(meas.source).name}"
    paths = write_replay_files(replay, Path(out_dir), tf or CSV)
    if not plots:
        return paths
    return paths + plot_replay(
        meas.time_s, measured, runs, replay.drive.inputs, replay.drive.outputs, title, Path(out_dir)
    )


def replay(
    converter: Annotated[str, typer.Argument(help="bundled name or converter .toml")],
    measurement: Annotated[str, typer.Argument(help="measured time series: .csv, .parquet, .mat or .mf4/.mdf")],
    model: ModelsOpt = None,
    out: OutOpt = Path("replay"),
    channel: ChannelOpt = None,
    drive: Annotated[
        str,
        typer.Option("--drive", help="pump-torque (pump torque and turbine speed given) | speeds (both speeds given)"),
    ] = "pump-torque",
    initial: Annotated[
        list[str] | None, typer.Option("--initial", help="NAME=VALUE initial state override (SI), repeatable")
    ] = None,
    window: Annotated[
        float | None,
        typer.Option(
            "--window",
            help="derivative smoothing window S, s: local least-squares slope over ±S/2, at most the record's span "
            "(default: 0.04)",
        ),
    ] = None,
    metrics_window: Annotated[
        float,
        typer.Option(
            "--metrics-window",
            help="width of the consecutive metric windows, s: from the median sample spacing to the record's span",
        ),
    ] = 1.0,
    allow_implausible: AllowImplausibleOpt = False,
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
) -> None:
    """Isolated converter driven by measured signals: DIR/<model>.csv, events, metrics, plots."""
    from ..analysis.replay import parse_initial
    from ..io.measurement import parse_channel_map
    from ..io.outputs import check_output_dir, output_dir
    from ..reports.console import replay_report

    tf = table_format(file_format, speed_unit)
    check_output_dir(out, [converter, measurement])
    result = replay_files(
        converter,
        measurement,
        model or [],
        drive,
        parse_channel_map(channel or []),
        parse_initial(initial or [], allow_implausible),
        window,
        metrics_window,
        allow_implausible,
    )
    inputs = [converter, measurement, result.measurement.source]
    with output_dir(out, inputs) as stage:
        write_replay(result, stage, tf, plots)
    stdout.print(replay_report(result, Path(out), tf.format, plots))
