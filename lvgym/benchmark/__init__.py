"""The frozen benchmark protocol: named suites of conditions with fixed seeds, metrics, and the runner."""

from .policy import Policy, ZeroPolicy

__all__ = ["Policy", "ZeroPolicy"]
