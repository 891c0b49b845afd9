"""The policies the benchmark's command lines know by name (``evaluate.py``, ``lvgym margins``,
``... budget``) and how a name, a factory or a saved model's path becomes a :class:`~.runner.PolicySpec`.
The options those commands share are declared in the command layer (:mod:`lvgym.cli.flights`).

Policies register themselves: :func:`register_policy` (``lvgym.baselines`` and ``lvgym.agents`` call it
for their built-ins, a user for their own) and :func:`register_policy_loader` (how a saved model's file
or folder is flown: ``lvgym.agents`` registers stable-baselines3's ``.zip`` and ``train.py``'s run
folders). The command layer imports those packages to fill the registry; this module names no
controller module (the layers of docs/architecture.md: the benchmark sits below the controllers and the
agents). A spec holds its factory as a string; the factory is imported in the worker that flies it.

``--policies`` takes, in :func:`resolve_policy`'s order: a registered name; ``module:factory`` (an
importable module, or one beside the working folder); ``path/to/file.py:factory`` (a Python file, loaded
by path under a private name in every worker: no ``__main__`` guard needed); a saved model a loader
takes. Any of them may be prefixed with ``label=`` to name it in the results; a factory's policy is
otherwise labelled by its own ``name`` where that is known without an env (a class's ``name``, or what a
factory without parameters returns), else by the file's stem or the module's last name.
"""

from __future__ import annotations

import inspect
import os
import re
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib.machinery import PathFinder
from pathlib import Path
from typing import Any

from lvgym.errors import ConfigError, did_you_mean

from .factory import callable_reference, is_file_reference, load_factory, module_root
from .runner import ZERO, PolicySpec

__all__ = ["LOADERS", "POLICIES", "PolicyLoader", "register_policy", "register_policy_loader", "resolve_policy"]

#: policy names -> how a worker builds them (filled by :func:`register_policy`; the benchmark's own: zero)
POLICIES: dict[str, PolicySpec] = {"zero": ZERO}


def _reference(factory: str | Callable[..., Any]) -> str:
    if isinstance(factory, str):
        if ":" not in factory:
            raise ValueError(f"factory {factory!r}: 'module:function' or a module-level callable")
        return factory
    return callable_reference(factory)


def register_policy(name: str, factory: str | Callable[..., Any], /, **kwargs: Any) -> PolicySpec:
    """Make ``name`` a policy of the benchmark: a worker builds it as ``factory(**kwargs)`` (plus
    ``env=<the condition's env>`` when the factory takes ``env``). ``factory``: a ``"module:function"``
    string (imported only where the policy flies) or a module-level callable; ``kwargs`` must pickle.
    Registering a name again with the same factory and kwargs does nothing; with another, a
    :class:`~lvgym.errors.ConfigError` names the name. Returns the spec."""
    if not isinstance(name, str) or not re.fullmatch(r"[\w.+-]+", name):
        raise ConfigError("policy name", name, "letters, digits, '_', '-', '.', '+' (it labels results)")
    spec = PolicySpec(name, _reference(factory), tuple(sorted(kwargs.items())))
    old = POLICIES.get(name)
    if old is not None and old != spec:
        raise ConfigError("policy", name, f"registered already as {old.factory} with {dict(old.kwargs)}; "
                                          "pick another name")
    POLICIES[name] = spec
    return spec


@dataclass(frozen=True)
class PolicyLoader:
    """How a saved policy on disk is flown: ``factory(path=<absolute path>)``; it takes files ending in
    one of ``suffixes`` and, with ``folders``, folders. ``description`` says what in an error message.
    ``describe`` (optional, ``"module:function"``): ``function(path=<absolute path>)`` is called in the main
    process when a command resolves the path; it returns one line naming what flies (printed on stderr; ``""``:
    nothing to say) or raises a ``ValueError`` or ``OSError`` whose message refuses the policy in one line."""

    factory: str
    suffixes: tuple[str, ...]
    folders: bool
    description: str
    describe: str = ""

    def takes(self, path: Path) -> bool:
        """Whether this loader flies the existing file or folder ``path``."""
        return (self.folders and path.is_dir()) or (path.is_file() and path.suffix in self.suffixes)


#: the loaders of saved policies, in the order they are tried (filled by :func:`register_policy_loader`)
LOADERS: list[PolicyLoader] = []


def register_policy_loader(factory: str | Callable[..., Any], suffixes: Sequence[str] = (), folders: bool = False,
                           description: str = "", describe: str | Callable[..., Any] | None = None) -> PolicyLoader:
    """Fly a saved policy (a file ending in one of ``suffixes``, or with ``folders`` a folder) given by its
    path in ``--policies``: the spec calls ``factory(path=<absolute path>)`` and is labelled by the file's
    stem or the folder's name; ``describe`` names what flies, or refuses it, when the path is resolved
    (:class:`PolicyLoader`). Idempotent for the same loader."""
    loader = PolicyLoader(_reference(factory), tuple(suffixes), bool(folders),
                          description or f"a file {'/'.join(suffixes)}", _reference(describe) if describe else "")
    if loader not in LOADERS:
        LOADERS.append(loader)
    return loader


