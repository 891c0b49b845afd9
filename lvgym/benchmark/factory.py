"""Policy factories by reference: how a string that names a factory becomes the function, in any process.

A reference is ``"package.module:function"`` (an importable module) or ``"/abs/path/file.py:function"`` (a
Python file). A file is loaded by its path under a private module name (``_lvgym_policy_<stem>_<hash>``,
kept in ``sys.modules``), never as ``__main__``: a user's file needs no ``if __name__ == "__main__"``
guard, and the spawned pool workers and Ray's workers load it the same way from its path. Its folder is
appended to ``sys.path`` (after everything else: a sibling module of the file imports, the benchmark's own
modules are never shadowed). ``path`` (optional) is a folder appended to ``sys.path`` before a module is
imported: where a module found beside the user's working folder lives, for workers that do not share the
main process's ``sys.path`` (Ray's).
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import re
import sys
from pathlib import Path
from typing import Any

__all__ = ["FactoryError", "callable_reference", "is_file_reference", "load_factory", "module_root"]


class FactoryError(ImportError):
    """A reference that does not give a callable: no such module, file or attribute, or the module's own
    code raised while it was imported (the message names the reference and the cause, in one line)."""


def is_file_reference(reference: str) -> bool:
    """Whether ``reference`` names a Python file (``path/to/file.py:function``)."""
    return reference.partition(":")[0].endswith(".py")


def _file_module_name(path: Path) -> str:
    stem = re.sub(r"\W", "_", path.stem)
    return f"_lvgym_policy_{stem}_{hashlib.sha1(str(path).encode()).hexdigest()[:10]}"


def _append_path(folder: str) -> None:
    if folder and folder not in sys.path:
        sys.path.append(folder)


def _import_file(path: Path) -> Any:
    """The module of the Python file ``path`` (loaded once per process under a private name)."""
    name = _file_module_name(path)
    if name in sys.modules:
        return sys.modules[name]
    if not path.is_file():
        raise FactoryError(f"{path}: no such file")
    _append_path(str(path.parent))
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module                      # before running it: dataclasses and pickle look it up
    try:
        spec.loader.exec_module(module)
    except (Exception, SystemExit) as exc:          # the file's own code raised (or exited)
        del sys.modules[name]
        raise FactoryError(f"importing {path} raised {_cause(exc)}") from exc
    return module


def _cause(exc: BaseException) -> str:
    """``Type: message`` of an exception, with the line of the user's code for a SyntaxError, one line."""
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def load_factory(reference: str, path: str = "") -> Any:
    """The object ``reference`` names (see the module docstring); a :class:`FactoryError` (an
    ``ImportError``) names what is missing or what the imported code raised."""
    target, sep, attr = reference.rpartition(":") if is_file_reference(reference) else reference.partition(":")
    if not sep or not target or not attr:
        raise FactoryError(f"{reference!r}: a factory is 'module:function' or 'path/to/file.py:function'")
    if target.endswith(".py"):
        module = _import_file(Path(target))
    else:
        _append_path(path)
        try:
            module = importlib.import_module(target)
        except ImportError as exc:
            raise FactoryError(f"cannot import {target!r} ({exc})") from exc
        except Exception as exc:  # noqa: BLE001  (the module's own code raised)
            raise FactoryError(f"importing {target!r} raised {_cause(exc)}") from exc
    obj: Any = module
    for part in attr.split("."):
        if not hasattr(obj, part):
            raise FactoryError(f"{target!r} has no {attr!r}")
        obj = getattr(obj, part)
    return obj


def callable_reference(factory: Any) -> str:
    """``"module:qualname"`` of a module-level callable, checked to import back as the same object (so a
    worker can import it); a ``ValueError`` otherwise (a lambda, a nested function, a function of
    ``__main__``)."""
    module, qualname = getattr(factory, "__module__", None), getattr(factory, "__qualname__", None)
    if not module or not qualname or "<" in qualname:
        raise ValueError(f"factory {factory!r}: a module-level function or class, or a 'module:function' string")
    if module == "__main__":
        raise ValueError(f"factory {qualname!r} is defined in __main__, which the workers cannot import: move it "
                         "to a module, or pass 'path/to/file.py:function'")
    reference = f"{module}:{qualname}"
    try:
        found = load_factory(reference)
    except ImportError:
        found = None
    if found is not factory:
        raise ValueError(f"factory {reference!r} does not import back as the object given")
    return reference


def module_root(module: str) -> str:
    """The ``sys.path`` folder module ``module`` was found under (``""`` for a built-in or namespace
    module): what a worker without this process's ``sys.path`` appends to import it."""
    spec = importlib.util.find_spec(module.partition(".")[0])
    if spec is None or not spec.origin or spec.origin in ("built-in", "frozen"):
        return ""
    origin = Path(spec.origin)
    return str(origin.parent.parent if spec.submodule_search_locations else origin.parent)
