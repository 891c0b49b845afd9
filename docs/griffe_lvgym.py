"""A griffe extension for the API reference (mkdocstrings, ``mkdocs.yml``).

- The wheel installs ``agents/`` as ``lvgym.agents`` and ``baselines/`` as ``lvgym.baselines``
  (setuptools ``package-dir``). griffe reads packages from folders, so it would find them as top-level
  ``agents`` and ``baselines``: once ``lvgym`` is loaded, they are loaded and attached under it, and their
  objects get their installed names (``lvgym.baselines.pid.PIDPolicy``).
- The docstrings are written for Sphinx: ``:class:`~.spec.TaskSpec``` and the other roles become code
  spans of the name (``TaskSpec``), which Markdown shows as code instead of the role's raw text.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

#: folder (a top-level package to griffe) -> its name under ``lvgym`` (pyproject.toml's package-dir)
PACKAGE_DIRS = {"agents": "agents", "baselines": "baselines"}

_ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|data|mod|obj|exc|const):`~?\.*([^`]+)`")


def _role_to_code(match: re.Match) -> str:
    target = match.group(1)
    if "<" in target and target.endswith(">"):          # :class:`title <target>`
        return f"``{target.split('<', 1)[0].strip()}``"
    return f"``{target.rsplit('.', 1)[-1] if match.group(0).count('~') else target}``"


class LvgymDocs(griffe.Extension):
    """Attach the package-dir packages under ``lvgym`` and turn Sphinx roles into code spans."""

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        if pkg.name != "lvgym":
            return
        for folder, name in PACKAGE_DIRS.items():
            if name not in pkg.members:
                pkg.set_member(name, loader.load(folder, try_relative_path=False))

    def on_object(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = _ROLE.sub(_role_to_code, obj.docstring.value)

    def on_module(self, *, mod: griffe.Module, **kwargs: Any) -> None:
        self.on_object(obj=mod)
