"""Command lines declared as dataclasses: one way for every lvgym command.

A command's options are the fields of a dataclass. Each field's attribute docstring (the string literal
under it) is its help; its default is shown; its type says how the text becomes a value::

    @dataclass
    class Args:
        episodes: int = arg(50, lo=1, hi=10**6, allowed="an integer >= 1")
        \"\"\"episodes (seeds) per condition and policy\"\"\"
        executor: str = arg("local", choices=EXECUTORS)
        \"\"\"local (process pool), serial or ray\"\"\"

    args = parse(Args, argv, prog="evaluate.py", doc=__doc__)

Types: ``int``, ``float``, ``str``, ``Path``; ``bool`` (``--x`` / ``--no-x``); ``list[T]`` (``nargs``, or
a repeated flag that adds up with ``extend=True``); ``tuple[T, T]`` (two values); ``list[tuple[...]]``
(a repeated flag of several values); ``T | None``; ``Literal[...]`` (choices). :func:`arg` declares on the
field what the helper checks before the command does any work: a range (``lo``, ``hi``, ``lo_open``,
checked by :func:`lvgym.errors.check_number`), choices (a tuple, or a function returning one, called when
the parser is built), or any ``check(option, value) -> value`` that raises :class:`~lvgym.errors.ConfigError`.
Checks that involve several options go in the dataclass's ``__post_init__`` (a ConfigError there is
reported the same way). Every refusal is one line naming the option, the value and what is allowed, and
a mistyped option is met with the nearest one::

    evaluate.py: error: --episodes = 0: an integer >= 1 (see evaluate.py --help)
    evaluate.py: error: unrecognized arguments: --episods 3; did you mean --episodes? (see evaluate.py --help)

A command runs under its own name (``prog``) or, started by the console script, as ``lvgym <command>``
(:func:`~.messages.command_name`).
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import difflib
import inspect
import math
import re
import sys
import textwrap
import types
import typing
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Literal

from lvgym.errors import ConfigError, check_number

from .messages import command_name, one_line_errors

__all__ = ["Spec", "arg", "build_parser", "check_fields", "field_docs", "parse", "parse_given"]

_KEY = "lvgym.commandline"                            # the key of a field's Spec in its metadata


# ---------------------------------------------------------------------------------------- declaring
@dataclasses.dataclass(frozen=True)
class Spec:
    """How a field is an option, besides its type and default (see :func:`arg`)."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    allowed: str | None = None
    choices: Sequence[Any] | Callable[[], Sequence[Any]] | None = None
    check: Callable[[str, Any], Any] | None = None
    positional: bool = False
    nargs: str | int | None = None
    extend: bool = False
    metavar: str | tuple[str, ...] | None = None
    flag: str | None = None
    switches: dict[str, str] | None = None
    help: str | None = None


def arg(default: Any = dataclasses.MISSING, *, default_factory: Any = dataclasses.MISSING,
        **spec: Any) -> Any:
    """A dataclass field that is an option: ``default`` (or ``default_factory``) as for
    :func:`dataclasses.field`, and the keywords of :class:`Spec`:

    - ``lo``, ``hi``, ``lo_open``: the range of a number (each number of a list), checked by
      :func:`lvgym.errors.check_number` (an ``int`` field's values must be integers); ``allowed``: the
      words of the refusal instead of check_number's (``"an integer >= 1"``);
    - ``choices``: the allowed values, or a function returning them (called when the parser is built, so
      a command's module need not import what lists them);
    - ``check``: ``check(option, value) -> value`` after the type and range, raising ConfigError;
    - ``positional``: a positional argument (a list: one or more values);
    - ``nargs``: a list's number of values (default ``"+"``); ``extend``: a repeated flag adds to the list;
    - ``metavar``, ``flag`` (the option's name, default ``--field-name``), ``help`` (instead of the
      attribute docstring);
    - ``switches``: for a ``Literal`` field, one flag per value (``{"check": "help", "write": "help"}``
      makes ``--check`` and ``--write``, exactly one of them; required when the field has no default)."""
    return dataclasses.field(default=default, default_factory=default_factory, metadata={_KEY: Spec(**spec)})


def _spec(f: dataclasses.Field) -> Spec:
    return f.metadata.get(_KEY, Spec())


def field_docs(cls: type) -> dict[str, str]:
    """The attribute docstrings of a dataclass's fields (its bases' too), by field name."""
    out: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        if not dataclasses.is_dataclass(klass):
            continue
        try:
            tree = ast.parse(textwrap.dedent(inspect.getsource(klass)))
        except (OSError, TypeError, SyntaxError):
            continue
        body = tree.body[0].body if tree.body and isinstance(tree.body[0], ast.ClassDef) else []
        for a, b in zip(body, body[1:]):
            if (isinstance(a, ast.AnnAssign) and isinstance(a.target, ast.Name) and isinstance(b, ast.Expr)
                    and isinstance(b.value, ast.Constant) and isinstance(b.value.value, str)):
                out[a.target.id] = " ".join(b.value.value.split())
    return out


