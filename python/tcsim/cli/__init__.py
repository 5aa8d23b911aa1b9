"""The ``tcsim`` command line (typer + rich): :data:`app` and :func:`main`, one module per command.

Each command module is load → compute → write → print; the command functions import the layers
they use when they run, so that ``tcsim --help`` starts fast.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

from . import (
    characterise,
    converters,
    design,
    design_study,
    discovery,
    drive,
    export_fmu,
    fit,
    fit_shapes,
    init,
    launch,
    monte_carlo,
    operating_point,
    replay,
    study,
    torque_estimate,
)
from .app import app, main

#: One example command line per command, shown as the last line of its ``--help`` (``Example: ...``).
EXAMPLES: dict[str, str] = {
    "converters": "tcsim converters",
    "vehicles": "tcsim vehicles",
    "init": "tcsim init converter --from k_factor_table.csv --out converter.toml",
    "characterise": "tcsim characterise li-sunden-2016 --model table",
    "operating-point": "tcsim operating-point li-sunden-2016 points.csv --model table",
    "fit": "tcsim fit li-sunden-2016 --target k_factor_table.csv --out fit",
    "study": "tcsim study li-sunden-2016 --out study",
    "monte-carlo": "tcsim monte-carlo monte-carlo.toml --chunk-size 100 --out monte-carlo",
    "replay": "tcsim replay li-sunden-2016 measurement.csv --model table --out replay",
    "fit-shapes": "tcsim fit-shapes li-sunden-2016 takeoff.csv --model quasi-dynamic --out fit-shapes",
    "launch": "tcsim launch midsize-awd-8at --scenario part-pedal --out launch",
    "drive": "tcsim drive --cycle us06 --model table --out drive",
    "torque-estimate": "tcsim torque-estimate ecm.csv dyno.csv --out torque-estimate",
    "export-fmu": "tcsim export-fmu li-sunden-2016 --model hrovat-tobler -o converter.fmu",
    "design": "tcsim design li-sunden-2016-design --out design",
    "design-study": "tcsim design-study li-sunden-2016-design --sweep pump_exit_radius_m=0.11:0.13:3",
}


def _register(name: str, command: Callable[..., Any], text: str | None = None) -> None:
    """Register ``command`` as ``tcsim name`` with its help (``text``, else its docstring) and example."""
    text = text or inspect.getdoc(command) or ""
    app.command(name, help=f"{text}\n\nExample: {EXAMPLES[name]}")(command)


app.callback(help=app.info.help)(discovery.options)
# registered in the order ``tcsim --help`` lists them
_register("converters", converters.converters)
_register("vehicles", discovery.vehicles)
_register("init", init.init, init.HELP)
_register("characterise", characterise.characterise)
_register("operating-point", operating_point.operating_point, operating_point.HELP)
_register("fit", fit.fit)
_register("study", study.study, study.HELP)
_register("monte-carlo", monte_carlo.monte_carlo, monte_carlo.HELP)
_register("replay", replay.replay)
_register("fit-shapes", fit_shapes.fit_shapes, fit_shapes.HELP)
_register("launch", launch.launch, launch.HELP)
_register("drive", drive.drive, drive.HELP)
_register("torque-estimate", torque_estimate.torque_estimate, torque_estimate.HELP)
_register("export-fmu", export_fmu.export_fmu, export_fmu.HELP)
_register("design", design.design, design.HELP)
_register("design-study", design_study.design_study, design_study.HELP)

__all__ = ["EXAMPLES", "app", "main"]
