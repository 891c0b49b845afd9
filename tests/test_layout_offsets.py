"""Every offset a compiled kernel uses comes from a layout.

Read from the source of every compiled function of the dynamics, simulator and task kernels: an index
into an array may be a loop variable, an offset of a layout (``CTX.gimbal``, ``at(X.eta_dot, K, N)``,
``XS.q_si * j``), a name assigned from one, or one of those plus a component index smaller than the
field (``XF.q_bi + 3``); never an integer worked out by hand (``x[13]``, ``X_ETA + 2 * K + k``,
``o + 8 + k``). The semantic check is tests/test_layout_padding.py: padded layouts shift every offset,
and the flights must not change.

Also: every layout's offsets tile its vector, and the tables in the docstrings are the layouts.
"""

import ast
import importlib
import inspect
import math
import textwrap

import numpy as np
import pytest

from lvgym.packing import Field, Packed, is_offsets, offsets_layout

KERNEL_MODULES = ["lvgym.dynamics.kernels", "lvgym.dynamics.stepper", "lvgym.dynamics.invariants",
                  "lvgym.simulator.advance", "lvgym.simulator.flight", "lvgym.simulator.servo", "lvgym.simulator.strips",
                  "lvgym.simulator.imu", "lvgym.simulator.timeline", "lvgym.simulator.piece", "lvgym.envs.signals",
                  "lvgym.envs.flightcomputer", "lvgym.baselines.pidkernel", "lvgym.baselines.aackernel",
                  "lvgym.baselines.lqgkernel", "lvgym.baselines.mpckernel", "lvgym.agents.policies.mlp"]
#: a component index added to an offset whose field size the check cannot see (a local name): a quaternion's
_COMPONENT = 4


def _compiled_functions(mod) -> list:
    """``(name, python function)`` of every numba function (njit or cfunc) of ``mod``."""
    out = []
    for name, obj in vars(mod).items():
        py = getattr(obj, "py_func", None) or getattr(obj, "_pyfunc", None)
        if py is not None and getattr(py, "__module__", None) == mod.__name__:
            out.append((name, py))
    return out


