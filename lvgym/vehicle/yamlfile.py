"""Strict reading of a YAML configuration file: every problem is a :class:`~lvgym.errors.ConfigError`
naming the file and the line.

:func:`read_yaml` loads with PyYAML's safe loader (plain data only: no Python objects; libyaml's C parser
when PyYAML has it, ten times faster than the Python one on the vehicle files' flow-style tables), and
refuses

- a syntax error (with the line and column where the parser stopped);
- a tag the safe loader has no constructor for (``!!python/object:...``, ``!include``, ...);
- a key given twice in one mapping (PyYAML silently keeps the last one);
- a key that is not a plain scalar (a list or mapping as a key).

It also returns the line of every key path (``stages[0].tanks[1].fill_ratio`` -> 42), so that errors
found later, on the parsed values, can name the line too (:func:`with_line`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from lvgym.errors import ConfigError

__all__ = ["StrictLoader", "read_yaml", "with_line"]


class StrictLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """PyYAML's ``CSafeLoader`` (``SafeLoader`` without libyaml); :func:`read_yaml` walks its node tree
    before constructing values."""


def _walk(node: yaml.Node, path: str, source: str, lines: dict[str, int], loader: StrictLoader) -> None:
    if node.tag not in loader.yaml_constructors:
        raise ConfigError(path or "<top>", node.tag, "plain YAML data only (numbers, strings, lists, mappings): "
                          "tags such as '!!python/object' are not read", source, node.start_mark.line + 1)
    if isinstance(node, yaml.MappingNode):
        loader.flatten_mapping(node)                    # merge keys (<<: *anchor) as the safe loader does
        seen: dict[Any, int] = {}
        for key_node, value_node in node.value:
            line = key_node.start_mark.line + 1
            if not isinstance(key_node, yaml.ScalarNode):
                raise ConfigError(path or "<top>", f"a {key_node.id} as a key", "keys are plain names", source, line)
            key = loader.construct_object(key_node)
            sub = f"{path}.{key}" if path else str(key)
            if key in seen:
                raise ConfigError(sub, key_node.value, f"each key once per mapping: {key_node.value!r} is also "
                                  f"given at line {seen[key]}", source, line)
            seen[key] = line
            lines[sub] = line
            _walk(value_node, sub, source, lines, loader)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            sub = f"{path}[{i}]"
            lines[sub] = item.start_mark.line + 1
            _walk(item, sub, source, lines, loader)


def read_yaml(path: str | Path, source: str | None = None, text: str | None = None) -> tuple[Any, dict[str, int]]:
    """The data of the YAML file ``path`` and the line (1-based) of every key path in it.

    ``source``: the file's name in errors (default: ``path``); ``text``: the file's text when the caller
    has read it already. A file that does not exist or cannot be read, a syntax error, an unsafe tag or a
    duplicate key raise :class:`ConfigError` naming the file (and the line)."""
    src = source or str(path)
    try:
        if text is None:
            text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError("file", str(path), "an existing YAML file (there is no such file)", src) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError("file", str(path), f"a readable UTF-8 YAML file ({exc})", src) from None
    loader = StrictLoader(text)
    lines: dict[str, int] = {}
    try:
        node = loader.get_single_node()
        if node is None:
            return None, lines
        _walk(node, "", src, lines, loader)
        return loader.construct_document(node), lines
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        where = f" at column {mark.column + 1}" if mark is not None else ""
        ctx = exc.context_mark
        if ctx is not None and mark is not None and ctx.line != mark.line:
            where += f"; what it was reading began at line {ctx.line + 1}"
        problem = " ".join(str(p) for p in (exc.context, exc.problem) if p)
        raise ConfigError("yaml", problem, f"valid YAML syntax (the parser stopped{where}; check the indentation "
                          "and the ': ' after each key)", src, line) from None
    except yaml.YAMLError as exc:
        raise ConfigError("yaml", str(exc), "valid YAML", src) from None
    finally:
        loader.dispose()


def with_line(exc: ConfigError, lines: dict[str, int]) -> ConfigError:
    """``exc`` with the line of its key path (or of the nearest enclosing key found in ``lines``)."""
    if exc.line is not None:
        return exc
    key = exc.key
    while key:
        if key in lines:
            return ConfigError(exc.key, exc.value, exc.allowed, exc.source, lines[key])
        cut = max(key.rfind("."), key.rfind("["))
        key = key[:cut] if cut > 0 else ""
    return exc
