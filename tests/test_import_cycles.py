"""No import cycle among lvgym's modules but those docs/architecture.md lists with a reason.

The graph has one node per installed module (``lvgym``, ``lvgym.agents``, ``lvgym.baselines`` and every module
under them: pyproject.toml's package-dir, so ``agents/`` is ``lvgym.agents``) and an edge from a module to
every lvgym module it imports: by an import statement anywhere in its source (at module level or inside a
function or method), or by ``importlib.import_module`` / ``__import__`` of a constant name. A relative import
is resolved against the module's package; ``from package import name`` is an edge to ``package.name`` when
that is a module, else to ``package``. Two kinds of import are no edge: one under ``if TYPE_CHECKING:``
never runs (it names types for annotations), and importing ``a.b.c`` runs the ``__init__`` of ``a`` and
``a.b`` first without ``a.b.c`` depending on them (a package that imports its own submodules would
otherwise close a cycle with each of them).

A cycle is a closed path of distinct modules; every one is found (the elementary cycles of each strongly
connected component) and must be a row of the table under "Import cycles that stay" in
docs/architecture.md, which in turn lists only cycles that exist.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import pkgutil
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INSTALLED = ("lvgym", "lvgym.agents", "lvgym.baselines")
_LOADERS = {"import_module", "__import__"}
#: more cycles than this in one component: report them without listing every one
_MAX_CYCLES = 1000


def installed_modules() -> set[str]:
    names: set[str] = set()
    for package in INSTALLED:
        pkg = importlib.import_module(package)
        names |= {package} | {m.name for m in pkgutil.walk_packages(pkg.__path__, package + ".")}
    return names


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _statements(tree: ast.AST):
    """Every node of ``tree`` but those under ``if TYPE_CHECKING:`` (its ``else`` runs and is kept)."""
    todo = [tree]
    while todo:
        node = todo.pop()
        yield node
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            todo.extend(node.orelse)
            continue
        todo.extend(ast.iter_child_nodes(node))


def _target(name: str, modules: set[str]) -> str | None:
    """The module of ``modules`` an import of ``name`` runs: ``name`` itself, else its longest prefix."""
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        if ".".join(parts[:k]) in modules:
            return ".".join(parts[:k])
    return None


def imported(source: str, module: str, is_package: bool, modules: set[str]) -> set[str]:
    """The modules of ``modules`` that the source of ``module`` (a package's ``__init__`` when
    ``is_package``) imports (see the module docstring)."""
    package = module if is_package else module.rpartition(".")[0]
    names: set[str] = set()
    for node in _statements(ast.parse(source)):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            names |= {f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names}
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            called = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            if called in _LOADERS and isinstance(node.args[0].value, str):
                names.add(node.args[0].value)
    return {t for t in (_target(n, modules) for n in names) if t is not None and t != module}


def import_graph() -> dict[str, set[str]]:
    """module -> the lvgym modules it imports, for every installed module."""
    modules = installed_modules()
    graph = {}
    for m in sorted(modules):
        spec = importlib.util.find_spec(m)
        graph[m] = imported(Path(spec.origin).read_text(encoding="utf-8"), m, spec.origin.endswith("__init__.py"),
                            modules)
    return graph


def components(graph: dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = set()
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.add(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(comp)
    return out


def cycles(graph: dict[str, set[str]]) -> list[tuple[str, ...]]:
    """Every elementary cycle of ``graph``, each as its modules from the smallest name on (the edge back to
    the first is implied), sorted; at most :data:`_MAX_CYCLES` per component."""
    out = []
    for comp in components(graph):
        order = sorted(comp)
        found = 0
        for i, start in enumerate(order):
            allowed = set(order[i:])
            todo = [(start, (start,))]
            while todo and found < _MAX_CYCLES:
                v, path = todo.pop()
                for w in sorted(graph[v] & allowed):
                    if w == start:
                        out.append(path)
                        found += 1
                    elif w not in path:
                        todo.append((w, path + (w,)))
    return sorted(out)


def listed_cycles() -> dict[tuple[str, ...], str]:
    """The rows of docs/architecture.md's table of the import cycles that stay: the cycle (its modules in
    backquotes, ``a -> b -> a``), rotated to start at its smallest name, and the reason."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text.split("### Import cycles that stay", 1)[1].split("\n#", 1)[0]
    out = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        names = re.findall(r"`([\w.]+)`", cells[0]) if len(cells) >= 2 else []
        if len(names) < 3 or names[0] != names[-1]:
            continue
        ring = names[:-1]
        k = ring.index(min(ring))
        out[tuple(ring[k:] + ring[:k])] = cells[1]
    return out


