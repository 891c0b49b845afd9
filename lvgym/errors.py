"""The one error type of lvgym's configuration: it names where, what and what is allowed.

Every layer that reads user values (vehicle YAML files, environment model options, env kwargs) raises
:class:`ConfigError`, so a user always sees the file, the key path, the offending value and the
allowed range in one line, e.g.::

    lvgym/vehicles/smile.yaml: stages[0].tanks[1].fill_ratio = 1.3: must be in [0, 1]
"""

from __future__ import annotations

import importlib.util
from typing import Any


class ConfigError(ValueError):
    """A configuration value that is missing, unknown or out of range.

    Parameters
    ----------
    key:
        Dotted key path, e.g. ``"stages[0].tanks[1].fill_ratio"`` or ``"atmosphere.model"``.
    value:
        The offending value (``MISSING`` for a missing key).
    allowed:
        What is allowed, in words, e.g. ``"must be in [0, 1]"`` or ``"one of 'us76', 'exponential'"``.
    source:
        The file (or other origin) the value came from, if any.
    line:
        The line of ``source`` (1-based) where the key is, if known.
    """

    def __init__(self, key: str, value: Any, allowed: str, source: str | None = None, line: int | None = None):
        self.key = key
        self.value = value
        self.allowed = allowed
        self.source = source
        self.line = line
        at = f"line {line}" if line is not None else ""
        where = f"{source}, {at}: " if source and at else f"{source or at}: " if source or at else ""
        shown = "<missing>" if value is MISSING else repr(value)
        super().__init__(f"{where}{key} = {shown}: {allowed}")

    def __reduce__(self) -> tuple:
        # pickle by the four fields (an exception pickles its ``args``, here the one message, and the
        # constructor wants four): a ConfigError raised in a worker process reaches the parent intact.
        # A value that does not pickle travels as its repr.
        import pickle

        value = self.value
        try:
            pickle.dumps(value)
        except Exception:  # noqa: BLE001
            value = _Shown(repr(value))
        return (type(self), (self.key, value, self.allowed, self.source, self.line), self.__dict__ | {"value": value})


class _Shown:
    """Stands in for a value that does not pickle: shows as the original's repr."""

    def __init__(self, text: str) -> None:
        self.text = text

    def __repr__(self) -> str:
        return self.text


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"

    def __reduce__(self) -> str:
        return "MISSING"                              # unpickles as the one marker (``value is MISSING``)


#: marker for a required key that is absent
MISSING = _Missing()


def require(package: str, extra: str, feature: str) -> None:
    """Check that ``package`` (an import name, e.g. ``"matplotlib"``), which ``feature`` needs and lvgym's
    core install leaves out, is installed; if not, raise ``ModuleNotFoundError`` in one line naming the
    extra that installs it, e.g. ``Recorder.plot needs matplotlib: pip install 'lvgym[studies]'``."""
    if importlib.util.find_spec(package) is None:
        raise ModuleNotFoundError(f"{feature} needs {package}, which lvgym's core install leaves out: "
                                  f"pip install 'lvgym[{extra}]'", name=package)


# ---------------------------------------------------------------------------- validators
def check_number(key: str, value: Any, lo: float, hi: float, *, integer: bool = False, lo_open: bool = False,
                 source: str | None = None) -> Any:
    """``value`` as a float (an int with ``integer``) when it is a number (not a bool) in ``[lo, hi]``
    (``(lo, hi]`` with ``lo_open``); else a :class:`ConfigError` naming ``key``."""
    ok_type = isinstance(value, int) if integer else isinstance(value, (int, float))
    if not ok_type or isinstance(value, bool) or not ((value > lo if lo_open else value >= lo) and value <= hi):
        kind = "an integer" if integer else "a number"
        raise ConfigError(key, value, f"{kind} in {'(' if lo_open else '['}{lo}, {hi}]", source)
    return int(value) if integer else float(value)


def check_choice(key: str, value: Any, allowed: tuple[str, ...], source: str | None = None) -> str:
    """``value`` when it is one of ``allowed``; else a :class:`ConfigError` naming ``key``."""
    if value not in allowed:
        raise ConfigError(key, value, f"one of {allowed}", source)
    return str(value)


def did_you_mean(value: Any, choices: Any) -> str:
    """`` (did you mean 'x'?)`` naming the closest of ``choices`` to ``value`` (:func:`difflib.get_close_matches`),
    or ``""`` when none is close: the hint a one-line error appends after what is allowed."""
    import difflib

    if not isinstance(value, str):
        return ""
    close = difflib.get_close_matches(value, [str(c) for c in choices], n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check_bool(key: str, value: Any, source: str | None = None) -> bool:
    """``value`` when it is a bool; else a :class:`ConfigError` naming ``key``."""
    if not isinstance(value, bool):
        raise ConfigError(key, value, "true or false", source)
    return value
