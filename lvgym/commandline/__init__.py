"""Command lines for every layer: a command's options declared as a dataclass, its one-line refusals, and
the subcommands of a console script. Beside the layers: it imports nothing of lvgym but
:mod:`lvgym.errors`, so the vehicle layer, the envs, the controllers' design tools and the agents declare
their command lines with it, and the command layer (the console script ``lvgym``) runs them.

- :mod:`.options`: a command line declared as a dataclass (help from the fields' docstrings, ranges and
  choices on the fields; :func:`arg`, :func:`parse`, :func:`parse_given`, :func:`check_fields`);
- :mod:`.messages`: the name a command runs under (:func:`command_name`, :func:`running_as`) and its
  one-line refusals (:func:`fail`, :func:`one_line_errors`, :func:`option_number`, :func:`parse_number`);
- :mod:`.subcommands`: a console script's subcommands (:class:`Command`, :func:`dispatch`).

A command line refuses a bad value in one line that names the option, the value and what is allowed,
before it creates a folder or starts a worker::

    train.py: error: --total-timesteps = -5: an integer in [1, 1000000000000] (see train.py --help)
"""

from __future__ import annotations

from .messages import command_name, fail, one_line_errors, option_number, parse_number, running_as
from .options import Spec, arg, build_parser, check_fields, field_docs, parse, parse_given
from .subcommands import Command, command_help, dispatch

__all__ = ["Command", "Spec", "arg", "build_parser", "check_fields", "command_help", "command_name", "dispatch",
           "fail", "field_docs", "one_line_errors", "option_number", "parse", "parse_given", "parse_number",
           "running_as"]
