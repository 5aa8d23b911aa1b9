"""The typer app, its consoles and the entry point that maps errors to exit codes.

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

from ..errors import InputError, TcsimWarning

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="tcsim: hydrodynamic torque converter models (table, Hrovat & Tobler, quasi-dynamic).",
)
#: Messages, warnings and progress go to stderr; results to stdout.
console = Console(stderr=True)
stdout = Console()

ModelOpt = Annotated[str, typer.Option("--model", "-m", help="table | hrovat-tobler | quasi-dynamic")]
ModelsOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--model",
        "-m",
        help="table | hrovat-tobler | quasi-dynamic, repeatable (default: every model the converter supports)",
    ),
]
OutOpt = Annotated[Path, typer.Option("--out", "-o", help="output directory")]
AllowImplausibleOpt = Annotated[
    bool,
    typer.Option(
        "--allow-implausible",
        help="run values outside the plausibility ranges (docs/guarantees.md) with a warning instead of refusing them",
    ),
]
ChannelOpt = Annotated[list[str] | None, typer.Option("--channel", help="TARGET=COLUMN channel mapping, repeatable")]


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
        show, code = getattr(e, "show", None), getattr(e, "exit_code", None)
        if callable(show) and isinstance(code, int):
            show()  # a usage error from the command-line parser (exit code 2)
            return code
        console.print(f"[red]tcsim failed:[/red] {type(e).__name__}: {escape(str(e))}", highlight=False, soft_wrap=True)
        return 1
    return 0
