"""The typer app, its consoles and the entry point that maps errors to exit codes.

Exit codes (conventions.md, guarantees.md): 0 success; 2 bad input, with one message naming the
file, the field, the value and what was expected, and no output written; 1 a failure that is not
the user's (the message says what failed); 130 interrupted by SIGINT (Ctrl-C), 143 by SIGTERM, with
one line ``interrupted (SIGINT): nothing written`` and nothing written (docs/guarantees.md).
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console

from ..errors import InputError, Interrupted, TcsimWarning, on_command_line, received_signals
from ..reports.format import rich_text

if TYPE_CHECKING:
    from ..io.tables import TableFormat

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="tcsim: hydrodynamic torque converter models (table, Hrovat & Tobler, quasi-dynamic).",
)
#: Messages, warnings and progress go to stderr; results to stdout.
console = Console(stderr=True, emoji=False)  # a value such as "a:b:c" is text, never an emoji code
stdout = Console(emoji=False)

ModelOpt = Annotated[str, typer.Option("--model", "-m", help="table | hrovat-tobler | quasi-dynamic")]
ModelsOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--model",
        "-m",
        help="table | hrovat-tobler | quasi-dynamic, repeatable (default: every model the converter supports)",
    ),
]


def _out_path(text: str | Path) -> Path:
    """``--out``: an empty name is a mistake (an unset shell variable), not the current folder. Typer
    passes the default (a Path) through the parser as well."""
    text = str(text)
    if not text.strip():
        raise InputError("command line", "--out", text, "a directory name (an empty name is not the current folder)")
    return Path(text)


OutOpt = Annotated[Path, typer.Option("--out", "-o", help="output directory", parser=_out_path)]
AllowImplausibleOpt = Annotated[
    bool,
    typer.Option(
        "--allow-implausible",
        help=(
            "run measured and command-line values outside the plausibility ranges (docs/guarantees.md) with a "
            "warning instead of refusing them (a converter file's design values are only warned of)"
        ),
    ),
]
ChannelOpt = Annotated[list[str] | None, typer.Option("--channel", help="TARGET=COLUMN channel mapping, repeatable")]
#: ``--format`` and ``--speed-unit`` of the commands that write result tables (tcsim.io.tables owns
#: the choices; tests/cli/test_result_formats.py checks that the help lists them).
FormatOpt = Annotated[
    str, typer.Option("--format", help="file format of the result tables: csv | parquet | mat (MATLAB)")
]
SpeedUnitOpt = Annotated[
    str,
    typer.Option(
        "--speed-unit",
        help="unit of the angular speed columns of the result tables: rad/s | rpm "
        "(rpm: *_rad_s columns become *_rpm, *_rad_s2 become *_rpm_per_s)",
    ),
]

#: ``--plots/--no-plots`` of the commands that draw figures (issue 16: a start-up that fits the job).
PlotsOpt = Annotated[
    bool,
    typer.Option("--plots/--no-plots", help="draw the figures (PNG); --no-plots writes the tables and files only"),
]


def and_plots(plots: bool) -> str:
    """`` and plots`` when the command drew its figures, else nothing (for the written-to lines)."""
    return " and plots" if plots else ""


def table_format(file_format: str, speed_unit: str) -> TableFormat:
    """``--format`` and ``--speed-unit`` checked (an :class:`InputError` of the command line names
    the option), before anything is read or computed."""
    from ..io.tables import TableFormat

    return TableFormat(file_format, speed_unit)


def say(line: str) -> None:
    """Print a plain line (a command's result) on stdout, never read as rich markup."""
    stdout.print(rich_text(line))


#: The warning lines this command has printed: a line is printed once (a fit's model and the run of
#: the fitted model gave the same line twice, from two places in the code).
_shown: set[str] = set()


def _show_warning(message, category, filename, lineno, file=None, line=None):
    message = on_command_line(str(message))
    text = f"{category.__name__}: {message}"
    if text in _shown:
        return
    _shown.add(text)
    if issubclass(category, TcsimWarning):
        console.print(f"[yellow]warning:[/yellow] {rich_text(message)}", highlight=False, soft_wrap=True)
    else:
        console.print(f"warning: {category.__name__}: {rich_text(message)}", highlight=False, soft_wrap=True)


#: The signals :func:`_raise_interrupted` turned into :class:`Interrupted` in this run.
_received = received_signals

#: The exit code typer returns for a ``KeyboardInterrupt`` it caught (the exception is lost).
_TYPER_INTERRUPT = 130


def _raise_interrupted(signum, frame):
    _received.append(signum)
    raise Interrupted(signum)


@contextlib.contextmanager
def _signal_handlers(handler) -> Iterator[None]:
    """SIGINT and SIGTERM go to ``handler`` while the block runs; the previous handlers are restored
    after. Outside the main thread signals are not ours to handle, and nothing changes."""
    try:
        previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def _signals_raise() -> contextlib.AbstractContextManager[None]:
    """SIGINT and SIGTERM raise :class:`Interrupted` (and are recorded, also when the exception is
    swallowed, e.g. raised in a ``__del__``) while the block runs."""
    return _signal_handlers(_raise_interrupted)


@contextlib.contextmanager
def _lost_interrupts_unreported() -> Iterator[None]:
    """Python prints an exception raised in a weakref callback or a ``__del__`` ("Exception ignored
    in …") and drops it; a signal's handler runs there when the garbage collector does. Such an
    :class:`Interrupted` is not printed while the block runs: it is in ``received_signals``, and the
    run stops at its next commit (:func:`tcsim.errors.raise_if_interrupted`) or at its end."""
    previous = sys.unraisablehook

    def hook(unraisable: Any) -> None:
        if not isinstance(unraisable.exc_value, Interrupted):
            previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = previous


def _signals_ignored() -> contextlib.AbstractContextManager[None]:
    """SIGINT and SIGTERM ignored while the block runs."""
    return _signal_handlers(signal.SIG_IGN)


def _forget_unhandled_interrupt() -> None:
    """Clear CPython's record of a ``KeyboardInterrupt`` that left an ``eval`` of a string (typer
    evaluates the commands' annotations that way): with it set, the interpreter ends the process by
    SIGINT at exit whatever its exit code. Every later string ``eval`` clears it (CPython 3.11–3.13,
    ``run_eval_code_obj``)."""
    eval("None")


def interrupt_line(e: KeyboardInterrupt) -> tuple[str, int]:
    """The one line and the exit code (128 + the signal's number) of an interrupted run."""
    from ..io import outputs

    signum = e.signum if isinstance(e, Interrupted) else signal.SIGINT
    name = signal.Signals(signum).name
    shards = sys.modules.get("tcsim.io.shards")  # a sharded study keeps its finished chunks
    if shards is not None and shards.resumable:
        where = ", ".join(shards.resumable)
        return f"interrupted ({name}): the finished chunks in {where} are kept; run it again to resume", 128 + signum
    if outputs.committed:
        done = ", ".join(str(p) for p in outputs.committed)
        return f"interrupted ({name}) after {done} was written completely", 128 + signum
    return f"interrupted ({name}): nothing written", 128 + signum


class _ReaderMayLeave:
    """``sys.stdout`` while a command runs: a reader that closes the pipe (``tcsim … | head``) ends
    what is shown, not the run. Click exited 1 at the first write after it, silently, with the
    outputs written in full; now the rest of the output goes to ``/dev/null`` (the descriptor too,
    so that the interpreter's last flush finds no broken pipe) and the run completes."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._to_devnull()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._to_devnull()

    def _to_devnull(self) -> None:
        devnull = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(devnull, self._stream.fileno())
        finally:
            os.close(devnull)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def main(argv: list[str] | None = None) -> int:
    """Entry point: runs the app and maps errors to exit codes (see the module's docstring), with
    stdout kept from failing when its reader leaves (:class:`_ReaderMayLeave`)."""
    shown = sys.stdout
    with contextlib.suppress(AttributeError, OSError, ValueError):  # a stream without a descriptor stays
        shown.fileno()
        sys.stdout = _ReaderMayLeave(shown)
    try:
        return _main(argv)
    finally:
        if isinstance(sys.stdout, _ReaderMayLeave):
            sys.stdout.flush()
            sys.stdout = shown
        if argv is None:  # the process ends with this run
            _ignore_signals_until_exit()


def _ignore_signals_until_exit() -> None:
    """The run is over and reported (its output committed or nothing written, its exit code
    decided): SIGINT and SIGTERM are ignored while the interpreter tears down (about 0.2 s). A
    signal then killed the process after the success line, which a shell took for an interrupted
    run (130) with its whole output written."""
    with contextlib.suppress(ValueError):  # not the main thread: not ours to change
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)


def _main(argv: list[str] | None) -> int:
    from ..io import outputs

    warnings.showwarning = _show_warning
    _shown.clear()
    outputs.command_line = ["tcsim", *(sys.argv[1:] if argv is None else argv)]
    outputs.committed.clear()
    if (shards := sys.modules.get("tcsim.io.shards")) is not None:
        shards.resumable.clear()
    _received.clear()
    try:
        with _signals_raise(), _lost_interrupts_unreported():
            return _run(argv)
    except KeyboardInterrupt as e:  # also raised by a second signal while the first is handled
        line, code = interrupt_line(e)
        _forget_unhandled_interrupt()
        with _signals_ignored():  # a second Ctrl-C now would print a traceback after the line
            console.print(rich_text(line), highlight=False, soft_wrap=True)
        return code
    finally:
        outputs.command_line = []


def _run(argv: list[str] | None) -> int:
    try:
        rv = app(args=argv, standalone_mode=False)
    except InputError as e:
        console.print(f"[red]error:[/red] {rich_text(e.on_command_line())}", highlight=False, soft_wrap=True)
        return 2
    except typer.Abort:
        console.print("aborted")
        return 1
    except SystemExit as e:  # typer/click's own exits
        return e.code if isinstance(e.code, int) else 1
    except Exception as e:  # click usage errors, and failures that are not the user's
        if _received:  # a signal handled inside an extension's import surfaces as its ImportError
            raise Interrupted(_received[-1]) from None
        if callable(getattr(e, "format_message", None)) and getattr(e, "exit_code", None) == 2:
            line = usage_error_line(e, sys.argv[1:] if argv is None else argv)
            console.print(f"[red]error:[/red] {rich_text(line)}", highlight=False, soft_wrap=True)
            return 2
        console.print(f"[red]tcsim failed:[/red] {type(e).__name__}: {rich_text(e)}", highlight=False, soft_wrap=True)
        return 1
    if rv == _TYPER_INTERRUPT or _received:  # typer caught the interrupt, or it was swallowed
        raise Interrupted(_received[-1]) if _received else KeyboardInterrupt()
    return 0


def usage_error_line(e: Exception, argv: list[str]) -> str:
    """A usage error of the command-line parser as one line naming the option and the value given
    (``command line: --pump-speed-rpm = 'abc': expected …``), like every other input error."""
    ctx = getattr(e, "ctx", None)
    command = " ".join(["tcsim", *([ctx.info_name] if ctx is not None and ctx.parent is not None else [])])
    reason = str(e.format_message()).rstrip(".")  # type: ignore[attr-defined]
    param = getattr(e, "param", None)
    opts = [o for o in getattr(param, "opts", []) if o.startswith("-")]
    if type(e).__name__ == "BadParameter" and opts:
        value = _option_value(argv, opts)
        detail = reason.split(": ", 1)[-1]
        return f"command line: {opts[0]} = {value!r}: expected a valid value ({detail}; see '{command} --help')"
    unknown = re.fullmatch(r"No such command '(.*)'(?:\. Did you mean '(.*)'\?)?", reason)
    if unknown:  # "No such command 'lauch'. Did you mean 'launch'?: expected the usage" read badly
        hint = f"did you mean '{unknown.group(2)}'? " if unknown.group(2) else ""
        return (
            f"command line: command = {unknown.group(1)!r}: expected a command of tcsim ({hint}see '{command} --help')"
        )
    return f"command line: {reason}: expected the usage of '{command} --help'"


def _option_value(argv: list[str], opts: list[str]) -> str:
    """The last value ``argv`` gives an option (``--opt VALUE`` or ``--opt=VALUE``)."""
    value = ""
    for i, arg in enumerate(argv):
        for opt in opts:
            if arg == opt and i + 1 < len(argv):
                value = argv[i + 1]
            elif arg.startswith(opt + "="):
                value = arg[len(opt) + 1 :]
    return value