class _Check:
    """Offsets in the index expressions of one function (see the module docstring)."""

    def __init__(self, fn_source: str, module_globals: dict) -> None:
        self.tree = ast.parse(textwrap.dedent(fn_source))
        self.layouts = {k for k, v in module_globals.items() if is_offsets(v)}
        self.globals = module_globals
        self.derived: set[str] = set()
        self.sizes: dict[str, int] = {}                # derived names with a known field size
        self.problems: list[str] = []

    def _size(self, node: ast.AST) -> int | None:
        """The field size of ``LAYOUT.field``, ``at(LAYOUT.field, K, N)`` or a name assigned from one
        (None when not such an expression or not known)."""
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "at" and node.args:
            node = node.args[0]
        if isinstance(node, ast.Name):
            return self.sizes.get(node.id)
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in self.layouts:
            lay = offsets_layout(self.globals[node.value.id])
            if isinstance(lay, Packed) and node.attr in lay:
                return lay.field(node.attr).size
            field = next((f for f in getattr(lay, "fields", ()) if f.name == node.attr), None)
            if field is not None and hasattr(field, "per_mode") and field.per_mode == field.per_slosh == \
                    field.per_both == 0:
                return field.const
            return _COMPONENT
        return None

    def layout_expr(self, node: ast.AST) -> bool:
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in self.layouts:
            return True
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "at":
            return True
        if isinstance(node, ast.Name) and node.id in self.derived:
            return True
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
            return self.layout_expr(node.left) or self.layout_expr(node.right)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult):   # a stride of the layout times j
            return any(isinstance(s, ast.Attribute) and self.layout_expr(s) for s in (node.left, node.right))
        if isinstance(node, ast.IfExp):
            return self.layout_expr(node.body) and self.layout_expr(node.orelse)
        return False

    def check_expr(self, node: ast.AST, where: str, bare_ok: bool, upper: bool = False) -> None:
        if isinstance(node, ast.Constant) and isinstance(node.value, int) and not isinstance(node.value, bool):
            if not (bare_ok and node.value < 3):
                self.problems.append(f"{where}: a bare integer index {node.value}")
            return
        # a square matrix field stored row major (``J_b``): ``o_J + 3 * i + k`` is its entry (i, k)
        sizes = [s for s in (self._size(n) for n in ast.walk(node)) if s is not None]
        matrix = {int(round(math.sqrt(s))) for s in sizes if s > 1 and int(round(math.sqrt(s))) ** 2 == s}
        for sub in ast.walk(node):
            if not isinstance(sub, ast.BinOp):
                continue
            ints = [s for s in (sub.left, sub.right) if isinstance(s, ast.Constant) and isinstance(s.value, int)]
            if not ints:
                continue
            other = sub.right if ints[0] is sub.left else sub.left
            c = ints[0].value
            if isinstance(sub.op, ast.Mult):
                if not (c in matrix and isinstance(other, ast.Name)):
                    self.problems.append(f"{where}: {ast.unparse(sub)} multiplies an offset by hand")
                continue
            size = self._size(other)
            limit = (size if size is not None else _COMPONENT) + (1 if upper else 0)
            plain = not any(isinstance(n, ast.Constant) and isinstance(n.value, int) for n in ast.walk(other))
            if isinstance(sub.op, ast.Add) and self.layout_expr(other) and 0 <= c < limit:
                continue                                   # a component of a layout's field
            if plain and ((isinstance(sub.op, ast.Add) and c == 1) or (isinstance(sub.op, ast.Sub) and c <= 2)):
                continue                                   # the next (or last) row of a table: i + 1, n - 2
            self.problems.append(f"{where}: {ast.unparse(sub)} is not a layout offset plus a component")

    def run(self) -> list[str]:
        fn = self.tree.body[0]
        # an offset handed in by the caller (who took it from a layout): ``q[o + 3]`` of a quaternion at o
        self.derived |= {a.arg for a in fn.args.args}
        index_names: set[str] = set()
        for node in ast.walk(fn):                      # the names assigned from a layout's offsets
            if isinstance(node, ast.Assign):
                targets = node.targets[0].elts if isinstance(node.targets[0], ast.Tuple) else [node.targets[0]]
                values = node.value.elts if isinstance(node.value, ast.Tuple) else [node.value]
                for t, v in zip(targets, values):
                    if isinstance(t, ast.Name) and self.layout_expr(v):
                        self.derived.add(t.id)
                        size = self._size(v)
                        if size is not None and (isinstance(v, ast.Attribute) or isinstance(v, ast.Call)):
                            self.sizes[t.id] = size
        for node in ast.walk(fn):
            if not isinstance(node, ast.Subscript):
                continue
            where = f"{fn.name}: {ast.unparse(node)}"
            parts = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
            for part in parts:
                if isinstance(part, ast.Slice):
                    for bound, up in ((part.lower, False), (part.upper, True)):
                        if bound is not None:
                            self.check_expr(bound, where, True, upper=up)
                    continue
                self.check_expr(part, where, bare_ok=True)
                index_names |= {n.id for n in ast.walk(part) if isinstance(n, ast.Name)}
        for node in ast.walk(fn):                      # what feeds an index by way of a local name
            if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name) and \
                    node.targets[0].id in index_names:
                self.check_expr(node.value, f"{fn.name}: {ast.unparse(node)}", bare_ok=True)
        return self.problems


def _problems(module: str) -> list[str]:
    mod = importlib.import_module(module)
    out = []
    for name, py in _compiled_functions(mod):
        out += _Check(inspect.getsource(py), vars(mod)).run()
    return out


@pytest.mark.parametrize("module", KERNEL_MODULES)
def test_kernels_take_their_offsets_from_a_layout(module):
    mod = importlib.import_module(module)
    assert _compiled_functions(mod), f"{module} has no compiled function to check"
    problems = _problems(module)
    assert not problems, "\n".join(problems)


