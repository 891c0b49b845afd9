"""The command-line helpers under their former name: :mod:`lvgym.commandline` (beside the layers) holds
them; this module repeats its names for scripts that import them from here. No module of lvgym imports
this one (``tests/test_layers.py``)."""

from lvgym.commandline import (Command, Spec, arg, build_parser, check_fields, command_help, command_name, dispatch,
                               fail, field_docs, one_line_errors, option_number, parse, parse_given, parse_number,
                               running_as)

__all__ = ["Command", "Spec", "arg", "build_parser", "check_fields", "command_help", "command_name", "dispatch",
           "fail", "field_docs", "one_line_errors", "option_number", "parse", "parse_given", "parse_number",
           "running_as"]
