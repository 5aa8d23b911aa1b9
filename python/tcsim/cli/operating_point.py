"""``tcsim operating-point``: backward operating points (pump speed and torque from turbine speed and torque)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .app import AllowImplausibleOpt, FormatOpt, ModelOpt, OutOpt, SpeedUnitOpt, say, table_format

HELP = (
    "Backward operating points: from turbine speed and torque (or power) to pump speed and torque. "
    "Writes DIR/operating_points.csv."
)


def operating_point(
    converter: Annotated[str, typer.Argument(help="bundled name or converter .toml (or table .csv/.vtcc)")],
    points: Annotated[
        str,
        typer.Argument(
            help="CSV or Parquet with turbine_speed_rad_s (or turbine_speed_rpm) and turbine_torque_nm (N·m, "
            "negative in coast) or turbine_power_w (W)"
        ),
    ],
    model: ModelOpt = "table",
    pump_speed_limit_rpm: Annotated[
        float | None,
        typer.Option(
            "--pump-speed-limit-rpm",
            help="highest pump speed, rpm: points that need more are flagged above-pump-speed-limit (default: none)",
        ),
    ] = None,
    out: OutOpt = Path("operating_points"),
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    allow_implausible: AllowImplausibleOpt = False,
) -> None:
    """Backward operating points of one model: DIR/operating_points.csv with valid and reason per point."""
    from ..io.outputs import check_output_dir, output_dir
    from ..io.points import read_points
    from ..io.results import write_frames
    from ..models.converter import load_converter
    from ..models.operating_point import check_pump_speed_limit, operating_point
    from ..units import RAD_S_PER_RPM

    tf = table_format(file_format, speed_unit)
    limit = check_pump_speed_limit("command line", "--pump-speed-limit-rpm", pump_speed_limit_rpm)
    check_output_dir(out, [converter, points])
    conv = load_converter(converter)
    if model not in conv.models:
        conv.require(model)  # names the missing section (or the unknown --model)
    data = read_points(points, allow_implausible)
    inputs = [converter, conv.path, points]
    check_output_dir(out, inputs)
    torque, power = (data.values, None) if data.load == "turbine_torque_nm" else (None, data.values)
    limit_rad_s = None if limit is None else limit * RAD_S_PER_RPM
    df = operating_point(conv, data.turbine_speed_rad_s, torque, model, limit_rad_s, turbine_power_w=power)
    with output_dir(out, inputs) as stage:
        write_frames({"operating_points.csv": df}, stage, tf)
    flagged = int((~df["valid"]).sum())
    msg = f"{model}: {len(df)} operating points written to {out}/{tf.file_name('operating_points.csv')}"
    if flagged:
        counts = df.loc[~df["valid"], "reason"].value_counts()
        msg += f"; {flagged} flagged (" + ", ".join(f"{n} {r}" for r, n in counts.items() if n) + ")"
    say(msg)
