"""``tcsim converters``: the bundled converters and their sources."""

from __future__ import annotations

from .app import stdout


def converters() -> None:
    """List the bundled converters and their sources."""
    from rich.table import Table

    from ..models.converter import bundled_converters
    from ..reports.format import rich_text

    table = Table(title="Bundled converters")
    table.add_column("name", no_wrap=True)
    table.add_column("models")
    # a source may hold a path longer than the column: folded, never cut
    table.add_column("source", overflow="fold")
    for conv in bundled_converters():
        table.add_row(rich_text(conv.name), ", ".join(conv.models), rich_text(conv.source))
    stdout.print(table)
