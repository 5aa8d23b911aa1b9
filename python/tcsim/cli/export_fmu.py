"""``tcsim export-fmu``: one converter model as an FMI 2.0 or 3.0 FMU (see :mod:`tcsim.io.fmu` and
:mod:`tcsim.io.fmu3`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .app import say

#: The command's ``--help`` text.
HELP = (
    "Export one model as an FMI 2.0 or 3.0 FMU, Model Exchange and Co-Simulation (linux binary, sources to "
    "rebuild elsewhere; no Python inside)."
)


def export_fmu_command(converter: str, model: str, out: Path, causality: str, fmi_version: str = "2") -> str:
    """Write the FMU; the line to print."""
    import json
    import xml.etree.ElementTree as ET
    import zipfile

    from ..io.fmu import export_fmu as write_fmu
    from ..io.fmu3 import fmi_version as version_of

    fmi = version_of(fmi_version)
    path = write_fmu(converter, model, out, causality, fmi=fmi)
    with zipfile.ZipFile(path) as zf:
        params = json.loads(zf.read("resources/model.json"))["parameters"]
        platforms = sorted({n.split("/")[1] for n in zf.namelist() if n.startswith("binaries/")})
        # the inputs as the FMU declares them (a list kept here left out turbine_accel_rad_s2)
        variables = ET.fromstring(zf.read("modelDescription.xml")).iter()
        inputs = [v.get("name", "") for v in variables if v.get("causality") == "input"]
    return (
        f"{model} model of {converter} written to {path} (FMI {fmi.name} Model Exchange and Co-Simulation, "
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
    fmi_version: Annotated[
        str, typer.Option("--fmi-version", help="2 (FMI 2.0, the default) | 3 (FMI 3.0)", metavar="2|3")
    ] = "2",
) -> None:
    """The command; its help is :data:`HELP`."""
    say(export_fmu_command(converter, model, out, causality, fmi_version))
