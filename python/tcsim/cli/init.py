"""``tcsim init``: a commented, valid starting file (:mod:`tcsim.io.templates`).

::

    tcsim init converter|vehicle|scenario|study|monte-carlo|design [--from TABLE] [--out FILE] [--force]

FILE defaults to ``converter.toml``, ``vehicle.toml``, ``scenario.csv``, ``study.toml``,
``monte-carlo.toml`` or ``design.toml`` in the current directory; an existing FILE is refused (exit 2,
one line) unless ``--force``.
"""

from __future__ import annotations

from typing import Annotated

import typer

from .app import say

#: The command's ``--help`` text.
HELP = (
    "Write a commented, valid starting file: converter, vehicle, scenario, study, monte-carlo or design "
    "(values from the bundled data, with units, ranges and sources); 'init converter --from TABLE' makes a "
    "converter of a characteristic table and marks what the other models still need."
)


def init(
    kind: Annotated[str, typer.Argument(help="converter | vehicle | scenario | study | monte-carlo | design")],
    from_table: Annotated[
        str | None,
        typer.Option("--from", help="converter only: a characteristic table (.csv, .vtcc) or converter .toml"),
    ] = None,
    out: Annotated[
        str | None,
        typer.Option("--out", "-o", help="file to write (default: KIND.toml; scenario.csv for a scenario)"),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="replace FILE if it exists")] = False,
) -> None:
    """The command; its help is :data:`HELP`."""
    from ..errors import InputError
    from ..io.templates import DEFAULT_FILES, check_kind, make_template, write_template

    check_kind(kind)
    target = DEFAULT_FILES[kind] if out is None else out
    if not target.strip():
        raise InputError("command line", "--out", target, "a file name (an empty name is not a file)")
    template = make_template(kind, target, from_table)  # the command names the file as the user gave it
    write_template(template, target, force, (from_table,) if from_table else ())
    say(f"wrote {target}: a {kind} file; run it with: {template.command}")
    if template.todo:
        sections = ", ".join(f"[{s}]" for s in template.todo)
        say(f"TODO in {target}: {sections} (commented out) before the models that need them")
