"""``tcsim converters``: the bundled converters and their sources."""

from __future__ import annotations

from .app import stdout


def converters() -> None:
    """List the bundled converters and their sources."""
    from rich.table import Table

    from ..models.converter import bundled_converters

    table = Table(title="Bundled converters")
    for col in ("name", "models", "source"):
        table.add_column(col)
    for conv in bundled_converters():
        table.add_row(conv.name, ", ".join(conv.models), conv.source)
    stdout.print(table)
