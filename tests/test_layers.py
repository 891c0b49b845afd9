"""The layers of docs/architecture.md: nothing imports upward.

The dynamics core imports neither gymnasium nor the environment models nor the vehicle layer; the
environment models and the vehicle layer are independent of each other and of everything above them; the
simulator imports no gymnasium; the benchmark names no controller or agent; the thesis's studies and the
verification cases sit on the simulator (no envs, no benchmark); the modules beside the layers
(``lvgym.packing``, ``lvgym.errors``, ``lvgym.rotations``, ``lvgym.borrow``, ``lvgym.parallel``,
``lvgym.commandline``) import none of them; the package root reaches no controller, agent or command; and
nothing imports the command layer (``lvgym.cli``) but its own modules and the entry scripts
(``python -m lvgym``, ``evaluate.py``, ``train.py``). Checked on the import statements of every module of a
layer (function-level ones too), and on the import paths it writes as strings (a policy's factory
``"package.module:function"``, a module name handed to importlib), followed through the lvgym modules they
import (the package root only registers env names with Gymnasium: it is checked on its own, and not followed
from the others).

The policy registry's dependencies point the other way: ``lvgym.baselines`` and ``lvgym.agents`` register
their policies with the benchmark, and the command layer (``evaluate.py``, ``lvgym.cli.policies``) imports
every module that registers one.
"""

import ast
import importlib.util
import pkgutil
import re
from pathlib import Path

import pytest

import lvgym

ON_TOP = ("lvgym.agents", "lvgym.baselines", "baselines_pid", "experiments")   # controllers and agents on top
COMMANDS = ("lvgym.cli",)                                                        # the command layer, above all
TOOLS = ("lvgym.studies", "lvgym.verify", "lvgym.bench")       # the studies, verification, speed benchmarks
ABOVE_ALL = ("gymnasium", "stable_baselines3", "torch", "lvgym.envs", "lvgym.simulator", "lvgym.benchmark") + ON_TOP
#: the modules beside the layers import none of the layers (nor one another's upper neighbours: each is a
#: base any layer may use)
BESIDE = ABOVE_ALL + ("lvgym.dynamics", "lvgym.environment", "lvgym.vehicle") + TOOLS + COMMANDS

FORBIDDEN = {
    "lvgym.dynamics": ABOVE_ALL + ("lvgym.environment", "lvgym.vehicle") + TOOLS + COMMANDS,
    "lvgym.environment": ABOVE_ALL + ("lvgym.dynamics", "lvgym.vehicle") + TOOLS + COMMANDS,
    "lvgym.vehicle": ABOVE_ALL + ("lvgym.dynamics", "lvgym.environment") + TOOLS + COMMANDS,
    "lvgym.simulator": ("gymnasium", "stable_baselines3", "torch", "lvgym.envs", "lvgym.benchmark") + ON_TOP + TOOLS
    + COMMANDS,
    "lvgym.envs": ("stable_baselines3.common.policies", "torch", "lvgym.benchmark") + ON_TOP + TOOLS + COMMANDS,
    "lvgym.benchmark": ("torch",) + ON_TOP + TOOLS + COMMANDS,
    # the thesis's studies and the verification cases fly the simulator: no envs, no benchmark
    "lvgym.studies": ("gymnasium", "stable_baselines3", "torch", "lvgym.envs", "lvgym.benchmark", "lvgym.verify",
                      "lvgym.bench") + ON_TOP + COMMANDS,
    "lvgym.verify": ("gymnasium", "stable_baselines3", "torch", "lvgym.envs", "lvgym.benchmark", "lvgym.studies",
                     "lvgym.bench") + ON_TOP + COMMANDS,
    # the speed benchmarks: of the dynamics core (as the core itself), of the envs (as the envs)
    "lvgym.bench": ABOVE_ALL + ("lvgym.environment", "lvgym.vehicle", "lvgym.studies", "lvgym.verify") + COMMANDS,
    "lvgym.bench_envs": ("stable_baselines3.common.policies", "torch", "lvgym.benchmark", "lvgym.studies") + ON_TOP
    + COMMANDS,
    # beside the layers
    "lvgym.packing": BESIDE,
    "lvgym.errors": BESIDE,
    "lvgym.rotations": BESIDE,
    "lvgym.borrow": BESIDE,
    "lvgym.parallel": BESIDE,
    "lvgym.commandline": BESIDE,
    # the controllers, then the agents, on top of the benchmark
    "lvgym.baselines": ("lvgym.agents", "baselines_pid", "experiments") + TOOLS + COMMANDS,
    "lvgym.agents": ("baselines_pid", "experiments") + TOOLS + COMMANDS,
    # inside the agents: training on the wrappers on the policies (what flies in the benchmark imports neither)
    "lvgym.agents.policies": ("lvgym.agents.training", "lvgym.agents.wrappers", "baselines_pid", "experiments") + TOOLS
    + COMMANDS,
    "lvgym.agents.wrappers": ("lvgym.agents.training", "baselines_pid", "experiments") + TOOLS + COMMANDS,
    # the package root (env ids, make_env on the benchmark's suites) and the command layer on top
    "lvgym": ("torch",) + ON_TOP + COMMANDS,
    "lvgym.cli": ("baselines_pid", "experiments"),
}
#: what imports the command layer: its own modules and the entry scripts (``python -m lvgym``)
ENTRY = ("lvgym.__main__",)
ROOT = Path(lvgym.__file__).parent


