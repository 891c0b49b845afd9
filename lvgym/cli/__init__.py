"""The command layer: the console script ``lvgym`` and the command lines of every tool.

- this package's root keeps the small helpers any layer's command line uses (:func:`fail`,
  :func:`one_line_errors`, :func:`option_number`, :func:`parse_number`) and imports no upper layer;
- :mod:`.args`: a command line declared as a dataclass (help from the fields' docstrings, ranges and
  choices on the fields), and the subcommands of a console script; it too imports no upper layer;
- :mod:`.main`: the console script ``lvgym`` (``lvgym --help`` lists the commands);
- :mod:`.evaluate`, :mod:`.margins`, :mod:`.fingerprint`: the benchmark's commands, with the options the
  flight commands share (:mod:`.flights`); the benchmark layer itself builds no parser.

A command line refuses a bad value in one line that names the option, the value and what is allowed,
before it creates a folder or starts a worker::

    train.py: error: --total-timesteps = -5: an integer in [1, 1000000000000] (see train.py --help)
"""

from __future__ import annotations

import argparse
from typing import Any, NoReturn

from lvgym.errors import ConfigError, check_number

__all__ = ["fail", "one_line_errors", "option_number", "parse_number"]


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
