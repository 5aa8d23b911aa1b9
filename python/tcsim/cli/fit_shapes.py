"""``tcsim fit-shapes``: pump and turbine shape effects fitted to a transient measurement, and the
sweep of thesis figures 4.1–4.2 (see :mod:`tcsim.analysis.shape_fit`).

:func:`shape_fit_command` is also the Python API ``tcsim.shape_fit.shape_fit_command``.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from .app import (
    AllowImplausibleOpt,
    ChannelOpt,
    FormatOpt,
    ModelOpt,
    OutOpt,
    SpeedUnitOpt,
    say,
    table_format,
)

if TYPE_CHECKING:
    from ..io.tables import TableFormat

#: The command's ``--help`` text.
HELP = "Fit the pump and turbine shape effects to a transient measurement; sweep plots like thesis figs 4.1–4.2."


def shape_fit_command(
    converter: str,
    measurement: str,
    out: Any,
    model: str,
    target: str,
    channels: Sequence[str] = (),
    drive: str = "pump-torque",
    equal: bool = False,
    allow_implausible: bool = False,
    tf: TableFormat | None = None,
) -> str:
    """Fit the shape effects of ``converter``'s ``model`` to ``measurement``.

    Drive ``pump-torque`` (a): time_s, pump_torque_nm, turbine_speed_rad_s are the inputs;
    ``speeds`` (b): time_s, pump_speed_rad_s, turbine_speed_rad_s. The target needs
    turbine_torque_nm (and pump_torque_nm, pump_speed_rad_s for the effective TR). Writes
    DIR/shape_fit.json, DIR/shape_fit.md, DIR/shape_sweep.csv and the sweep plots (with the fitted
    pair), all or nothing; ``tf``: the sweep table's format and speed unit (default CSV in rad/s).
    Returns a one-line summary. Measured values outside the plausibility ranges are refused unless
    ``allow_implausible``.
    """
    from ..analysis import shape_fit as sf
    from ..analysis.effective import measured_effective_torques
    from ..errors import TcsimWarning
    from ..io.measurement import parse_channel_map, read_measurement
    from ..io.outputs import check_output_dir, output_dir
    from ..io.results import write_frames, write_text_files
    from ..io.tables import CSV
    from ..models.converter import load_converter
    from ..models.dynamic import dynamic_model
    from ..models.shape_effects import sweep_values
    from ..plots.shape_sweep import plot_shape_effect_sweep
    from ..reports.shape_fit import report_markdown, shape_fit_json

    tf = tf or CSV
    check_output_dir(out, [converter, measurement])
    sf.check_choice("--model", model, sf.MODELS)
    sf.check_choice("--target", target, sf.TARGETS)
    sf.check_choice("--drive", drive, sf.DRIVES)
    conv = load_converter(converter)
    conv.require(model)
    meas = read_measurement(
        measurement,
        parse_channel_map(channels),
        required=sf.required_channels(target, drive),
        optional=("pump_speed_rad_s", "pump_torque_nm"),
        allow_implausible=allow_implausible,
    )
    inputs = [converter, measurement, conv.path, meas.source]
    check_output_dir(out, inputs)
    base = dynamic_model(conv, model)
    inertia = base.spec["inertia_kg_m2"]
    effective = measured_effective_torques(meas, inertia[1], inertia[0])
    drv, y = sf.drive_of(meas, drive), effective[target]
    result = sf.fit_shape_effects(conv, base, drv, meas.time_s, y, target, equal=equal, rates="filtered")
    for line in result.bound_warnings(meas.source):
        warnings.warn(line, TcsimWarning, stacklevel=1)
    fitted = (result.pump_shape_effect_m2, result.turbine_shape_effect_m2)
    sweep = sf.shape_effect_sweep(conv, base, drv, sweep_values(base), pairs=[fitted], times_s=meas.time_s)
    sweep.loc[(sweep.pump_shape_effect_m2 == fitted[0]) & (sweep.turbine_shape_effect_m2 == fitted[1]), "label"] = (
        f"fitted: Sp={fitted[0]:.4g}, St={fitted[1]:.4g}"
    )
    measured = sf.measured_frame(meas, effective)
    steady = sf.steady_run(conv, drv, meas.time_s)
    minima = sf.sweep_minima(sweep)
    with output_dir(out, inputs) as stage:
        title = f"{conv.name}, {result.model}: shape effects"
        plots = plot_shape_effect_sweep(sweep, stage, title, measured=measured, steady=steady)
        write_frames({"shape_sweep.csv": sweep}, stage, tf)
        write_text_files(
            {
                "shape_fit.json": shape_fit_json(result, conv, meas, drive, minima, plots),
                "shape_fit.md": report_markdown(result, conv, meas, drive, minima, sweep),
            },
            stage,
        )
    sweep_file = tf.file_name("shape_sweep.csv")
    return f"{result.one_line()}. Written to {out}/: shape_fit.json, shape_fit.md, {sweep_file} and plots."


def fit_shapes(
    converter: Annotated[str, typer.Argument(help="bundled name or converter .toml")],
    measurement: Annotated[str, typer.Argument(help="take-off measurement: .csv, .parquet, .mat or .mf4/.mdf")],
    model: ModelOpt = "quasi-dynamic",
    target: Annotated[
        str, typer.Option("--target", help="effective_turbine_torque_nm | effective_torque_ratio")
    ] = "effective_turbine_torque_nm",
    out: OutOpt = Path("shape_fit"),
    channel: ChannelOpt = None,
    drive: Annotated[str, typer.Option("--drive", help="pump-torque | speeds")] = "pump-torque",
    equal: Annotated[bool, typer.Option("--equal", help="fit one shape effect, S_p = S_t")] = False,
    allow_implausible: AllowImplausibleOpt = False,
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
) -> None:
    """The command; its help is :data:`HELP`."""
    tf = table_format(file_format, speed_unit)
    say(
        shape_fit_command(
            converter, measurement, out, model, target, channel or [], drive, equal, allow_implausible, tf
        )
    )
