"""``tcsim design``: from a converter design (torus, blades, fluid, metal inertias) to its converter
file, its characteristic, its isolated take-off and its vehicle launch against a reference converter.

::

    tcsim design DESIGN [--out DIR] [--reference CONVERTER] [--vehicle VEHICLE]

DESIGN is a design ``.toml`` or a bundled design's name (``li-sunden-2016-design``); the schema is in
docs/design.md ("Design files"). DIR (default ``design``) receives, all at once and nothing on
error (:mod:`tcsim.io.outputs`): ``converter.toml``, ``characteristic.csv``,
``reference_characteristic.csv``, ``takeoff.csv``, ``launch.csv``, ``summary.csv``, the plots of
the characteristic (design and reference), of the take-off and of the launch, and ``report.md``
(all of it on one page). Bad input: exit 2, one line naming the
file, the field and the value.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .app import FormatOpt, OutOpt, PlotsOpt, SpeedUnitOpt, say, table_format

#: The command's ``--help`` text.
HELP = (
    "From a converter design (torus, blades, fluid) to DIR/converter.toml, its characteristic, its "
    "isolated take-off and its vehicle launch (to 50 km/h) against a reference converter."
)


def design(
    design: Annotated[str, typer.Argument(help="design .toml or bundled design name (li-sunden-2016-design)")],
    out: OutOpt = Path("design"),
    reference: Annotated[
        str, typer.Option("--reference", help=r"reference converter with \[geometry]: bundled name or .toml")
    ] = "li-sunden-2016",
    vehicle: Annotated[
        str | None,
        typer.Option(
            "--vehicle",
            help="vehicle of the launch, its converter swapped: bundled name or .toml "
            "(default: the bundled vehicle, tcsim vehicles)",
        ),
    ] = None,
    file_format: FormatOpt = "csv",
    speed_unit: SpeedUnitOpt = "rad/s",
    plots: PlotsOpt = True,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..analysis.design_report import design_report
    from ..io.design_outputs import write_design_files
    from ..io.outputs import check_output_dir, output_dir
    from ..io.results import write_text_files
    from ..models.design_file import LOSS_DEFAULTS_FROM, load_design_file
    from ..models.vehicle import load_vehicle
    from ..plots.characteristic import plot_characteristic
    from ..plots.design import plot_design_launch, plot_design_takeoff
    from ..reports.design import report_markdown

    tf = table_format(file_format, speed_unit)
    check_output_dir(out, [design, reference, *([vehicle] if vehicle else [])])
    file = load_design_file(design)
    veh = load_vehicle(vehicle)
    report = design_report(file, reference, vehicle=veh)
    inputs = [design, file.path, reference, report.reference.path, veh.path, *([vehicle] if vehicle else [])]
    check_output_dir(out, inputs)
    with output_dir(out, inputs) as stage:
        write_design_files(report, file.path, stage, tf)
        title = f"{file.name} against {report.reference.name}"
        curves = {f"{name} (hrovat-tobler)": df for name, df in report.characteristics.items()}
        if plots:
            plot_characteristic(curves, stage, f"{title}, Hrovat & Tobler closed form")
            plot_design_takeoff(report.takeoffs, stage, f"{title}: isolated take-off")
            plot_design_launch(report.launches, stage, f"{title}: launch, Hrovat & Tobler")
        names = {p.name for p in Path(stage).iterdir()}
        write_text_files({"report.md": report_markdown(report, file, names)}, stage)
    g = report.derived.geometry
    say(
        f"{file.name}: converter.toml with S_p, S_t, S_s = {g.pump.shape_effect_m2:.6g}, "
        f"{g.turbine.shape_effect_m2:.6g}, {g.stator.shape_effect_m2:.6g} m², L_f = {g.fluid_length_m:.6g} m, "
        f"written to {out}"
    )
    defaults = report.derived.default_losses
    if defaults:
        say(f"losses not in the design, taken from Table D.1 ({LOSS_DEFAULTS_FROM}): {', '.join(defaults)}")
    for row in report.summary.itertuples():
        say(
            f"{row.role} {row.converter}: stall TR {row.stall_torque_ratio:.3f}, take-off effective-TR dip "
            f"{row.takeoff_effective_tr_dip:.4f} at {row.takeoff_effective_tr_dip_time_s:.2f} s, launch 0–50 km/h "
            f"{row.launch_time_0_50_km_h_s:.2f} s (effective-TR deficit "
            f"{row.launch_effective_tr_deficit_first_0_5_s:.4f} over the first 0.5 s)"
        )
