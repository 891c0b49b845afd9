"""The one error type of lvgym's configuration: it names where, what and what is allowed.

Every layer that reads user values (vehicle YAML files, environment model options, env kwargs) raises
:class:`ConfigError`, so a user always sees the file, the key path, the offending value and the
allowed range in one line, e.g.::

    lvgym/vehicles/smile.yaml: stages[0].tanks[1].fill_ratio = 1.3: must be in [0, 1]
"""

from __future__ import annotations

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
    """

    def __init__(self, key: str, value: Any, allowed: str, source: str | None = None):
        self.key = key
        self.value = value
        self.allowed = allowed
        self.source = source
        where = f"{source}: " if source else ""
        shown = "<missing>" if value is MISSING else repr(value)
        super().__init__(f"{where}{key} = {shown}: {allowed}")


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


#: marker for a required key that is absent
MISSING = _Missing()


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


def check_bool(key: str, value: Any, source: str | None = None) -> bool:
    """``value`` when it is a bool; else a :class:`ConfigError` naming ``key``."""
    if not isinstance(value, bool):
        raise ConfigError(key, value, "true or false", source)
    return value
