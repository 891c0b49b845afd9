"""Compiled functions take a few named blocks, not long argument lists (at most 12 parameters).

Two ways of finding them, so that neither can miss one: every numba dispatcher (``@nb.njit``) and
``cfunc`` object in the globals of every module of the installed packages (``lvgym``, ``lvgym.baselines``,
``lvgym.agents``), and every function definition, at any depth (a kernel made inside a factory too), of
their source files that is decorated with ``njit``, ``jit`` or ``cfunc``. The
:class:`~lvgym.simulator.Simulator` is built from a few frozen specs, so its constructor is held to the
same limit.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
from pathlib import Path

from numba.core.ccallback import CFunc
from numba.core.registry import CPUDispatcher

import lvgym
import lvgym.agents
import lvgym.baselines

MAX_ARGUMENTS = 12
PACKAGES = (lvgym, lvgym.baselines, lvgym.agents)
DECORATORS = {"njit", "jit", "cfunc"}


def _modules() -> list[str]:
    names = []
    for pkg in PACKAGES:
        names.append(pkg.__name__)
        names += [m.name for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + ".")
                  if not m.name.endswith(".__main__")]
    return sorted(set(names))


def _compiled() -> dict[str, int]:
    """``module.qualname`` -> number of parameters of every compiled function in the modules' globals
    (dispatchers and cfuncs)."""
    out = {}
    for name in _modules():
        for obj in vars(importlib.import_module(name)).values():
            if isinstance(obj, CPUDispatcher):
                py = obj.py_func
            elif isinstance(obj, CFunc):
                py = obj._pyfunc
            else:
                continue
            out[f"{py.__module__}.{py.__qualname__}"] = len(inspect.signature(py).parameters)
    return out


def _count(args: ast.arguments) -> int:
    return len(args.posonlyargs) + len(args.args) + len(args.kwonlyargs) + bool(args.vararg) + bool(args.kwarg)


def _decorated_in(source: str, label: str) -> dict[str, int]:
    """``label:line name`` -> number of parameters of every function of ``source`` (at any depth)
    decorated with njit, jit or cfunc (called or not, as ``nb.njit`` or a bare name)."""
    out = {}
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for dec in node.decorator_list:
                target = dec.func if isinstance(dec, ast.Call) else dec
                if (target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")) in DECORATORS:
                    out[f"{label}:{node.lineno} {node.name}"] = _count(node.args)
    return out


def _decorated() -> dict[str, int]:
    out = {}
    for pkg in PACKAGES:
        for path in sorted(Path(pkg.__path__[0]).rglob("*.py")):
            out |= _decorated_in(path.read_text(encoding="utf-8"), str(path))
    return out


def test_no_compiled_function_takes_more_than_twelve_arguments():
    found = _compiled()
    # the walk sees the kernels it is meant to hold to the limit (it cannot pass on an empty list)
    assert {"lvgym.dynamics.kernels.vehicle_deriv", "lvgym.dynamics.kernels._eliminate_pendulum",
            "lvgym.environment.aerokernels.aero_loads_at", "lvgym.simulator.flight._flight_loads",
            "lvgym.envs.signals.observe_k", "lvgym.baselines.lqgkernel.lqg_step_k"} <= set(found)
    assert found["lvgym.dynamics.kernels._eliminate_pendulum"] == 9
    long = {k: n for k, n in found.items() if n > MAX_ARGUMENTS}
    assert not long, f"compiled functions with more than {MAX_ARGUMENTS} parameters: {long}"


def test_no_decorated_function_takes_more_than_twelve_arguments():
    found = _decorated()
    # every dispatcher of the modules' globals is among the decorated definitions the source walk found
    names = {key.rpartition(" ")[2] for key in found}
    walked = {qualname.rpartition(".")[2] for qualname in _compiled()}
    assert walked - names <= {"_flight_loads", "_zoh"}          # the loads functions, compiled by a call
    long = {k: n for k, n in found.items() if n > MAX_ARGUMENTS}
    assert not long, f"njit/cfunc functions with more than {MAX_ARGUMENTS} parameters: {long}"


def test_the_source_walk_finds_nested_kernels_and_counts_every_kind_of_parameter():
    source = ("import numba as nb\nfrom numba import njit\n\n"
              "def factory(n):\n"
              "    @nb.njit(cache=True)\n"
              "    def inner(a, b, /, c, *d, e, **f):\n"
              "        return a\n"
              "    @njit\n"
              "    def bare(x):\n"
              "        return x\n"
              "    def plain(a, b, c, d, e, f, g, h, i, j, k, l, m):\n"
              "        return a\n"
              "    return inner, bare, plain\n")
    assert _decorated_in(source, "f") == {"f:6 inner": 6, "f:9 bare": 1}


def test_the_simulator_is_built_from_a_few_specs():
    from lvgym.simulator import Simulator

    assert len(inspect.signature(Simulator.__init__).parameters) <= MAX_ARGUMENTS
