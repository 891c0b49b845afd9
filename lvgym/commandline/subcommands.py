"""The subcommands of a console script: :class:`Command` declares one (or a group of them), :func:`dispatch`
runs the one the command line names, under the name ``prog <command>`` (:func:`~.messages.running_as`)."""

from __future__ import annotations

import dataclasses
import difflib
import importlib
import importlib.util
import sys
from collections.abc import Sequence
from typing import Any, NoReturn

from .messages import fail, running_as

__all__ = ["Command", "command_help", "dispatch"]


@dataclasses.dataclass(frozen=True)
class Command:
    """A subcommand of :func:`dispatch`: its name, ``target`` (``"module:function"``, called with the rest
    of the command line; None for a group only), a one-line help, the extra that installs what it needs
    (``needs``: top-level modules, looked for before the command's module is imported) and, for a group,
    its subcommands (a group with a target runs it when no subcommand is named)."""

    name: str
    target: str | None
    help: str
    extra: str | None = None
    needs: tuple[str, ...] = ()
    sub: tuple[Command, ...] = ()


def _listing(commands: Sequence[Command], prefix: str = "") -> list[tuple[str, str]]:
    rows = []
    for c in commands:
        if c.target is not None or not c.sub:
            rows.append((prefix + c.name, c.help))
        rows += _listing(c.sub, f"{prefix}{c.name} ")
    return rows


def command_help(commands: Sequence[Command], prog: str, description: str = "") -> str:
    """The help of a command group: usage, ``description`` and one line per command."""
    rows = _listing(commands)
    width = max(len(n) for n, _ in rows) + 2
    lines = [f"usage: {prog} <command> [options]   ({prog} <command> --help: its options)", ""]
    lines += [description, ""] if description else []
    lines += ["commands:"] + [f"  {n.ljust(width)}{h}" for n, h in rows]
    return "\n".join(lines) + "\n"


def _usage_error(prog: str, message: str) -> NoReturn:
    sys.stderr.write(f"{prog}: error: {message} (see {prog} --help)\n")
    raise SystemExit(2)


def dispatch(commands: Sequence[Command], argv: Sequence[str] | None, prog: str, description: str = "",
             own: Command | None = None) -> Any:
    """Run the subcommand named by ``argv[0]`` with the rest of ``argv`` (under the name ``prog <name>``,
    :func:`running_as`); returns what it returns. ``--help`` (or nothing) lists the commands; an unknown
    one is refused with the nearest names; a command whose extra is not installed is refused in one line
    naming it. ``own``: the group these commands belong to (run when ``argv`` names no subcommand)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    names = {c.name: c for c in commands}
    if own is not None and own.target is not None and (not argv or argv[0] not in names):
        return _run(own, argv, prog)
    if not argv or argv[0] in ("-h", "--help"):
        sys.stdout.write(command_help(commands, prog, description))
        return 0
    cmd = names.get(argv[0])
    if cmd is None:
        near = difflib.get_close_matches(argv[0], list(names), n=3, cutoff=0.5)
        tip = f"; did you mean {' or '.join(near)}?" if near else f"; one of {', '.join(names)}"
        _usage_error(prog, f"unknown command {argv[0]!r}{tip}")
    if cmd.sub:
        return dispatch(cmd.sub, argv[1:], f"{prog} {cmd.name}", cmd.help, own=cmd)
    return _run(cmd, argv[1:], f"{prog} {cmd.name}")


def _run(cmd: Command, argv: list[str], prog: str) -> Any:
    missing = [m for m in cmd.needs if importlib.util.find_spec(m) is None]
    if missing:
        extra = f"pip install 'lvgym[{cmd.extra}]'" if cmd.extra else "install it"
        fail(prog, f"needs {', '.join(missing)}, which {'is' if len(missing) == 1 else 'are'} not installed: {extra}")
    assert cmd.target is not None
    module, _, function = cmd.target.partition(":")
    with running_as(prog):
        return getattr(importlib.import_module(module), function or "main")(argv)
