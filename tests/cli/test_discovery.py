"""Discovery: ``tcsim --version``, ``tcsim vehicles``, and an ``Example:`` line in every command's help
whose command line the parser accepts (the quick ones are run)."""

from __future__ import annotations

import re
import shlex
from importlib import metadata

import pytest
import typer

from tcsim.cli import EXAMPLES, app
from tcsim.models.vehicle import bundled_vehicle_names, load_vehicle

COMMANDS = [c.name for c in app.registered_commands]
#: Examples that need no file of the user's and take seconds: run, not only parsed.
RUN = ("converters", "vehicles", "characterise", "design")


def test_version_prints_the_package_version(cli):
    r = cli("--version")
    assert r.code == 0, r.stderr
    assert r.stdout.strip() == f"tcsim {metadata.version('tcsim')}"


def test_vehicles_lists_each_bundled_vehicle_and_its_converter_uncut(cli):
    r = cli("vehicles")
    assert r.code == 0, r.stderr
    names = bundled_vehicle_names()
    assert names
    for name in names:
        vehicle = load_vehicle(name)
        assert vehicle.name in r.stdout and vehicle.converter_spec in r.stdout


def test_every_command_has_an_example():
    assert sorted(COMMANDS) == sorted(EXAMPLES)


@pytest.mark.parametrize("name", COMMANDS)
def test_help_shows_an_example_the_parser_accepts(cli, tmp_path, name):
    r = cli(name, "--help")
    assert r.code == 0, r.stderr
    example = EXAMPLES[name]
    assert f"Example: {example}" in " ".join(r.stdout.split())  # however the help wraps it
    args = shlex.split(example)
    assert args[:2] == ["tcsim", name]
    group = typer.main.get_command(app)
    parent = group.context_class(group, info_name="tcsim")
    command = group.get_command(parent, name)  # type: ignore[attr-defined]
    assert command is not None
    command.make_context(name, args[2:], parent=parent)  # parses the options and arguments; raises if refused
    if name in RUN:
        r = cli(*args[1:], cwd=tmp_path)
        assert r.code == 0, r.stderr


@pytest.mark.parametrize("name", COMMANDS)
def test_help_shows_every_bracketed_word_of_its_options(cli, name):
    """rich reads ``[word]`` in a help text as markup and drops it (``tcsim study --help`` said
    "converter with a  section"; ``tcsim characterise --help`` hid its default pump speed, written
    ``[default: 2000]``): every option's and argument's help shows its bracketed text."""
    command = typer.main.get_command(app).commands[name]  # type: ignore[attr-defined]
    r = cli(name, "--help")
    assert r.code == 0, r.stderr
    shown = " ".join(w for w in r.stdout.split() if w != "│")  # the panel's borders between wrapped lines
    for param in command.params:
        text = getattr(param, "help", None) or ""
        for inside in re.findall(r"\\?\[([^\]]+)\]", text):
            bracketed = "[" + " ".join(inside.split()) + "]"
            assert bracketed in shown, (name, param.name, bracketed)


@pytest.mark.parametrize(
    ("word", "expected"),
    [
        (
            "lauch",
            "command line: command = 'lauch': expected a command of tcsim (did you mean 'launch'? see 'tcsim --help')",
        ),
        ("xyzzy", "command line: command = 'xyzzy': expected a command of tcsim (see 'tcsim --help')"),
    ],
)
def test_a_mistyped_command_is_one_line_naming_it(cli, word, expected):
    # fresh-eyes trial: "No such command 'lauch'. Did you mean 'launch'?: expected the usage of ..."
    r = cli(word)
    assert r.code == 2 and r.stderr.strip() == f"error: {expected}", r.stderr