_LABEL = re.compile(r"^(?P<label>[\w.+-]+)=(?P<ref>.+)$")


def _describe(loader: PolicyLoader, path: Path, text: str, prog: str) -> None:
    """The loader's line on what ``path`` flies, on stderr; its refusal as a one-line exit."""
    if not loader.describe:
        return
    try:
        note = load_factory(loader.describe)(path=str(path.resolve()))
    except (ImportError, ValueError, OSError) as exc:
        raise SystemExit(f"{prog}: policy {text!r}: {exc}")
    if note:
        print(f"{prog}: policy {text!r} flies {note}", file=sys.stderr)


def _forms() -> str:
    saved = ", ".join(loader.description for loader in LOADERS)
    return f"a registered name, module:factory, path/to/file.py:factory{', ' + saved if saved else ''}"


def _factory_spec(text: str, label: str, prog: str) -> PolicySpec:
    """The spec of ``module:factory`` or ``path/to/file.py:factory``, its factory imported here (in the
    main process) so that a missing module or a broken file fails before any episode."""
    if is_file_reference(text):
        file, _, attr = text.rpartition(":")
        path = Path(file).expanduser().resolve()
        if not path.is_file():
            raise SystemExit(f"{prog}: policy {text!r}: no such file {str(path)!r}")
        spec = PolicySpec(label or path.stem, f"{path}:{attr}")
    else:
        module, _, attr = text.partition(":")
        try:
            root = module_root(module)                      # where this process finds it ...
        except (ImportError, ValueError):
            root = ""
        if not root and PathFinder.find_spec(module.partition(".")[0], [os.getcwd()]) is not None:
            root = os.getcwd()                              # ... or beside the working folder
        # carried to the workers: Ray's do not share this process's sys.path
        spec = PolicySpec(label or module.rpartition(".")[2], text, (), root)
    try:
        factory = load_factory(spec.factory, spec.path)
    except ImportError as exc:
        raise SystemExit(f"{prog}: policy {text!r}: {exc}")
    if not callable(factory):
        raise SystemExit(f"{prog}: policy {text!r}: {attr!r} is a {type(factory).__name__}, not a callable factory")
    own = "" if label else _own_name(factory, text, prog)
    return PolicySpec(own, spec.factory, spec.kwargs, spec.path) if own else spec


def _own_name(factory: Callable[..., Any], text: str, prog: str) -> str:
    """The policy's own ``name`` where it is known without an env (it then labels the results): a class's
    ``name`` attribute, or the ``name`` of what a factory without parameters returns (called here, so that
    one that raises fails before any episode). ``""`` for a factory of the env."""
    if isinstance(factory, type):
        name = getattr(factory, "name", "")
        return name if isinstance(name, str) else ""
    try:
        params = inspect.signature(factory).parameters.values()
    except (TypeError, ValueError):
        return ""
    if any(p.name == "env" or (p.default is p.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD))
           for p in params):
        return ""
    try:
        policy = factory()
    except Exception as exc:  # noqa: BLE001  (the user's factory: its error, in one line)
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise SystemExit(f"{prog}: policy {text!r}: its factory raised {type(exc).__name__}{': ' + first if first else ''}")
    name = getattr(policy, "name", "")
    return name if isinstance(name, str) else ""


def resolve_policy(name: str, prog: str = "evaluate.py") -> PolicySpec:
    """The :class:`PolicySpec` of ``name``: a registered name, ``module:factory``, ``path/to/file.py:factory``
    or a saved policy a loader takes (:data:`LOADERS`: a stable-baselines3 ``.zip``, a ``train.py`` run
    folder once ``lvgym.agents`` is imported), optionally ``label=...``. Checks here, in the main process,
    that the factory imports, so a missing package or a broken file fails before any episode runs; a bad
    value exits with a one-line message starting ``prog:``."""
    m = None if name in POLICIES or Path(name).exists() else _LABEL.match(name)
    label, text = (m["label"], m["ref"]) if m else ("", name)
    if text in POLICIES:
        spec = POLICIES[text]
        try:
            spec.resolve()
        except ImportError as exc:
            module = spec.factory.partition(":")[0]
            raise SystemExit(f"{prog}: policy {text!r} needs {spec.factory} (the {module.split('.')[0]} "
                             f"package), which is not available: {exc}")
        return PolicySpec(label, spec.factory, spec.kwargs, spec.path) if label else spec
    path = Path(text)
    if ":" in text and not path.exists():
        return _factory_spec(text, label, prog)
    if path.exists() or any(path.suffix in loader.suffixes for loader in LOADERS):
        if not path.exists():
            raise SystemExit(f"{prog}: policy {text!r}: no such file")
        for loader in LOADERS:
            if loader.takes(path):
                _describe(loader, path, text, prog)
                return PolicySpec(label or (path.name if path.is_dir() else path.stem), loader.factory,
                                  (("path", str(path.resolve())),))
        raise SystemExit(f"{prog}: policy {text!r}: not a saved policy a loader takes; a policy is {_forms()}")
    raise SystemExit(f"{prog}: policy {text!r}{did_you_mean(text, POLICIES)}: not {_forms()}; the registered "
                     f"names: {sorted(POLICIES)}")