@dataclasses.dataclass(frozen=True)
class _Kind:
    """A field's type taken apart: the scalar type, whether None is allowed, list / tuple shape, choices."""

    scalar: Any
    optional: bool = False
    many: bool = False                  # a list
    width: int = 0                      # a tuple's number of values (0: not a tuple)
    literal: tuple[Any, ...] = ()


def _kind(hint: Any) -> _Kind:
    optional = False
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        rest = [a for a in typing.get_args(hint) if a is not type(None)]
        optional = len(rest) < len(typing.get_args(hint))
        if len(rest) != 1:
            raise TypeError(f"an option's type must be one type or that type | None, not {hint}")
        hint, origin = rest[0], typing.get_origin(rest[0])
    many = origin in (list, Sequence)
    if many:
        hint = typing.get_args(hint)[0] if typing.get_args(hint) else str
        origin = typing.get_origin(hint)
    width = 0
    if origin is tuple:
        items = typing.get_args(hint)
        if not items or Ellipsis in items or len(set(items)) != 1:
            raise TypeError(f"a tuple option has a fixed number of values of one type, not {hint}")
        width, hint, origin = len(items), items[0], typing.get_origin(items[0])
    if origin is Literal:
        values = typing.get_args(hint)
        return _Kind(type(values[0]), optional, many, width, values)
    if hint not in (int, float, str, bool, Path):
        raise TypeError(f"an option's type is int, float, str, bool, Path, a list, tuple or Literal of them, not {hint}")
    return _Kind(hint, optional, many, width)


def _hints(cls: type) -> dict[str, Any]:
    module = sys.modules.get(cls.__module__)
    return typing.get_type_hints(cls, vars(module) if module else None)


# ---------------------------------------------------------------------------------------- the parser
def _shown(value: Any) -> str:
    if isinstance(value, (list, tuple)):
        return " ".join(_shown(v) for v in value) if value else "none"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _help(f: dataclasses.Field, doc: str, kind: _Kind, flag: str) -> str:
    text = _spec(f).help or doc
    default = f.default if f.default is not dataclasses.MISSING else (
        f.default_factory() if f.default_factory is not dataclasses.MISSING else dataclasses.MISSING)
    if default is not dataclasses.MISSING and not re.search(r"\(default\b|\bdefault:", text):
        if kind.scalar is bool and not kind.many:
            text += f" (default: {flag if default else '--no-' + flag[2:]})"
        elif default is not None and default != []:
            text += f" (default: {_shown(default)})"
    return text.replace("%", "%%")


def build_parser(cls: type, prog: str, doc: str | None = None, epilog: bool | str = False) -> argparse.ArgumentParser:
    """The argparse parser of dataclass ``cls``: one-line errors, ``doc``'s first paragraph as its
    description and, with ``epilog`` (True: the rest of ``doc``; or a text), an epilog. Options not given
    are left out of the namespace (their defaults are the dataclass's)."""
    paragraphs = inspect.cleandoc(doc or "").split("\n\n", 1)
    tail = epilog if isinstance(epilog, str) else (paragraphs[1] if epilog and len(paragraphs) > 1 else None)
    p = _Parser(prog=command_name(prog), description=paragraphs[0] or None, epilog=tail,
                formatter_class=argparse.RawDescriptionHelpFormatter, argument_default=argparse.SUPPRESS)
    one_line_errors(p)
    docs, hints = field_docs(cls), _hints(cls)
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        s, kind = _spec(f), _kind(hints[f.name])
        flag = s.flag or "--" + f.name.replace("_", "-")
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        kw: dict[str, Any] = {"help": _help(f, docs.get(f.name, ""), kind, flag)}
        choices = s.choices() if callable(s.choices) else s.choices
        choices = tuple(choices) if choices is not None else (kind.literal or None)
        if s.switches is not None:
            group = p.add_mutually_exclusive_group(required=required)
            for value, text in s.switches.items():
                group.add_argument(f"--{value}", dest=f.name, action="store_const", const=value, help=text)
            continue
        if kind.scalar is bool and not kind.many and not kind.width:
            p.add_argument(flag, dest=f.name, action=argparse.BooleanOptionalAction, **kw)
            continue
        if choices is not None:
            kw["choices"] = tuple(str(c) for c in choices) if kind.scalar is not str else choices
        if s.metavar is not None:
            kw["metavar"] = s.metavar
            if choices is not None:                 # the metavar hides them in the usage: say them in the help
                kw["help"] += f" [one of: {', '.join(str(c) for c in choices)}]"
        if kind.width:
            kw["nargs"] = kind.width
            if kind.many:
                kw["action"] = "append"
        elif kind.many:
            kw["nargs"] = s.nargs or "+"
            if s.extend:
                kw["action"] = "extend"
        if s.positional:
            if not required:
                kw["default"] = f.default if f.default is not dataclasses.MISSING else f.default_factory()
                kw["nargs"] = kw.get("nargs", "?") if not kind.many else (s.nargs or "*")
            p.add_argument(f.name, **kw)
        else:
            p.add_argument(flag, dest=f.name, required=required, **kw)
    return p


