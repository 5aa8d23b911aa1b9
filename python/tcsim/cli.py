"""The ``tcsim`` command line (typer + rich).

Exit codes (conventions.md): 0 success; 2 bad input, with one message naming the file, the
field, the value and what was expected, and no output written; 1 a failure that is not the
user's (the message says what failed).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from .errors import InputError, TcsimWarning

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="tcsim: hydrodynamic torque converter models (table, Hrovat & Tobler, quasi-dynamic).",
)
console = Console(stderr=True)
stdout = Console()

ModelOpt = Annotated[str, typer.Option("--model", "-m", help="table | hrovat-tobler | quasi-dynamic")]
OutOpt = Annotated[Path, typer.Option("--out", "-o", help="output directory")]


@app.command()
def converters() -> None:
    """List the bundled converters and their sources."""
    from .converter import bundled_converters

    table = Table(title="Bundled converters")
    for col in ("name", "models", "source"):
        table.add_column(col)
    for conv in bundled_converters():
        table.add_row(conv.name, ", ".join(conv.models), conv.source)
    stdout.print(table)


@app.command()
def characterise(
    converter: Annotated[str, typer.Argument(help="bundled name, converter .toml, or table .csv/.vtcc")],
    model: ModelOpt = "",
    pump_speed_rpm: Annotated[float, typer.Option(help="fixed pump speed of the sweep")] = 2000.0,
    out: OutOpt = Path("characteristic"),
) -> None:
    """Steady-state sweep: DIR/characteristic.csv and plots of TR, CF, K-factor and efficiency."""
    from .converter import load_converter
    from .outputs import output_dir
    from .plots import plot_characteristic
    from .steady import characterise as run
    from .steady import coupling_point

    conv = load_converter(converter)
    model = model or ("hrovat-tobler" if "hrovat-tobler" in conv.models else "table")
    conv.require(model)
    df = run(conv, model, pump_speed_rpm)
    cp = coupling_point(conv) if model == "hrovat-tobler" else None
    with output_dir(out) as stage:
        df.to_csv(stage / "characteristic.csv", index=False)
        table = conv.characteristic if model == "hrovat-tobler" else None
        plot_characteristic(
            {f"{model} model": df},
            stage,
            f"{conv.name}, pump at {pump_speed_rpm:g} rpm",
            table=table,
            coupling_point=cp,
        )
    msg = f"{model}: {len(df)} points written to {out}/characteristic.csv and plots"
    if cp is not None:
        msg += f"; coupling point at SR {cp:.4f}"
    stdout.print(msg)


@app.command()
def fit(
    converter: Annotated[str, typer.Argument(help="converter whose Hrovat & Tobler parameters are the start point")],
    target: Annotated[
        str, typer.Option("--target", help="characteristic table to fit: .csv, .vtcc or converter .toml")
    ],
    out: OutOpt = Path("fit"),
    free: Annotated[
        str | None, typer.Option(help="comma-separated parameters to free (default: losses and the six angles)")
    ] = None,
    bound: Annotated[list[str] | None, typer.Option(help="NAME=LO:HI bounds of a free parameter, repeatable")] = None,
    speed_ratio_max: Annotated[
        float | None, typer.Option(help="fit SR from 0 up to this (default: the table's coupling point)")
    ] = None,
) -> None:
    """Fit Hrovat & Tobler parameters to a characteristic table: DIR/fitted.toml, report, plots."""
    from .fitting import fit_command

    stdout.print(fit_command(converter, target, out, free, bound or [], speed_ratio_max))


@app.command()
def study(
    converter: Annotated[str, typer.Argument(help="converter with a [geometry] section")],
    out: OutOpt = Path("study"),
) -> None:
    """Appendix D parameter study: one figure per parameter and DIR/study.csv."""
    from .study import study_command

    stdout.print(study_command(converter, out))


@app.command()
def replay(
    converter: Annotated[str, typer.Argument(help="bundled name or converter .toml")],
    measurement: Annotated[str, typer.Argument(help="measured time series: .csv, .parquet, .mat or .mf4/.mdf")],
    model: Annotated[
        list[str] | None,
        typer.Option(
            "--model",
            "-m",
            help="table | hrovat-tobler | quasi-dynamic, repeatable (default: every model the converter supports)",
        ),
    ] = None,
    out: OutOpt = Path("replay"),
    channel: Annotated[
        list[str] | None, typer.Option("--channel", help="TARGET=COLUMN channel mapping, repeatable")
    ] = None,
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
            "--window", help="derivative smoothing window S, s: local least-squares slope over ±S/2 [default: 0.04]"
        ),
    ] = None,
    metrics_window: Annotated[
        float, typer.Option("--metrics-window", help="width of the consecutive metric windows, s")
    ] = 1.0,
) -> None:
    """Isolated converter driven by measured signals: DIR/<model>.csv, events, metrics, plots."""
    from .replay import replay_command

    stdout.print(
        replay_command(
            converter, measurement, model or [], out, channel or [], drive, initial or [], window, metrics_window
        )
    )


@app.command("fit-shapes")
def fit_shapes(
    converter: Annotated[str, typer.Argument(help="bundled name or converter .toml")],
    measurement: Annotated[str, typer.Argument(help="take-off measurement: .csv, .parquet, .mat or .mf4/.mdf")],
    model: ModelOpt = "quasi-dynamic",
    target: Annotated[
        str, typer.Option("--target", help="effective_turbine_torque_nm | effective_torque_ratio")
    ] = "effective_turbine_torque_nm",
    out: OutOpt = Path("shape_fit"),
    channel: Annotated[
        list[str] | None, typer.Option("--channel", help="TARGET=COLUMN channel mapping, repeatable")
    ] = None,
    drive: Annotated[str, typer.Option("--drive", help="pump-torque | speeds")] = "pump-torque",
    equal: Annotated[bool, typer.Option("--equal", help="fit one shape effect, S_p = S_t")] = False,
) -> None:
    """Fit the pump and turbine shape effects to a transient measurement; sweep plots like thesis figs 4.1–4.2."""
    from .shape_fit import shape_fit_command

    stdout.print(shape_fit_command(converter, measurement, out, model, target, channel or [], drive, equal))


@app.command()
def launch(
    vehicle: Annotated[
        str | None, typer.Argument(help="bundled vehicle name or vehicle .toml (default: midsize-awd-8at)")
    ] = None,
    out: OutOpt = Path("launch"),
    scenario: Annotated[
        str,
        typer.Option("--scenario", help="flip-flop | part-pedal | FILE with time_s, accelerator_pedal, brake_pedal"),
    ] = "flip-flop",
    model: Annotated[
        list[str] | None,
        typer.Option(
            "--model",
            "-m",
            help="table | hrovat-tobler | quasi-dynamic, repeatable (default: every model the converter supports)",
        ),
    ] = None,
    sweep_shape_effects: Annotated[
        bool,
        typer.Option(
            "--sweep-shape-effects", help="also sweep S_p = S_t of the dynamic models (like thesis figs 4.3–4.6)"
        ),
    ] = False,
) -> None:
    """Vehicle take-off with every converter model: DIR/summary.csv, DIR/<model>.csv, plots like thesis figs 3.5, 3.6, 3.20."""
    from .launch import launch_command

    stdout.print(launch_command(vehicle, out, scenario, model or [], sweep_shape_effects))


@app.command("export-fmu")
def export_fmu(
    converter: Annotated[str, typer.Argument(help="bundled name or converter .toml")],
    model: Annotated[str, typer.Option("--model", "-m", help="table | hrovat-tobler | quasi-dynamic")],
    out: Annotated[Path, typer.Option("--out", "-o", help="the FMU file to write (*.fmu)")],
    causality: Annotated[
        str,
        typer.Option("--causality", help="pump-torque (pump torque and turbine speed in) | speeds (both speeds in)"),
    ] = "pump-torque",
) -> None:
    """Export one model as an FMI 2.0 FMU, Model Exchange and Co-Simulation (linux64 binary, sources to rebuild elsewhere; no Python inside)."""
    from .fmu import export_fmu_command

    stdout.print(export_fmu_command(converter, model, out, causality), highlight=False, soft_wrap=True)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    if issubclass(category, TcsimWarning):
        console.print(f"[yellow]warning:[/yellow] {escape(str(message))}", highlight=False, soft_wrap=True)
    else:
        console.print(f"warning: {category.__name__}: {escape(str(message))}", highlight=False, soft_wrap=True)


def main(argv: list[str] | None = None) -> int:
    """Entry point: runs the app and maps errors to exit codes."""
    warnings.showwarning = _show_warning
    try:
        app(args=argv, standalone_mode=False)
    except InputError as e:
        console.print(f"[red]error:[/red] {escape(str(e))}", highlight=False, soft_wrap=True)
        return 2
    except typer.Abort:
        console.print("aborted")
        return 1
    except SystemExit as e:  # typer/click's own exits
        return e.code if isinstance(e.code, int) else 1
    except Exception as e:  # click usage errors, and failures that are not the user's
        if callable(getattr(e, "show", None)) and isinstance(getattr(e, "exit_code", None), int):
            e.show()  # a usage error from the command-line parser (exit code 2)
            return e.exit_code
        console.print(f"[red]tcsim failed:[/red] {type(e).__name__}: {escape(str(e))}", highlight=False, soft_wrap=True)
        return 1
    return 0
