"""``tcsim characterise``: the steady-state sweep of one model."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..units import DEFAULT_PUMP_SPEED_RPM
from .app import (
    AllowImplausibleOpt,
    FormatOpt,
    OutOpt,
    PlotsOpt,
    SpeedUnitOpt,
    and_plots,
    say,
    table_format,
)

CharacteriseModelOpt = Annotated[
    str,
    typer.Option(
        "--model",
        "-m",
        help="table | hrovat-tobler | quasi-dynamic (default: hrovat-tobler when the converter has its geometry, "
        "else table)",
    ),
]


def characterise(
    converter: Annotated[str, typer.Argument(help="bundled name, converter .toml, or table .csv/.vtcc")],
    model: CharacteriseModelOpt = "",
    pump_speed_rpm: Annotated[
        float | None, typer.Option(help=f"fixed pump speed of the sweep, rpm (default: {DEFAULT_PUMP_SPEED_RPM:g})")
    ] = None,
    input_torque_nm: Annotated[
        float | None,
        typer.Option(
            "--input-torque-nm",
            help="fixed pump (input) torque of the sweep, N·m, the pump speed solved at each speed ratio "
            "(instead of --pump-speed-rpm)",
        ),
    ] = None,
    out: OutOpt = Path("characteristic"),
    allow_implausible: AllowImplausibleOpt = False,
    speed_ratio: Annotated[
        str | None,
        typer.Option(
            "--speed-ratio",
            help="sweep MIN:MAX:STEP (default: 0:1:0.01 with the table's points or the coupling point); "
            "negative and above 1 allowed, |SR| <= 100, at most 100001 points",
        ),
    ] = None,
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
) -> None:
    """Steady-state sweep: DIR/characteristic.csv and plots of TR, CF, K-factor and efficiency."""
    from ..errors import InputError
    from ..io.outputs import check_output_dir, output_dir
    from ..io.results import write_frames
    from ..models.converter import load_converter
    from ..models.steady import characterise as run
    from ..models.steady import coupling_point, speed_ratio_sweep, sweep_speed_ratios
    from ..plots.characteristic import plot_characteristic

    tf = table_format(file_format, speed_unit)
    if pump_speed_rpm is not None and input_torque_nm is not None:
        raise InputError(
            "command line",
            "--input-torque-nm",
            input_torque_nm,
            "either --input-torque-nm or --pump-speed-rpm, not both",
        )
    if speed_ratio is not None:
        speed_ratio_sweep(speed_ratio)  # the command line first, before any file is read
    rpm = DEFAULT_PUMP_SPEED_RPM if pump_speed_rpm is None else pump_speed_rpm
    check_output_dir(out, [converter])
    conv = load_converter(converter)
    inputs = [converter, conv.path]
    check_output_dir(out, inputs)
    model = model or ("hrovat-tobler" if "hrovat-tobler" in conv.models else "table")
    conv.require(model)
    sr = None if speed_ratio is None else sweep_speed_ratios(conv, model, speed_ratio)
    df = run(conv, model, rpm, sr, allow_implausible=allow_implausible, input_torque_nm=input_torque_nm)
    cp = coupling_point(conv) if model == "hrovat-tobler" else None
    if cp is not None and sr is not None and not sr[0] <= cp <= sr[-1]:
        cp = None
    with output_dir(out, inputs) as stage:
        write_frames({"characteristic.csv": df}, stage, tf)
        table = conv.characteristic if model == "hrovat-tobler" else None
        if plots:
            plot_characteristic(
                {f"{model} model": df},
                stage,
                f"{conv.name}, pump at {rpm:g} rpm"
                if input_torque_nm is None
                else f"{conv.name}, input torque {input_torque_nm:g} N·m",
                table=table,
                coupling_point=cp,
            )
    msg = f"{model}: {len(df)} points written to {out}/{tf.file_name('characteristic.csv')}{and_plots(plots)}"
    if cp is not None:
        msg += f"; coupling point at SR {cp:.4f}"
    say(msg)
