"""Errors and warnings that tcsim reports to its users.

A :class:`InputError` is the user's to fix: the command line turns it into exit code 2 and one
line that names the file, the field, the value and what was expected. Anything else that goes
wrong is a failure of tcsim or of a solver (exit code 1).
"""

from __future__ import annotations

import re
import signal
import unicodedata
from collections.abc import Mapping
from pathlib import Path
from typing import Any

#: The ``source`` of an error about an argument of a function call (its ``field`` is the parameter's
#: name, ``pump_speed_rpm``); the command line shows it as the option of that name
#: (:meth:`InputError.on_command_line`).
ARGUMENT = "argument"

#: The keyword argument that runs an implausible input anyway (the command line's ``--allow-implausible``).
ALLOW_IMPLAUSIBLE = "allow_implausible"

#: Parameters whose command-line option is not the name with dashes.
_OPTION_OF = {"out_path": "--out", "bounds": "--bound"}


def option_name(parameter: str) -> str:
    """The command-line option of the function parameter ``parameter`` (``pump_speed_rpm`` →
    ``--pump-speed-rpm``; the options take the parameters' names, ``out_path`` is ``--out``, ``bounds`` ``--bound``)."""
    return _OPTION_OF.get(parameter, "--" + parameter.replace("_", "-"))


_ARGUMENT_AT_START = re.compile(rf"^{ARGUMENT}: ([a-z_][a-z0-9_]*)")


def on_command_line(message: str) -> str:
    """A warning's ``message`` as the command line words it: one that starts with an argument
    (``argument: pump_speed_rpm = …``) names the option instead (``command line: --pump-speed-rpm``)."""
    return _ARGUMENT_AT_START.sub(lambda m: f"command line: {option_name(m.group(1))}", message, count=1)


class InputError(Exception):
    """Bad user input: a file, a field in it, the offending value and what was expected.

    ``override`` names the keyword argument that runs the input anyway (:data:`ALLOW_IMPLAUSIBLE`),
    said after ``expected``.
    """

    def __init__(
        self,
        source: str,
        field: str,
        value: Any,
        expected: str,
        core_source: str | None = None,
        override: str | None = None,
    ):
        self.source = str(source)
        self.field = field
        self.value = value
        self.expected = expected
        #: The input the core blamed (``tcsim._core.input_sources()``), as data, when the core found it.
        self.core_source = core_source
        self.override = override
        super().__init__(str(self))

    @classmethod
    def argument(cls, parameter: str, value: Any, expected: str, **kwargs: Any) -> InputError:
        """An error about the argument ``parameter`` of a function call (source :data:`ARGUMENT`)."""
        return cls(ARGUMENT, parameter, value, expected, **kwargs)

    def replace(self, **changes: Any) -> InputError:
        """A copy with ``changes`` to its fields (``source``, ``field``, ``value``, ``expected``,
        ``core_source``, ``override``); the others, the override included, are kept."""
        fields = {k: getattr(self, k) for k in ("source", "field", "value", "expected", "core_source", "override")}
        return InputError(**(fields | changes))

    def __str__(self) -> str:
        expected = self.expected if self.override is None else f"{self.expected}; {self.override}=True runs it anyway"
        return escape_controls(f"{self.source}: {self.field} = {_show(self.value)}: expected {expected}")

    def on_command_line(self) -> InputError:
        """This error as the command line words it: an argument is the option of its name
        (:func:`option_name`), the override is its option (``--allow-implausible``)."""
        if self.source != ARGUMENT and self.override is None:
            return self
        source, field = (self.source, self.field)
        if self.source == ARGUMENT:
            source, field = "command line", option_name(self.field)
        expected = self.expected
        if self.override is not None:
            expected = f"{expected}; {option_name(self.override)} runs it anyway"
        return InputError(source, field, self.value, expected, self.core_source)


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM turned into an exception by :func:`tcsim.cli.main`, so that the run unwinds
    and cleans up as on Ctrl-C; ``signum`` is the signal's number."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


#: The signals the command line turned into :class:`Interrupted` in this run. Python drops an
#: exception raised inside a weakref callback or a ``__del__`` (a signal handler runs there when the
#: garbage collector does), so the exception can be lost; this record is not.
received_signals: list[int] = []


def raise_if_interrupted() -> None:
    """Raise :class:`Interrupted` for a signal received in this run whose exception was lost, so that
    nothing is committed after an interrupt."""
    if received_signals:
        raise Interrupted(received_signals[-1])