def test_the_check_sees_offsets_worked_out_by_hand():
    glob = {"CTX": Packed("t", [Field("gimbal", 2), Field("q", 4)]).at, "M": Packed("m", [Field("m", 9)]).at}
    bad = ["def k(x, K, j):\n    return x[13 + 2 * K + K + j]",
           "def k(x, j):\n    o = 21 + 4 * j\n    return x[o + 1]",
           "def k(x):\n    return x[6]",
           "def k(x):\n    return x[CTX.gimbal + 2]",                 # beyond the 2-entry field
           "def k(x, o):\n    return x[o + 8]",
           "def k(rhs):\n    for i in range(3):\n        rhs[3 + i] = 0.0",
           "def k(x, i):\n    return x[CTX.q + 3 * i]"]                 # a 4-entry field is no matrix
    good = ["def k(x, j):\n    return x[CTX.gimbal + 1] + x[CTX.q + 3] + x[j] + x[0]",
            "def k(x, K, N):\n    o = at(X, K, N)\n    return x[o + 2]",
            "def k(x):\n    return x[CTX.q:CTX.q + 4]",
            "def k(t, tl):\n    i = search(tl, t) - 1\n    return tl[i + 1] - tl[i]",
            "def k(x, i, j):\n    o = M.m\n    return x[o + 3 * i + j] + x[o + 8]"]
    for src in bad:
        assert _Check(src, glob).run(), src
    for src in good:
        assert not _Check(src, glob).run(), src


LAYOUTS = ["lvgym.simulator.layouts:CONTEXT", "lvgym.simulator.layouts:CONDITIONS", "lvgym.simulator.layouts:RAIL",
           "lvgym.simulator.layouts:RAIL_STATE", "lvgym.simulator.layouts:SERVO", "lvgym.simulator.layouts:ACTUATOR",
           "lvgym.simulator.layouts:IMU", "lvgym.simulator.layouts:IMU_STATE",
           "lvgym.envs.layouts:TASK", "lvgym.envs.layouts:OBS_STATE", "lvgym.envs.layouts:OBS_SENSORS",
           "lvgym.envs.layouts:OBS_FLIGHT", "lvgym.envs.layouts:FLIGHT_DRAWS", "lvgym.envs.layouts:NAV", "lvgym.envs.layouts:REWARD"]


@pytest.mark.parametrize("ref", LAYOUTS)
def test_a_layout_tiles_its_vector(ref):
    module, name = ref.split(":")
    lay = getattr(importlib.import_module(module), name)
    covered = np.zeros(lay.size, dtype=int)
    for o, f in lay.leaves():
        covered[o:o + f.size] += 1
    assert covered.max() <= 1
    assert lay.padded or covered.min() == 1                  # unpadded: no gap


def test_the_docstring_tables_are_the_layouts():
    from lvgym.dynamics import layout as dyn
    from lvgym.envs import ascent
    from lvgym.envs.layouts import OBS_SENSORS, OBS_STATE
    from lvgym.simulator import layouts as sim
    for o, f in OBS_STATE.leaves():
        line = next(line for line in ascent.__doc__.splitlines() if f"``{f.name}``" in line)
        assert line.split()[0] == str(o)
        assert f.doc.split(";")[0][:30] in line
    for o, f in OBS_SENSORS.leaves():
        assert f"``{f.name}``" in ascent.__doc__
    from lvgym.envs.layouts import FLIGHT_SOURCE, OBS_FLIGHT
    for o, f in OBS_FLIGHT.leaves():
        assert f.doc.split(";")[0][:30] in ascent.__doc__ and FLIGHT_SOURCE[f.name] in ascent.__doc__
    for lay in (sim.CONTEXT, sim.CONDITIONS, sim.ACTUATOR, sim.IMU, sim.IMU_STATE):
        assert lay.table() in sim.__doc__
    for lin in (dyn.STATE, dyn.PARAMS, dyn.LOADS):
        assert lin.table() in dyn.__doc__