def _arrow(cycle: tuple[str, ...]) -> str:
    return " -> ".join(cycle + cycle[:1])


# ------------------------------------------------------------------------------------------ the checker
def test_the_edges_are_the_imports_that_run():
    modules = {"p", "p.a", "p.b", "p.c", "p.d", "p.sub", "p.sub.e", "q"}
    source = ("from __future__ import annotations\nimport os\nfrom typing import TYPE_CHECKING\n"
              "from . import b\nfrom .sub import e\nfrom p import thing\n"
              "if TYPE_CHECKING:\n    from .c import C\nelse:\n    import q\n"
              "def f():\n    from .d import g\n    return importlib.import_module('p.sub')\n")
    assert imported(source, "p.a", False, modules) == {"p.b", "p.sub.e", "p", "q", "p.d", "p.sub"}
    # a package's relative import is against itself; a module's own name is no edge
    assert imported("from . import a\nfrom .a import x\nimport p\n", "p", True, modules) == {"p.a"}
    assert imported("from .. import b\nfrom ..c import y\n", "p.sub.e", False, modules) == {"p.b", "p.c"}


def test_every_elementary_cycle_is_found_once():
    graph = {"a": {"b"}, "b": {"a", "c"}, "c": {"a", "d"}, "d": set(), "e": {"e2"}, "e2": {"e"}, "f": {"a"}}
    assert cycles(graph) == [("a", "b"), ("a", "b", "c"), ("e", "e2")]
    assert sorted(map(sorted, components(graph))) == [["a", "b", "c"], ["e", "e2"]]


def test_the_graph_holds_module_level_and_function_level_imports():
    graph = import_graph()
    assert {"lvgym", "lvgym.agents.policies.sb3", "lvgym.baselines.design.tune", "lvgym.cli.main"} <= set(graph)
    assert "lvgym.commandline" in graph["lvgym.vehicle.slender"]         # inside main()
    assert "lvgym.envs.vector" in graph["lvgym"]                          # inside make_vector()
    assert "lvgym.simulator.tabulate" in graph["lvgym.simulator.core"]   # at module level
    assert "lvgym.simulator.core" not in graph["lvgym.simulator.view"]   # under TYPE_CHECKING only


# ------------------------------------------------------------------------------------------ the rule
@pytest.fixture(scope="module")
def found() -> list[tuple[str, ...]]:
    return cycles(import_graph())


def test_no_import_cycle_but_those_listed(found):
    listed = listed_cycles()
    new = sorted((_arrow(c) for c in found if c not in listed), key=len)
    assert not new, (f"{len(new)} import cycles (list one in docs/architecture.md with its reason, or remove it), "
                     "the shortest first:\n" + "\n".join(new[:20]))


def test_every_listed_cycle_exists_and_says_why(found):
    assert "| cycle | why it stays |" in (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    listed = listed_cycles()
    gone = [_arrow(c) for c in listed if c not in found]
    assert not gone, "docs/architecture.md lists import cycles that no longer exist:\n" + "\n".join(gone)
    assert all(len(reason.split()) >= 3 for reason in listed.values()), listed