#: a string that names a module (``"lvgym.baselines.pid"``) or a factory in one
#: (``"lvgym.agents.policies.sb3:load_policy"``)
#: (a dotted name or a factory: a bare word such as "experiments" may be a dict key)
IMPORT_PATH = re.compile(r"^(?P<module>(?:lvgym|baselines_pid|experiments|gymnasium|stable_baselines3|sb3_contrib|torch)"
                         r"(?:\.\w+)*)(?::[\w.]+)?$")


def _names_a_module(text: str) -> str:
    """The module an import-path string names (``""`` for other strings)."""
    m = IMPORT_PATH.match(text)
    return m["module"] if m and ("." in m["module"] or ":" in text) else ""


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the docstring nodes of a module, its classes and functions (prose, not import paths)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
                out.add(id(first.value))
    return out


def _source_imports(path: Path, package: str) -> set[str]:
    """Absolute names imported by the source file ``path`` of a module of ``package``, and the modules
    named by import-path strings in its code."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    prose = _docstrings(tree)
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
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in prose:
            if _names_a_module(node.value):
                out.add(_names_a_module(node.value))
    return out


def _imports(module: str) -> set[str]:
    """Absolute names imported by the source of ``module`` (statements and import-path strings)."""
    spec = importlib.util.find_spec(module)
    package = module if spec.origin.endswith("__init__.py") else module.rpartition(".")[0]
    return _source_imports(Path(spec.origin), package)


def _is_module(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _follow(todo: list[str], names: set[str]) -> set[str]:
    """``names`` with everything the lvgym modules of ``todo`` import, followed through lvgym modules."""
    seen: set[str] = set()
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


def _closure(package: str) -> set[str]:
    """What the modules of ``package`` (a package, a module, or the package root ``lvgym`` alone) import,
    followed through the lvgym modules."""
    if package == "lvgym":
        names = _imports("lvgym")
        return _follow([n for n in names if n.startswith("lvgym.") and _is_module(n)], set(names))
    pkg = importlib.import_module(package)
    if not hasattr(pkg, "__path__"):
        return _follow([package], set())
    return _follow([package] + [m.name for m in pkgutil.walk_packages(pkg.__path__, package + ".")], set())


def _registering_modules() -> set[str]:
    """The modules of lvgym that call ``register_policy`` or ``register_policy_loader`` (outside the
    registry itself)."""
    out = set()
    names = ["lvgym.baselines", "lvgym.agents"]
    for package in ("lvgym", "lvgym.baselines", "lvgym.agents"):     # the last two live in their own folders
        names += [m.name for m in pkgutil.walk_packages(importlib.import_module(package).__path__, package + ".")]
    for name in sorted(set(names)):
        if name.startswith("lvgym.benchmark"):
            continue
        spec = importlib.util.find_spec(name)
        tree = ast.parse(Path(spec.origin).read_text(encoding="utf-8"))
        if any(isinstance(n, ast.Call) and getattr(n.func, "id", getattr(n.func, "attr", None))
               in ("register_policy", "register_policy_loader") for n in ast.walk(tree)):
            out.add(name)
    return out


def _under(name: str, packages: tuple[str, ...]) -> bool:
    """Whether module ``name`` is one of ``packages`` or inside one (``lvgym.bench`` is not ``lvgym.benchmark``)."""
    return any(name == p or name.startswith(p + ".") for p in packages)


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_layer_imports_nothing_above_it(package):
    bad = sorted(n for n in _closure(package) if _under(n, FORBIDDEN[package]))
    assert not bad, f"{package} reaches {bad}"


def test_the_check_sees_an_upward_import():
    assert any(n.startswith("lvgym.simulator") for n in _closure("lvgym.envs"))
    assert "gymnasium" in _closure("lvgym.envs")
    assert "lvgym.commandline" in _closure("lvgym.vehicle")                 # beam's and slender's main
    assert "lvgym.benchmark.suites" in _closure("lvgym")                      # make_env
    assert "lvgym.envs.ascent" in _closure("lvgym")                           # the env ids' entry points
    assert {"lvgym.agents", "lvgym.baselines"} <= _closure("lvgym.cli")       # the policies command line
    # inside the agents: training reaches the wrappers and the policies, the wrappers the policies
    assert {"lvgym.agents.wrappers.residual", "lvgym.agents.policies.sb3"} <= _closure("lvgym.agents.training")
    assert "lvgym.agents.policies.residual" in _closure("lvgym.agents.wrappers")


def test_every_installed_module_is_in_a_checked_layer():
    """Each installed module is a key of FORBIDDEN or under one (the package root is checked alone; the
    entry script ``python -m lvgym`` runs the command layer)."""
    unchecked = [m for m in _installed_modules() if m not in ENTRY and m not in FORBIDDEN
                 and not any(m.startswith(k + ".") for k in FORBIDDEN if k != "lvgym")]
    assert not unchecked, f"modules no layer rule covers: {unchecked}"


def test_nothing_below_the_command_layer_imports_it():
    """Only the command layer's own modules and the entry scripts import ``lvgym.cli``: a layer that declares
    a command line uses ``lvgym.commandline``, beside the layers. Every installed module, the controllers'
    and the agents' too, by an import statement (function-level ones too) or a string."""
    bad = {m: sorted(n for n in _imports(m) | _loads_by_name(m) if n == "lvgym.cli" or n.startswith("lvgym.cli."))
           for m in _installed_modules() if not (m == "lvgym.cli" or m.startswith("lvgym.cli.")) and m not in ENTRY}
    bad = {m: names for m, names in bad.items() if names}
    assert not bad, f"modules below the command layer import it: {bad}"
    assert "lvgym.cli.main" in _imports("lvgym.__main__")                     # the check sees an import of it


