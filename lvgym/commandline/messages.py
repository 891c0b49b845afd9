"""How a command line names itself and refuses a bad value: one line naming the option, the value and
what is allowed, then the exit.

- :func:`command_name`, :func:`running_as`: the name a command answers to (``lvgym <command>`` when the
  console script started it, else its own, ``train.py``);
- :func:`one_line_errors`: an argparse parser that reports a bad command line in one line;
- :func:`option_number`, :func:`parse_number`: a number of the command line, checked with the option's name;
- :func:`fail`: exit (status 1) with one line ``prog: message``.
"""

from __future__ import annotations

import argparse
import contextlib
import contextvars
from collections.abc import Iterator
from typing import Any, NoReturn

from lvgym.errors import ConfigError, check_number

__all__ = ["command_name", "fail", "one_line_errors", "option_number", "parse_number", "running_as"]

_COMMAND: contextvars.ContextVar[str | None] = contextvars.ContextVar("lvgym_command", default=None)


def command_name(default: str) -> str:
    """The name the running command answers to: ``lvgym <command>`` when the console script started it
    (:func:`running_as`), else ``default`` (``train.py``, ``python -m lvgym.studies``)."""
    return _COMMAND.get() or default


@contextlib.contextmanager
def running_as(name: str) -> Iterator[str]:
    """Within the block, :func:`command_name` is ``name``."""
    token = _COMMAND.set(name)
    try:
        yield name
    finally:
        _COMMAND.reset(token)


def one_line_errors(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Make ``parser`` report a bad command line in one line (``prog: error: ... (see prog --help)``)
    instead of its usage block and the error; returns ``parser``."""

    def error(message: str) -> NoReturn:
        parser.exit(2, f"{parser.prog}: error: {message} (see {parser.prog} --help)\n")

    parser.error = error  # type: ignore[method-assign]
    return parser


def option_number(option: str, value: Any, lo: float, hi: float, *, integer: bool = False,
                  lo_open: bool = False) -> Any:
    """``value`` checked like :func:`lvgym.errors.check_number` with the option's name (``--step``) as key;
    ``None`` passes (the option's default)."""
    if value is None:
        return None
    return check_number(option, value, lo, hi, integer=integer, lo_open=lo_open)


def parse_number(text: Any, option: str = "") -> Any:
    """A command-line number as int or float (None passes); a non-number raises ``ConfigError`` naming
    ``option`` if given, else is left for the range check to refuse."""
    if text is None or isinstance(text, (int, float)):
        return text
    try:
        return int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            if option:
                raise ConfigError(option, text, "a number") from None
            return text


def fail(prog: str, exc: BaseException | str) -> NoReturn:
    """Exit (status 1) printing the one line ``prog: <message>`` (a ConfigError's message names the key,
    the value and what is allowed); only the first line of a longer message."""
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    raise SystemExit(f"{prog}: {text}")
