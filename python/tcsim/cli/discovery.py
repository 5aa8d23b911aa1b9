"""Discovery: ``tcsim vehicles`` (the bundled vehicles, their converters and sources) and ``tcsim --version``."""

from __future__ import annotations

from typing import Annotated

import typer

from .app import say, stdout


def vehicles() -> None:
    """List the bundled vehicles, the converter each names, and their descriptions and sources."""
    from rich.table import Table

    from ..models.vehicle import bundled_vehicle_names, load_vehicle
    from ..reports.format import rich_text

    table = Table(title="Bundled vehicles")
    for col in ("name", "converter"):
        table.add_column(col, no_wrap=True)  # names are what the user types: never cut
    for col in ("description", "source"):
        table.add_column(col)
    for name in bundled_vehicle_names():
        v = load_vehicle(name)
        table.add_row(
            rich_text(v.name), rich_text(v.converter_spec), rich_text(v.description or ""), rich_text(v.source)
        )
    stdout.print(table)


def version_line() -> str:
    """``tcsim <version>``, the version of the installed package's metadata."""
    from importlib import metadata

    return f"tcsim {metadata.version('tcsim')}"


def _print_version(value: bool) -> None:
    if value:
        say(version_line())
        raise typer.Exit()


def options(
    version: Annotated[
        bool,
        typer.Option("--version", help="print 'tcsim <version>' and exit", callback=_print_version, is_eager=True),
    ] = False,
) -> None:
    """The options of ``tcsim`` itself (before the command)."""