def test_the_check_sees_an_import_path_written_as_a_string():
    assert "lvgym.agents.policies.sb3" in _imports("lvgym.agents")      # ppo's factory, registered as a string
    assert "lvgym.benchmark.runner" in _imports("lvgym.benchmark.registry")   # zero's


def test_the_benchmark_names_no_controller_and_the_command_layer_imports_every_registering_module():
    registering = _registering_modules()
    assert {"lvgym.baselines", "lvgym.agents"} <= registering
    assert not any(m.startswith(("lvgym.benchmark", "lvgym.envs", "lvgym.simulator")) for m in registering)
    evaluate = _follow([], _source_imports(ROOT.parent / "evaluate.py", ""))
    evaluate = _follow([n for n in evaluate if n.startswith("lvgym.") and _is_module(n)], evaluate)
    assert registering <= evaluate, f"evaluate.py does not import {sorted(registering - evaluate)}"
    assert registering <= _follow(["lvgym.cli.policies"], set())


def test_every_registered_factory_lives_at_or_below_the_package_that_registers_it():
    import lvgym.cli.policies  # noqa: F401  (registers the built-ins)
    from lvgym.benchmark.registry import LOADERS, POLICIES

    factories = [spec.factory for spec in POLICIES.values()] + [loader.factory for loader in LOADERS]
    modules = {f.partition(":")[0] for f in factories}
    assert modules == {"lvgym.benchmark.runner", "lvgym.baselines.pid", "lvgym.baselines.aac", "lvgym.baselines.lqg",
                       "lvgym.baselines.mpc", "lvgym.baselines.privileged", "lvgym.baselines.designed",
                       "lvgym.baselines.indi", "lvgym.baselines.eso",
                       "lvgym.agents.policies.sb3", "lvgym.agents.policies.bc", "lvgym.agents.policies.inversion",
                       "lvgym.agents.policies.inversion_record"}
    for module in modules:                          # a worker imports it: the factory reaches no study
        assert not any(n.startswith("experiments") for n in _follow([module], set())), module


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
    return _names_loaded(Path(importlib.util.find_spec(module).origin).read_text(encoding="utf-8"))


def _names_loaded(source: str) -> set[str]:
    """The module names a source imports by a string (see :func:`_loads_by_name`)."""
    tree = ast.parse(source)
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
    assert {"lvgym.cli", "lvgym.agents.policies.sb3", "lvgym.agents.training.train", "lvgym.agents.wrappers.residual",
            "lvgym.baselines.pid", "lvgym.baselines.design.tune"} <= set(modules)
    found = {m: _experiments(_imports(m) | _loads_by_name(m)) for m in modules}
    bad = {m: names for m, names in found.items() if names}
    assert not bad, f"installed modules import experiments/: {bad}"
    # the checks see such imports: a study's __main__ imports its module, and a load by name
    assert "experiments.error_budget.budget" in _imports("experiments.error_budget.budget")
    assert _names_loaded("import importlib\nm = importlib.import_module('experiments.x')\n"
                         "runpy.run_module('experiments.y')\n__import__('sys')\n") == {"experiments.x",
                                                                                        "experiments.y", "sys"}
