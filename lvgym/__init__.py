"""lvgym: a Gymnasium benchmark for thrust-vector control of flexible, sloshing launch vehicles."""

__version__ = "0.1.0"
