"""``tcsim export-fmu``: one converter model as an FMI 2.0 FMU (see :mod:`tcsim.io.fmu`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .app import say

#: The command's ``--help`` text.
HELP = (
    "Export one model as an FMI 2.0 FMU, Model Exchange and Co-Simulation (linux64 binary, sources to "
    "rebuild elsewhere; no Python inside)."
)


def export_fmu_command(converter: str, model: str, out: Path, causality: str) -> str:
    """Write the FMU; the line to print."""
    import json
    import zipfile

    from ..io.fmu import CAUSALITIES, COMMON_INPUTS
    from ..io.fmu import export_fmu as write_fmu

    path = write_fmu(converter, model, out, causality)
    with zipfile.ZipFile(path) as zf:
        params = json.loads(zf.read("resources/model.json"))["parameters"]
        platforms = sorted({n.split("/")[1] for n in zf.namelist() if n.startswith("binaries/")})
    inputs = (*CAUSALITIES[causality], *COMMON_INPUTS)
    return (
        f"{model} model of {converter} written to {path} (FMI 2.0 Model Exchange and Co-Simulation, "
        f"{', '.join(platforms)}; inputs {', '.join(inputs)}; {len(params)} tunable parameters)"
    )


def export_fmu(
    converter: Annotated[str, typer.Argument(help="bundled name or converter .toml")],
    model: Annotated[str, typer.Option("--model", "-m", help="table | hrovat-tobler | quasi-dynamic")],
    out: Annotated[Path, typer.Option("--out", "-o", help="the FMU file to write (*.fmu)")],
    causality: Annotated[
        str,
        typer.Option(
            "--causality",
            help="pump-torque (pump torque and turbine speed in) | speeds (both speeds in) | "
            "torques (pump torque and turbine load torque in, both speeds out)",
        ),
    ] = "pump-torque",
) -> None:
    """The command; its help is :data:`HELP`."""
    say(export_fmu_command(converter, model, out, causality))
