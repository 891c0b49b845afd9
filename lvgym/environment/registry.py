"""Environment models chosen by name in configuration.

Each model class registers itself under a kind (``"gravity"``, ``"atmosphere"``, ``"wind"``,
``"aerodynamics"``) and a name (``"us76"``). :func:`make` builds one from a name or from a mapping such
as ``{"model": "exponential", "scale_height": 7200.0}``; unknown names and unknown options raise
:class:`lvgym.errors.ConfigError` naming the key, the value and what is allowed.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

from lvgym.errors import MISSING, ConfigError

T = TypeVar("T")

_REGISTRY: dict[str, dict[str, type]] = {}


def register(kind: str, name: str) -> Callable[[type[T]], type[T]]:
    """Class decorator: make ``cls`` buildable as ``make(kind, name)``."""

    def deco(cls: type[T]) -> type[T]:
        models = _REGISTRY.setdefault(kind, {})
        if name in models and models[name] is not cls:
            raise RuntimeError(f"{kind} model {name!r} registered twice")
        models[name] = cls
        return cls

    return deco


def names(kind: str) -> tuple[str, ...]:
    """Registered model names of ``kind``."""
    return tuple(sorted(_REGISTRY.get(kind, {})))


def make(kind: str, spec: str | Mapping[str, Any], *, key: str | None = None, **overrides: Any) -> Any:
    """Build the ``kind`` model named by ``spec``.

    ``spec`` is a name (``"us76"``) or a mapping with a ``"model"`` entry and the model's options.
    ``key`` is the configuration key path used in error messages (default: ``kind``).
    """
    key = key or kind
    if kind not in _REGISTRY:
        raise ConfigError("kind", kind, f"one of {names_of_kinds()}")
    if isinstance(spec, str):
        name, options = spec, {}
    elif isinstance(spec, Mapping):
        if "model" not in spec:
            raise ConfigError(f"{key}.model", MISSING, f"required; one of {list(names(kind))}")
        options = dict(spec)
        name = options.pop("model")
    else:
        raise ConfigError(key, spec, "a model name or a mapping with a 'model' entry")
    models = _REGISTRY[kind]
    if name not in models:
        raise ConfigError(f"{key}.model", name, f"one of {list(names(kind))}")
    options.update(overrides)
    cls = models[name]
    accepted, takes_any = _options(cls)
    for option in options:
        if option not in accepted and not takes_any:
            raise ConfigError(f"{key}.{option}", options[option],
                              f"unknown option of {kind} model {name!r}; allowed: {sorted(accepted)}")
    try:
        return cls(**options)
    except ConfigError as err:  # models name their options "<kind>.<option>": give the caller's key path
        if key == kind or not err.key.startswith(f"{kind}."):
            raise
        raise ConfigError(key + err.key[len(kind):], err.value, err.allowed, err.source) from None


@functools.lru_cache(maxsize=None)
def _options(cls: type) -> tuple[Any, bool]:
    """The parameters of ``cls``'s constructor and whether it takes any keyword (read once per class)."""
    accepted = inspect.signature(cls).parameters
    return accepted, any(p.kind is inspect.Parameter.VAR_KEYWORD for p in accepted.values())


def names_of_kinds() -> list[str]:
    """Kinds that have at least one registered model."""
    return sorted(_REGISTRY)