class TcsimWarning(UserWarning):
    """A suspicious but usable input (for example an implausible stall torque)."""


class CoreText(str):
    """A value as the core wrote it, already in the file's notation (``"1930"``, ``7 values``): shown
    as it is, not quoted again."""


#: Escapes of the control characters that have a short one; the others are shown as ``\\xNN``/``\\uNNNN``.
_SHORT_ESCAPES = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


#: A line break as the readers split lines: CRLF, CR or LF.
_LINE_BREAK = re.compile(rb"\r\n|\r|\n")


def read_user_text(path: str | Path, expected: str = "a readable UTF-8 text file") -> str:
    """The text of a user's file (UTF-8, a byte-order mark skipped); a file that cannot be read, or
    is not UTF-8, is an :class:`InputError` naming the file and why (not the exception's name)."""
    try:
        return Path(path).read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as e:
        raise not_utf8(path, e) from None
    except OSError as e:
        raise InputError(str(path), "(file)", e.strerror or type(e).__name__, expected) from None


def not_utf8(path: str | Path, e: UnicodeDecodeError) -> InputError:
    """The refusal of a file that is not UTF-8 text (UTF-16 by its byte-order mark, or a byte that
    no UTF-8 text holds, as Latin-1 or Windows-1252 files do), naming the byte's line."""
    data = bytes(e.object)
    try:  # a reader's error may concern a chunk of the file (pandas): find the first bad byte of all of it
        Path(path).read_bytes().decode("utf-8")
    except UnicodeDecodeError as whole:
        data, e = bytes(whole.object), whole
    except OSError:
        pass
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        what = "UTF-16 text"
    else:
        line = len(_LINE_BREAK.findall(data, 0, e.start)) + 1  # CR-only files (old Mac exports) too
        what = f"byte 0x{data[e.start]:02x} on line {line} (offset {e.start})"
    return InputError(str(path), "(file)", what, "UTF-8 text (save the file as UTF-8)")


def escape_controls(text: str) -> str:
    """``text`` with every control or format character (a newline, a tab, an escape sequence, a
    line or paragraph separator, a right-to-left override) and every lone surrogate (an
    undecodable byte of a file name) written as a Python-style escape (``\\n``, ``\\x1b``,
    ``\\u2028``), so that a message is one line of printable text whatever a file or a key holds.
    Spaces, including non-breaking ones, are kept."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or unicodedata.category(c) == "Zs" else _escape(c) for c in text)


def _escape(c: str) -> str:
    if c in _SHORT_ESCAPES:
        return _SHORT_ESCAPES[c]
    code = ord(c)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def _show(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    text = repr(value) if isinstance(value, str) and not isinstance(value, CoreText) else str(value)
    return text if len(text) <= 80 else text[:77] + "..."


def core_value(value: Any) -> Any:
    """The core reports values as text; show numbers as numbers and the rest as the core wrote it."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return CoreText(value) if isinstance(value, str) else value


#: How each input the core names in an error (its ``source``: ``tcsim._core.input_sources()``) is
#: shown when the caller has no file for it.
CORE_SOURCE_NAMES: dict[str, str] = {
    "converter": "converter",
    "drive": "drive",
    "initial": "initial state",
    "scenario": "scenario",
    "vehicle": "vehicle",
    "options": "solver options",
}


def core_input_error(
    source: str, field: str, value: Any, expected: str, files: Mapping[str, str], field_prefix: str = ""
) -> InputError:
    """The :class:`InputError` of an input error the core attributed to ``source`` (one of
    :data:`CORE_SOURCE_NAMES`): shown as ``files[source]`` (the file the caller read that input
    from), else by the input's name."""
    where = files.get(source) or CORE_SOURCE_NAMES.get(source, source)
    return InputError(where, field_prefix + field, core_value(value), expected, core_source=source)


def from_core(exc: Exception, files: Mapping[str, str] | str, field_prefix: str = "") -> InputError:
    """Wrap a ``tcsim._core.CoreInputError`` (args: message, field, value, expected, source).
    ``files`` maps the core's sources to files (see :func:`core_input_error`); a single name is the
    file of the one input the caller passed (a converter's, for the steady-state functions), which
    the error is then about whatever its source."""
    _message, field, value, expected = exc.args[:4]
    if isinstance(files, str):
        return InputError(files, field_prefix + field, core_value(value), expected)
    return core_input_error(exc.args[4], field, value, expected, files, field_prefix)
