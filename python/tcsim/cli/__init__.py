"""The ``tcsim`` command line (typer + rich): :data:`app` and :func:`main`, one module per command.

Each command module is load → compute → write → print; the command functions import the layers
they use when they run, so that ``tcsim --help`` starts fast.
"""

from __future__ import annotations

from . import (
    characterise,
    converters,
    design,
    design_study,
    drive,
    export_fmu,
    fit,
    fit_shapes,
    launch,
    operating_point,
    replay,
    study,
    torque_estimate,
)
from .app import app, main

# registered in the order ``tcsim --help`` lists them
app.command()(converters.converters)
app.command()(characterise.characterise)
app.command("operating-point", help=operating_point.HELP)(operating_point.operating_point)
app.command()(fit.fit)
app.command()(study.study)
app.command()(replay.replay)
app.command("fit-shapes", help=fit_shapes.HELP)(fit_shapes.fit_shapes)
app.command(help=launch.HELP)(launch.launch)
app.command(help=drive.HELP)(drive.drive)
app.command("torque-estimate", help=torque_estimate.HELP)(torque_estimate.torque_estimate)
app.command("export-fmu", help=export_fmu.HELP)(export_fmu.export_fmu)
app.command(help=design.HELP)(design.design)
app.command("design-study", help=design_study.HELP)(design_study.design_study)

__all__ = ["app", "main"]
