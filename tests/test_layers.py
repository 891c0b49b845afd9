"""DESIGN.md layers: nothing imports upward.

The dynamics core imports neither gymnasium nor the environment models nor the vehicle layer; the
environment models and the vehicle layer are independent of each other and of everything above them; the
simulator imports no gymnasium. Checked on the import statements of every module of a layer, followed
through the lvgym modules they import (the package root only registers env names with Gymnasium).
"""

import ast
import importlib.util
import pkgutil
from pathlib import Path

import pytest

import lvgym

ON_TOP = ("lvgym.agents", "lvgym.baselines", "baselines_pid", "experiments")   # controllers and agents on top
ABOVE_ALL = ("gymnasium", "stable_baselines3", "torch", "lvgym.envs", "lvgym.simulator", "lvgym.benchmark") + ON_TOP

FORBIDDEN = {
    "lvgym.dynamics": ABOVE_ALL + ("lvgym.environment", "lvgym.vehicle"),
    "lvgym.environment": ABOVE_ALL + ("lvgym.dynamics", "lvgym.vehicle"),
    "lvgym.vehicle": ABOVE_ALL + ("lvgym.dynamics", "lvgym.environment"),
    "lvgym.simulator": ("gymnasium", "stable_baselines3", "torch", "lvgym.envs", "lvgym.benchmark") + ON_TOP,
    "lvgym.envs": ("stable_baselines3.common.policies", "torch", "lvgym.benchmark") + ON_TOP,
    "lvgym.benchmark": ("torch",) + ON_TOP,
}
ROOT = Path(lvgym.__file__).parent


def _imports(module: str) -> set[str]:
    """Absolute names imported by the source of ``module``."""
    spec = importlib.util.find_spec(module)
    tree = ast.parse(Path(spec.origin).read_text(encoding="utf-8"))
    package = module if spec.origin.endswith("__init__.py") else module.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            out.add(base)
            out |= {f"{base}.{a.name}" for a in node.names if importlib.util.find_spec(base) is not None
                    and _is_module(f"{base}.{a.name}")}
    return out


def _is_module(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _closure(package: str) -> set[str]:
    pkg = importlib.import_module(package)
    todo = [package] + [m.name for m in pkgutil.walk_packages(pkg.__path__, package + ".")]
    seen: set[str] = set()
    names: set[str] = set()
    while todo:
        m = todo.pop()
        if m in seen or m == "lvgym":
            continue
        seen.add(m)
        for name in _imports(m):
            names.add(name)
            if name.startswith("lvgym.") and _is_module(name):
                todo.append(name)
    return names


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_layer_imports_nothing_above_it(package):
    bad = sorted(n for n in _closure(package) if n.startswith(FORBIDDEN[package]))
    assert not bad, f"{package} reaches {bad}"


def test_the_check_sees_an_upward_import():
    assert any(n.startswith("lvgym.simulator") for n in _closure("lvgym.envs"))
    assert "gymnasium" in _closure("lvgym.envs")


#: the installed packages (pyproject.toml's package-dir: agents/ is lvgym.agents, baselines/ lvgym.baselines)
INSTALLED = ("lvgym", "lvgym.agents", "lvgym.baselines")
_LOADERS = {"import_module", "__import__", "run_module", "find_spec"}


def _installed_modules() -> list[str]:
    names: set[str] = set()
    for package in INSTALLED:
        pkg = importlib.import_module(package)
        names |= {package} | {m.name for m in pkgutil.walk_packages(pkg.__path__, package + ".")}
    return sorted(names)


def _loads_by_name(module: str) -> set[str]:
    """Module names ``module`` imports by a string (``importlib.import_module("x")``, ``__import__``,
    ``runpy.run_module``, ``find_spec``)."""
    tree = ast.parse(Path(importlib.util.find_spec(module).origin).read_text(encoding="utf-8"))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            if name in _LOADERS and isinstance(node.args[0].value, str):
                out.add(node.args[0].value)
    return out


def _experiments(names: set[str]) -> list[str]:
    return sorted(n for n in names if n == "experiments" or n.startswith("experiments."))


def test_nothing_installed_imports_the_experiments():
    """experiments/ (the one-off studies) is not installed: no module of lvgym, lvgym.agents or
    lvgym.baselines imports it, by an import statement or by name."""
    modules = _installed_modules()
    assert {"lvgym.cli", "lvgym.agents.policy", "lvgym.baselines.pid", "lvgym.baselines.design.tune"} <= set(modules)
    found = {m: _experiments(_imports(m) | _loads_by_name(m)) for m in modules}
    bad = {m: names for m, names in found.items() if names}
    assert not bad, f"installed modules import experiments/: {bad}"
    # the checks see such imports: a study's __main__ imports its module, another study loads sys by name
    assert "experiments.error_budget.budget" in _imports("experiments.error_budget.budget")
    assert _loads_by_name("experiments.aeroelastic_divergence.structural_limit") == {"sys"}