class _Parser(argparse.ArgumentParser):
    """argparse with "did you mean" for an unknown option (difflib against the parser's options)."""

    def parse_args(self, args: Sequence[str] | None = None, namespace: Any = None) -> argparse.Namespace:  # type: ignore[override]
        ns, extra = self.parse_known_args(args, namespace)
        if extra:
            known = [o for a in self._actions for o in a.option_strings]
            hints = [m[0] for x in extra if x.startswith("-") and not _is_number(x)
                     for m in [difflib.get_close_matches(x.split("=", 1)[0], known, n=1, cutoff=0.6)] if m]
            tip = f"; did you mean {', '.join(dict.fromkeys(hints))}?" if hints else ""
            self.error(f"unrecognized arguments: {' '.join(extra)}{tip}")
        return ns


def _is_number(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


# ---------------------------------------------------------------------------------------- the values
def _convert(option: str, text: Any, kind: _Kind, s: Spec) -> Any:
    """One value of an option: its type, then its range (ConfigError naming ``option``)."""
    value = text
    if isinstance(text, str) and kind.scalar in (int, float):
        try:
            value = int(text) if kind.scalar is int else float(text)
        except ValueError:
            try:
                number = float(text)
                value = int(number) if kind.scalar is int and math.isfinite(number) and number == int(number) else number
            except ValueError:
                pass
    elif isinstance(text, str) and kind.scalar is Path:
        value = Path(text)
    elif kind.literal and isinstance(text, str) and kind.scalar is not str:
        value = kind.scalar(text)
    if kind.scalar in (int, float) and (s.lo is not None or s.hi is not None):
        lo = -math.inf if s.lo is None else s.lo
        hi = math.inf if s.hi is None else s.hi
        try:
            value = check_number(option, value, lo, hi, integer=kind.scalar is int, lo_open=s.lo_open)
        except ConfigError as exc:
            raise ConfigError(option, value, s.allowed or exc.allowed) from None
    elif kind.scalar in (int, float) and (isinstance(value, str) or (kind.scalar is int and isinstance(value, float))):
        raise ConfigError(option, value, s.allowed or ("an integer" if kind.scalar is int else "a number"))
    return value


def _value(option: str, raw: Any, kind: _Kind, s: Spec) -> Any:
    if raw is None:
        return None
    if kind.width and kind.many:
        value: Any = [tuple(_convert(option, x, kind, s) for x in group) for group in raw]
    elif kind.width:
        value = tuple(_convert(option, x, kind, s) for x in raw)
    elif kind.many:
        value = [_convert(option, x, kind, s) for x in raw]
    else:
        value = _convert(option, raw, kind, s)
    return s.check(option, value) if s.check is not None else value


def parse_given(cls: type, argv: Sequence[str] | None = None, prog: str = "", doc: str | None = None,
                epilog: bool | str = False) -> tuple[Any, set[str]]:
    """``cls`` from the command line ``argv`` (None: ``sys.argv[1:]``) and the names of the fields given
    on it. Every value is converted and checked here; a bad one exits (status 2) with one line."""
    parser = build_parser(cls, prog, doc, epilog)
    ns = parser.parse_args(None if argv is None else list(argv))
    hints = _hints(cls)
    values: dict[str, Any] = {}
    try:
        for f in dataclasses.fields(cls):
            if f.name in vars(ns):
                s = _spec(f)
                option = f.name if s.positional else (s.flag or "--" + f.name.replace("_", "-"))
                values[f.name] = _value(option, getattr(ns, f.name), _kind(hints[f.name]), s)
        out = cls(**values)
    except ConfigError as exc:
        parser.error(str(exc))
    given = {f.name for f in dataclasses.fields(cls) if f.name in vars(ns) and not _spec(f).positional}
    return out, given


def check_fields(obj: Any) -> Any:
    """``obj`` (a dataclass instance built in Python, not from a command line) when every field declared
    with a range, choices or a check (:func:`arg`) holds an allowed value; else the ConfigError naming
    the option that the command line would have given."""
    hints = _hints(type(obj))
    for f in dataclasses.fields(obj):
        s, value = _spec(f), getattr(obj, f.name)
        if not f.init or value is None or s.switches is not None:
            continue
        kind = _kind(hints[f.name])
        option = f.name if s.positional else (s.flag or "--" + f.name.replace("_", "-"))
        choices = s.choices() if callable(s.choices) else s.choices
        choices = tuple(choices) if choices is not None else (kind.literal or None)
        if kind.width:
            items = [x for group in (value if kind.many else [value]) for x in group]
        else:
            items = list(value) if kind.many else [value]
        for item in items:
            if choices is not None and item not in choices:
                raise ConfigError(option, item, f"one of {list(choices)}")
        _value(option, value, kind, s)
    return obj


def parse(cls: type, argv: Sequence[str] | None = None, prog: str = "", doc: str | None = None,
          epilog: bool | str = False) -> Any:
    """``cls`` from the command line (:func:`parse_given` without the names given)."""
    return parse_given(cls, argv, prog, doc, epilog)[0]
